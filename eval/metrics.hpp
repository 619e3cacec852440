// SPDX-License-Identifier: GPL-3.0-or-later
// Per-frame accuracy of an estimated raster against the ground truth (docs/conventions.md
// "Metrics"), for the circle and the cylinder alike (a cylinder is compared cell by cell).
#pragma once

#include "core/raster.hpp"

#include <vector>

namespace sonomap::eval {

struct MetricsConfig {
  // A known estimate cell more than this closer than the truth is a ghost (a surface that is
  // no longer there). Default: 2 voxels of the 0.05 m global map.
  double ghost_tolerance = 0.10;
  // A cell is on a silhouette edge of the truth when the truth range jumps by more than this to
  // an azimuth neighbour (or the neighbour is empty). There a sub-degree sliver of a near
  // object decides the truth (a box corner 0.01 degrees into a bin), which no map with
  // centimetre voxels resolves: one such bin of 1.4 m error alone makes an RMSE of 7.5 cm over
  // 360 bins. rmse_off_edges leaves those cells out, so it measures the surfaces themselves.
  double edge_jump = 0.25;
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
  // The same over the cells known in both that are not on a silhouette edge of the truth.
  double rmse_off_edges = 0.0;
  int edge_cells = 0;  // truth-occupied cells on a silhouette edge
};

// The ghost rule of `ghosts`: the estimate knows the cell, and the truth is empty there or
// farther than the estimate by more than `tolerance`.
bool is_ghost(const RasterCell& estimate, const RasterCell& truth, double tolerance);

// Throws std::invalid_argument if the rasters differ in shape or the tolerance is negative
// or not finite.
// `row_width` cells make one ring of azimuth neighbours (wrapping at 360 degrees); 0: no
// neighbours, so no cell is on an edge.
RasterMetrics compare_cells(const std::vector<RasterCell>& estimate,
                            const std::vector<RasterCell>& truth, const MetricsConfig& config = {},
                            int row_width = 0);
RasterMetrics compare(const Circle& estimate, const Circle& truth, const MetricsConfig& config = {});
RasterMetrics compare(const Cylinder& estimate, const Cylinder& truth,
                      const MetricsConfig& config = {});

}  // namespace sonomap::eval
