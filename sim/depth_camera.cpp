// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/depth_camera.hpp"

#include "sim/simulation.hpp"

#include <algorithm>
#include <cmath>

namespace sonomap::sim {

DepthCamera::DepthCamera(const CameraSpec& spec) : spec_(spec) { validate(spec_); }

void DepthCamera::trace(const World& world, const Eigen::Isometry3d& world_T_camera, DepthImage& image) const {
  RayHits hits;  // casts into the image's own buffers
  hits.z.swap(image.z);
  hits.incidence.swap(image.incidence);
  world.cast(PinholeRays::of(spec_, world_T_camera), hits);
  for (float& z : hits.z)
    if (!std::isfinite(z)) z = 0.0f;  // nothing hit: no return (incidence is 0 there)
  image.width = spec_.width;
  image.height = spec_.height;
  image.z.swap(hits.z);
  image.incidence.swap(hits.incidence);
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
