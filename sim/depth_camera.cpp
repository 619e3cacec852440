// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/depth_camera.hpp"

#include "sim/simulation.hpp"

#include <algorithm>
#include <cmath>

namespace sonomap::sim {

DepthCamera::DepthCamera(const CameraSpec& spec) : spec_(spec) { validate(spec_); }

DepthImage DepthCamera::trace(const World& world, const Eigen::Isometry3d& world_T_camera) const {
  const RayHits hits = world.cast(PinholeRays::of(spec_, world_T_camera));

  DepthImage image;
  image.width = spec_.width;
  image.height = spec_.height;
  image.z.resize(hits.z.size());
  image.incidence.resize(hits.z.size());
  const Eigen::Matrix3f world_R_camera = world_T_camera.linear().cast<float>();
  for (int v = 0; v < spec_.height; ++v)
    for (int u = 0; u < spec_.width; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * spec_.width + u;
      if (!std::isfinite(hits.z[p])) {
        image.z[p] = 0.0f;
        image.incidence[p] = 0.0f;
        continue;
      }
      image.z[p] = hits.z[p];
      const Eigen::Vector3f d = world_R_camera * Eigen::Vector3f(static_cast<float>((u - spec_.cx) / spec_.fx),
                                                                  static_cast<float>((v - spec_.cy) / spec_.fy), 1.0f);
      const float cos_incidence = std::min(1.0f, std::abs(d.normalized().dot(hits.normal_world[p])));
      image.incidence[p] = std::acos(cos_incidence);
    }
  return image;
}

DepthImage DepthCamera::clip_to_range(DepthImage image) const {
  for (float& z : image.z)
    if (z < spec_.min_range || z > spec_.max_range) z = 0.0f;
  return image;
}

std::vector<Eigen::Vector3f> DepthCamera::back_project(const std::vector<float>& depth) const {
  std::vector<Eigen::Vector3f> points;
  points.reserve(depth.size());
  for (int v = 0; v < spec_.height; ++v)
    for (int u = 0; u < spec_.width; ++u) {
      const float z = depth[static_cast<std::size_t>(v) * spec_.width + u];
      if (z > 0.0f)
        points.emplace_back(static_cast<float>((u - spec_.cx) * z / spec_.fx),
                            static_cast<float>((v - spec_.cy) * z / spec_.fy), z);
    }
  return points;
}

}  // namespace sonomap::sim
