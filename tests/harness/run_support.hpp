// SPDX-License-Identifier: GPL-3.0-or-later
// Short runs of the shipped smoke scene for the run tests, at a quarter of the pixels.
#pragma once

#include "harness/app/run.hpp"
#include "test_scenario_files.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace sonomap::test {

// The smoke scene's camera at a quarter of the pixels: the same geometry, a quarter of the rays.
inline std::vector<std::string> small_camera() {
  return {"sensor.width=320", "sensor.height=240", "sensor.intrinsics.fx=262.5",
          "sensor.intrinsics.fy=262.5", "sensor.intrinsics.cx=159.5", "sensor.intrinsics.cy=119.5"};
}

// A quiet run of `frames` frames of scenes/smoke.yaml with the small camera, no pictures and
// no sweeps.
inline harness::RunOptions smoke_run(const std::filesystem::path& out, const std::string& mapper,
                                     int frames) {
  harness::RunOptions o;
  o.scenario = shipped("scenes/smoke.yaml");
  o.out = out;
  o.mapper = mapper;
  o.frames = frames;
  o.overrides = small_camera();
  o.picture_frames = {-1};
  o.sweep_frames = {-1};
  o.quiet = true;
  return o;
}

}  // namespace sonomap::test
