// SPDX-License-Identifier: GPL-3.0-or-later
// Sensor-centric rasters (docs/conventions.md): the 2D circle (azimuth bins) and the 3D cylinder
// (azimuth bins x height rows). Each cell keeps the minimum horizontal range of the obstacle
// points that fall in it, and that point. Unknown is +infinity, distinct from any range.
// The sonification sectors (groups of bins) are a pure function of a circle.
#pragma once

#include "core/types.hpp"

#include <Eigen/Core>
#include <cmath>
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
  // Throws std::invalid_argument naming the field unless: azimuth_bins in [1, 36000], all
  // values finite, band_min < band_max, row_height > 0 with at least one row and at most
  // kMaxCylinderCells cells in the cylinder, max_range > 0.
  void validate() const;
  // 64 MB of cells; the default cylinder has 6,840, a 1 cm x 0.1 degree one over 2 m 720,000.
  static constexpr double kMaxCylinderCells = 4e6;
  double bin_width_deg() const { return 360.0 / azimuth_bins; }
  // Row r covers heights [band_min + r * row_height, band_min + (r + 1) * row_height] above
  // the ground (the cylinder covers [band_min, band_min + rows() * row_height]).
  double row_bottom(int row) const { return band_min + row * row_height; }
  double row_top(int row) const { return band_min + (row + 1) * row_height; }
};

struct RasterCell {
  float range = kUnknownRange;                              // horizontal distance, metres
  Eigen::Vector3f point = Eigen::Vector3f::Constant(NAN);   // the world point that set it
  bool known() const { return range != kUnknownRange; }
};

struct Circle {
  std::vector<RasterCell> bins;  // azimuth_bins cells

  Circle() = default;
  explicit Circle(int azimuth_bins) : bins(static_cast<size_t>(azimuth_bins)) {}
  int size() const { return static_cast<int>(bins.size()); }
  double bin_width_deg() const { return 360.0 / static_cast<double>(bins.size()); }
  // Bin k holds azimuths [k, k + 1) * bin width; its centre is at (k + 0.5) * bin width.
  double bin_centre_deg(int bin) const { return (bin + 0.5) * bin_width_deg(); }
  int known_count() const;
  void clear();  // every bin unknown, size kept
};

struct Cylinder {
  int azimuth_bins = 0;
  int rows = 0;
  std::vector<RasterCell> cells;  // row-major: cells[row * azimuth_bins + bin]

  Cylinder() = default;
  Cylinder(int azimuth_bins_, int rows_)
      : azimuth_bins(azimuth_bins_), rows(rows_),
        cells(static_cast<size_t>(azimuth_bins_) * static_cast<size_t>(rows_)) {}
  RasterCell& at(int row, int bin) { return cells[static_cast<size_t>(row) * azimuth_bins + bin]; }
  const RasterCell& at(int row, int bin) const {
    return cells[static_cast<size_t>(row) * azimuth_bins + bin];
  }
  int known_count() const;
  void clear();  // every cell unknown, size kept
};

// Empty rasters shaped by a config (every cell unknown).
Circle make_circle(const RasterConfig& config);
Cylinder make_cylinder(const RasterConfig& config);

// One sonification sector (docs/conventions.md "Sectors"): the bin with the smallest range among
// the sector's bins. Ties go to the lowest bin index (the first met counter-clockwise).
struct Sector {
  float range = kUnknownRange;  // range of the closest bin; unknown if every bin is unknown
  double angle_deg = NAN;       // centre angle of that bin, degrees in [0, 360)
  int bin = -1;                 // its index in the circle, -1 when unknown
  Eigen::Vector3f point = Eigen::Vector3f::Constant(NAN);  // the world point that set it
  bool known() const { return range != kUnknownRange; }
};

// Splits the circle into `sector_count` equal sectors: sector s holds bins
// [s * n, (s + 1) * n) with n = bins / sector_count (36 sectors of 10 one-degree bins by default).
// Throws std::invalid_argument unless sector_count > 0 divides the number of bins.
std::vector<Sector> circle_sectors(const Circle& circle, int sector_count = 36);

}  // namespace sonomap
