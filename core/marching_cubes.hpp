// SPDX-License-Identifier: GPL-3.0-or-later
// Marching cubes over a sparse (distance, weight) grid, per 8^3 leaf, and a per-leaf cache of
// dense surface samples for rasters.
//
// Grid convention (shared by VDB-GPDF and the TSDF peer): index-space voxel ijk holds the value
// at the world point (ijk + 0.5) * voxel_size (floor binning). Value x = signed distance,
// negative in free space and positive behind surfaces; value y = fusion weight, 0 = never
// observed. A cube (8 neighbouring voxel centres) is valid when all corner weights reach the
// minimum weight; the surface is its zero crossing.
#pragma once

#include "core/types.hpp"

#include <Eigen/Core>
#include <openvdb/openvdb.h>

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace sonomap {

using DistanceWeightGrid = openvdb::Grid<openvdb::Vec2STree>;

// A read-only accessor that is not registered with its tree, for a grid that does not change
// while the accessor lives. getConstAccessor() enters each accessor in its tree's concurrent
// hash map (so that the tree can reset it when it changes) and takes it out again: 4,000 of them
// took 0.50 ms on one thread and 0.93 ms on two, which contend for the map (these: 0.05 and
// 0.06 ms). A 5 cm VDB-GPDF frame makes about 2,800, one or more per leaf task
// (docs/performance.md, "Accessors not registered").
template <class TreeT>
using ReadAccessor = openvdb::tree::ValueAccessor<const TreeT, false>;
template <class GridT>
ReadAccessor<typename GridT::TreeType> read_accessor(const GridT& grid) {
  return ReadAccessor<typename GridT::TreeType>(grid.tree());
}

struct SurfaceMesh {
  std::vector<Eigen::Vector3f> vertices;   // world coordinates
  std::vector<Eigen::Vector3i> triangles;  // counter-clockwise seen from free space
  void clear() {
    vertices.clear();
    triangles.clear();
  }
};

// Hash for leaf / voxel coordinates.
struct CoordHash {
  size_t operator()(const openvdb::Coord& c) const {
    const uint64_t h = static_cast<uint64_t>(static_cast<uint32_t>(c.x())) * 73856093u ^
                       static_cast<uint64_t>(static_cast<uint32_t>(c.y())) * 19349663u ^
                       static_cast<uint64_t>(static_cast<uint32_t>(c.z())) * 83492791u;
    return static_cast<size_t>(h);
  }
};

constexpr int kLeafLog2 = DistanceWeightGrid::TreeType::LeafNodeType::LOG2DIM;  // 3
constexpr int kLeafDim = 1 << kLeafLog2;                                         // 8

// The leaf origin (index space) of the leaf holding voxel ijk.
inline openvdb::Coord leaf_origin_of(const openvdb::Coord& ijk) {
  return ijk & ~(kLeafDim - 1);
}

// The leaf holding voxel ijk as one cell of a grid with one value per leaf (the origin over
// kLeafDim), and back.
inline openvdb::Coord leaf_key_of(const openvdb::Coord& ijk) { return ijk >> kLeafLog2; }
inline openvdb::Coord leaf_origin_of_key(const openvdb::Coord& key) {  // no << : keys may be negative
  return openvdb::Coord(key.x() * kLeafDim, key.y() * kLeafDim, key.z() * kLeafDim);
}

// Index-space voxel holding world point p (floor binning).
inline openvdb::Coord voxel_of(const Eigen::Vector3d& p, double voxel_size) {
  return openvdb::Coord(static_cast<int>(std::floor(p.x() / voxel_size)),
                        static_cast<int>(std::floor(p.y() / voxel_size)),
                        static_cast<int>(std::floor(p.z() / voxel_size)));
}

// The centre of voxel ijk of a grid of `voxel_size` metres, and of the leaf at `origin`.
inline Eigen::Vector3d voxel_centre(const openvdb::Coord& ijk, double voxel_size) {
  return Eigen::Vector3d(ijk.x() + 0.5, ijk.y() + 0.5, ijk.z() + 0.5) * voxel_size;
}

inline Eigen::Vector3d leaf_centre(const openvdb::Coord& origin, double voxel_size) {
  return (Eigen::Vector3d(origin.x(), origin.y(), origin.z()) + Eigen::Vector3d::Constant(kLeafDim * 0.5)) *
         voxel_size;
}

// Appends the triangles of the cubes whose lowest corner lies in the leaf at leaf_origin.
// Vertices shared by cubes of this leaf are not duplicated.
void march_leaf(const DistanceWeightGrid& grid, const openvdb::Coord& leaf_origin,
                double voxel_size, float min_weight, SurfaceMesh& out);

// The whole surface: every leaf of the grid, in the grid's (deterministic) leaf order.
SurfaceMesh march_grid(const DistanceWeightGrid& grid, double voxel_size, float min_weight);

// Points on the triangles themselves, so that neighbouring samples are at most `spacing`
// apart along every edge: each triangle is subdivided into n^2 sub-triangles with
// n = ceil(longest edge / spacing) and all their corners are appended, each once: a mesh
// vertex once, and the points inside an edge once when its triangles divide it alike.
void sample_surface(const SurfaceMesh& mesh, double spacing, std::vector<Eigen::Vector3f>& out);

// The voxels of one leaf (origin, one bit per voxel in the leaf's own order) that changed.
using LeafMask = DistanceWeightGrid::TreeType::LeafNodeType::NodeMaskType;
struct LeafChanges {
  openvdb::Coord origin;
  LeafMask voxels;
};

// Leaves that must be re-marched after the voxels in `touched` changed: each touched leaf and,
// for voxels on a leaf's lower faces, the lower neighbours whose cubes reach into it.
// Returned sorted (deterministic).
std::vector<openvdb::Coord> dirty_leaves(const std::vector<LeafChanges>& changed);
// The active voxels of `touched` (a grid of the same leaf size, any value type), leaf by leaf,
// in the tree's order.
template <class GridT>
std::vector<LeafChanges> leaf_changes(const GridT& touched) {
  static_assert(GridT::TreeType::LeafNodeType::LOG2DIM == kLeafLog2, "a LeafMask per leaf");
  std::vector<LeafChanges> changed;
  for (auto leaf = touched.tree().cbeginLeaf(); leaf; ++leaf)
    changed.push_back({leaf->origin(), leaf->getValueMask()});
  return changed;
}

// Dense surface samples per leaf of a grid, refreshed leaf by leaf, queried by a horizontal
// disc so the cost follows the queried area, not the whole map.
class SurfaceCache {
 public:
  explicit SurfaceCache(double leaf_size = 0.4) : leaf_size_(leaf_size) {}
  // Replaces (or, if samples is empty, drops) the samples of one leaf.
  void set(const openvdb::Coord& leaf_origin, std::vector<Eigen::Vector3f> samples);
  // Appends the samples within horizontal distance `radius` of center whose height z lies in
  // [z_min, z_max], leaf by leaf in a fixed order; a leaf whose samples all lie outside the
  // disc or the heights is skipped without reading them.
  void collect(const Eigen::Vector3d& center, double radius, double z_min, double z_max,
               std::vector<Eigen::Vector3f>& out) const;
  // The same leaves, in the same order, handed over whole: every sample collect() appends is
  // in `out`'s spans in its order, with the other samples of its leaf around it.
  void spans(const Eigen::Vector3d& center, double radius, double z_min, double z_max,
             std::vector<SampleSpan>& out) const;
  size_t leaf_count() const { return leaves_.size(); }
  size_t sample_count() const;
  void clear() { leaves_.clear(); }

 private:
  struct LeafSamples {
    std::vector<Eigen::Vector3f> points;
    Eigen::Vector3f min, max;  // their bounds
  };
  // Calls visit(leaf, all_within, all_in) for each leaf that may hold a sample within the disc
  // and the heights, in a fixed order; all_within says that every sample of the leaf is within
  // the disc, all_in that every sample is within the disc and the heights.
  template <class Visit>
  void visit_leaves(const Eigen::Vector3d& center, double radius, double z_min, double z_max,
                    Visit&& visit) const;

  double leaf_size_;  // world size of one leaf (8 voxels)
  std::unordered_map<openvdb::Coord, LeafSamples, CoordHash> leaves_;
  int min_z_ = 0, max_z_ = -1;  // range of leaf origins' z (index space) seen so far
};

}  // namespace sonomap
