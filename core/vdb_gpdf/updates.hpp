// SPDX-License-Identifier: GPL-3.0-or-later
// One update per global voxel the frame's votes reached (stage "query_points"). Internal to
// core/vdb_gpdf*.
#pragma once

#include "core/marching_cubes.hpp"
#include "core/vdb_gpdf.hpp"
#include "core/vdb_gpdf/depth_view.hpp"
#include "core/vdb_gpdf/local_frame.hpp"

#include <Eigen/Core>
#include <openvdb/openvdb.h>

#include <vector>

namespace sonomap::gpdf {

// One query point's contribution: the voxel it falls in, its signed distance and weight.
struct QueryUpdate {
  openvdb::Coord voxel;
  float distance;
  float weight;
  bool hit = false;  // from a surface point or behind it (not from free space in front)
  bool seen_inside = false;  // inside by its votes, and an object arrived there (arrival_seen)
};

// The map as it was before the frame: the fused values, and per voxel the time a frame last put
// it on the free side (VdbGpdf::seen_free_at_).
struct MapBefore {
  const DistanceWeightGrid& fused;
  const openvdb::FloatGrid& seen_free_at;
};

// Stage "query_points": every local leaf's votes, counted per global voxel (cast_votes), then one
// GP query per voxel (in parallel, each voxel writing its own slot). `now`: the frame's time.
std::vector<QueryUpdate> query_updates(const VdbGpdfConfig& config, const LocalFrame& local,
                                       const DepthView& view, const MapBefore& map, double now,
                                       const Eigen::Vector3d& origin);

}  // namespace sonomap::gpdf
