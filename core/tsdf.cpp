// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/tsdf.hpp"

#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/parallel.hpp"
#include "core/stopwatch.hpp"

namespace sonomap {

namespace {
using Clock = StageClock;
}  // namespace

void TsdfConfig::validate() const {
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  auto fail = [](const std::string& what) { throw std::invalid_argument("TsdfConfig: " + what); };
  if (!positive(voxel)) fail("voxel must be > 0, got " + std::to_string(voxel));
  if (!positive(truncation)) fail("truncation must be > 0, got " + std::to_string(truncation));
  if (!(weight_cap >= 0.0)) fail("weight_cap must be >= 0 (0 = no cap)");
  if (!(min_weight >= 0.0) || !std::isfinite(min_weight)) fail("min_weight must be >= 0");
  if (!(min_range >= 0.0 && positive(max_range) && min_range < max_range))
    fail("need 0 <= min_range < max_range");
}

Tsdf::Tsdf(TsdfConfig config)
    : config_(validated(config)),
      fused_(config.voxel, static_cast<float>(config.min_weight), config.weight_cap) {}

void Tsdf::integrate(const Frame& frame) {
  check_pose(frame);
  times_.stages.clear();
  const auto t_start = Clock::now();
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
      const Eigen::Vector3d centre = Eigen::Vector3d(ijk.x() + 0.5, ijk.y() + 0.5, ijk.z() + 0.5) * voxel;
      const double sdf = (centre - origin).norm() - depth;  // positive behind the surface
      if (sdf >= trunc) continue;
      const float tsdf = static_cast<float>(std::max(sdf, -trunc));
      acc.setValue(ijk, fused_.weighted_average(acc.getValue(ijk), openvdb::Vec2s(tsdf, 1.0f)));
      touch.setValueOn(ijk);
    } while (dda.step());
  }
  times_.stages.emplace_back("integrate", ms_since(t0));

  t0 = Clock::now();
  fused_.refresh(dirty_leaves(touched));
  times_.stages.emplace_back("surface", ms_since(t0));
  times_.stages.emplace_back("total", ms_since(t_start));
}

void Tsdf::surface_points(const Eigen::Vector3d& center, double radius,
                          std::vector<Eigen::Vector3f>& out) const {
  fused_.surface_points(center, radius, out);
}

DistanceQuery Tsdf::query_point(const Eigen::Vector3f& xf) const {
  DistanceQuery out;
  if (!xf.allFinite()) return out;
  const Eigen::Vector3d g = xf.cast<double>() / config_.voxel - Eigen::Vector3d::Constant(0.5);
  const Eigen::Vector3d base = g.array().floor();
  const Eigen::Vector3d f = g - base;
  const openvdb::Coord b(static_cast<int>(base.x()), static_cast<int>(base.y()),
                         static_cast<int>(base.z()));
  auto acc = fused_.grid().getConstAccessor();
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

void Tsdf::surface_mesh(std::vector<Eigen::Vector3f>& vertices,
                        std::vector<Eigen::Vector3i>& triangles) const {
  fused_.surface_mesh(vertices, triangles);
}

size_t Tsdf::memory_bytes() const {
  return fused_.memory_bytes();
}

}  // namespace sonomap
