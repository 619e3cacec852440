// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/vdb_gpdf/updates.hpp"

#include <algorithm>
#include <optional>

#include "core/vdb_gpdf/votes.hpp"

namespace sonomap::gpdf {
namespace {

// A surface point's negative value is dropped at a centre the camera saw more than this many
// voxels behind the measured surface (voxel_update).
constexpr double kBehindMargin = 0.25;
// A behind vote is dropped at a centre whose own pixel measured a surface more than this many
// voxels beyond it (depth noise's room; 0 and 1 gave the same fidelity figures).
constexpr double kSeenPastVoxels = 0.5;
// A voxel the map holds as free that this frame puts inside an object, more than this many
// voxels behind the surface its pixel measured, has been entered: an object arrived.
// That surface must also be new to the map: its measured point more than this many voxels in
// front of any surface the map holds (else the voxel may lie behind a panel thinner than the
// behind votes' reach, in free space the map saw: in the random box rooms of docs/fidelity.md
// surfaces then ran up to a voxel past thin panels' hidden sides). Half a voxel is the depth
// noise's room: at 0.4 voxel or less the panels' bulges came back.
constexpr double kArrivedVoxels = 1.0;
constexpr double kNewSurfaceVoxels = 0.5;
// Where the map last saw the voxel free longer ago than kRecentlyFreeSeconds, an arrival
// reaches no more than kStaleArrivedVoxels behind the measured surface. Objects arrive in
// space seen free just before (a person stepping in, the random rooms' jumping box), and
// there the behind votes enter at any depth. Space seen free long ago is where a surface comes
// back that carving took: a thin panel's far side, seen long after its near side, whose
// behind votes (two query steps along the normal, farther along an oblique ray) went on
// through the panel into the space seen free in front of its near side (the long walk of
// docs/fidelity.md: chair 2's 3 cm back re-placed 6.5 cm too thick). A limit of 1.5 or 2
// voxels lost objects from the cylinder whose space, too, was seen free long before; 3 voxels
// left every figure of the shipped scenes as good or better. It is measured along the ray: seen
// within 60 degrees of its normal, a panel's behind votes enter as before. Frames without
// times (all at time 0) see every voxel as recently free: the rule is then as before.
constexpr double kRecentlyFreeSeconds = 1.0;
constexpr double kStaleArrivedVoxels = 3.0;
// The most an inside ("behind") vote adds to a voxel's value, in voxels. Behind votes land up
// to two query steps behind the surface, and the GPs' distance there (to the visible face)
// says nothing of how thin the object is: a panel may end a centimetre behind its face. Next
// to a free voxel beside a silhouette or beyond a thin object's hidden side, a large inside
// value pulled the marching cubes' crossing past the object: with the free votes beside
// silhouettes (vote_free_where_unvoted) and no cap, the random box rooms of docs/fidelity.md had
// 16 readings too near (11 with the cap), and on the smoke scene a box's corner ran 8 mm into
// the next bin.
constexpr double kInsideCapVoxels = 0.5;

// What a voxel's update reads besides its votes: the frame's local GPs, its voxels near the
// points, its depth image and the map as it was before the frame (one per task: accessors).
struct UpdateLookups {
  const LocalGps& locals;
  mutable LocalGps::Lookup gp_lookup;  // its caches change as the voxels are visited
  ReadAccessor<openvdb::MaskTree> near;
  const DepthView& view;
  ReadAccessor<DistanceWeightGrid::TreeType> map;
  ReadAccessor<openvdb::FloatTree> seen_free_at;
  double now;
};

// Whether the surface that `sight`'s pixel measured is new to the map: the map's value at the
// measured point (trilinear between the 8 voxel centres around it) says free space more than
// kNewSurfaceVoxels in front of any surface it holds, or the map has not observed all 8.
bool measured_surface_is_new(const VdbGpdfConfig& config, const UpdateLookups& at, const DepthView::Sight& sight) {
  const std::optional<Eigen::Vector3d> measured = at.view.measured(sight);
  if (!measured) return false;
  const Eigen::Vector3d g = *measured / config.global_voxel - Eigen::Vector3d::Constant(0.5);
  const Eigen::Vector3d base = g.array().floor();
  const Eigen::Vector3d t = g - base;
  const openvdb::Coord b(static_cast<int>(base.x()), static_cast<int>(base.y()), static_cast<int>(base.z()));
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    const openvdb::Vec2s old = at.map.getValue(b.offsetBy(dx, dy, dz));
    if (!(old[1] > 0.0f)) return true;
    value += (dx ? t.x() : 1 - t.x()) * (dy ? t.y() : 1 - t.y()) * (dz ? t.z() : 1 - t.z()) * old[0];
  }
  return value < -kNewSurfaceVoxels * config.global_voxel;
}

// Whether an object has arrived at `voxel`, seen along `sight`: its pixel measured a surface
// more than kArrivedVoxels in front of the centre (and, where the map saw the voxel free only
// long ago, no more than kStaleArrivedVoxels), and that surface is new to the map. A voxel
// behind a panel thinner than the behind votes' reach (two query steps) is also "behind the
// measured surface"; but the panel is one the map holds already.
bool arrival_seen(const VdbGpdfConfig& config, const UpdateLookups& at, const openvdb::Coord& voxel,
                  const DepthView::Sight& sight) {
  // The stamp is read last, and only for centres deep behind: arrival() is asked of every
  // voxel a frame puts inside.
  auto freed_recently = [&] { return at.now - at.seen_free_at.getValue(voxel) <= kRecentlyFreeSeconds; };
  return at.view.seen_behind(sight, kArrivedVoxels * config.global_voxel) &&
         (!at.view.seen_behind(sight, kStaleArrivedVoxels * config.global_voxel) || freed_recently()) &&
         measured_surface_is_new(config, at, sight);
}

// One voxel's update from its votes and the local GPs' distance d at its centre: each kept
// vote adds +-d with one unit of weight. Near the surface a free-space value needs the depth
// image's word for it (DepthView): a centre the camera saw behind the surface keeps no
// negative "hit" vote (a surface point's plane, tilted by an edge, can call it free), and a
// free vote near the surface needs the centre's pixel and its 8 neighbours to have measured
// something farther (a front point or ray beside a grazing face passes a centre inside it).
bool voxel_update(const VdbGpdfConfig& config, const openvdb::Coord& voxel, VoteCounts votes,
                  openvdb::Vec4f surface, openvdb::Vec2s lateral, const UpdateLookups& at, QueryUpdate& out) {
  const DepthView& view = at.view;
  const Eigen::Vector3d centre = voxel_centre(voxel, config.global_voxel);
  const DepthView::Sight sight = view.sight(centre);  // projected once for every check below
  std::optional<bool> in_front;  // view.seen_in_front(sight) (9 pixels), asked at most once
  auto seen_in_front = [&] {
    if (!in_front) in_front = view.seen_in_front(sight);
    return *in_front;
  };
  // Only lateral votes reached it (clouds: LeafQueries::add_lateral): their plane's offset
  // where the cloud measured around the centre; where it saw through the centre, the free
  // vote beside surfaces it stood in for (vote_free_where_unvoted).
  if (lateral[1] > 0.0f && votes == VoteCounts(0) && surface[1] + surface[3] == 0.0f) {
    if (!seen_in_front()) {
      if (!view.measured_around(sight, config.global_voxel)) return false;
      const double weight = config.inverse_variance_fusion ? lateral[1] / config.variance_on_surface : lateral[1];
      out = {voxel, lateral[0] / lateral[1], static_cast<float>(weight), true};
      return true;
    }
    if (at.near.isValueOn(voxel)) votes[kFree] = 1;
  }
  const bool behind = view.seen_behind(sight, kBehindMargin * config.global_voxel);
  if (surface[3] > 0 && behind) surface[2] = surface[3] = 0.0f;
  if (votes[kFree] > 0 && at.near.isValueOn(voxel) && !seen_in_front()) votes[kFree] = 0;
  // A point behind the surface whose centre the camera saw through is not inside: beside a
  // silhouette the normal leans sideways and its behind points land in free space (with the
  // free votes of vote_free_where_unvoted they made the surface bulge past the silhouette).
  // Seen through by its own pixel is enough to drop the guess (not to carve: a free vote needs
  // all 9 pixels): at a panel's end the 9 pixels include the panel, and behind votes along the
  // end's diagonal normals put the panel's hidden side past where the rays went on.
  if (votes[kHitInside] > 0 && (seen_in_front() || view.seen_past(sight, kSeenPastVoxels * config.global_voxel)))
    votes[kHitInside] = 0;
  // Nor does a behind vote overturn space the map holds as free, unless an object arrived
  // there: the free space was seen, while a behind vote only guesses the object's depth. Seen
  // from its far side, a panel thinner than the votes' reach let them into the space seen
  // free in front of it, and its near side moved up to 9 cm toward its viewer.
  std::optional<bool> arrived;  // arrival_seen(config, at, voxel, sight), asked at most once
  auto arrival = [&] {
    if (!arrived) arrived = arrival_seen(config, at, voxel, sight);
    return *arrived;
  };
  if (votes[kHitInside] > 0) {
    const openvdb::Vec2s old = at.map.getValue(voxel);
    if (old[1] > 0.0f && old[0] < 0.0f && !arrival()) votes[kHitInside] = 0;
  }
  // A front point's centre behind the tangent plane: free if the camera saw through it, inside
  // if its pixel saw the surface nearer, else unknown (beside a silhouette, where a curved or
  // grazing surface's plane is no guide: a column's edge grew 8 cm into free space).
  if (votes[kFrontInside] > 0) {
    if (seen_in_front()) {
      votes[kFree] += votes[kFrontInside];
      votes[kFrontInside] = 0;
    } else if (!behind) {
      votes[kFrontInside] = 0;
    }
  }
  const int inside = votes[kHitInside] + votes[kFrontInside];
  const int free = votes[kFree];
  const double surface_votes = surface[1] + surface[3];
  const double weight = inside + free + surface_votes;
  if (weight == 0.0) return false;
  // Surface votes carry their own values: the GPs are asked only for the other votes' distance
  // (or for the variance that inverse-variance fusion weights by).
  double distance = 0.0, variance = config.variance_on_surface;
  if (inside + free > 0 || config.inverse_variance_fusion) {
    const GpPrediction pred = at.locals.smallest(centre, config.inverse_variance_fusion, at.gp_lookup);
    if (!pred.valid) return false;
    distance = pred.distance;
    variance = pred.variance;
  }
  // An inside vote's value is capped: it says the centre is inside, not how deep (see
  // kInsideCapVoxels).
  const double inside_distance = std::min(distance, kInsideCapVoxels * config.global_voxel);
  const double sum = surface[0] + surface[2] + inside_distance * inside - distance * free;
  out = {voxel, static_cast<float>(sum / weight),
         static_cast<float>(config.inverse_variance_fusion ? weight / variance : weight),
         votes[kHitInside] + surface_votes > 0};
  out.seen_inside = out.hit && out.distance > 0.0f && arrival();
  return true;
}

}  // namespace

std::vector<QueryUpdate> query_updates(const VdbGpdfConfig& config, const LocalFrame& local,
                                       const DepthView& view, const MapBefore& map, double now,
                                       const Eigen::Vector3d& origin) {
  FrameVotes votes;
  cast_votes(config, local, view, map.fused, origin, votes);
  std::vector<const VoteGrid::TreeType::LeafNodeType*> vote_leaves;
  votes.counts.tree().getNodes(vote_leaves);
  std::vector<std::vector<QueryUpdate>> per_leaf(vote_leaves.size());
  parallel_for_each_index(vote_leaves.size(), [&](size_t i) {
    const UpdateLookups lookups{local.gps,
                                LocalGps::Lookup(local.gps.index),
                                read_accessor(local.near),
                                view,
                                read_accessor(map.fused),
                                read_accessor(map.seen_free_at),
                                now};
    const auto surface_acc = read_accessor(votes.surface);
    const auto lateral_acc = read_accessor(votes.lateral);
    QueryUpdate update;
    per_leaf[i].reserve(vote_leaves[i]->onVoxelCount());  // (grown one by one: 600 allocations a frame)
    for (auto v = vote_leaves[i]->cbeginValueOn(); v; ++v) {
      const openvdb::Coord& c = v.getCoord();
      if (voxel_update(config, c, *v, surface_acc.getValue(c), lateral_acc.getValue(c), lookups, update))
        per_leaf[i].push_back(update);
    }
  });
  size_t total = 0;
  for (const auto& leaf_updates : per_leaf) total += leaf_updates.size();
  std::vector<QueryUpdate> updates;
  updates.reserve(total);
  for (const auto& leaf_updates : per_leaf) updates.insert(updates.end(), leaf_updates.begin(), leaf_updates.end());
  return updates;
}

}  // namespace sonomap::gpdf
