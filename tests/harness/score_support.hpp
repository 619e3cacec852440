// SPDX-License-Identifier: GPL-3.0-or-later
// A closed-form case for the score tests: a listener standing still at the centre of a 4 x 4 m
// room (walls 2 m away in +-x and +-y, heading along +x), and a circle of one constant range.
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace sonomap::test {

// Two frames, a small noiseless camera, the listener at (0, 0, 1.5) facing +x.
inline std::string square_room_scenario() {
  return "name: square\nseed: 1\nframes: 2\n"
         "sensor:\n  width: 160\n  height: 120\n"
         "  intrinsics: {fx: 131.25, fy: 131.25, cx: 79.5, cy: 59.5}\n"
         "  min_range: 0.3\n  max_range: 5.0\n  rate: 30\n  noise: {model: none}\n"
         "body:\n  interpolation: linear_slerp\n  keyframes:\n    - {time: 0.0, position: [0.0, 0.0, 1.5], yaw: 0}\n"
         "    - {time: 1.0, position: [0.0, 0.0, 1.5], yaw: 0}\n"
         "static:\n  - name: room\n    room: {size: [4.0, 4.0, 2.5]}\n";
}

// frame,bin,estimate rows: every bin of each frame at `range`.
inline std::string constant_circle_csv(const std::vector<int>& frames, double range) {
  std::string text = "frame,bin,estimate\n";
  for (int f : frames)
    for (int k = 0; k < 360; ++k) text += std::to_string(f) + "," + std::to_string(k) + "," + std::to_string(range) + "\n";
  return text;
}

// Bin k's truth: the nearest wall point over azimuths [k, k + 1] degrees. A wall 2 m away
// along an axis is 2 / cos(phi) away at phi degrees off that axis, so the minimum over the
// wedge is at the end nearer an axis.
inline double square_room_truth(int bin) {
  auto off_axis = [](double deg) {
    const double m = std::fmod(deg, 90.0);
    return std::min(m, 90.0 - m);
  };
  const double phi = std::min(off_axis(bin), off_axis(bin + 1.0));
  return 2.0 / std::cos(phi * M_PI / 180.0);
}

inline double square_room_rmse(double range) {
  double sum = 0.0;
  for (int k = 0; k < 360; ++k) sum += (range - square_room_truth(k)) * (range - square_room_truth(k));
  return std::sqrt(sum / 360.0);
}

}  // namespace sonomap::test
