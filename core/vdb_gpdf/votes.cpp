// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/vdb_gpdf/votes.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/grid_walk.hpp"
#include "core/vdb_gpdf/kept_leaf_writer.hpp"
#include "core/vdb_gpdf/normals.hpp"

namespace sonomap::gpdf {
namespace {

// A ring's line within this many voxels of the plane of the next two rings on one side lies on
// that surface (LeafQueries::plane_to_next_rings): 2 cm at 5 cm, half of a 4 cm table top's
// front face, whose lower half a ring must not take for the top.
constexpr double kOnRingPlaneVoxels = 0.4;
// Votes reserved per source: its own, 2 behind, 3 in front and the carving ray's (6-7 on
// average in the room at 5 cm), so that a leaf's vote list rarely grows by copying.
constexpr size_t kVotesPerSource = 16;

// One local leaf's votes: per source point p, p itself, points behind it (along the normal)
// and in front of it (along the ray), and every observed global voxel its ray crosses. A
// vote's sign is the side of p's tangent plane its voxel's centre lies on: the marching cubes
// read values at voxel centres, and a point's own side can differ from its centre's by up to
// half a voxel (binning raw values shifted a sphere's surface by 0.8 voxel).
class LeafQueries {
 public:
  LeafQueries(const VdbGpdfConfig& config, const LocalFrame& local, const DistanceWeightGrid& fused,
              size_t leaf, const Eigen::Vector3d& origin, const DepthView& view)
      : config_(config), view_(view), gp_(local.gps.gps[leaf]), origin_(origin), vg_(config.global_voxel),
        lateral_(!view.has_image()), observed_(read_accessor(fused)), cells_(local.cells), index_(local.gps.index),
        wide_{local.cells, local.gps, leaf} {}

  std::vector<Vote> votes;

  // Source p (its leaf's training point `trained` where it is one: the leaf's sources begin with
  // them, in order).
  void add(const Eigen::Vector3d& p, std::optional<size_t> trained) {
    Eigen::Vector3d u = origin_ - p;
    const double range = u.norm();
    if (!(range > 0.0)) return;
    u /= range;  // toward the sensor: the direction the query points are placed along
    const openvdb::Coord c = voxel_of(p, config_.local_voxel);
    const PlaneFit fit = surface_normal(cells_, index_, c, p, u,
                                        lateral_ ? &wide_ : nullptr, ring_reach(range));
    const Eigen::Vector3d normal = fit.line ? plane_to_next_rings(p, u, fit.along) : fit.normal;
    const Eigen::Vector3d facing = normal.isZero() ? u : normal;  // the tangent plane's normal
    const openvdb::Coord own = voxel_of(p, vg_);
    // The GP's own distance at p (its surface fit misses p by that much) moves the value
    // inward, as the first-order value at the centre: -d(p) - facing . (centre - p). p lies in
    // this leaf: its GP is the nearest.
    const double d = trained ? gp_.distance_at_point(*trained) : distance_at(p);
    cast(own, kSurface, static_cast<float>(-d - facing.dot(voxel_centre(own, vg_) - p)));
    const bool trusted = normal.dot(u) > kMinNormalDotRay;  // zero normal: not trusted
    if (lateral_ && trusted) add_lateral(own, p, facing, d);
    // Behind points along the normal, not the ray (behind points along a grazing ray leave
    // thin objects), and only where the normal is trusted: a view within 6 degrees of the
    // surface leaves its side in doubt, and a flipped normal puts "behind" in free space.
    if (trusted)
      for (int j = 1; j <= config_.trunc_behind; ++j) vote(p - j * config_.query_step * normal, p, facing, true);
    // Front points along the ray: the ray crossed that space, so it is free for sure.
    for (int j = 1; j <= config_.trunc_front; ++j) vote(p + j * config_.query_step * u, p, facing, false);
    if (config_.free_space_carving) carve(p, u, range);
  }

 private:
  double distance_at(const Eigen::Vector3d& p) const {
    const GpPrediction at_p = gp_.predict(p, false, false);
    return at_p.valid ? at_p.distance : 0.0;
  }

  // How far a ring's neighbourhood is widened: past the next ring of a lidar whose rings are up
  // to kRingSpacingDeg apart, beyond the ball, within the leaves around (one leaf's width).
  double ring_reach(double range) const {
    return std::clamp(std::tan(kRingSpacingDeg * M_PI / 180.0) * range, (kNormalReach + 1) * config_.local_voxel,
                      LeafCells::Leaf::DIM * config_.local_voxel);
  }

  // A ring whose neighbourhood, even widened, holds its own line only: the surface is seen at a
  // grazing angle, and the next rings cross it farther away than the widened reach (rings 2.3
  // degrees apart cross a table top 0.8 m below the eye and 2 m ahead 25 cm apart). Without a
  // normal a source casts no lateral vote, the top held voxels on its rings only, and its edges
  // read up to a ring's spacing too far (rooms 13-24 of docs/fidelity.md: 125 thin-slab bins,
  // the TSDF peer 24). The normal is then the plane's through the line and the nearest point of
  // a next ring, where the rings show the surface going on: the next rings on both sides lie on
  // that plane within a voxel (between two rings of one surface), or the line lies within
  // kOnRingPlaneVoxels of the plane of the next two rings on one side (a surface's first or
  // last ring). Else it stays zero. The nearest ring alone was not enough: a level lidar's ring
  // on a counter top's 4 cm front face took the top's plane, whose offsets put the top's first
  // layer of voxels on the free side, and the circle read the top's front edge up to 0.18 m too
  // far (tests/core, "a counter top 4 cm thick").
  Eigen::Vector3d plane_to_next_rings(const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                                      const Eigen::Vector3d& line) const {
    CubeRangeImage::NextRings below = view_.next_rings(p, line, -1.0), above = view_.next_rings(p, line, 1.0);
    std::optional<Eigen::Vector3d> n = plane_between_rings(p, line, below, above);
    if (!n) n = plane_to_one_side(p, line, below, above);
    if (!n) return Eigen::Vector3d::Zero();
    return n->dot(u) < 0.0 ? Eigen::Vector3d(-*n) : *n;
  }

  // The unit normal of the plane spanned by a line and a direction (none: they are parallel).
  static std::optional<Eigen::Vector3d> plane_normal(const Eigen::Vector3d& line, const Eigen::Vector3d& along) {
    const Eigen::Vector3d n = line.cross(along);
    if (!(n.norm() > 1e-9)) return std::nullopt;
    return n.normalized();
  }

  // Between two rings of one surface: the plane through the line and the nearer of the next
  // rings on either side, where it passes within a voxel of the other.
  std::optional<Eigen::Vector3d> plane_between_rings(const Eigen::Vector3d& p, const Eigen::Vector3d& line,
                                                     const CubeRangeImage::NextRings& below,
                                                     const CubeRangeImage::NextRings& above) const {
    if (!below.first || !above.first) return std::nullopt;
    const bool below_nearer = (*below.first - p).squaredNorm() < (*above.first - p).squaredNorm();
    const Eigen::Vector3d& nearer = below_nearer ? *below.first : *above.first;
    const Eigen::Vector3d& farther = below_nearer ? *above.first : *below.first;
    const std::optional<Eigen::Vector3d> n = plane_normal(line, nearer - p);
    if (!n || !(std::abs(n->dot(farther - p)) <= vg_)) return std::nullopt;
    return n;
  }

  // A surface's first or last ring: the plane through the line and the nearer next ring of a
  // side whose next two rings span a plane that the line lies on, within kOnRingPlaneVoxels.
  std::optional<Eigen::Vector3d> plane_to_one_side(const Eigen::Vector3d& p, const Eigen::Vector3d& line,
                                                   CubeRangeImage::NextRings& below,
                                                   CubeRangeImage::NextRings& above) const {
    std::optional<Eigen::Vector3d> next;
    for (CubeRangeImage::NextRings* rings : {&below, &above}) {
      view_.add_second_ring(*rings);
      if (!rings->first || !rings->second) continue;
      const std::optional<Eigen::Vector3d> n = plane_normal(line, *rings->second - *rings->first);
      if (!n || !(std::abs(n->dot(p - *rings->first)) <= kOnRingPlaneVoxels * vg_)) continue;
      if (!next || (*rings->first - p).squaredNorm() < (*next - p).squaredNorm()) next = rings->first;
    }
    return next ? plane_normal(line, *next - p) : std::nullopt;
  }

  // Appends a vote field by field (as append_run: no Vote built on the stack and copied).
  void cast(const openvdb::Coord& voxel, VoteKind kind, float offset = 0.0f) {
    Vote& v = votes.emplace_back();
    v.voxel = voxel;
    v.kind = kind;
    v.offset = offset;
  }

  // A sparse cloud, a lidar's rings, meets a surface along lines a few voxels apart. Its
  // votes then observe a strip one voxel wide around each line, and marching cubes, which
  // needs all eight corners of a cube, left most of it out: from every eighth row of the
  // random box rooms' images, the circle read too far at 32 corner bins of 410 and 72 thin
  // ones (the ray-traced TSDF peer, whose rays cross several voxels around each hit, 6 and
  // 10). So each source also gives its tangent plane's offset to the 26 voxels around its own
  // whose centres lie within a voxel of the plane; voxel_update uses them only where no other
  // vote reached and the cloud did not see through the centre.
  void add_lateral(const openvdb::Coord& own, const Eigen::Vector3d& p, const Eigen::Vector3d& facing, double d) {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const openvdb::Coord v = own.offsetBy(dx, dy, dz);
          const double offset = -d - facing.dot(voxel_centre(v, vg_) - p);
          if ((dx || dy || dz) && std::abs(offset) < vg_) cast(v, kLateral, static_cast<float>(offset));
        }
  }

  void vote(const Eigen::Vector3d& q, const Eigen::Vector3d& p, const Eigen::Vector3d& facing, bool hit) {
    const openvdb::Coord v = voxel_of(q, vg_);
    // A point behind whose centre lies in front of the plane sits astride the surface: the
    // plane's offset is its value (the GPs' distance, to the nearest surface anywhere, would
    // push the surface out). A point in front whose centre lies behind the plane is judged by
    // the depth image at the centre (voxel_update).
    const double offset = -facing.dot(voxel_centre(v, vg_) - p);  // > 0 behind the plane
    if (hit && offset <= 0.0) {
      cast(v, kSurface, static_cast<float>(offset));
      return;
    }
    if (!hit && offset > 0.0) {
      cast(v, kFrontInside);
      return;
    }
    cast(v, hit ? kHitInside : kFree);
  }

  // Every observed global voxel the ray crosses (DDA) from one carving step in front of p to
  // the sensor: fixed steps along fixed rays (a static camera) can skip a voxel forever, and
  // then a moved object is never carved there. Two levels: leaf blocks first, voxels only
  // inside blocks that exist (observed voxels lie near surfaces, so most of a ray crosses no
  // block at all).
  void carve(const Eigen::Vector3d& p, const Eigen::Vector3d& u, double range) {
    const double start = config_.carving_step;
    if (range <= start) return;
    const Eigen::Vector3d eye = (p + start * u) / vg_;
    const double end = (range - start) / vg_;
    GridWalk<3> blocks(eye, u, 0.0, end);
    do {
      const openvdb::Coord block = blocks.cell();
      const auto* leaf = observed_.probeConstLeaf(block);
      if (!leaf) continue;
      GridWalk<0> walk(eye, u, blocks.time(), std::min(blocks.next(), end));
      do {
        const openvdb::Coord v = walk.cell();
        // A voxel on the block's edge may round into the neighbour: that block visits it.
        // Observed = active: every fused voxel has weight > 0, and the leaf's mask is 64 bytes
        // where its values are 4 kB (their cache misses cost about 1 ms of a 5 cm room frame).
        if (leaf_origin_of(v) != block || !leaf->isValueOn(v)) continue;
        cast(v, kFree);
        if (lateral_ && leaf->getValue(v)[0] > 0.0f) beside_ray(v);  // held inside: the object left
      } while (walk.step());
    } while (blocks.step());
  }

  // A lidar's rings cross space a few voxels apart (7 cm at 2 m for rings 2 degrees apart), so
  // where an object left, rows of voxels between two rings were crossed by no ray and kept its
  // old surface (random box rooms from rings: 17 bins read too near where the box had stood,
  // the TSDF peer 9; a level lidar's rings cross the same rows every sweep, and the ghost
  // stayed for good). Where a ray carves a voxel the map held inside an object, the observed
  // voxels just above and below get a vote "beside a ray": one free vote where no other vote
  // of the frame reached (vote_free_where_unvoted). Only there: beside space the map already
  // held free, a ray passing just above a table top 4 cm thick between two rings would carve it.
  void beside_ray(const openvdb::Coord& v) {
    for (const int dz : {-1, 1}) {
      const openvdb::Coord n = v.offsetBy(0, 0, dz);
      if (observed_.isValueOn(n)) cast(n, kBesideRay);
    }
  }

  const VdbGpdfConfig& config_;
  const DepthView& view_;
  const SurfaceGp& gp_;
  Eigen::Vector3d origin_;
  double vg_;
  bool lateral_;
  ReadAccessor<DistanceWeightGrid::TreeType> observed_;
  const std::vector<LeafCells>& cells_;
  LocalGps::IndexAccessor index_;
  WideNeighbourhood wide_;
};

// Counts the frame's votes per global voxel (and sums the surface votes' offsets), in a fixed
// order: the result does not depend on the thread count.
void count_votes(const std::vector<std::vector<Vote>>& votes, VoteGrid& counts, SurfaceVoteGrid& surface,
                 LateralVoteGrid& lateral, openvdb::MaskGrid& beside_rays) {
  KeptLeafWriter<VoteGrid> counted(counts);
  auto surface_acc = surface.getAccessor();
  auto lateral_acc = lateral.getAccessor();
  auto beside_acc = beside_rays.getAccessor();
  for (const auto& leaf_votes : votes)
    for (const Vote& vote : leaf_votes) {
      if (vote.kind == kBesideRay) {
        beside_acc.setValueOn(vote.voxel);
        continue;
      }
      if (vote.kind == kLateral) {
        lateral_acc.setValue(vote.voxel, lateral_acc.getValue(vote.voxel) + openvdb::Vec2s(vote.offset, 1.0f));
        counted.on(vote.voxel);
        continue;
      }
      if (vote.kind == kSurface) {
        openvdb::Vec4f sums = surface_acc.getValue(vote.voxel);
        const int at = vote.offset > 0.0f ? 0 : 2;
        sums[at] += vote.offset;
        sums[at + 1] += 1.0f;
        surface_acc.setValue(vote.voxel, sums);
        counted.on(vote.voxel);  // every voted voxel is visited through `counts`
        continue;
      }
      ++counted.on(vote.voxel)[vote.kind];
    }
}

// Every voxel of `voxels` that no vote reached gets one free vote, which voxel_update keeps
// near the frame's surfaces only where the depth image (or the cloud's cube) shows its centre
// free. Called for the voxels near the frame's points, and for a cloud's voxels beside its
// carving rays (LeafQueries::beside_ray). Near the points: beside a silhouette no surface
// point has free space in front of it and carving rays cross only voxels observed before, so
// that space was never given a value, and marching cubes, which needs all eight corners of a
// cube, ended the surface up to half a voxel short of the silhouette (scenes/smoke.yaml: the
// ball's limb 2.5 cm short, and bins it enters read the wall behind). The space then counts as
// observed and gathers carving votes; a person stepping into it is in the map at once by the
// arrival rule (fuse_updates).
void vote_free_where_unvoted(const openvdb::MaskGrid& voxels, VoteGrid& counts) {
  auto acc = counts.getAccessor();
  VoteCounts free_vote(0);
  free_vote[kFree] = 1;
  for (auto v = voxels.cbeginValueOn(); v; ++v)
    if (!acc.isValueOn(v.getCoord())) acc.setValue(v.getCoord(), free_vote);
}

// A lidar's rings cross the same heights sweep after sweep. Where an object left, the old
// surface at its edges stayed as single voxels held inside, each between two rows that rays
// cross but held free on either side, so that no ray crosses a voxel held inside beside them
// (LeafQueries::beside_ray): a spinning lidar's box left its vertical edges in the circle for
// good. A voxel held inside with no voxel around it held inside is an object thinner than a
// voxel every way; right above or below a voxel a ray crossed in this frame (a free vote), and
// reached by no vote of its own, it is marked beside a ray too. (A counter top between two
// rings has its neighbours along the top held inside: it stays.)
void mark_lone_inside_beside_rays(const VoteGrid& counts, const DistanceWeightGrid& fused,
                                  openvdb::MaskGrid& beside_rays) {
  std::vector<const VoteGrid::TreeType::LeafNodeType*> leaves;
  counts.tree().getNodes(leaves);
  std::vector<std::vector<openvdb::Coord>> found(leaves.size());
  parallel_for_each_index(leaves.size(), [&](size_t i) {
    const auto voted = read_accessor(counts);
    const auto map = read_accessor(fused);
    auto held_inside = [&](const openvdb::Coord& c) {
      openvdb::Vec2s value;
      return map.probeValue(c, value) && value[0] > 0.0f;
    };
    auto alone = [&](const openvdb::Coord& n) {
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz)
            if ((dx || dy || dz) && held_inside(n.offsetBy(dx, dy, dz))) return false;
      return true;
    };
    for (auto v = leaves[i]->cbeginValueOn(); v; ++v) {
      if ((*v)[kFree] == 0) continue;
      for (const int dz : {-1, 1}) {
        const openvdb::Coord n = v.getCoord().offsetBy(0, 0, dz);
        if (!voted.isValueOn(n) && held_inside(n) && alone(n)) found[i].push_back(n);
      }
    }
  });
  auto mask = beside_rays.getAccessor();
  for (const auto& coords : found)
    for (const openvdb::Coord& n : coords) mask.setValueOn(n);
}

}  // namespace

void cast_votes(const VdbGpdfConfig& config, const LocalFrame& local, const DepthView& view,
                const DistanceWeightGrid& fused, const Eigen::Vector3d& origin, FrameVotes& out) {
  const size_t leaves = local.gps.gps.size();
  std::vector<std::vector<Vote>> votes(leaves);
  parallel_for_each_index(leaves, [&](size_t leaf) {
    LeafQueries queries(config, local, fused, leaf, origin, view);
    // The sources: the leaf's training points, then its sparse sources.
    const std::vector<Eigen::Vector3f>& trained = local.gps.gps[leaf].points();
    const std::vector<Eigen::Vector3f>& sparse = local.sparse_sources[leaf];
    queries.votes.reserve((trained.size() + sparse.size()) * kVotesPerSource);
    for (size_t i = 0; i < trained.size(); ++i) queries.add(trained[i].cast<double>(), i);
    for (const Eigen::Vector3f& p : sparse) queries.add(p.cast<double>(), std::nullopt);
    votes[leaf] = std::move(queries.votes);
  });
  openvdb::MaskGrid beside_rays(false);
  count_votes(votes, out.counts, out.surface, out.lateral, beside_rays);
  // Before the free votes below, which no ray cast: a free vote counted so far is a ray crossing.
  if (!view.has_image()) mark_lone_inside_beside_rays(out.counts, fused, beside_rays);
  vote_free_where_unvoted(local.near, out.counts);
  vote_free_where_unvoted(beside_rays, out.counts);
}

}  // namespace sonomap::gpdf
