// SPDX-License-Identifier: GPL-3.0-or-later
// What a frame's sources say of the global voxels (part of stage "query_points"): votes cast
// per local leaf, counted per global voxel. Internal to core/vdb_gpdf*.
#pragma once

#include "core/marching_cubes.hpp"
#include "core/vdb_gpdf.hpp"
#include "core/vdb_gpdf/depth_view.hpp"
#include "core/vdb_gpdf/local_frame.hpp"

#include <openvdb/openvdb.h>

namespace sonomap::gpdf {

// What one query point or carving ray says of the global voxel it falls in. The value itself
// is the local GPs' distance at the voxel's centre, computed once per voxel whatever the
// number of votes (one GP query per touched voxel: a frame's 66k query points and carving
// rays fall in 22k voxels at 5 cm, in 4k at 10 cm); a vote gives its sign and one unit of
// weight. "Hit" votes come from a surface point or a point behind it, "free" votes from
// points in front of the surface and from carving rays.
// A source point's own vote is different: its voxel's value is the centre's signed offset from
// the tangent plane (what a surface sample says of a voxel it lies in), not the GPs' distance,
// which beyond a silhouette edge would push the surface sideways into free space.
// "Lateral" votes carry a source's tangent plane one voxel sideways, and "beside a ray" votes
// a carving ray's free space one voxel up and down, in frames without a depth image only
// (LeafQueries::add_lateral, LeafQueries::beside_ray).
enum VoteKind { kHitInside, kFrontInside, kFree, kSurface, kLateral, kBesideRay };
struct Vote {
  openvdb::Coord voxel;
  VoteKind kind;
  float offset = 0.0f;  // kSurface: signed distance of the centre from the tangent plane
};
using VoteCounts = openvdb::math::Vec3<int32_t>;  // per kind, kHitInside .. kFree
using VoteGrid = openvdb::Grid<openvdb::tree::Tree4<VoteCounts, 5, 4, 3>::Type>;
// Surface votes: (sum of positive offsets, their count, sum of negative offsets, their count).
using SurfaceVoteGrid = openvdb::Grid<openvdb::tree::Tree4<openvdb::Vec4f, 5, 4, 3>::Type>;
using LateralVoteGrid = openvdb::Grid<openvdb::tree::Tree4<openvdb::Vec2s, 5, 4, 3>::Type>;  // offsets' sum, count

// A frame's votes per global voxel: their counts per kind (every voted voxel active here), the
// surface votes' offsets and the lateral votes' offsets.
struct FrameVotes {
  VoteGrid counts{VoteCounts(0)};
  SurfaceVoteGrid surface{openvdb::Vec4f(0.0f)};
  LateralVoteGrid lateral{openvdb::Vec2s(0.0f)};
};

// Every local leaf's votes (in parallel, one task per leaf), counted per global voxel in leaf
// order, with the free votes no ray cast (vote_free_where_unvoted).
void cast_votes(const VdbGpdfConfig& config, const LocalFrame& local, const DepthView& view,
                const DistanceWeightGrid& fused, const Eigen::Vector3d& origin, FrameVotes& out);

}  // namespace sonomap::gpdf
