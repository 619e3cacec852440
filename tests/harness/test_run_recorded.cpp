// SPDX-License-Identifier: GPL-3.0-or-later
// Recorded data in: a TUM RGB-D sequence written by `sonomap render` runs through the same
// chain, and its rasters agree with the simulator run it came from within the depth
// quantisation (1/5000 m per PNG unit).
#include "cli_support.hpp"
#include "test_scenario_files.hpp"

#include "harness/app/run.hpp"

#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

namespace fs = std::filesystem;

namespace {

// circle.csv of one frame: bin -> estimate text (empty = unknown).
std::map<int, std::string> circle_of(const fs::path& csv, int frame) {
  std::istringstream in(sonomap::test::text_of(csv));
  std::map<int, std::string> bins;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string f, bin, estimate;
    std::getline(row, f, ',');
    std::getline(row, bin, ',');
    std::getline(row, estimate, ',');
    if (std::stoi(f) == frame) bins[std::stoi(bin)] = estimate;
  }
  return bins;
}

}  // namespace

TEST_CASE("a rendered TUM sequence gives the simulator's circle within the depth quantisation",
          "[run][recorded]") {
  sonomap::test::ScratchDir scratch("run-recorded");
  const std::string scenario = sonomap::test::shipped("scenes/smoke.yaml").string();
  const fs::path tum = scratch.path() / "tum";
  const std::vector<std::string> small = {"--set", "sensor.width=320", "--set", "sensor.height=240",
                                          "--set", "sensor.intrinsics.fx=262.5", "--set", "sensor.intrinsics.fy=262.5",
                                          "--set", "sensor.intrinsics.cx=159.5", "--set", "sensor.intrinsics.cy=119.5"};
  std::vector<std::string> render = {"--quiet", "render", scenario, "--out", tum.string(), "--frames", "6"};
  render.insert(render.end(), small.begin(), small.end());
  REQUIRE(sonomap::test::run_sonomap(render).status == 0);

  sonomap::harness::RunOptions simulated;
  simulated.scenario = scenario;
  simulated.out = scratch.path() / "simulated";
  simulated.mapper = "depth_only";
  simulated.frames = 6;
  for (std::size_t i = 1; i < small.size(); i += 2) simulated.overrides.push_back(small[i]);
  simulated.picture_frames = simulated.sweep_frames = {-1};
  simulated.quiet = true;
  sonomap::harness::run_scenario(simulated);

  sonomap::harness::RunOptions recorded = simulated;
  recorded.scenario = tum;
  recorded.out = scratch.path() / "recorded";
  recorded.overrides.clear();
  const auto summary = sonomap::harness::run_scenario(recorded).summary;
  CHECK_FALSE(summary.ground_truth);
  CHECK_FALSE(summary.circle.final_frame.has_value());

  const auto a = circle_of(simulated.out / "circle.csv", 5);
  const auto b = circle_of(recorded.out / "circle.csv", 5);
  REQUIRE(a.size() == 360);
  REQUIRE(b.size() == 360);
  int known = 0, disagree = 0;
  for (int k = 0; k < 360; ++k) {
    const std::string& x = a.at(k);
    const std::string& y = b.at(k);
    if (x.empty() || y.empty()) {
      disagree += x.empty() != y.empty();
      continue;
    }
    ++known;
    // Rounding z to the PNG unit moves a point by at most half a unit (0.1 mm) of z, so by
    // 0.1 mm x |ray| / z along its ray: at most 1.255 x at this camera's image corners
    // (sqrt(1 + (160 / 262.5)^2 + (120 / 262.5)^2)); its horizontal range by no more.
    CHECK(std::abs(std::stod(x) - std::stod(y)) <= 0.5 / 5000.0 * 1.255 + 1e-6);
  }
  CHECK(known > 40);
  CHECK(disagree == 0);
}
