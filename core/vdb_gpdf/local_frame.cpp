// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/vdb_gpdf/local_frame.hpp"

#include <openvdb/tools/Morphology.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <unordered_map>

#include "core/point_binning.hpp"
#include "core/vdb_gpdf/kept_leaf_writer.hpp"

namespace sonomap::gpdf {
namespace {

// A global voxel without a training point gets a query source of its own only when its
// frame points fill this many local voxels: a patch of surface, not a lone mixed pixel beside
// a silhouette (one or two of those made a box's edge run 5 cm into free space; a corner seen
// along its diagonal, tests/core/test_circle_fidelity.cpp). At the image's edge the frame
// cuts every patch, and one local voxel is enough: a panel entering the view at the image's
// corner, 16 pixels in three global voxels, was otherwise not in the circle.
constexpr int kMinSparseCells = 3;
constexpr double kEdgePixels = 3.0;

Eigen::Vector3d centroid(const openvdb::Vec4f& sum) {
  return Eigen::Vector3d(sum[0], sum[1], sum[2]) / sum[3];
}

// Stage "voxelise", in parallel over a split of the work that never depends on the thread count
// (kWorkParts chunks of the frame's points, kWorkParts buckets of local leaves, one task per
// local leaf), and each voxel adds its terms in the serial order: the result is the serial one,
// to the bit.
constexpr size_t kWorkParts = 8;

// The bucket of the local leaf holding voxel v: a hash of the leaf's index (its origin's low
// bits are all zero).
size_t bucket_of(const openvdb::Coord& v) {
  return CoordHash{}(v >> PointSumGrid::TreeType::LeafNodeType::LOG2DIM) % kWorkParts;
}

// One bucket's leaves of the point sums, built apart and then moved into the grid (a grid per
// bucket would allocate top nodes of its own, 256 kB each, every frame).
class PointSumLeaves {
 public:
  using Leaf = PointSumGrid::TreeType::LeafNodeType;

  // Adds `sum` to voxel v's value and activates it.
  void add(const openvdb::Coord& v, const openvdb::Vec4f& sum) {
    Leaf& l = leaf(v);
    const openvdb::Index i = Leaf::coordToOffset(v);
    last_values_[i] += sum;
    l.setValueOn(i);
  }

  void move_into(PointSumGrid& grid) {
    for (auto& [origin, leaf] : leaves_) grid.tree().addLeaf(leaf.release());
    leaves_.clear();
    last_ = nullptr;
  }

 private:
  // A bucket's runs come in the image's order, a row's mostly in one leaf: the leaf of the run
  // before and its values are kept (a value read through the leaf checks whether its buffer is
  // loaded).
  Leaf& leaf(const openvdb::Coord& v) {
    const openvdb::Coord origin = leaf_origin_of(v);
    if (last_ != nullptr && last_->origin() == origin) return *last_;
    std::unique_ptr<Leaf>& slot = leaves_[origin];
    if (!slot) slot = std::make_unique<Leaf>(origin, openvdb::Vec4f(0.0f));
    last_ = slot.get();
    last_values_ = last_->buffer().data();
    return *last_;
  }

  std::unordered_map<openvdb::Coord, std::unique_ptr<Leaf>, CoordHash> leaves_;
  Leaf* last_ = nullptr;
  openvdb::Vec4f* last_values_ = nullptr;
};

// Consecutive fused points in one local voxel (neighbouring pixels mostly share one) and their
// sum, added to the grid at once.
struct PointRun {
  openvdb::Coord voxel;
  openvdb::Vec4f sum;
};

using RunsPerBucket = std::vector<std::vector<PointRun>>;

// Appends a run field by field: a PointRun built on the stack with narrow stores and copied
// in with wide loads stalled store-to-load forwarding (a third of chunk_runs' samples).
void append_run(std::vector<PointRun>& runs, const openvdb::Coord& voxel, const openvdb::Vec4f& sum) {
  PointRun& r = runs.emplace_back();
  r.voxel = voxel;
  r.sum = sum;
}

// The runs that start among points [begin, end), each summed to its end (past `end` if it goes
// on: a run belongs whole to the chunk it starts in), sorted into their voxels' buckets. The
// sum is kept in four floats, added as Vec4f's += adds (x, y, z, 1): the same bits.
void chunk_runs(const PointBinner& binner, const std::vector<Eigen::Vector3f>& points, size_t begin,
                size_t end, RunsPerBucket& buckets) {
  for (std::vector<PointRun>& bucket : buckets) bucket.reserve((end - begin) / buckets.size());
  PointBinner::Batch b;
  openvdb::Coord run(std::numeric_limits<int>::min());
  for (size_t i = begin; i-- > 0;) {  // the run going on at `begin`, if any
    binner.bin(&points[i], 1, b);
    if (b.fused[0]) {
      run = b.voxel(0);
      break;
    }
  }
  bool own = false;  // the current run started in this chunk
  float sx = 0.0f, sy = 0.0f, sz = 0.0f, count = 0.0f;
  const auto close_run = [&] {
    if (own) append_run(buckets[bucket_of(run)], run, openvdb::Vec4f(sx, sy, sz, count));
  };
  for (size_t first = begin; first < points.size(); first += PointBinner::kBatch) {
    const size_t n = std::min(PointBinner::kBatch, points.size() - first);
    binner.bin(&points[first], n, b);
    for (size_t k = 0; k < n; ++k) {
      if (!b.fused[k]) continue;
      if ((b.vx[k] != run.x()) | (b.vy[k] != run.y()) | (b.vz[k] != run.z())) {
        close_run();
        if (first + k >= end) return;
        run = b.voxel(k);
        sx = sy = sz = count = 0.0f;
        own = true;
      }
      sx += b.x[k];
      sy += b.y[k];
      sz += b.z[k];
      count += 1.0f;
    }
  }
  close_run();
}

// Adds the frame's points in range to their local voxels: runs found per chunk of points, then
// added per bucket in the points' order, so each voxel sums its runs as one serial pass would.
void sum_points(const VdbGpdfConfig& config, const Frame& frame, PointSumGrid& grid) {
  const PointBinner binner(config.local_voxel, config.min_range, config.max_range, frame.world_T_camera);
  const std::vector<Eigen::Vector3f>& points = frame.points_camera;
  std::vector<RunsPerBucket> runs(kWorkParts, RunsPerBucket(kWorkParts));  // per chunk
  parallel_for_each_index(kWorkParts, [&](size_t c) {
    chunk_runs(binner, points, points.size() * c / kWorkParts, points.size() * (c + 1) / kWorkParts, runs[c]);
  });
  std::vector<PointSumLeaves> buckets(kWorkParts);
  parallel_for_each_index(kWorkParts, [&](size_t b) {
    for (const RunsPerBucket& chunk : runs)
      for (const PointRun& r : chunk[b]) buckets[b].add(r.voxel, r.sum);
  });
  for (PointSumLeaves& bucket : buckets) bucket.move_into(grid);  // leaves in any order: the same tree
}

// A local leaf that a surface crosses holds about DIM x DIM = 64 occupied local voxels in a
// depth image's frame, and voxel_downsample thins them. A lidar's ring crosses one as a line of
// about 8, and every fifth of those left training points 10 cm apart, three of the local GPs'
// length scales: from every eighth row of the random box rooms, 3 more bins too far at corners,
// 11 at thin slabs and 2 at grazing faces (docs/fidelity.md, "A lidar's rings"). In a cloud, a
// leaf with fewer than half a plane's voxels keeps every one.
constexpr size_t kSparseLeafCells = LeafCells::Leaf::DIM * LeafCells::Leaf::DIM / 2;

// A local leaf's local voxels and those of its 26 neighbouring leaves, each leaf fetched once,
// so that a voxel's 26 neighbours are read as bits of their leaves' masks.
class LocalVoxelsAround {
 public:
  using Leaf = PointSumGrid::TreeType::LeafNodeType;
  LocalVoxelsAround(const PointSumGrid& grid, const Leaf& leaf) : origin_(leaf.origin()) {
    const auto acc = read_accessor(grid);
    const int dim = static_cast<int>(Leaf::DIM);
    for (int i = 0; i < 27; ++i)
      leaves_[i] = acc.probeConstLeaf(origin_.offsetBy((i / 9 - 1) * dim, (i / 3 % 3 - 1) * dim, (i % 3 - 1) * dim));
  }
  // Whether local voxel v (at most one voxel outside the leaf on each axis) holds points.
  bool occupied(const openvdb::Coord& v) const {
    const Leaf* leaf =
        leaves_[9 * side(v.x() - origin_.x()) + 3 * side(v.y() - origin_.y()) + side(v.z() - origin_.z())];
    return leaf != nullptr && leaf->isValueOn(v);
  }

 private:
  static int side(int local) { return local < 0 ? 0 : local < static_cast<int>(Leaf::DIM) ? 1 : 2; }
  openvdb::Coord origin_;
  std::array<const Leaf*, 27> leaves_{};
};

// Where the surface through local voxel v ends, as the sensor at `eye` sees it: the unit
// direction across the line of sight in which it ends, or none. It ends there when v's surface
// is one local voxel thick (at most kEdgeNeighbours of its 26 neighbours hold points) and the
// sum of their offsets across the line of sight is kEdgeImbalance voxels or more and half their
// count (on a plane's edge 3 of its 5 neighbours lie inward: 3; at its corner, (2, 2) of 3;
// inside a plane they cancel). Depth noise thickens far surfaces along the line of sight into
// shells whose outer cells lean inward too: a count above a plane's 8 rules them out (without
// it, four in five local voxels of the room's 640 x 480 frames counted).
constexpr int kEdgeNeighbours = 8;
constexpr double kEdgeImbalance = 2.0;
std::optional<Eigen::Vector3d> surface_end(const LocalVoxelsAround& around, const openvdb::Coord& v,
                                           const Eigen::Vector3d& centroid, const Eigen::Vector3d& eye) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        if ((dx | dy | dz) == 0 || !around.occupied(v.offsetBy(dx, dy, dz))) continue;
        if (++count > kEdgeNeighbours) return std::nullopt;
        sum += Eigen::Vector3d(dx, dy, dz);
      }
  const Eigen::Vector3d ray = (centroid - eye).normalized();
  const Eigen::Vector3d across = sum - sum.dot(ray) * ray;
  if (across.norm() < kEdgeImbalance || across.norm() < 0.5 * count) return std::nullopt;
  return Eigen::Vector3d(-across.normalized());
}

// Whether local voxel v (its points' centroid c) lies on an edge of its surface that the sensor
// saw past: a local voxel beyond it, its pixel (or cell) measured a surface more than a global
// voxel farther. Every voxel_downsample-th local voxel trains the GPs, so their field put an
// edge up to that spacing short of the points: a 4 cm slab's side seen at 7 degrees read 2 cm
// short, 0.2 m too far in the circle; such voxels train the GPs too (docs/fidelity.md, "A
// surface's edge in the training points"). Where the view's edge cut the surface, nothing was
// measured beyond it and the surface goes on: a training point there carried a table's top a
// voxel past its corner below the view (test "a table whose corner stays just below the view").
// `around` is fetched for the first voxel of a leaf that passes the image's cheap test.
bool at_seen_edge(std::optional<LocalVoxelsAround>& around, const PointSumGrid& points,
                  const PointSumGrid::TreeType::LeafNodeType& leaf, const DepthView& view,
                  const openvdb::Coord& v, const Eigen::Vector3d& c, const Eigen::Vector3d& eye,
                  const VdbGpdfConfig& config) {
  if (!view.near_silhouette(c)) return false;
  if (!around) around.emplace(points, leaf);
  const std::optional<Eigen::Vector3d> end = surface_end(*around, v, c, eye);
  return end && view.seen_past(view.sight(c + *end * config.local_voxel), config.global_voxel);
}

// Asks the memory for a local leaf's occupied sums at once, before the loop that reads them one
// by one: the voxelise stage wrote them a few megabytes of leaves ago, so each is a cache miss,
// and the loop's work per voxel is too long for the processor to overlap them on its own.
void ask_for_sums(const PointSumGrid::TreeType::LeafNodeType& leaf) {
  const openvdb::Vec4f* sums = leaf.buffer().data();
  for (auto v = leaf.cbeginValueOn(); v; ++v) __builtin_prefetch(sums + v.pos());
}

// The space a local leaf's centroids lie in: its cube, with a local voxel to spare on every side
// (a centroid of float sums may round a hair past its voxel's face).
Eigen::AlignedBox3d local_leaf_box(const openvdb::Coord& origin, double local_voxel) {
  const Eigen::Vector3d centre = leaf_centre(origin, local_voxel);
  const Eigen::Vector3d half = Eigen::Vector3d::Constant((kLeafDim / 2.0 + 1.0) * local_voxel);
  return {centre - half, centre + half};
}

// The local leaves indexed for the GPs. Per local leaf, in parallel: its GP training points (the
// centroids of every voxel_downsample-th occupied local voxel, or of every one in a cloud's
// sparse leaf, then of the others on an edge that the sensor saw past; not the voxel centres:
// centres put a face up to half a local voxel inside or outside it), their box, and its cells;
// then the leaf index and the neighbour links.
void index_local_leaves(const VdbGpdfConfig& config, const DepthView& view, const Eigen::Vector3d& eye,
                        LocalFrame& out) {
  const bool cloud = !view.has_image();
  std::vector<const PointSumGrid::TreeType::LeafNodeType*> leaves;
  for (auto leaf = out.points.tree().cbeginLeaf(); leaf; ++leaf) leaves.push_back(leaf.getLeaf());
  const size_t n = leaves.size();
  LocalGps& gps = out.gps;
  gps.voxel = config.local_voxel;
  gps.origins.resize(n);
  gps.centres.resize(n);
  gps.bounds.resize(n);
  out.training.resize(n);
  std::vector<LeafCells>& cells = out.cells;
  cells.resize(n);
  parallel_for_each_index(n, [&](size_t i) {
    const size_t on = leaves[i]->onVoxelCount();
    const int stride = cloud && on < kSparseLeafCells ? 1 : config.voxel_downsample;
    const bool near_silhouette = view.may_touch_silhouette(local_leaf_box(leaves[i]->origin(), config.local_voxel));
    // Room for every training point up front (edge voxels only near a silhouette): each vector
    // grown one by one was hundreds of allocations a frame.
    const size_t most_trained = near_silhouette ? on : on / stride + 1;
    cells[i].cells.reserve(on);
    cells[i].trained.reserve(most_trained);
    out.training[i].reserve(most_trained);
    cells[i].cell_of.fill(-1);
    ask_for_sums(*leaves[i]);
    std::optional<LocalVoxelsAround> around;
    LeafCells::Leaf::NodeMaskType at_edges;  // the cells on an edge, trained after the others
    int k = 0;
    for (auto v = leaves[i]->cbeginValueOn(); v; ++v, ++k) {
      const Eigen::Vector3d c = centroid(*v);
      cells[i].cell_of[v.pos()] = static_cast<int16_t>(cells[i].cells.size());
      cells[i].cells.push_back({c, voxel_of(c, config.global_voxel)});
      if (cloud) cells[i].box.extend(c);  // for WideNeighbourhood, clouds only
      const bool strided = k % stride == 0;
      const bool on_edge = !strided && near_silhouette &&
                           at_seen_edge(around, out.points, *leaves[i], view, v.getCoord(), c, eye, config);
      if (!strided && !on_edge) continue;
      const Eigen::Vector3f point = c.cast<float>();  // as the GP holds it
      cells[i].trained.emplace_back(voxel_of(point.cast<double>(), config.global_voxel));
      if (strided) out.training[i].push_back(point);
      if (on_edge) at_edges.setOn(static_cast<openvdb::Index>(k));
    }
    for (auto e = at_edges.beginOn(); e; ++e)
      out.training[i].push_back(cells[i].cells[e.pos()].centroid.cast<float>());
    for (const Eigen::Vector3f& t : out.training[i]) gps.bounds[i].extend(t.cast<double>());
    gps.origins[i] = leaves[i]->origin();
    gps.centres[i] = leaf_centre(gps.origins[i], config.local_voxel);
  });
  for (size_t i = 0; i < n; ++i) gps.index.setValue(leaf_key_of(gps.origins[i]), static_cast<int>(i));
  gps.link_neighbours();
}

// Per global voxel holding a local voxel's centroid: how many it holds, or -1 when it holds a
// GP training point. (Serial: one pass of cheap adds, the centroids are computed already.)
void count_cells(const std::vector<LeafCells>& leaves, openvdb::Int32Grid& counts) {
  KeptLeafWriter<openvdb::Int32Grid> counted(counts);
  for (const LeafCells& leaf : leaves)
    for (const auto& cell : leaf.cells) ++counted.on(cell.global);
  auto count = counts.getAccessor();
  for (const LeafCells& leaf : leaves)
    for (const openvdb::Coord& g : leaf.trained)
      if (count.isValueOn(g)) count.setValue(g, -1);
}

// The global voxels holding one of the frame's points (their local voxels' centroids) and their
// 26 neighbours. A ray proves free only the space it crosses, and the centre of a voxel it
// crosses can lie up to 0.87 voxel off it, so next to a surface that centre can be behind the
// surface. Rays grazing past a silhouette edge, a corner or a thin top carved the object's own
// inside, hundreds of rays against one or two surface samples, and the circle lost the edge
// (room, 300 frames: 69 bin readings too far by over 0.1 m, TSDF peer 15). In these voxels a
// free-space value needs the depth image's word that the centre is free (DepthView).
// (Serial, beside count_cells: a threaded dilation of this small mask was slower.)
void near_surface(const std::vector<LeafCells>& leaves, openvdb::MaskGrid& mask) {
  auto acc = mask.getAccessor();
  for (const LeafCells& leaf : leaves)
    for (const auto& cell : leaf.cells) acc.setValueOn(cell.global);
  openvdb::tools::dilateActiveValues(mask.tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                     openvdb::tools::IGNORE_TILES, false);
}

// The sources besides the training points: the first centroid (in leaf order) of every global
// voxel without a training point that holds kMinSparseCells local voxels or more, or lies at
// the image's edge. Candidates are found per leaf in parallel, then taken in leaf order
// (marking their global voxel -1 in `counts`).
void add_sparse_sources(const DepthView& view, const std::vector<LeafCells>& leaves,
                        openvdb::Int32Grid& counts, LocalFrame& local) {
  std::vector<LeafCells::Leaf::NodeMaskType> candidates(leaves.size());  // per leaf, by cell index
  parallel_for_each_index(leaves.size(), [&](size_t i) {
    const auto count = read_accessor(counts);
    const std::vector<LeafCells::Cell>& cells = leaves[i].cells;
    for (size_t k = 0; k < cells.size(); ++k) {
      const int held = count.getValue(cells[k].global);
      if (held >= kMinSparseCells || (held >= 1 && view.at_edge(cells[k].centroid, kEdgePixels)))
        candidates[i].setOn(static_cast<openvdb::Index>(k));
    }
  });
  local.sparse_sources.resize(leaves.size());
  auto count = counts.getAccessor();
  for (size_t i = 0; i < leaves.size(); ++i) {
    local.sparse_sources[i].reserve(candidates[i].countOn());  // the most it takes (none: no allocation)
    for (auto k = candidates[i].beginOn(); k; ++k) {
      const LeafCells::Cell& cell = leaves[i].cells[k.pos()];
      if (count.getValue(cell.global) < 1) continue;  // taken by an earlier candidate
      count.setValue(cell.global, -1);
      local.sparse_sources[i].push_back(cell.centroid.cast<float>());
    }
  }
}

}  // namespace

void voxelise(const VdbGpdfConfig& config, const Frame& frame, const DepthView& view, LocalFrame& out) {
  sum_points(config, frame, out.points);
  index_local_leaves(config, view, frame.world_T_camera.translation(), out);
  const std::vector<LeafCells>& cells = out.cells;
  openvdb::Int32Grid counts(0);
  parallel_both([&] { count_cells(cells, counts); }, [&] { near_surface(cells, out.near); });
  add_sparse_sources(view, cells, counts, out);
}

void train_local_gps(const GpParams& params, LocalFrame& local) {
  local.gps.gps.resize(local.training.size());
  parallel_for_each_index(local.training.size(),
                          [&](size_t i) { local.gps.gps[i].train(std::move(local.training[i]), params); });
}

}  // namespace sonomap::gpdf
