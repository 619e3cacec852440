// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/vdb_gpdf/normals.hpp"

#include <Eigen/Eigenvalues>

#include <array>
#include <cstdint>

namespace sonomap::gpdf {
namespace {

// The local voxels the PCA normal reads: a ball, not the cube (the cube's corners add a third
// more probes and bias the neighbourhood toward the grid's diagonals), 57 voxels. Per column
// (dx, dy) the ball holds |dz| <= its reach (none where the reach is negative).
using NormalBallColumns = std::array<std::array<int, 2 * kNormalReach + 1>, 2 * kNormalReach + 1>;
constexpr NormalBallColumns normal_ball_columns() {
  NormalBallColumns reach{};
  for (int dx = -kNormalReach; dx <= kNormalReach; ++dx)
    for (int dy = -kNormalReach; dy <= kNormalReach; ++dy) {
      int r = -1;
      for (int dz = 0; dz <= kNormalReach; ++dz)
        if (dx * dx + dy * dy + dz * dz <= kNormalReach * kNormalReach + 1) r = dz;
      reach[dx + kNormalReach][dy + kNormalReach] = r;
    }
  return reach;
}
constexpr int voxels_in(const NormalBallColumns& columns) {
  int n = 0;
  for (const auto& row : columns)
    for (const int reach : row) n += reach < 0 ? 0 : 2 * reach + 1;
  return n;
}
static_assert(voxels_in(normal_ball_columns()) == 57, "the ball of radius sqrt(5) local voxels");

// The local voxels within kNormalReach of one voxel, read through the (at most 2 x 2 x 2)
// leaves they span, fetched once: one accessor probing the ball's 57 voxels bounced between
// leaves, each switch a descent of the tree (about 1 ms of a 5 cm room frame). A voxel's
// centroid is read from its leaf's cells, computed once per frame, not divided out of the
// point sums again for every source whose ball holds it (2 to 3 ms of a 5 cm room frame).
class NormalNeighbourhood {
 public:
  using Leaf = LeafCells::Leaf;
  static_assert(Leaf::LOG2DIM == kLeafLog2 && Leaf::DIM > 2 * kNormalReach,
                "leaf_origin_of() must find this grid's leaves, and the ball span two per axis at most");
  NormalNeighbourhood(const std::vector<LeafCells>& cells, const LocalGps::IndexAccessor& index,
                      const openvdb::Coord& c) {
    const openvdb::Coord low = leaf_origin_of(c.offsetBy(-kNormalReach));
    const openvdb::Coord high = leaf_origin_of(c.offsetBy(kNormalReach));
    for (int i = 0; i < 8; ++i) {
      const openvdb::Coord origin = low.offsetBy((i & 4) ? Leaf::DIM : 0, (i & 2) ? Leaf::DIM : 0,
                                                 (i & 1) ? Leaf::DIM : 0);
      if (origin.x() > high.x() || origin.y() > high.y() || origin.z() > high.z()) continue;
      const int leaf = index.getValue(leaf_key_of(origin));
      leaves_[i] = leaf >= 0 ? &cells[leaf] : nullptr;
    }
    for (int axis = 0; axis < 3; ++axis)
      for (int d = -kNormalReach; d <= kNormalReach; ++d) {
        const int v = c[axis] + d;
        const bool high_leaf = v - low[axis] >= static_cast<int>(Leaf::DIM);
        leaf_bit_[axis][d + kNormalReach] = static_cast<uint8_t>(high_leaf ? 4 >> axis : 0);
        offset_[axis][d + kNormalReach] =
            static_cast<uint16_t>((v & (Leaf::DIM - 1)) << ((2 - axis) * Leaf::LOG2DIM));  // as coordToOffset
      }
  }
  // Calls visit(centroid) for each local voxel of the ball around c that holds points, in x, y, z
  // nested order (the scatter's sums are added in that order).
  template <class Visit>
  void for_each_centroid(Visit&& visit) const {
    static constexpr NormalBallColumns kColumns = normal_ball_columns();
    for (int x = 0; x <= 2 * kNormalReach; ++x)
      for (int y = 0; y <= 2 * kNormalReach; ++y) {
        const int reach = kColumns[x][y];
        const int column_bits = leaf_bit_[0][x] | leaf_bit_[1][y];
        const int column_offset = offset_[0][x] + offset_[1][y];
        for (int z = kNormalReach - reach; z <= kNormalReach + reach; ++z) {
          const LeafCells* leaf = leaves_[column_bits | leaf_bit_[2][z]];
          if (!leaf) continue;
          const int cell = leaf->cell_of[column_offset + offset_[2][z]];
          if (cell >= 0) visit(leaf->cells[cell].centroid);
        }
      }
  }

 private:
  std::array<const LeafCells*, 8> leaves_{};
  // Per axis and offset from c (0 for -kNormalReach): the axis's bit of the index in leaves_ (the
  // low or the high leaf along it) and its term of the voxel's offset in that leaf. A probe then
  // adds table entries instead of comparing and masking coordinates.
  std::array<std::array<uint8_t, 2 * kNormalReach + 1>, 3> leaf_bit_{};
  std::array<std::array<uint16_t, 2 * kNormalReach + 1>, 3> offset_{};
};

constexpr double kLineSpread = 0.2;  // second eigenvalue below this share of the largest: a line
constexpr int kMinPlanePoints = 5;
PlaneFit fit_plane(const Scatter& s, const Eigen::Vector3d& u) {
  if (s.count < kMinPlanePoints) return {};
  const Eigen::Vector3d mean = Eigen::Vector3d(s.sx, s.sy, s.sz) / s.count;
  Eigen::Matrix3d outer;
  outer << s.xx, s.xy, s.xz, s.xy, s.yy, s.yz, s.xz, s.yz, s.zz;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(outer / s.count - mean * mean.transpose());
  Eigen::Vector3d n = eig.eigenvectors().col(0);  // smallest eigenvalue first
  if (eig.info() != Eigen::Success || !n.allFinite()) return {};
  n.normalize();
  return {n.dot(u) < 0.0 ? Eigen::Vector3d(-n) : n, eig.eigenvalues()[1] < kLineSpread * eig.eigenvalues()[2],
          eig.eigenvectors().col(2).normalized()};
}

// Whether a fit is what one ring's points give: a line, or a plane that the line of sight runs
// along (within kMinNormalDotRay), the ring's own scan plane through the sensor. A ring lies in
// that plane whatever the surface, and a depth camera's quantised depth spreads an image row's
// points across it in steps 1.4 cm high on a slab 3 m away. That plane's normal lies at right
// angles to the ray with either sign: sources on room 17's slab took normals 17 degrees off
// the vertical pointing down into the slab, and its top, seen by rings 35 cm apart, held
// surface near one ring only (docs/fidelity.md, "A ring's own scan plane").
bool of_one_ring(const PlaneFit& fit, const Eigen::Vector3d& u) {
  return fit.line || (!fit.normal.isZero() && !(fit.normal.dot(u) > kMinNormalDotRay));
}

}  // namespace

// The surface normal at p facing the sensor (u: unit vector from p toward it), by PCA over the
// centroids of the occupied local voxels within two voxels of p's (up to 57, about 25 on a
// plane). The normal is zero where the neighbourhood is too small for a plane. In a cloud
// (`wide` given), a neighbourhood of one ring (of_one_ring), as a lidar's ring crosses a
// surface, fits any plane through the ring: it is widened to `wide_reach` to take in the next
// ring, and where that still holds one ring only, the normal is zero too, `line` is set and
// `along` is the ring's direction (elsewhere `line` is false). So is a ball with too few points
// for a plane (a short step of a ring's staircase, a ring's end), but there only the next
// rings may give the normal: a plane fitted to the widened neighbourhood took in other surfaces
// around a ring's end (rooms 1-12 from rings: 6 to 12 more bins too near at low boxes, thin
// slabs and grazing faces, for one fewer too far at corners and thin slabs; docs/fidelity.md,
// "A ring's own scan plane"). From the ball alone, the random box rooms from rings one image
// row each read too far at 37 corner bins of 410, 52 low and 106 thin (docs/fidelity.md,
// "Rings one row each").
// (A normal from the local GP's gradient one step toward the sensor was tried first: at grazing
// views that point can still lie behind the sampled surface, the gradient then points into the
// object, and front points land inside it: measured 13 cm deep in a box.)
PlaneFit surface_normal(const std::vector<LeafCells>& cells, const LocalGps::IndexAccessor& index,
                        const openvdb::Coord& c, const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                        const WideNeighbourhood* wide, double wide_reach) {
  Scatter ball;
  NormalNeighbourhood(cells, index, c).for_each_centroid([&](const Eigen::Vector3d& at) { ball.add(at - p); });
  const PlaneFit fit = fit_plane(ball, u);
  const bool too_few = ball.count < kMinPlanePoints;
  if (!wide || !(too_few || of_one_ring(fit, u))) return {fit.normal};
  const PlaneFit widened = fit_plane(wide->around(p, wide_reach), u);
  if (of_one_ring(widened, u)) return {Eigen::Vector3d::Zero(), true, widened.along};
  if (too_few) return {};
  return widened;
}

}  // namespace sonomap::gpdf
