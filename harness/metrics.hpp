// SPDX-License-Identifier: GPL-3.0-or-later
// Per-frame accuracy of an estimated raster against the ground truth (conventions.md
// "Metrics"), for the circle and the cylinder alike (a cylinder is compared cell by cell).
#pragma once

#include "core/raster.hpp"

#include <vector>

namespace sonomap::harness {

struct MetricsConfig {
  // A known estimate cell more than this closer than the truth is a ghost (a surface that is
  // no longer there). Default: 2 voxels of the 0.05 m global map.
  double ghost_tolerance = 0.10;
};

struct RasterMetrics {
  int cells = 0;             // cells compared (bins, or bins x rows)
  int truth_occupied = 0;    // cells the truth knows
  int estimate_known = 0;    // cells the estimate knows
  int known_in_both = 0;     // the coverage numerator and the RMSE population
  int ghosts = 0;            // known in the estimate and empty in the truth, or too close
  // known_in_both / truth_occupied; NaN when the truth has no occupied cell (undefined).
  double coverage = 0.0;
  // sqrt(mean((estimate - truth)^2)) over cells known in both, metres; NaN when there are none.
  double rmse = 0.0;
};

// Throws std::invalid_argument if the rasters differ in shape or the tolerance is negative
// or not finite.
RasterMetrics compare_cells(const std::vector<RasterCell>& estimate,
                            const std::vector<RasterCell>& truth, const MetricsConfig& config = {});
RasterMetrics compare(const Circle& estimate, const Circle& truth, const MetricsConfig& config = {});
RasterMetrics compare(const Cylinder& estimate, const Cylinder& truth,
                      const MetricsConfig& config = {});

}  // namespace sonomap::harness
