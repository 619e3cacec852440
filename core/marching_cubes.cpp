// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/marching_cubes.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace sonomap {
namespace {

// Cube corners (unit offsets) and edges as (lower corner offset, axis).
constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                               {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
constexpr int kEdgeCorners[12][2] = {{0, 1}, {1, 2}, {3, 2}, {0, 3}, {4, 5}, {5, 6},
                                     {7, 6}, {4, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
constexpr int kEdgeAxis[12] = {0, 1, 0, 1, 0, 1, 0, 1, 2, 2, 2, 2};
constexpr int kFaces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                              {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};

int edge_between(int a, int b) {
  for (int e = 0; e < 12; ++e)
    if ((kEdgeCorners[e][0] == a && kEdgeCorners[e][1] == b) ||
        (kEdgeCorners[e][0] == b && kEdgeCorners[e][1] == a))
      return e;
  return -1;
}

using TriangleList = std::vector<std::array<int, 3>>;  // edge indices

// Our own triangle table, derived instead of typed in: on each face the zero crossing is a set
// of segments, one per run of inside corners (so on an ambiguous face the inside corners are
// kept apart; the rule depends on the face alone, so neighbouring cubes agree and the surface
// is closed). The segments chain into loops (every cut edge lies on two faces); each loop is
// oriented so its normal points to the outside corners and fanned into triangles.
TriangleList triangles_for(int config) {
  auto inside = [config](int corner) { return (config >> corner) & 1; };
  std::array<std::vector<int>, 12> links;
  for (const auto& face : kFaces) {
    for (int i = 0; i < 4; ++i) {
      const int prev = face[(i + 3) % 4];
      if (!inside(face[i]) || inside(prev)) continue;  // not the start of an inside run
      int last = i;
      while (inside(face[(last + 1) % 4])) last = (last + 1) % 4;
      const int enter = edge_between(prev, face[i]);
      const int leave = edge_between(face[last], face[(last + 1) % 4]);
      links[enter].push_back(leave);
      links[leave].push_back(enter);
    }
  }
  auto midpoint = [](int e) -> Eigen::Vector3d {
    const int* a = kCorner[kEdgeCorners[e][0]];
    const int* b = kCorner[kEdgeCorners[e][1]];
    return Eigen::Vector3d(a[0] + b[0], a[1] + b[1], a[2] + b[2]) * 0.5;
  };
  TriangleList out;
  std::array<bool, 12> used{};
  for (int start = 0; start < 12; ++start) {
    if (links[start].empty() || used[start]) continue;
    std::vector<int> loop{start};
    used[start] = true;
    int prev = -1, cur = start;
    for (;;) {
      const int next = links[cur][0] != prev ? links[cur][0] : links[cur][1];
      if (next == start || loop.size() == 12) break;
      loop.push_back(next);
      used[next] = true;
      prev = cur;
      cur = next;
    }
    Eigen::Vector3d normal = Eigen::Vector3d::Zero(), outward = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < loop.size(); ++i) {
      normal += midpoint(loop[i]).cross(midpoint(loop[(i + 1) % loop.size()]));
      const int a = kEdgeCorners[loop[i]][0], b = kEdgeCorners[loop[i]][1];
      const Eigen::Vector3d ab(kCorner[b][0] - kCorner[a][0], kCorner[b][1] - kCorner[a][1],
                               kCorner[b][2] - kCorner[a][2]);
      outward += inside(a) ? ab : Eigen::Vector3d(-ab);
    }
    if (normal.dot(outward) < 0.0) std::reverse(loop.begin(), loop.end());
    for (size_t i = 1; i + 1 < loop.size(); ++i) out.push_back({loop[0], loop[i], loop[i + 1]});
  }
  return out;
}

const std::array<TriangleList, 256>& triangle_table() {
  static const std::array<TriangleList, 256> table = [] {
    std::array<TriangleList, 256> t;
    for (int c = 0; c < 256; ++c) t[c] = triangles_for(c);
    return t;
  }();
  return table;
}

constexpr int kSpan = kLeafDim + 1;  // a leaf's cubes read one voxel beyond it
// A column (x, y) of the span, and a voxel (x, y, z) as the z-th of its column.
inline int column_index(int x, int y) { return x * kSpan + y; }
inline int local_index(int x, int y, int z) { return column_index(x, y) * kSpan + z; }

// Corners 0-3 go round the square of a cube's lower face, corners 4-7 the same one voxel up.
constexpr bool corners_are_two_squares() {
  constexpr int kSquare[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int c = 0; c < 8; ++c)
    if (kCorner[c][0] != kSquare[c % 4][0] || kCorner[c][1] != kSquare[c % 4][1] || kCorner[c][2] != c / 4)
      return false;
  return true;
}

// The values a leaf's cubes read: its own voxels and the first plane of its upper neighbours.
// Per column (x, y) of the span, bit z says whether voxel (x, y, z) is observed (weight >=
// min_weight) and whether it is inside (distance >= 0): a cube's eight corners are then bits
// of four columns, and a column's cubes that are observed and cut by the surface are found
// for all eight heights at once.
struct LeafSpan {
  std::array<float, kSpan * kSpan * kSpan> dist;
  std::array<uint16_t, kSpan * kSpan> observed{}, inside{};
};

// Reads the span of the leaf at `origin` from that leaf and its 7 upper neighbours, each found
// once: a look-up per voxel through an accessor (729 of them) cost most of the marching. A
// neighbour that is not a leaf holds one value (a tile's, or the background) throughout.
void read_span(const DistanceWeightGrid& grid, const openvdb::Coord& origin, float min_weight,
               LeafSpan& span) {
  using Leaf = DistanceWeightGrid::TreeType::LeafNodeType;
  const auto acc = read_accessor(grid);
  for (int part = 0; part < 8; ++part) {
    const int upper[3] = {(part >> 2) & 1, (part >> 1) & 1, part & 1};
    const openvdb::Coord part_origin =
        origin.offsetBy(upper[0] * kLeafDim, upper[1] * kLeafDim, upper[2] * kLeafDim);
    const Leaf* leaf = acc.probeConstLeaf(part_origin);
    const openvdb::Vec2s* values = leaf ? leaf->buffer().data() : nullptr;  // loaded once, not per value
    const auto tile = leaf ? openvdb::Vec2s() : acc.getValue(part_origin);
    int lo[3], hi[3];  // this part's box in the span
    for (int a = 0; a < 3; ++a) {
      lo[a] = upper[a] ? kLeafDim : 0;
      hi[a] = upper[a] ? kSpan : kLeafDim;
    }
    for (int x = lo[0]; x < hi[0]; ++x)
      for (int y = lo[1]; y < hi[1]; ++y) {
        unsigned observed = 0, inside = 0;
        for (int z = lo[2]; z < hi[2]; ++z) {
          const auto& v = values ? values[Leaf::coordToOffset(openvdb::Coord(x, y, z))] : tile;
          span.dist[local_index(x, y, z)] = v[0];
          observed |= static_cast<unsigned>(v[1] >= min_weight) << z;
          inside |= static_cast<unsigned>(v[0] >= 0.0f) << z;
        }
        span.observed[column_index(x, y)] |= static_cast<uint16_t>(observed);
        span.inside[column_index(x, y)] |= static_cast<uint16_t>(inside);
      }
  }
}

// Whether the span holds both an observed voxel inside and one outside: else no cube is cut.
bool has_both_sides(const LeafSpan& span) {
  unsigned in = 0, out = 0;
  for (size_t c = 0; c < span.observed.size(); ++c) {
    in |= span.observed[c] & span.inside[c];
    out |= span.observed[c] & ~span.inside[c];
  }
  return in != 0 && out != 0;
}

// The columns of the cubes above (x, y): those of corners 0-3, in order (corners 4-7 are the
// same columns one bit up).
struct CubeColumns {
  int at[4];
};
CubeColumns cube_columns(int x, int y) {
  static_assert(corners_are_two_squares(), "corners 0-3 go round the square at z, corners 4-7 the same at z + 1");
  return {{column_index(x, y), column_index(x + 1, y), column_index(x + 1, y + 1),
           column_index(x, y + 1)}};
}

// Bit z set: cube z of the columns has its eight corners observed, some of them inside and not
// all (the others hold no surface).
unsigned cut_cubes(const LeafSpan& span, const CubeColumns& columns) {
  unsigned observed = ~0u, any_inside = 0, all_inside = ~0u;
  for (const int c : columns.at) {
    observed &= span.observed[c];
    any_inside |= span.inside[c];
    all_inside &= span.inside[c];
  }
  const unsigned cut = observed & (observed >> 1) & (any_inside | any_inside >> 1) & ~(all_inside & all_inside >> 1);
  return cut & ((1u << kLeafDim) - 1);
}

// Cube z's configuration: bit c set when corner c is inside.
int cube_config(const LeafSpan& span, const CubeColumns& columns, int z) {
  int config = 0;
  for (int c = 0; c < 4; ++c) {
    const unsigned bits = span.inside[columns.at[c]] >> z;
    config |= static_cast<int>(bits & 1u) << c | static_cast<int>((bits >> 1) & 1u) << (c + 4);
  }
  return config;
}

}  // namespace

void march_leaf(const DistanceWeightGrid& grid, const openvdb::Coord& origin, double voxel_size,
                float min_weight, SurfaceMesh& out) {
  const auto& table = triangle_table();
  LeafSpan span;
  read_span(grid, origin, min_weight, span);
  if (!has_both_sides(span)) return;
  const auto& dist = span.dist;

  std::array<int, kSpan * kSpan * kSpan * 3> vertex_of_edge;
  vertex_of_edge.fill(-1);
  auto vertex = [&](int x, int y, int z, int axis) {
    int& id = vertex_of_edge[local_index(x, y, z) * 3 + axis];
    if (id >= 0) return id;
    const int step[3] = {axis == 0, axis == 1, axis == 2};
    const float da = dist[local_index(x, y, z)];
    const float db = dist[local_index(x + step[0], y + step[1], z + step[2])];
    const double t = static_cast<double>(da) / (static_cast<double>(da) - db);
    const Eigen::Vector3d p(origin.x() + x + 0.5 + t * step[0], origin.y() + y + 0.5 + t * step[1],
                            origin.z() + z + 0.5 + t * step[2]);
    id = static_cast<int>(out.vertices.size());
    out.vertices.push_back((p * voxel_size).cast<float>());
    return id;
  };
  for (int x = 0; x < kLeafDim; ++x)
    for (int y = 0; y < kLeafDim; ++y) {
      const CubeColumns columns = cube_columns(x, y);
      for (unsigned cut = cut_cubes(span, columns); cut != 0; cut &= cut - 1) {
        const int z = __builtin_ctz(cut);
        const int config = cube_config(span, columns, z);
        for (const auto& tri : table[config]) {
          Eigen::Vector3i ids;
          for (int k = 0; k < 3; ++k) {
            const int e = tri[k];
            const int* o = kCorner[kEdgeCorners[e][0]];
            ids[k] = vertex(x + o[0], y + o[1], z + o[2], kEdgeAxis[e]);
          }
          out.triangles.push_back(ids);
        }
      }
    }
}

SurfaceMesh march_grid(const DistanceWeightGrid& grid, double voxel_size, float min_weight) {
  SurfaceMesh mesh;
  for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf)
    march_leaf(grid, leaf->origin(), voxel_size, min_weight, mesh);
  return mesh;
}

namespace {

// Emits each sample of a mesh once. Corners that are vertices are emitted the first time
// only. A point inside an edge is computed from the edge's lower-numbered vertex, so two
// triangles that divide their shared edge alike compute it bit for bit alike, and only the
// first emits it. A repeat never changes a raster, whose cells keep the first point met at
// equal range; without this, nearly half of a flat wall's samples would be repeats.
class SampleEmitter {
 public:
  SampleEmitter(const SurfaceMesh& mesh, std::vector<Eigen::Vector3f>& out)
      : mesh_(mesh), out_(out), vertex_emitted_(mesh.vertices.size(), false) {
    // An open-addressing table of the divided edges, at most 3/4 full: each triangle adds
    // at most 3 edges. No allocation per edge: this runs for every leaf a frame touches.
    size_t capacity = 16;
    while (capacity < 4 * mesh.triangles.size()) capacity *= 2;
    edges_.assign(capacity, DividedEdge{});
    mask_ = capacity - 1;
  }

  void vertex(int v) {
    if (vertex_emitted_[v]) return;
    vertex_emitted_[v] = true;
    out_.push_back(mesh_.vertices[v]);
  }
  // The inner points of edge (p, q) divided in n, steps 1 to n - 1 from its lower-numbered
  // vertex, unless the edge was divided in n before.
  void edge(int p, int q, int n) {
    const int lo = std::min(p, q), hi = std::max(p, q);
    if (!first_division(static_cast<uint64_t>(lo) * mesh_.vertices.size() + static_cast<uint64_t>(hi), n)) return;
    const Eigen::Vector3f a = mesh_.vertices[lo], d = mesh_.vertices[hi] - a;
    for (int s = 1; s < n; ++s) out_.push_back(a + d * (static_cast<float>(s) / n));
  }
  void inner(const Eigen::Vector3f& p) { out_.push_back(p); }

 private:
  struct DividedEdge {
    uint64_t key_plus_one = 0;  // 0: an empty slot
    int divisions = 0;
  };
  // False if the edge was divided in n before; the first division of an edge is recorded.
  bool first_division(uint64_t key, int n) {
    for (size_t slot = (key * 0x9E3779B97F4A7C15ull) >> 32 & mask_;; slot = (slot + 1) & mask_) {
      DividedEdge& e = edges_[slot];
      if (e.key_plus_one == 0) {
        e = DividedEdge{key + 1, n};
        return true;
      }
      if (e.key_plus_one == key + 1) return e.divisions != n;
    }
  }

  const SurfaceMesh& mesh_;
  std::vector<Eigen::Vector3f>& out_;
  std::vector<bool> vertex_emitted_;
  std::vector<DividedEdge> edges_;
  size_t mask_ = 0;
};

}  // namespace

void sample_surface(const SurfaceMesh& mesh, double spacing, std::vector<Eigen::Vector3f>& out) {
  std::vector<int> divisions(mesh.triangles.size());
  size_t count = 0;
  for (size_t k = 0; k < mesh.triangles.size(); ++k) {
    const Eigen::Vector3i& t = mesh.triangles[k];
    const Eigen::Vector3f a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = divisions[k] = std::max(1, static_cast<int>(std::ceil(longest / spacing)));
    count += static_cast<size_t>(n + 1) * (n + 2) / 2;
  }
  out.reserve(out.size() + count);  // one allocation instead of a growing vector's many
  SampleEmitter emit(mesh, out);
  for (size_t k = 0; k < mesh.triangles.size(); ++k) {
    const Eigen::Vector3i& t = mesh.triangles[k];
    const int n = divisions[k];
    // The grid a + (b - a) i / n + (c - a) j / n, i + j <= n, in the order: corners, the
    // edges ab, bc, ca, then the inner points.
    for (int v = 0; v < 3; ++v) emit.vertex(t[v]);
    for (int e = 0; e < 3; ++e) emit.edge(t[e], t[(e + 1) % 3], n);
    const Eigen::Vector3f a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    for (int i = 1; i < n; ++i)
      for (int j = 1; j < n - i; ++j)
        emit.inner(a + (b - a) * (static_cast<float>(i) / n) + (c - a) * (static_cast<float>(j) / n));
  }
}

namespace {

// Bit s (1 to 7) set when a voxel of `voxels` lies on the leaf's lower faces along each axis of
// subset s (1 x, 2 y, 4 z): the cubes of the neighbour one leaf lower along those axes reach
// it. Read word by word: voxel x << 6 | y << 3 | z is bit y << 3 | z of word x, so the face
// x = 0 is word 0, y = 0 the low byte of every word and z = 0 the low bit of every byte.
unsigned lower_neighbours_reached(const LeafMask& voxels) {
  static_assert(kLeafLog2 == 3 && LeafMask::WORD_COUNT == 8, "a word per plane of constant x");
  constexpr uint64_t kY0 = 0xFF, kZ0 = 0x0101010101010101ull;
  uint64_t any_x = 0;
  for (openvdb::Index w = 0; w < LeafMask::WORD_COUNT; ++w) any_x |= voxels.getWord<uint64_t>(w);
  const uint64_t x0 = voxels.getWord<uint64_t>(0);
  const uint64_t on_faces[8] = {0, x0, any_x & kY0, x0 & kY0, any_x & kZ0, x0 & kZ0, any_x & 1, x0 & 1};
  unsigned subsets = 0;
  for (unsigned s = 1; s < 8; ++s)
    if (on_faces[s] != 0) subsets |= 1u << s;
  return subsets;
}

}  // namespace

std::vector<openvdb::Coord> dirty_leaves(const std::vector<LeafChanges>& changed) {
  std::vector<openvdb::Coord> out;
  for (const LeafChanges& leaf : changed) {
    if (leaf.voxels.isOff()) continue;
    out.push_back(leaf.origin);
    const unsigned subsets = lower_neighbours_reached(leaf.voxels);
    for (unsigned s = 1; s < 8; ++s)
      if (subsets & (1u << s))
        out.push_back(leaf.origin.offsetBy((s & 1) ? -kLeafDim : 0, (s & 2) ? -kLeafDim : 0,
                                           (s & 4) ? -kLeafDim : 0));
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void SurfaceCache::set(const openvdb::Coord& leaf_origin, std::vector<Eigen::Vector3f> samples) {
  if (samples.empty()) {
    leaves_.erase(leaf_origin);
    return;
  }
  if (min_z_ > max_z_) {
    min_z_ = max_z_ = leaf_origin.z();
  } else {
    min_z_ = std::min(min_z_, leaf_origin.z());
    max_z_ = std::max(max_z_, leaf_origin.z());
  }
  LeafSamples& leaf = leaves_[leaf_origin];
  leaf.min = leaf.max = samples.front();
  for (const Eigen::Vector3f& p : samples) {
    leaf.min = leaf.min.cwiseMin(p);
    leaf.max = leaf.max.cwiseMax(p);
  }
  leaf.points = std::move(samples);
}

namespace {

// Whether (x, y) lies within horizontal distance sqrt(r2) of the centre.
inline bool within_disc(float x, float y, const Eigen::Vector3d& center, double r2) {
  const double dx = x - center.x(), dy = y - center.y();
  return dx * dx + dy * dy <= r2;
}

}  // namespace

template <class Visit>
void SurfaceCache::visit_leaves(const Eigen::Vector3d& center, double radius, double z_min,
                                double z_max, Visit&& visit) const {
  if (leaves_.empty() || !(radius >= 0.0)) return;
  const int x0 = static_cast<int>(std::floor((center.x() - radius) / leaf_size_)) * kLeafDim;
  const int x1 = static_cast<int>(std::floor((center.x() + radius) / leaf_size_)) * kLeafDim;
  const int y0 = static_cast<int>(std::floor((center.y() - radius) / leaf_size_)) * kLeafDim;
  const int y1 = static_cast<int>(std::floor((center.y() + radius) / leaf_size_)) * kLeafDim;
  // within_disc() rounds monotonically in each coordinate, so the corner of a leaf's bounds
  // farthest from the centre bounds its samples' distances from above, and the point of the
  // bounds nearest to it (floats all) from below.
  const double r2 = radius * radius;
  auto within = [&](float x, float y) { return within_disc(x, y, center, r2); };
  auto in_heights = [&](float z) { return z >= z_min && z <= z_max; };
  auto farther = [](float lo, float hi, double c) {
    return std::abs(lo - c) > std::abs(hi - c) ? lo : hi;
  };
  auto nearest = [](float lo, float hi, double c) {
    return c < lo ? lo : (c > hi ? hi : static_cast<float>(c));
  };
  for (int x = x0; x <= x1; x += kLeafDim)
    for (int y = y0; y <= y1; y += kLeafDim)
      for (int z = min_z_; z <= max_z_; z += kLeafDim) {
        const auto it = leaves_.find(openvdb::Coord(x, y, z));
        if (it == leaves_.end()) continue;
        const LeafSamples& leaf = it->second;
        if (leaf.max.z() < z_min || leaf.min.z() > z_max) continue;
        if (!within(nearest(leaf.min.x(), leaf.max.x(), center.x()),
                    nearest(leaf.min.y(), leaf.max.y(), center.y())))
          continue;
        const bool all_within = within(farther(leaf.min.x(), leaf.max.x(), center.x()),
                                       farther(leaf.min.y(), leaf.max.y(), center.y()));
        visit(leaf, all_within, all_within && in_heights(leaf.min.z()) && in_heights(leaf.max.z()));
      }
}

void SurfaceCache::collect(const Eigen::Vector3d& center, double radius, double z_min,
                           double z_max, std::vector<Eigen::Vector3f>& out) const {
  const double r2 = radius * radius;
  visit_leaves(center, radius, z_min, z_max, [&](const LeafSamples& leaf, bool all_within, bool all_in) {
    if (all_in) {
      out.insert(out.end(), leaf.points.begin(), leaf.points.end());
      return;
    }
    for (const auto& p : leaf.points)
      if ((all_within || within_disc(p.x(), p.y(), center, r2)) && p.z() >= z_min && p.z() <= z_max)
        out.push_back(p);
  });
}

void SurfaceCache::spans(const Eigen::Vector3d& center, double radius, double z_min,
                         double z_max, std::vector<SampleSpan>& out) const {
  out.clear();
  visit_leaves(center, radius, z_min, z_max, [&](const LeafSamples& leaf, bool, bool) {
    out.push_back(SampleSpan{leaf.points.data(), leaf.points.size()});
  });
}

size_t SurfaceCache::sample_count() const {
  size_t n = 0;
  for (const auto& kv : leaves_) n += kv.second.points.size();
  return n;
}

}  // namespace sonomap
