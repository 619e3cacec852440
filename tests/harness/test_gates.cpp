// SPDX-License-Identifier: GPL-3.0-or-later
// CI gates, JUnit XML, statistics over seeds in the report, and `diff`. The figures gated on
// are facts: a camera with a 57 degree field of view sees well under half of the circle; a
// constant circle in a square room has the RMSE of the closed-form wedge minima.
#include "cli_support.hpp"
#include "score_support.hpp"
#include "test_scenario_files.hpp"

#include "harness/report/rollup.hpp"

#include <algorithm>
#include <cmath>

namespace fs = std::filesystem;
using sonomap::test::run_sonomap;
using sonomap::test::text_of;

namespace {

std::string seeded_sweep(const std::string& extra) {
  return "name: gated\nframes: 2\nseeds: [1, 2, 3]\n"
         "set: [sensor.width=160, sensor.height=120, sensor.intrinsics.fx=131.25,\n"
         "      sensor.intrinsics.fy=131.25, sensor.intrinsics.cx=79.5, sensor.intrinsics.cy=59.5,\n"
         "      edf.enabled=false]\n"
         "scenarios:\n  - {id: smoke, file: " + sonomap::test::shipped("scenes/smoke.yaml").string() + "}\n"
         "variants:\n  - {id: depth, mapper: depth_only}\n  - {id: tsdf, mapper: tsdf, voxel: 0.1}\n"
         "pictures: [-1]\nsweeps: [-1]\n" + extra;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("gates: a failing gate makes compare and report exit 1 and JUnit shows one case per check",
          "[gates]") {
  sonomap::test::ScratchDir scratch("gates");
  const std::string checks =
      "gates:\n"
      "  - {scenario: smoke, variant: depth, metric: circle_final_coverage, op: '<', value: 0.5}\n"
      "  - {text: sees the whole circle, scenario: smoke, variant: depth, metric: circle_final_coverage,\n"
      "     op: '>=', value: 0.99}\n"
      "claims:\n"
      "  - {text: a camera sees under half the circle, scenario: smoke, variant: tsdf,\n"
      "     metric: circle_final_coverage, op: '<', value: 0.5}\n";
  const fs::path sweep = scratch.write("sweep.yaml", seeded_sweep(checks));
  const fs::path out = scratch.path() / "out", junit = scratch.path() / "junit.xml";
  const auto r = run_sonomap({"--quiet", "compare", sweep.string(), "--out", out.string(), "-j", "2",
                              "--junit", junit.string()});
  INFO(r.output);
  CHECK(r.status == 1);  // every run finished; the second gate fails
  CHECK(fs::exists(out / "runs" / "smoke-tsdf-s3" / "summary.json"));
  const std::string report = text_of(out / "report.md");
  INFO(report);
  CHECK(report.find("## Gates") != std::string::npos);
  CHECK(report.find("| sees the whole circle | smoke / depth | `circle_final_coverage` |") != std::string::npos);
  CHECK(report.find("1 of 2 gates pass.") != std::string::npos);
  const std::string xml = text_of(junit);
  INFO(xml);
  CHECK(count(xml, "<testcase ") == 3);
  CHECK(count(xml, "<failure ") == 1);
  CHECK(xml.find("tests=\"2\" failures=\"1\"") != std::string::npos);
  CHECK(xml.find("name=\"circle_final_coverage &lt; 0.5\"") != std::string::npos);

  const auto again = run_sonomap({"--quiet", "report", out.string()});
  CHECK(again.status == 1);
  CHECK(again.output.find("1 of 2 gates fail") != std::string::npos);
}

TEST_CASE("a gate naming a scenario the sweep does not have is rejected with its line and key", "[gates]") {
  sonomap::test::ScratchDir scratch("gates-bad");
  const fs::path sweep = scratch.write(
      "sweep.yaml", seeded_sweep("gates:\n  - {scenario: hall, variant: depth, metric: circle_final_rmse,\n"
                                 "     op: '<', value: 1}\n"));
  const auto r = run_sonomap({"compare", sweep.string(), "--out", (scratch.path() / "out").string()});
  CHECK(r.status == 2);
  CHECK(r.output.find("sweep.yaml:15") != std::string::npos);
  CHECK(r.output.find("gates[0].scenario") != std::string::npos);
}

// The report's intervals, recomputed here from rollup.csv's own numbers with the t quantile of
// the published table (2 degrees of freedom for 3 seeds).
TEST_CASE("the report's statistics over seeds are the t intervals of the rolled-up values", "[gates][stats]") {
  sonomap::test::ScratchDir scratch("gates-stats");
  const fs::path sweep = scratch.write("sweep.yaml", seeded_sweep(""));
  const fs::path out = scratch.path() / "out";
  const auto r = run_sonomap({"--quiet", "compare", sweep.string(), "--out", out.string(), "-j", "2"});
  INFO(r.output);
  REQUIRE(r.status == 0);
  const auto rollup = sonomap::harness::RollupTable::parse(text_of(out / "rollup.csv"));
  const auto stats = sonomap::harness::RollupTable::parse(text_of(out / "rollup_stats.csv"));
  const int metric = rollup.column("circle_mean_rmse");
  std::vector<double> values;
  for (const auto& row : rollup.rows)
    if (rollup.cell(row, rollup.column("variant")) == "tsdf") values.push_back(rollup.number(row, metric));
  REQUIRE(values.size() == 3);
  const double mean = (values[0] + values[1] + values[2]) / 3;
  double squares = 0;
  for (double v : values) squares += (v - mean) * (v - mean);
  const double half = 4.302652729911275 * std::sqrt(squares / 2) / std::sqrt(3.0);
  bool found = false;
  for (const auto& row : stats.rows)
    if (row[1] == "tsdf" && row[2] == "circle_mean_rmse") {
      found = true;
      CHECK(row[3] == "3");
      CHECK(std::stod(row[4]) == Approx(mean).epsilon(1e-5));
      CHECK(std::stod(row[6]) == Approx(mean - half).epsilon(1e-5).margin(1e-9));
      CHECK(std::stod(row[7]) == Approx(mean + half).epsilon(1e-5).margin(1e-9));
    }
  CHECK(found);
  const std::string pairs = text_of(out / "pairs.csv");
  CHECK(pairs.find("smoke,depth,tsdf,circle_mean_rmse,3,") != std::string::npos);
  CHECK(text_of(out / "report.md").find("## Statistics over seeds") != std::string::npos);
  CHECK(fs::exists(out / "plots" / "smoke_stats_circle_mean_rmse.png"));
}

TEST_CASE("diff prints the metric changes and fails only past a tolerance", "[diff]") {
  sonomap::test::ScratchDir scratch("diff");
  const fs::path scene = scratch.write("square.yaml", sonomap::test::square_room_scenario());
  auto score = [&](double range, const std::string& name) {
    const fs::path csv = scratch.write(name + ".csv", sonomap::test::constant_circle_csv({1}, range));
    const fs::path out = scratch.path() / name;
    REQUIRE(run_sonomap({"--quiet", "score", scene.string(), "--circle", csv.string(), "--out", out.string(),
                         "--pictures", "-1"}).status == 0);
    return out.string();
  };
  // Closer to the walls (2 to 2.83 m) is better: RMSE by hand, larger at 1.5 m than at 2.2 m.
  const std::string far = score(2.2, "far"), near = score(1.5, "near");
  REQUIRE(sonomap::test::square_room_rmse(1.5) > sonomap::test::square_room_rmse(2.2) + 0.1);
  const auto worse = run_sonomap({"diff", far, near, "--tolerance", "circle_mean_rmse=0.05"});
  INFO(worse.output);
  CHECK(worse.status == 1);
  CHECK(worse.output.find("circle_mean_rmse") != std::string::npos);
  CHECK(worse.output.find("worse (tolerance 0.05: FAIL)") != std::string::npos);
  const auto better = run_sonomap({"diff", near, far, "--tolerance", "circle_mean_rmse=0.05"});
  CHECK(better.status == 0);
  CHECK(better.output.find("better (tolerance 0.05: ok)") != std::string::npos);
  CHECK(run_sonomap({"diff", far, near}).status == 0);  // no tolerance: a report, not a verdict
  const auto loose = run_sonomap({"diff", far, near, "--tolerance", "circle_mean_rmse=5"});
  CHECK(loose.status == 0);
  const auto bad = run_sonomap({"diff", far, near, "--tolerance", "circle_rmse=0.1"});
  CHECK(bad.status == 2);
  CHECK(bad.output.find("circle_rmse") != std::string::npos);
  CHECK(run_sonomap({"diff", far, (scratch.path() / "none").string()}).status == 2);
}
