// SPDX-License-Identifier: GPL-3.0-or-later
// summary.json as a type: what `run` writes reads back through RunSummary unchanged, agrees
// with frames.csv (written by other code), and a reader refuses what it does not understand.
#include "cli_support.hpp"
#include "run_support.hpp"
#include "test_scenario_files.hpp"

#include "harness/app/run.hpp"
#include "harness/formats/run_summary.hpp"
#include "harness/support/errors.hpp"

#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

namespace fs = std::filesystem;
using nlohmann::json;
using sonomap::test::ScratchDir;

namespace {

// The last line's field in `column` of a CSV with a header.
double last_row_value(const fs::path& csv, const std::string& column) {
  std::istringstream in(sonomap::test::text_of(csv));
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line)) last = line;
  auto split = [](const std::string& text) {
    std::vector<std::string> fields;
    std::stringstream s(text);
    for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
    return fields;
  };
  const auto names = split(header), values = split(last);
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == column) return std::stod(values.at(i));
  throw std::runtime_error("no column " + column);
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
