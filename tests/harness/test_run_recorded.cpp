// SPDX-License-Identifier: GPL-3.0-or-later
// Recorded data in: a TUM RGB-D sequence written by `sonomap render` runs through the same
// chain, and its rasters agree with the simulator run it came from within the depth
// quantisation (1/5000 m per PNG unit).
#include "test_sequence_support.hpp"

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;
using sonomap::test::circle_of;

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
  {
    // Without truth there is no error to report, not an error of zero: every metric cell of
    // frames.csv is empty (only the known counts are filled).
    std::ifstream frames(recorded.out / "frames.csv");
    std::string header, row;
    REQUIRE(std::getline(frames, header));
    REQUIRE(std::getline(frames, row));
    const auto column = [](const std::string& line, const std::string& name, const std::string& head) {
      std::stringstream h(head), l(line);
      std::string hn, lv;
      while (std::getline(h, hn, ',') && std::getline(l, lv, ','))
        if (hn == name) return lv;
      return std::string("missing");
    };
    for (const char* name : {"circle_rmse", "circle_rmse_off_edges", "cylinder_rmse_off_edges"})
      CHECK(column(row, name, header).empty());
  }

  // Rounding z to the PNG unit moves a point by at most half a unit (0.1 mm) of z, so by
  // 0.1 mm x |ray| / z along its ray: at most 1.255 x at this camera's image corners
  // (sqrt(1 + (160 / 262.5)^2 + (120 / 262.5)^2)); its horizontal range by no more.
  const int known = sonomap::test::compare_circles(circle_of(simulated.out / "circle.csv", 5),
                                                   circle_of(recorded.out / "circle.csv", 5),
                                                   0.5 / 5000.0 * 1.255 + 1e-6);
  CHECK(known > 40);
}
