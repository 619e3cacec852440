// SPDX-License-Identifier: GPL-3.0-or-later
// The frame on VDB-GPDF's fine local grid (stages "voxelise" and "local_gps"): its points summed
// per local voxel, its local leaves' cells, training points and GPs. Internal to core/vdb_gpdf*.
#pragma once

#include "core/gp.hpp"
#include "core/marching_cubes.hpp"
#include "core/parallel.hpp"
#include "core/vdb_gpdf.hpp"
#include "core/vdb_gpdf/depth_view.hpp"

#include <Eigen/Geometry>
#include <openvdb/openvdb.h>

#include <array>
#include <cstdint>
#include <vector>

namespace sonomap::gpdf {

// The frame's local GPs, one per active leaf of the local grid, and the lookup of the nearest
// one: cubic leaves are their own Voronoi cells, so the containing leaf wins; else the nearest
// of its 26 neighbours; else the nearest of all (rare: points far from every surface).
struct LocalGps {
  double voxel = 0.02;
  std::vector<openvdb::Coord> origins;
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::AlignedBox3d> bounds;  // of each GP's training points
  std::vector<SurfaceGp> gps;
  // Per leaf, at one voxel per leaf, its index (-1 where no leaf is): a tree, not a hash map,
  // because an accessor finds the 26 neighbours of a leaf mostly in the node it has cached.
  openvdb::Int32Tree index{-1};
  using IndexAccessor = ReadAccessor<openvdb::Int32Tree>;  // per call
  // Up to 26 leaves, held in place (a vector per leaf, grown one by one, was about 2,000
  // allocations a frame).
  struct LeafList {
    std::array<int, 26> leaves;
    int count = 0;
    void add(int leaf) { leaves[static_cast<size_t>(count++)] = leaf; }
    const int* begin() const { return leaves.data(); }
    const int* end() const { return leaves.data() + count; }
  };
  std::vector<LeafList> neighbours;  // per leaf, its neighbouring leaves

  // Once every leaf is indexed: most queries lie in a leaf, and then smallest() reads its
  // neighbours from here instead of 26 lookups.
  void link_neighbours() {
    neighbours.resize(origins.size());
    parallel_for_each_index(origins.size(), [&](size_t i) {
      IndexAccessor at(index);
      neighbours[i].count = 0;
      for_each_neighbour(at, origins[i], [&](int j) { neighbours[i].add(j); });
    });
  }

  // Calls f(index) for every leaf among the 26 around the leaf at `home`, in x, y, z order. When
  // all 27 keys lie in one node of the index (two keys in five), they are read from its values:
  // through the accessor a key cost about 57 instructions.
  template <typename F>
  void for_each_neighbour(const IndexAccessor& at, const openvdb::Coord& home, F&& f) const {
    using IndexNode = openvdb::Int32Tree::LeafNodeType;
    const openvdb::Coord key = leaf_key_of(home);
    constexpr int kNodeOrigin = ~static_cast<int>(IndexNode::DIM - 1);  // a key's bits of its node's origin
    const bool one_node = (key.offsetBy(-1) & kNodeOrigin) == (key.offsetBy(1) & kNodeOrigin);
    const IndexNode* node = one_node ? at.probeConstLeaf(key) : nullptr;
    const int* values = node ? node->buffer().data() : nullptr;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const openvdb::Coord k = key.offsetBy(dx, dy, dz);
          const int i = values ? values[IndexNode::coordToOffset(k)] : at.getValue(k);
          if (i >= 0) f(i);
        }
  }

  // The leaves around q's own leaf: linked already when that leaf exists, else looked up
  // here once (a quarter of a frame's queries, those between the frame's surfaces, used to
  // look them up twice: 26 hash look-ups for the nearest leaf, 26 more for the rest).
  struct Around {
    const int* begin = nullptr;
    const int* end = nullptr;
    LeafList found;
  };

  // One task's reads of the index, kept from query to query: its accessor has the node of the
  // last query's leaf cached (a fresh one descended the tree from its root, about 60
  // instructions, for each of a frame's 30,000 voxels), and the leaves around the last query's
  // home leaf are kept (consecutive voxels of a vote leaf mostly share their local leaf: the 26
  // look-ups of a home without a leaf were a quarter of the nearest leaf's cost). Not copied:
  // `around` may point into itself.
  struct Lookup {
    explicit Lookup(const openvdb::Int32Tree& index) : at(index) {}
    Lookup(const Lookup&) = delete;
    Lookup& operator=(const Lookup&) = delete;
    IndexAccessor at;
    openvdb::Coord home = openvdb::Coord::max();
    int own = -1;  // the home's leaf, or -1
    Around around;
  };

  // The nearest leaf to q (its own, else the nearest around it, else the nearest of all; ties
  // to the lower index); `lookup.around` then holds the leaves around q's.
  int nearest(const Eigen::Vector3d& q, Lookup& lookup) const {
    const openvdb::Coord home = leaf_origin_of(voxel_of(q, voxel));
    if (home != lookup.home) look_around(home, lookup);
    if (lookup.own >= 0) return lookup.own;
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    auto consider = [&](int i) {
      const double d2 = (centres[i] - q).squaredNorm();
      if (d2 < best_d2 || (d2 == best_d2 && i < best)) {
        best_d2 = d2;
        best = i;
      }
    };
    std::for_each(lookup.around.begin, lookup.around.end, consider);
    if (best >= 0) return best;
    for (int i = 0; i < static_cast<int>(centres.size()); ++i) consider(i);
    return best;
  }

  void look_around(const openvdb::Coord& home, Lookup& lookup) const {
    Around& around = lookup.around;
    lookup.home = home;
    lookup.own = lookup.at.getValue(leaf_key_of(home));
    if (lookup.own < 0) {
      around.found.count = 0;
      for_each_neighbour(lookup.at, home, [&](int j) { around.found.add(j); });
    }
    const LeafList& leaves = lookup.own >= 0 ? neighbours[lookup.own] : around.found;
    around.begin = leaves.begin();
    around.end = leaves.end();
  }

  // The smallest distance the local GPs predict at q. Each GP knows only its own patch, so its
  // distance is an upper bound: a surface just across a leaf border is invisible to the
  // nearest leaf's GP, which then calls a voxel beside a box's edge several centimetres deep
  // in free space and the edge is carved off. Besides the nearest GP, every leaf around q's
  // whose training points' box is nearer than the best distance so far (the box, not the
  // leaf's cube: most neighbours are then skipped unasked).
  GpPrediction smallest(const Eigen::Vector3d& q, bool with_variance, Lookup& lookup) const {
    GpPrediction best;
    auto consider = [&](int i) {
      const GpPrediction p = gps[i].predict(q, with_variance, false);
      if (p.valid && (!best.valid || p.distance < best.distance)) best = p;
    };
    const int first = nearest(q, lookup);
    if (first < 0) return best;
    consider(first);
    const Around& around = lookup.around;
    for (const int* i = around.begin; i != around.end; ++i)
      if (*i != first && (!best.valid || bounds[*i].exteriorDistance(q) < best.distance)) consider(*i);
    return best;
  }
};

// Per local voxel: the sum of the frame's points in it (x, y, z) and their count (w).
using PointSumGrid = openvdb::Grid<openvdb::tree::Tree4<openvdb::Vec4f, 5, 4, 3>::Type>;

// One local leaf's occupied local voxels (centroid and the global voxel holding it) in the
// order of its mask, the global voxels holding its GP training points, and per local voxel
// its cell's index (-1: no point fell in it).
struct LeafCells {
  using Leaf = PointSumGrid::TreeType::LeafNodeType;
  struct Cell {
    Eigen::Vector3d centroid;
    openvdb::Coord global;
  };
  std::vector<Cell> cells;
  Eigen::AlignedBox3d box;  // of the cells' centroids, in a cloud's frame (empty in an image's)
  std::vector<openvdb::Coord> trained;
  std::array<int16_t, Leaf::SIZE> cell_of{};  // 1 kB a leaf: no bit counting per probe
};

// The frame on the fine local grid: per local voxel the sum of its points, per local leaf its
// cells, its GP training points and (after train_local_gps) its GP, and the global voxels near
// the frame's surface.
struct LocalFrame {
  PointSumGrid points{openvdb::Vec4f(0.0f)};
  LocalGps gps;
  std::vector<LeafCells> cells;
  std::vector<std::vector<Eigen::Vector3f>> training;  // per local leaf; moved into its GP (train_local_gps)
  // Per local leaf the points queries are placed around besides its training points (the
  // sources): one centroid in every global voxel holding frame points in kMinSparseCells
  // local voxels or more but no training point (a far surface, a pixel per local voxel, would
  // otherwise be fused in patches).
  std::vector<std::vector<Eigen::Vector3f>> sparse_sources;
  openvdb::MaskGrid near{false};
};

// Stage "voxelise": the frame's points into `out` (points, cells, training points, sparse sources,
// the global voxels near the surface).
void voxelise(const VdbGpdfConfig& config, const Frame& frame, const DepthView& view, LocalFrame& out);

// Stage "local_gps": one GP per local leaf, trained in parallel (each writes its own slot).
void train_local_gps(const GpParams& params, LocalFrame& local);

}  // namespace sonomap::gpdf
