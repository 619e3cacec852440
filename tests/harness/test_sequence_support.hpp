// SPDX-License-Identifier: GPL-3.0-or-later
// Shared by the recorded-data tests: the smoke scene at a small camera, a run of it, and one
// frame's circle from circle.csv.
#pragma once

#include "cli_support.hpp"
#include "test_scenario_files.hpp"

#include "harness/app/run.hpp"

#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace sonomap::test {

// circle.csv of one frame: bin -> estimate text (empty = unknown).
inline std::map<int, std::string> circle_of(const std::filesystem::path& csv, int frame) {
  std::istringstream in(text_of(csv));
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

// 320 x 240 keeps these runs to seconds. (Not named small_camera: run_support.hpp has one
// returning by value, and two inline functions of one name break the one-definition rule.)
inline const std::vector<std::string>& small_camera_keys() {
  static const std::vector<std::string> keys = {
      "sensor.width=320", "sensor.height=240", "sensor.intrinsics.fx=262.5",
      "sensor.intrinsics.fy=262.5", "sensor.intrinsics.cx=159.5", "sensor.intrinsics.cy=119.5"};
  return keys;
}

// A run of `input` (a scenario with `overrides`, or a recording), 6 frames, by depth_only
// unless another mapper is named.
inline nlohmann::json run_quietly(const std::filesystem::path& input, const std::filesystem::path& out,
                                  std::vector<std::string> overrides = {}, const std::string& mapper = "depth_only") {
  harness::RunOptions options;
  options.scenario = input;
  options.out = out;
  options.mapper = mapper;
  options.frames = 6;
  options.overrides = std::move(overrides);
  options.picture_frames = options.sweep_frames = {-1};
  options.quiet = true;
  return harness::run_scenario(options).summary;
}

// Bins where both circles are known differ by at most `tolerance` metres; the same bins are
// unknown in both. Returns the number of bins known in both.
inline int compare_circles(const std::map<int, std::string>& a, const std::map<int, std::string>& b,
                           double tolerance) {
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
    INFO("bin " << k << ": " << x << " vs " << y);
    CHECK(std::abs(std::stod(x) - std::stod(y)) <= tolerance);
  }
  CHECK(disagree == 0);
  return known;
}

// A 4x4 matrix as YAML rows, exactly (17 significant digits).
inline std::string yaml_matrix(const Eigen::Matrix4d& m) {
  std::string out = "[";
  for (int r = 0; r < 4; ++r) {
    out += r ? ", [" : "[";
    for (int c = 0; c < 4; ++c) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%s%.17g", c ? ", " : "", m(r, c));
      out += buf;
    }
    out += "]";
  }
  return out + "]";
}

}  // namespace sonomap::test
