// SPDX-License-Identifier: GPL-3.0-or-later
// Ground-truth rasters from a reference point cloud (a surveyed scan of a real scene, e.g. Cow
// and Lady's cow_and_lady_gt.ply) instead of exact triangles: per cell, the minimum horizontal
// distance from the raster origin over the reference points in the cell's height slab and
// azimuth wedge. Same slabs and wedges as ground_truth_rasters (docs/conventions.md).
//
// How it differs from the exact truth: the points are samples of the surface, so a cell's
// cloud range is never nearer than the exact one (r_exact <= r_cloud), and when every surface
// point lies within rho of a reference point (rho: the cloud's covering radius; a grid at
// spacing s has rho <= s), r_cloud <= r_exact_shrunk + rho, where r_exact_shrunk is the exact
// minimum over the cell shrunk by rho (points at least rho from both slab faces and both wedge
// edge lines). Cells thinner than 2 rho, or whose surface is only a sliver near an edge, may
// be unknown in the cloud truth although known in the exact one.
#pragma once

#include "core/raster.hpp"
#include "core/types.hpp"
#include "eval/ground_truth.hpp"

#include <Eigen/Core>
#include <vector>

namespace sonomap::eval {

// The minimum over the points in each cell. A point's bin is floor(azimuth / bin width) around
// the heading (half-open wedges: a point exactly on an edge counts once, in the bin after it);
// slabs are closed as for the exact truth. A cell whose minimum exceeds max_range, or that holds
// no point, is unknown. Throws std::invalid_argument for an invalid config or a non-finite
// origin or point.
GroundTruthRasters cloud_truth_rasters(const std::vector<Eigen::Vector3f>& points,
                                       const RasterOrigin& origin, const RasterConfig& config);

// A reference cloud of triangles (e.g. a scenario's static scene for `render --format rosbag`)
// whose covering radius is at most `spacing`: a square grid at 0.8 spacing in each triangle's
// plane plus samples every 0.8 spacing along its edges (a point is within 0.8/sqrt(2) spacing of
// a grid point, or the way to it crosses an edge within that distance, where an edge sample is
// within 0.4 spacing: 0.97 spacing in all). Throws std::invalid_argument unless spacing > 0.
std::vector<Eigen::Vector3f> surface_samples(const std::vector<GroundTruthTriangle>& triangles, double spacing);

}  // namespace sonomap::eval
