// SPDX-License-Identifier: GPL-3.0-or-later
// summary.json as a type: what `run` writes reads back through RunSummary unchanged, agrees
// with frames.csv (written by other code), and a reader refuses what it does not understand.
#include "cli_support.hpp"
#include "run_support.hpp"
#include "test_scenario_files.hpp"

#include "harness/app/run.hpp"
#include "harness/formats/run_summary.hpp"
#include "harness/report/rollup.hpp"
#include "harness/support/errors.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <map>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using nlohmann::json;
using sonomap::test::ScratchDir;

namespace {

// A CSV with a header, read by the roll-up's table (the reader `report` and the gates use).
sonomap::harness::RollupTable csv_table(const fs::path& csv) {
  return sonomap::harness::RollupTable::parse(sonomap::test::text_of(csv));
}

// The last line's field in `column` of a CSV with a header.
double last_row_value(const fs::path& csv, const std::string& column) {
  const auto table = csv_table(csv);
  const int c = table.column(column);
  if (c < 0 || table.rows.empty()) throw std::runtime_error("no column " + column);
  return table.number(table.rows.back(), c);
}

}  // namespace

TEST_CASE("summary.json reads back through RunSummary unchanged and agrees with frames.csv",
          "[run_summary]") {
  ScratchDir scratch("run-summary");
  auto o = sonomap::test::smoke_run(scratch.path() / "out", "depth_only", 6);
  o.every = 3;
  o.tags = {"variant=plain"};
  const auto outcome = sonomap::harness::run_scenario(o);

  const auto read = sonomap::harness::read_run_summary(o.out);
  std::ifstream in(o.out / "summary.json");
  const json file = json::parse(in);
  CHECK(file["schema_version"] == sonomap::harness::kResultSchemaVersion);
  CHECK(json(read) == file);              // nothing lost or renamed on the way back
  CHECK(json(outcome.summary) == file);  // the outcome is what was written
  CHECK(read.evaluated_frames == 3);      // frames 0, 3 and the last (5)
  CHECK(read.tags.at("variant") == "plain");
  REQUIRE(read.circle.final_frame);
  CHECK(read.circle.final_frame->coverage ==
        Approx(last_row_value(o.out / "frames.csv", "circle_coverage")).margin(1e-6));
  CHECK(read.cylinder.final_frame->estimate_known ==
        static_cast<int>(last_row_value(o.out / "frames.csv", "cylinder_known")));
  const auto timings = sonomap::harness::read_run_timings(o.out);
  CHECK(timings.at("integrate").samples == 6);  // every frame is integrated
  CHECK(timings.at("raster").samples == 3);     // only the evaluated ones are rasterised
}

TEST_CASE("a summary of another schema, or with a field missing, is refused naming the file",
          "[run_summary]") {
  ScratchDir scratch("run-summary-bad");
  auto o = sonomap::test::smoke_run(scratch.path() / "out", "depth_only", 2);
  sonomap::harness::run_scenario(o);
  std::ifstream in(o.out / "summary.json");
  const json good = json::parse(in);
  using Catch::Matchers::Contains;
  using sonomap::harness::read_run_summary;

  json older = good;
  older.erase("schema_version");
  scratch.write("older/summary.json", older.dump(2));
  CHECK_THROWS_WITH(read_run_summary(scratch.path() / "older"),
                    Contains("older/summary.json") && Contains("schema_version"));

  json newer = good;
  newer["schema_version"] = sonomap::harness::kResultSchemaVersion + 1;
  scratch.write("newer/summary.json", newer.dump(2));
  CHECK_THROWS_AS(read_run_summary(scratch.path() / "newer"), sonomap::harness::InputError);

  json partial = good;
  partial["metrics"].erase("cylinder");
  scratch.write("partial/summary.json", partial.dump(2));
  CHECK_THROWS_WITH(read_run_summary(scratch.path() / "partial"),
                    Contains("partial/summary.json") && Contains("cylinder"));
  CHECK_THROWS_WITH(read_run_summary(scratch.path() / "absent"), Contains("absent/summary.json"));
}

namespace {

// Per frame of timings.csv, the value of `column` (frames where it is empty left out).
std::map<int, double> column_by_frame(const fs::path& csv, const std::string& column) {
  const auto table = csv_table(csv);
  const int c = table.column(column), frame = table.column("frame");
  REQUIRE(c >= 0);
  std::map<int, double> values;
  for (const auto& row : table.rows)
    if (!table.cell(row, c).empty()) values[static_cast<int>(table.number(row, frame))] = table.number(row, c);
  return values;
}

// The upper median of the values at frames [first, last], and how many there were.
std::pair<double, std::size_t> median_at(const std::map<int, double>& values, int first, int last) {
  std::vector<double> v;
  for (const auto& [frame, ms] : values)
    if (frame >= first && frame <= last) v.push_back(ms);
  REQUIRE(!v.empty());
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return {v[v.size() / 2], v.size()};
}

}  // namespace

TEST_CASE("a run of 300 frames gives each stage's growth in timings.json: the median of frames 200-299 "
          "against 100-199, as timings.csv shows them",
          "[run_summary]") {
  ScratchDir scratch("run-summary-growth");
  auto o = sonomap::test::smoke_run(scratch.path() / "out", "depth_only", 300);
  o.every = 50;  // rasters at frames 0, 50, ..., 250 and the last, 299
  sonomap::harness::run_scenario(o);
  const auto timings = sonomap::harness::read_run_timings(o.out);
  std::ifstream in(o.out / "timings.json");
  CHECK(json(timings) == json::parse(in));  // nothing lost on the way back
  for (const std::string stage : {"integrate", "raster"}) {
    CAPTURE(stage);
    const auto csv = column_by_frame(o.out / "timings.csv", stage + "_ms");
    const auto& growth = timings.at(stage).growth;
    REQUIRE(growth);
    CHECK(growth->early_first == 100);
    CHECK(growth->early_last == 199);
    CHECK(growth->late_first == 200);
    CHECK(growth->late_last == 299);
    const auto [early, early_n] = median_at(csv, 100, 199);
    const auto [late, late_n] = median_at(csv, 200, 299);
    CHECK(growth->early_samples == early_n);
    CHECK(growth->late_samples == late_n);
    // timings.csv rounds to a microsecond
    CHECK(growth->early_median_ms == Approx(early).margin(5e-4));
    CHECK(growth->late_median_ms == Approx(late).margin(5e-4));
    CHECK(growth->late_over_early == Approx(growth->late_median_ms / growth->early_median_ms));
  }
  CHECK(timings.at("integrate").growth->early_samples == 100);  // every frame is integrated
  CHECK(timings.at("raster").growth->early_samples == 2);       // frames 100 and 150
  CHECK(timings.at("raster").growth->late_samples == 3);        // 200, 250 and 299
}

TEST_CASE("growth needs 300 frames, the stage in both windows, and a measurable time at the start",
          "[run_summary]") {
  using sonomap::harness::summarise_timings;
  using sonomap::harness::TimedFrame;
  std::vector<TimedFrame> every_frame, late_only, zero_early;
  for (int f = 0; f < 300; ++f) {
    every_frame.push_back({f, f < 200 ? 10.0 : 12.0});
    if (f >= 200) late_only.push_back({f, 1.0});
    zero_early.push_back({f, f < 200 ? 0.0 : 1.0});
  }
  const auto long_run = summarise_timings({{"a", every_frame}, {"b", late_only}, {"c", zero_early}}, 300);
  REQUIRE(long_run.at("a").growth);
  CHECK(long_run.at("a").growth->early_median_ms == 10.0);
  CHECK(long_run.at("a").growth->late_median_ms == 12.0);
  CHECK(long_run.at("a").growth->late_over_early == Approx(1.2));
  CHECK(long_run.at("a").median_ms == 10.0);  // 200 of the 300 frames took 10 ms
  CHECK(long_run.at("a").samples == 300);
  CHECK_FALSE(long_run.at("b").growth);
  CHECK_FALSE(long_run.at("c").growth);
  const auto short_run = summarise_timings({{"a", every_frame}}, 299);
  CHECK_FALSE(short_run.at("a").growth);
  CHECK(json(short_run.at("a")).contains("growth") == false);
}
