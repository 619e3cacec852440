// SPDX-License-Identifier: GPL-3.0-or-later
// score: rasters from any program judged against the exact ground truth. Facts: scoring does
// not depend on who produced an estimate (a run's own circle scores the run's metrics); a
// constant-range circle in a square room scores the RMSE of closed-form wedge minima; bad
// estimate files are refused with file:line and leave nothing behind.
#include "cli_support.hpp"
#include "run_support.hpp"
#include "score_support.hpp"
#include "test_scenario_files.hpp"

#include "harness/formats/run_summary.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

namespace fs = std::filesystem;
using nlohmann::json;
using sonomap::test::run_sonomap;

namespace {

json summary_of(const fs::path& dir) {
  std::ifstream in(dir / "summary.json");
  return json::parse(in);
}

std::vector<std::string> with_small_camera(std::vector<std::string> args) {
  for (const auto& s : sonomap::test::small_camera()) args.insert(args.end(), {"--set", s});
  return args;
}

}  // namespace

TEST_CASE("scoring the circle and cylinder a run wrote gives the run's own metrics", "[score]") {
  sonomap::test::ScratchDir scratch("score-run");
  const fs::path run = scratch.path() / "run", scored = scratch.path() / "scored";
  const std::string scene = sonomap::test::shipped("scenes/smoke.yaml").string();
  const auto r = run_sonomap(with_small_camera({"--quiet", "run", scene, "--out", run.string(), "--frames", "4",
                                                "--every", "2", "--mapper", "tsdf", "--voxel", "0.1",
                                                "--pictures", "-1", "--sweeps", "-1", "--set", "edf.enabled=false"}));
  INFO(r.output);
  REQUIRE(r.status == 0);
  const json expected = summary_of(run);
  const std::string tolerance = expected["config"]["metrics"]["ghost_tolerance"].dump();
  const auto s = run_sonomap(with_small_camera(
      {"--quiet", "score", scene, "--circle", (run / "circle.csv").string(), "--cylinder",
       (run / "cylinder.csv").string(), "--out", scored.string(), "--frames", "4", "--set",
       "metrics.ghost_tolerance=" + tolerance, "--pictures", "-1"}));
  INFO(s.output);
  REQUIRE(s.status == 0);
  const json got = summary_of(scored);
  CHECK(got["evaluated_frames"] == expected["evaluated_frames"]);
  for (const char* raster : {"circle", "cylinder"}) {
    const json& e = expected["metrics"][raster];
    const json& g = got["metrics"][raster];
    for (const char* integer : {"cells", "truth_occupied", "estimate_known", "known_in_both", "ghosts", "edge_cells"})
      CHECK(g["final"][integer] == e["final"][integer]);
    // The CSV keeps micrometres: the RMSE agrees to well under a millimetre.
    CHECK(g["final"]["coverage"].get<double>() == e["final"]["coverage"].get<double>());
    CHECK(g["final"]["rmse"].get<double>() == Approx(e["final"]["rmse"].get<double>()).margin(1e-5));
    CHECK(g["mean"]["rmse"].get<double>() == Approx(e["mean"]["rmse"].get<double>()).margin(1e-5));
    CHECK(g["mean"]["coverage"].get<double>() == Approx(e["mean"]["coverage"].get<double>()).epsilon(1e-12));
  }
  // The scored folder's truth columns are the run's (the same exact ground truth).
  CHECK(sonomap::test::text_of(scored / "circle.csv") == sonomap::test::text_of(run / "circle.csv"));
  CHECK(sonomap::test::text_of(scored / "frames.csv").substr(0, 200) ==
        sonomap::test::text_of(run / "frames.csv").substr(0, 200));
}

TEST_CASE("a constant-range circle in a square room scores the RMSE of the closed-form wedge minima",
          "[score]") {
  sonomap::test::ScratchDir scratch("score-square");
  const fs::path scene = scratch.write("square.yaml", sonomap::test::square_room_scenario());
  const double range = 1.25;
  const fs::path circle = scratch.write("circle.csv", sonomap::test::constant_circle_csv({0, 1}, range));
  const fs::path out = scratch.path() / "out";
  const auto s = run_sonomap({"--quiet", "score", scene.string(), "--circle", circle.string(), "--out", out.string()});
  INFO(s.output);
  REQUIRE(s.status == 0);
  const json m = summary_of(out)["metrics"]["circle"];
  CHECK(m["final"]["coverage"].get<double>() == 1.0);
  CHECK(m["final"]["ghosts"] == 360);  // every bin 0.75 m or more closer than the wall
  CHECK(m["final"]["rmse"].get<double>() == Approx(sonomap::test::square_room_rmse(range)).epsilon(1e-6));
  CHECK(m["mean"]["rmse"].get<double>() == Approx(sonomap::test::square_room_rmse(range)).epsilon(1e-6));
  CHECK(m["final"]["rmse_off_edges"].get<double>() == Approx(sonomap::test::square_room_rmse(range)).epsilon(1e-6));
  CHECK(fs::exists(out / "pictures" / "frame_000001_circle.png"));
  CHECK(!fs::exists(out / "cylinder.csv"));
  // report treats it like any run.
  const fs::path sweep = scratch.path() / "sweep";
  fs::create_directories(sweep / "runs");
  fs::rename(out, sweep / "runs" / "square-const");
  const auto rep = run_sonomap({"--quiet", "report", sweep.string()});
  INFO(rep.output);
  CHECK(rep.status == 0);
  CHECK(sonomap::test::text_of(sweep / "rollup.csv").find("square-const,square,external,external") != std::string::npos);
}

TEST_CASE("bad estimate files are refused with file:line and leave nothing behind", "[score]") {
  sonomap::test::ScratchDir scratch("score-bad");
  const fs::path scene = scratch.write("square.yaml", sonomap::test::square_room_scenario());
  const std::string good = sonomap::test::constant_circle_csv({0}, 1.0);
  // (name, text, expected "file:line", expected words)
  const std::vector<std::tuple<std::string, std::string, std::string, std::string>> cases = {
      {"unknown_frame", good + "7,0,1.0\n", "unknown_frame.csv:362", "frame"},
      {"bin_range", "frame,bin,estimate\n0,360,1.0\n", "bin_range.csv:2", "bin"},
      {"nan", "frame,bin,estimate\n0,0,nan\n", "nan.csv:2", "finite"},
      {"negative", "frame,bin,estimate\n0,0,-0.5\n", "negative.csv:2", ">= 0"},
      {"duplicate", good + "0,5,1.0\n", "duplicate.csv:362", "duplicate"},
      {"no_header", "0,0,1.0\n", "no_header.csv:1", "header"},
      {"missing_cells", "frame,bin,estimate\n0,0,1.0\n", "missing_cells.csv", "1 of its 360"},
  };
  for (const auto& [name, text, where, words] : cases) {
    const fs::path csv = scratch.write(name + ".csv", text);
    const fs::path out = scratch.path() / ("out_" + name);
    const auto s = run_sonomap({"--quiet", "score", scene.string(), "--circle", csv.string(), "--out", out.string()});
    INFO(name << ": " << s.output);
    CHECK(s.status == 2);
    CHECK(s.output.find(where) != std::string::npos);
    CHECK(s.output.find(words) != std::string::npos);
    CHECK(sonomap::test::nothing_written(out));
  }
}

TEST_CASE("a scored folder reads back through the run's summary type, with what was scored",
          "[score][summary]") {
  sonomap::test::ScratchDir scratch("score-typed");
  const fs::path scene = scratch.write("square.yaml", sonomap::test::square_room_scenario());
  const fs::path circle = scratch.write("circle.csv", sonomap::test::constant_circle_csv({0, 1}, 1.25));
  const fs::path out = scratch.path() / "out";
  REQUIRE(run_sonomap({"--quiet", "score", scene.string(), "--circle", circle.string(), "--out", out.string(),
                       "--pictures", "-1", "--tag", "variant=const"}).status == 0);
  const sonomap::harness::RunSummary s = sonomap::harness::read_run_summary(out);
  REQUIRE(s.scored.has_value());
  CHECK(s.scored->circle == circle.string());
  CHECK_FALSE(s.scored->cylinder.has_value());
  CHECK(s.config.command == std::optional<std::string>(""));
  CHECK_FALSE(s.config.edf.has_value());  // score runs no EDF comparison
  CHECK(s.config.mapper == "external");
  CHECK(s.tags.at("variant") == "const");
  CHECK(s.evaluated_frames == 2);
  REQUIRE(s.circle.final_frame.has_value());
  CHECK(s.circle.final_frame->rmse == Approx(sonomap::test::square_room_rmse(1.25)).epsilon(1e-6));
  CHECK_FALSE(s.cylinder.final_frame.has_value());
  // The file is the struct written back: nothing in it that the type does not hold.
  CHECK(json(s) == summary_of(out));
}

TEST_CASE("diff and report refuse a result of another schema version, naming its summary.json",
          "[score][summary][diff]") {
  sonomap::test::ScratchDir scratch("score-schema");
  const fs::path scene = scratch.write("square.yaml", sonomap::test::square_room_scenario());
  const fs::path circle = scratch.write("circle.csv", sonomap::test::constant_circle_csv({0, 1}, 1.25));
  const fs::path sweep = scratch.path() / "sweep", good = sweep / "runs" / "good", old = sweep / "runs" / "old";
  fs::create_directories(sweep / "runs");
  for (const fs::path& out : {good, old})
    REQUIRE(run_sonomap({"--quiet", "score", scene.string(), "--circle", circle.string(), "--out", out.string(),
                         "--pictures", "-1"}).status == 0);
  json older = summary_of(old);
  older["schema_version"] = 0;
  std::ofstream(old / "summary.json") << older.dump(2);
  const auto diff = run_sonomap({"diff", good.string(), old.string()});
  CHECK(diff.status == 2);
  CHECK(diff.output.find((old / "summary.json").string()) != std::string::npos);
  CHECK(diff.output.find("schema_version 0") != std::string::npos);
  const auto report = run_sonomap({"--quiet", "report", sweep.string()});
  CHECK(report.status == 2);
  CHECK(report.output.find((old / "summary.json").string()) != std::string::npos);
}
