// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/depth_only.hpp"

#include <chrono>
#include <cmath>

namespace sonomap {

void DepthOnlyMapper::integrate(const Frame& frame) {
  const auto start = std::chrono::steady_clock::now();
  check_pose(frame);  // throws before anything changes
  points_.clear();
  skipped_ = 0;
  points_.reserve(frame.points_camera.size());
  for (const Eigen::Vector3f& p : frame.points_camera) {
    if (!p.allFinite()) {
      ++skipped_;
      continue;
    }
    points_.push_back((frame.world_T_camera * p.cast<double>()).cast<float>());
  }
  const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
  times_.stages = {{"transform", elapsed.count()}};
}

void DepthOnlyMapper::surface_points(const Eigen::Vector3d& center, double radius,
                                     std::vector<Eigen::Vector3f>& out) const {
  surface_points_in_band(center, radius, -INFINITY, INFINITY, out);
}

void DepthOnlyMapper::surface_points_in_band(const Eigen::Vector3d& center, double radius,
                                             double z_min, double z_max,
                                             std::vector<Eigen::Vector3f>& out) const {
  out.clear();
  const double radius2 = radius * radius;
  for (const Eigen::Vector3f& p : points_) {
    const double dx = p.x() - center.x();
    const double dy = p.y() - center.y();
    if (dx * dx + dy * dy <= radius2 && p.z() >= z_min && p.z() <= z_max) out.push_back(p);
  }
}

void DepthOnlyMapper::query(const std::vector<Eigen::Vector3f>& points,
                            std::vector<DistanceQuery>& out) const {
  out.assign(points.size(), DistanceQuery{});
}

}  // namespace sonomap
