// SPDX-License-Identifier: GPL-3.0-or-later
// The exact ground-truth circle and cylinder (docs/conventions.md "Ground truth rasters") from the
// scene's true triangles at one instant: per cell, the minimum horizontal distance from the
// raster origin over the triangles clipped to the cell's height slab and angular wedge.
// This is the oracle for the rasteriser: it shares no code with it (only the raster types).
#pragma once

#include "core/raster.hpp"
#include "core/types.hpp"

#include <Eigen/Core>
#include <array>
#include <vector>

namespace sonomap::eval {

// A triangle in world coordinates (the same type as sim::WorldTriangle).
using GroundTruthTriangle = std::array<Eigen::Vector3d, 3>;

struct GroundTruthRasters {
  Circle circle;      // config.azimuth_bins bins
  Cylinder cylinder;  // config.azimuth_bins x config.rows()
};

// Exact wedge minima. Geometry:
//  - the circle's height slab is z in [ground_z + band_min, ground_z + band_max], cylinder row r's
//    is [ground_z + row_bottom(r), ground_z + row_top(r)] (closed: a horizontal face exactly on a
//    row edge counts in both rows);
//  - bin k's wedge is the closed set of azimuths [k, k + 1] * bin width around the origin,
//    relative to the heading (counter-clockwise, 0 ahead);
//  - a cell's value is min |(p - o).xy| over the triangles' points p in slab and wedge, and the
//    point attaining it; unknown when that minimum exceeds max_range (or nothing is there).
// Every triangle is clipped to the slab, then to each wedge it can reach (its angular extent,
// so distant small triangles touch a few bins); the minimum over the clipped convex polygon is
// the minimum over its edges, since the origin is the wedge apex and so on the boundary of any
// clipped polygon that contains it. Nothing is sampled.
// Throws std::invalid_argument for an invalid config or a non-finite origin or vertex.
GroundTruthRasters ground_truth_rasters(const std::vector<GroundTruthTriangle>& triangles,
                                        const RasterOrigin& origin, const RasterConfig& config);

}  // namespace sonomap::eval
