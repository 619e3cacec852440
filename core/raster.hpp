// SPDX-License-Identifier: GPL-3.0-or-later
// Sensor-centric rasters (conventions.md): the 2D circle (azimuth bins) and the 3D cylinder
// (azimuth bins x height rows). Each cell keeps the minimum horizontal range of the obstacle
// points that fall in it, and that point. Unknown is +infinity, distinct from any range.
#pragma once

#include "core/types.hpp"

#include <Eigen/Core>
#include <limits>
#include <vector>

namespace sonomap {

constexpr float kUnknownRange = std::numeric_limits<float>::infinity();

struct RasterConfig {
  int azimuth_bins = 360;     // bins over [0, 360) degrees, counter-clockwise, 0 = ahead
  double band_min = 0.1;      // obstacle band above the ground, metres
  double band_max = 2.0;
  double row_height = 0.1;    // cylinder rows over [band_min, band_max]
  double max_range = 5.0;     // horizontal range beyond which points are ignored
  int rows() const;           // number of cylinder rows
};

struct RasterCell {
  float range = kUnknownRange;                              // horizontal distance, metres
  Eigen::Vector3f point = Eigen::Vector3f::Constant(NAN);   // the world point that set it
  bool known() const { return range != kUnknownRange; }
};

struct Circle {
  std::vector<RasterCell> bins;  // azimuth_bins cells
};

struct Cylinder {
  int azimuth_bins = 0;
  int rows = 0;
  std::vector<RasterCell> cells;  // row-major: cells[row * azimuth_bins + bin]
  RasterCell& at(int row, int bin) { return cells[static_cast<size_t>(row) * azimuth_bins + bin]; }
  const RasterCell& at(int row, int bin) const {
    return cells[static_cast<size_t>(row) * azimuth_bins + bin];
  }
};

}  // namespace sonomap
