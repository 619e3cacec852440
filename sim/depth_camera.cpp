// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/depth_camera.hpp"

#include "sim/simulation.hpp"
#include "core/vector_isa.hpp"

#include <algorithm>
#include <cmath>

namespace sonomap::sim {

DepthCamera::DepthCamera(const CameraSpec& spec) : spec_(spec) { validate(spec_); }

void DepthCamera::trace(const World& world, const Eigen::Isometry3d& world_T_camera, DepthImage& image) const {
  RayHits hits;  // casts into the image's own buffers
  hits.z.swap(image.z);
  hits.incidence.swap(image.incidence);
  world.cast(PinholeRays::of(spec_, world_T_camera), hits);
  for (float& z : hits.z) z = std::isfinite(z) ? z : 0.0f;  // nothing hit: no return (incidence is 0 there)
  image.width = spec_.width;
  image.height = spec_.height;
  image.z.swap(hits.z);
  image.incidence.swap(hits.incidence);
}

DepthImage DepthCamera::clip_to_range(DepthImage image) const {
  const double near = spec_.min_range, far = spec_.max_range;
  for (float& z : image.z) z = (z < near) | (z > far) ? 0.0f : z;  // a selection, which vectorises
  return image;
}

namespace {

// Row v's optical-frame x = (u - cx) z / fx and y = (v - cy) z / fy, in double as the pinhole
// model is written, for every pixel: branch-free, so that the loop vectorises (the two
// divisions a pixel were most of back_project's time).
SONOMAP_VECTOR_LOOP void project_row(const CameraSpec& spec, int v, const float* __restrict z, float* __restrict x,
                                     float* __restrict y) {
  const double row = v - spec.cy;
  for (int u = 0; u < spec.width; ++u) {
    x[u] = static_cast<float>((u - spec.cx) * z[u] / spec.fx);
    y[u] = static_cast<float>(row * z[u] / spec.fy);
  }
}

void project_row_baseline(const CameraSpec& spec, int v, const float* z, float* x, float* y) {
  project_row(spec, v, z, x, y);
}
SONOMAP_AVX2_KERNEL void project_row_avx2(const CameraSpec& spec, int v, const float* z, float* x, float* y) {
  project_row(spec, v, z, x, y);
}
SONOMAP_AVX512_KERNEL void project_row_avx512(const CameraSpec& spec, int v, const float* z, float* x, float* y) {
  project_row(spec, v, z, x, y);
}

}  // namespace

std::vector<Eigen::Vector3f> DepthCamera::back_project(const std::vector<float>& depth) const {
  const auto project = kernel_for(vector_isa(), &project_row_baseline, &project_row_avx2, &project_row_avx512);
  std::vector<Eigen::Vector3f> points(depth.size());
  std::vector<float> x(spec_.width), y(spec_.width);
  std::size_t count = 0;
  for (int v = 0; v < spec_.height; ++v) {
    const float* z = depth.data() + static_cast<std::size_t>(v) * spec_.width;
    project(spec_, v, z, x.data(), y.data());
    for (int u = 0; u < spec_.width; ++u) {  // every pixel written, the count moved past valid ones
      points[count] = Eigen::Vector3f(x[u], y[u], z[u]);
      count += z[u] > 0.0f;
    }
  }
  points.resize(count);
  return points;
}

}  // namespace sonomap::sim
