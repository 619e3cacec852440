// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/tsdf.hpp"

#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/parallel.hpp"
#include "core/stopwatch.hpp"

namespace sonomap {

namespace {

using Clock = StageClock;
using Leaf = DistanceWeightGrid::TreeType::LeafNodeType;

// The frame's depth image as the projective update reads it: returns outside the range limits
// (measured along the ray, as for the points) are blanked to 0, "no return". Single precision:
// the optical-frame coordinates are metres, far from where float rounding matters.
class DepthImage {
 public:
  DepthImage(const Frame& frame, double min_range, double max_range, std::vector<float>& buffer)
      : width_(frame.width), height_(frame.height), k_(frame.intrinsics), depth_(buffer),
        fx_(static_cast<float>(k_.fx)), fy_(static_cast<float>(k_.fy)),
        cx_(static_cast<float>(k_.cx + 0.5)), cy_(static_cast<float>(k_.cy + 0.5)) {
    depth_.resize(frame.depth.size());
    std::vector<float> x2(static_cast<size_t>(width_));  // per column: ((u - cx) / fx)^2
    for (int u = 0; u < width_; ++u) x2[u] = static_cast<float>(std::pow((u - k_.cx) / k_.fx, 2));
    const float min2 = static_cast<float>(min_range * min_range), max2 = static_cast<float>(max_range * max_range);
    for (int v = 0; v < height_; ++v) {
      const float y2 = static_cast<float>(std::pow((v - k_.cy) / k_.fy, 2));
      const float* in = &frame.depth[static_cast<size_t>(v) * width_];
      float* out = &depth_[static_cast<size_t>(v) * width_];
      for (int u = 0; u < width_; ++u) {
        const float z = in[u], range2 = z * z * (1.0f + x2[u] + y2);  // NaN and inf fail below
        out[u] = z > 0.0f && range2 >= min2 && range2 <= max2 ? z : 0.0f;
      }
    }
  }
  int width() const { return width_; }
  int height() const { return height_; }
  const PinholeIntrinsics& intrinsics() const { return k_; }
  float at(int u, int v) const { return depth_[static_cast<size_t>(v) * width_ + u]; }

  // The depth measured at the pixel nearest to the optical-frame point pc (z > 0), given 1 / z;
  // 0 outside the image or where the pixel has no return.
  float depth_towards(const Eigen::Vector3f& pc, float inv_z) const {
    const float u = fx_ * pc.x() * inv_z + cx_, v = fy_ * pc.y() * inv_z + cy_;  // + 0.5: nearest
    if (!(u >= 0.0f && u < width_ && v >= 0.0f && v < height_)) return 0.0f;
    return at(static_cast<int>(u), static_cast<int>(v));  // u, v >= 0: truncation is floor
  }

  // False when a sphere (optical-frame centre c) lies wholly outside the pixels' view cone or
  // beyond `reach` from the camera.
  bool may_see(const Eigen::Vector3d& c, double radius, double reach) const {
    if (c.z() < -radius || c.norm() > reach + radius) return false;
    // The side planes through the camera and the outer edges of the border pixels.
    auto outside = [&](double a, double b, double offset) {  // plane a * x_or_y + offset * z >= 0
      return a * b + offset * c.z() < -radius * std::hypot(a, offset);
    };
    return !(outside(k_.fx, c.x(), k_.cx + 0.5) || outside(-k_.fx, c.x(), width_ - 0.5 - k_.cx) ||
             outside(k_.fy, c.y(), k_.cy + 0.5) || outside(-k_.fy, c.y(), height_ - 0.5 - k_.cy));
  }

 private:
  int width_, height_;
  PinholeIntrinsics k_;
  std::vector<float>& depth_;
  float fx_, fy_, cx_, cy_;  // cx_, cy_ include the half pixel that rounds to the nearest
};

// Marks in `blocks` (one voxel per leaf, at leaf origin / 8) every leaf that may hold a voxel
// in the band of a return: within the truncation of the return along its ray and within
// `slack` to the side. Per image row one set of half extents bounds that segment's box for
// every pixel of the row, so neighbouring returns mostly give the same box of leaves; a return
// inside the region where the previous return's box would not change is skipped.
void mark_band_leaves(const DepthImage& image, const Eigen::Isometry3d& world_T_camera, double leaf_size,
                      double truncation, double slack, openvdb::MaskTree& blocks) {
  openvdb::tree::ValueAccessor<openvdb::MaskTree> acc(blocks);
  const PinholeIntrinsics& k = image.intrinsics();
  const Eigen::Matrix3d r = world_T_camera.linear();
  const Eigen::Vector3f t = world_T_camera.translation().cast<float>();
  const Eigen::Vector3f step = (r.col(0) / k.fx).cast<float>();  // world ray change per column
  const float inv_leaf = static_cast<float>(1.0 / leaf_size), leaf = static_cast<float>(leaf_size);
  for (int v = 0; v < image.height(); ++v) {
    // Rays (x, y, 1) in the optical frame, in the world: a unit ray's component along world
    // axis a is at most |ray_a| / |ray|, where |ray_a| is largest at one end of the row and
    // |ray| is smallest at the column of the principal point.
    const double row_y = (v - k.cy) / k.fy;
    const Eigen::Vector3d first = r * Eigen::Vector3d(-k.cx / k.fx, row_y, 1.0);
    const Eigen::Vector3d last = first + (image.width() - 1) * r.col(0) / k.fx;
    const Eigen::Vector3d unit = (first.cwiseAbs().cwiseMax(last.cwiseAbs()) / std::sqrt(1.0 + row_y * row_y))
                                     .cwiseMin(1.0);
    const Eigen::Vector3f m = (truncation * unit.array() + slack).matrix().cast<float>();
    const Eigen::Vector3f row = first.cast<float>();
    Eigen::Vector3f same_lo = Eigen::Vector3f::Constant(1.0f), same_hi = Eigen::Vector3f::Zero();
    for (int u = 0; u < image.width(); ++u) {
      const float z = image.at(u, v);
      const Eigen::Vector3f p = t + z * (row + static_cast<float>(u) * step);
      // One branch for both (no return, or the same box): dropouts are frequent and random.
      if ((!(z > 0.0f)) | ((p.array() >= same_lo.array()).all() & (p.array() < same_hi.array()).all())) continue;
      openvdb::Coord lo, hi;
      for (int a = 0; a < 3; ++a) {
        lo[a] = static_cast<int>(std::floor((p[a] - m[a]) * inv_leaf));
        hi[a] = static_cast<int>(std::floor((p[a] + m[a]) * inv_leaf));
        same_lo[a] = lo[a] * leaf + m[a];  // p in [same_lo, same_hi): the same box of leaves
        same_hi[a] = (hi[a] + 1) * leaf - m[a];
      }
      for (int x = lo.x(); x <= hi.x(); ++x)
        for (int y = lo.y(); y <= hi.y(); ++y)
          for (int zz = lo.z(); zz <= hi.z(); ++zz) acc.setValueOn(openvdb::Coord(x, y, zz));
    }
  }
}

// Marks the leaves already in the map that the camera may see within `reach` (carving).
void mark_leaves_in_view(const DistanceWeightGrid& grid, const DepthImage& image,
                         const Eigen::Isometry3d& camera_T_world, double voxel, double reach,
                         openvdb::MaskTree& blocks) {
  openvdb::tree::ValueAccessor<openvdb::MaskTree> acc(blocks);
  const double half = 0.5 * kLeafDim * voxel, radius = std::sqrt(3.0) * half;
  for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
    const openvdb::Coord o = leaf->origin();
    const Eigen::Vector3d centre = Eigen::Vector3d(o.x(), o.y(), o.z()) * voxel + Eigen::Vector3d::Constant(half);
    if (image.may_see(camera_T_world * centre, radius, reach))
      acc.setValueOn(leaf_key_of(o));
  }
}

// One leaf's projective update (see the header); returns the voxels whose distance or
// validity (weight >= min_weight) changed, which is what the surface depends on.
LeafMask fuse_leaf(Leaf& leaf, const DepthImage& image, const Eigen::Isometry3d& camera_T_world,
                   const TsdfConfig& config, const FusedGrid& grid) {
  const float trunc = static_cast<float>(config.truncation), min_weight = static_cast<float>(config.min_weight);
  // Below it a voxel is left alone: far in front of the surface, unless carving.
  const float lowest = config.space_carving ? -std::numeric_limits<float>::infinity() : -trunc;
  const openvdb::Coord o = leaf.origin();
  const Eigen::Vector3f first = (camera_T_world * ((Eigen::Vector3d(o.x(), o.y(), o.z()) +
                                                    Eigen::Vector3d::Constant(0.5)) * config.voxel)).cast<float>();
  // Column a: one voxel along world axis a, in the optical frame.
  const Eigen::Matrix3f steps = (camera_T_world.linear() * config.voxel).cast<float>();
  LeafMask changed;
  for (int x = 0; x < kLeafDim; ++x)
    for (int y = 0; y < kLeafDim; ++y)
      for (int z = 0; z < kLeafDim; ++z) {
        const Eigen::Vector3f pc = first + steps * Eigen::Vector3f(x, y, z);
        if (!(pc.z() > 0.0f)) continue;
        const float inv_z = 1.0f / pc.z();
        const float depth = image.depth_towards(pc, inv_z);
        if (!(depth > 0.0f)) continue;
        // Along the ray: the voxel's distance from the camera minus the return's.
        const float sdf = pc.norm() * (1.0f - depth * inv_z);
        if (!(sdf < trunc && sdf > lowest)) continue;
        const openvdb::Index i = static_cast<openvdb::Index>((x << 6) | (y << 3) | z);
        const openvdb::Vec2s old = leaf.getValue(i);
        const openvdb::Vec2s now = grid.weighted_average(old, openvdb::Vec2s(std::max(sdf, -trunc), 1.0f));
        leaf.setValueOn(i, now);
        if (now[0] != old[0] || (now[1] >= min_weight) != (old[1] >= min_weight)) changed.setOn(i);
      }
  return changed;
}

}  // namespace

void TsdfConfig::validate() const {
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  auto fail = [](const std::string& what) { throw std::invalid_argument("TsdfConfig: " + what); };
  if (!positive(voxel)) fail("voxel must be > 0, got " + std::to_string(voxel));
  if (!positive(truncation)) fail("truncation must be > 0, got " + std::to_string(truncation));
  if (!(weight_cap >= 0.0)) fail("weight_cap must be >= 0 (0 = no cap)");
  // Held as a float by the grid: a larger value would become infinity there.
  if (!(min_weight >= 0.0 && min_weight <= std::numeric_limits<float>::max()))
    fail("min_weight must be >= 0 and a finite float");
  if (!(min_range >= 0.0 && positive(max_range) && min_range < max_range))
    fail("need 0 <= min_range < max_range");
}

Tsdf::Tsdf(TsdfConfig config)
    : FusedGridMapper(validated(config).voxel, static_cast<float>(config.min_weight), config.weight_cap),
      config_(config) {}

void Tsdf::integrate(const Frame& frame) {
  check_pose(frame);
  times_.stages.clear();
  const auto t_start = Clock::now();
  const std::vector<LeafChanges> changed = has_depth_image(frame) ? integrate_image(frame) : integrate_rays(frame);
  const auto t0 = Clock::now();
  fused_.refresh(dirty_leaves(changed));
  times_.stages.emplace_back("surface", ms_since(t0));
  times_.stages.emplace_back("total", ms_since(t_start));
}

std::vector<LeafChanges> Tsdf::integrate_image(const Frame& frame) {
  auto t0 = Clock::now();
  const DepthImage image(frame, config_.min_range, config_.max_range, depth_buffer_);
  const double voxel = config_.voxel, trunc = config_.truncation;
  const Eigen::Isometry3d camera_T_world = frame.world_T_camera.inverse();
  // A voxel in the band lies within the truncation of its pixel's return along the ray, and
  // its centre's ray within half a pixel diagonal of the pixel's: less than a pixel's width at
  // the far range limit.
  const double pixel_width = config_.max_range / std::min(frame.intrinsics.fx, frame.intrinsics.fy);
  mark_band_leaves(image, frame.world_T_camera, kLeafDim * voxel, trunc, pixel_width, blocks_);
  if (config_.space_carving)
    mark_leaves_in_view(fused_.grid(), image, camera_T_world, voxel, config_.max_range, blocks_);
  DistanceWeightGrid::TreeType& tree = fused_.grid().tree();
  std::vector<Leaf*> leaves;
  std::vector<bool> created;
  for (auto b = blocks_.cbeginValueOn(); b; ++b) {
    const openvdb::Coord c = b.getCoord();
    const openvdb::Coord origin = leaf_origin_of_key(c);
    Leaf* leaf = tree.probeLeaf(origin);
    created.push_back(leaf == nullptr);
    leaves.push_back(leaf ? leaf : tree.touchLeaf(origin));
  }
  for (auto leaf = blocks_.beginLeaf(); leaf; ++leaf) leaf->setValuesOff();  // kept for the next frame
  times_.stages.emplace_back("blocks", ms_since(t0));

  t0 = Clock::now();
  std::vector<LeafChanges> changed(leaves.size());
  parallel_for_each_index(leaves.size(), [&](size_t i) {
    changed[i] = {leaves[i]->origin(), fuse_leaf(*leaves[i], image, camera_T_world, config_, fused_)};
  });
  // A new leaf that no voxel of the frame reached goes again (a background tile).
  for (size_t i = 0; i < leaves.size(); ++i)
    if (created[i] && leaves[i]->isEmpty()) tree.addTile(1, leaves[i]->origin(), tree.background(), false);
  times_.stages.emplace_back("integrate", ms_since(t0));
  return changed;
}

std::vector<LeafChanges> Tsdf::integrate_rays(const Frame& frame) {
  const std::vector<Eigen::Vector3d> points =
      world_points(frame, config_.min_range, config_.max_range);
  const Eigen::Vector3d origin = frame.world_T_camera.translation();
  const double voxel = config_.voxel, trunc = config_.truncation;

  auto t0 = Clock::now();
  openvdb::MaskGrid touched(false);
  auto acc = fused_.grid().getAccessor();
  auto touch = touched.getAccessor();
  using Ray = openvdb::math::Ray<double>;
  for (const auto& p : points) {
    Eigen::Vector3d u = p - origin;
    const double depth = u.norm();
    if (!(depth > 0.0)) continue;
    u /= depth;
    const Eigen::Vector3d start = config_.space_carving ? origin : Eigen::Vector3d(p - trunc * u);
    const double length = (p + trunc * u - start).norm();
    // Index space: voxel ijk spans [ijk, ijk + 1) (floor binning), so the DDA's cells match.
    const Ray ray(openvdb::Vec3d(start.x() / voxel, start.y() / voxel, start.z() / voxel),
                  openvdb::Vec3d(u.x(), u.y(), u.z()), 0.0, length / voxel);
    openvdb::math::DDA<Ray, 0> dda(ray);
    do {
      const openvdb::Coord ijk = dda.voxel();
      const double sdf = (voxel_centre(ijk, voxel) - origin).norm() - depth;  // positive behind the surface
      if (sdf >= trunc) continue;
      const float tsdf = static_cast<float>(std::max(sdf, -trunc));
      acc.setValue(ijk, fused_.weighted_average(acc.getValue(ijk), openvdb::Vec2s(tsdf, 1.0f)));
      touch.setValueOn(ijk);
    } while (dda.step());
  }
  std::vector<LeafChanges> changed = leaf_changes(touched);
  times_.stages.emplace_back("integrate", ms_since(t0));
  return changed;
}

DistanceQuery Tsdf::query_point(const Eigen::Vector3f& xf) const {
  DistanceQuery out;
  if (!xf.allFinite()) return out;
  const Eigen::Vector3d g = xf.cast<double>() / config_.voxel - Eigen::Vector3d::Constant(0.5);
  const Eigen::Vector3d base = g.array().floor();
  const Eigen::Vector3d f = g - base;
  const openvdb::Coord b(static_cast<int>(base.x()), static_cast<int>(base.y()),
                         static_cast<int>(base.z()));
  const auto acc = read_accessor(fused_.grid());
  double d = 0.0;
  Eigen::Vector3d grad = Eigen::Vector3d::Zero();
  for (int c = 0; c < 8; ++c) {
    const int i = c & 1, j = (c >> 1) & 1, k = (c >> 2) & 1;
    const openvdb::Vec2s v = acc.getValue(b.offsetBy(i, j, k));
    if (!(v[1] >= config_.min_weight) || v[1] <= 0.0f) return out;
    const double wx = i ? f.x() : 1.0 - f.x(), wy = j ? f.y() : 1.0 - f.y(),
                 wz = k ? f.z() : 1.0 - f.z();
    d += wx * wy * wz * v[0];
    grad += Eigen::Vector3d((i ? 1.0 : -1.0) * wy * wz, (j ? 1.0 : -1.0) * wx * wz,
                            (k ? 1.0 : -1.0) * wx * wy) * v[0];
  }
  out.observed = true;
  out.distance = static_cast<float>(std::abs(d));
  // Away from the surface: down the TSDF in free space (d < 0), up it behind (d > 0).
  if (grad.norm() > 0.0) out.gradient = ((d < 0.0 ? -1.0 : 1.0) * grad.normalized()).cast<float>();
  return out;
}

void Tsdf::query(const std::vector<Eigen::Vector3f>& points,
                 std::vector<DistanceQuery>& out) const {
  out.assign(points.size(), DistanceQuery{});
  parallel_for_each_index(points.size(), [&](size_t i) { out[i] = query_point(points[i]); });
}

}  // namespace sonomap
