// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/open3d_tsdf.hpp"

#include "core/marching_cubes.hpp"
#include "core/parallel.hpp"
#include "core/stopwatch.hpp"

#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <open3d/pipelines/integration/UniformTSDFVolume.h>

#include <cmath>
#include <optional>
#include <stdexcept>

namespace sonomap {

namespace integration = open3d::pipelines::integration;

namespace {

constexpr int kBlockResolution = 16;  // voxels per block side (Open3D's default)

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

// The volume, the reused input image, and the mesh with its dense samples extracted on demand.
struct Open3dTsdf::Volume {
  integration::ScalableTSDFVolume tsdf;
  open3d::geometry::RGBDImage image;
  bool surface_stale = true;
  SurfaceMesh mesh;
  std::vector<Eigen::Vector3f> samples;  // on the mesh, at most half a voxel apart

  explicit Volume(const Open3dTsdfConfig& c)
      : tsdf(c.voxel, c.truncation, integration::TSDFVolumeColorType::NoColor, kBlockResolution) {}

  // Open3D's voxel at global voxel index c (centre (c + 0.5) voxel), if it was observed.
  std::optional<float> distance_at(const Eigen::Vector3i& c) const {
    const Eigen::Vector3i block(floor_div(c.x(), kBlockResolution), floor_div(c.y(), kBlockResolution),
                                floor_div(c.z(), kBlockResolution));
    const auto it = tsdf.volume_units_.find(block);
    if (it == tsdf.volume_units_.end()) return std::nullopt;
    const auto& unit = *it->second.volume_;
    const open3d::geometry::TSDFVoxel& v = unit.voxels_[unit.IndexOf(c - block * kBlockResolution)];
    if (!(v.weight_ > 0.0f)) return std::nullopt;
    return v.tsdf_ * static_cast<float>(tsdf.sdf_trunc_);  // Open3D keeps tsdf / truncation
  }

  void refresh_surface(double voxel) {
    if (!surface_stale) return;
    const auto extracted = tsdf.ExtractTriangleMesh();
    mesh.clear();
    mesh.vertices.reserve(extracted->vertices_.size());
    for (const Eigen::Vector3d& p : extracted->vertices_) mesh.vertices.push_back(p.cast<float>());
    mesh.triangles = extracted->triangles_;
    samples.clear();
    sample_surface(mesh, 0.5 * voxel, samples);
    surface_stale = false;
  }
};

Open3dTsdf::Open3dTsdf(Open3dTsdfConfig config)
    : config_(validated(config)), volume_(std::make_unique<Volume>(config_)) {}

Open3dTsdf::~Open3dTsdf() = default;

void Open3dTsdf::integrate(const Frame& frame) {
  check_pose(frame);
  times_.stages.clear();
  if (frame.depth.empty()) return;  // nothing to fuse
  const PinholeIntrinsics& k = frame.intrinsics;
  if (!has_depth_image(frame))
    throw std::invalid_argument("frame " + std::to_string(frame.index) +
                                ": no pinhole intrinsics (fx, fy > 0, finite cx, cy): the open3d "
                                "mapper integrates the depth image");
  const auto t_start = StageClock::now();
  // The depth image as Open3D wants it (float metres, 0 = no return), pixels outside the
  // range limits (along the ray, as the other mappers) left out.
  open3d::geometry::Image& depth = volume_->image.depth_;
  depth.Prepare(frame.width, frame.height, 1, 4);
  if (volume_->image.color_.width_ != frame.width || volume_->image.color_.height_ != frame.height)
    volume_->image.color_.Prepare(frame.width, frame.height, 1, 1);  // NoColor ignores it
  float* out = depth.PointerAs<float>();
  for (int v = 0; v < frame.height; ++v) {
    const double y = (v - k.cy) / k.fy;
    for (int u = 0; u < frame.width; ++u) {
      const size_t p = static_cast<size_t>(v) * frame.width + u;
      const double z = frame.depth[p], x = (u - k.cx) / k.fx;
      const double range = z * std::sqrt(1.0 + x * x + y * y);
      out[p] = std::isfinite(z) && z > 0.0 && range >= config_.min_range && range <= config_.max_range
                   ? frame.depth[p] : 0.0f;
    }
  }
  const double convert_ms = ms_since(t_start);
  auto t0 = StageClock::now();
  const open3d::camera::PinholeCameraIntrinsic intrinsic(frame.width, frame.height, k.fx, k.fy, k.cx, k.cy);
  // Open3D's extrinsic is camera_T_world; its camera frame (x right, y down, z forward) is
  // our optical frame (docs/conventions.md).
  volume_->tsdf.Integrate(volume_->image, intrinsic, frame.world_T_camera.inverse().matrix());
  volume_->surface_stale = true;
  times_.stages.emplace_back("convert", convert_ms);
  times_.stages.emplace_back("integrate", ms_since(t0));
  times_.stages.emplace_back("total", ms_since(t_start));
}

void Open3dTsdf::surface_points(const Eigen::Vector3d& center, double radius,
                                std::vector<Eigen::Vector3f>& out) const {
  surface_points_in_band(center, radius, -INFINITY, INFINITY, out);
}

void Open3dTsdf::surface_points_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                                        double z_max, std::vector<Eigen::Vector3f>& out) const {
  volume_->refresh_surface(config_.voxel);
  out.clear();
  const Eigen::Vector2f c = center.head<2>().cast<float>();
  const float r2 = static_cast<float>(radius * radius);
  for (const Eigen::Vector3f& p : volume_->samples)
    if ((p.head<2>() - c).squaredNorm() <= r2 && p.z() >= z_min && p.z() <= z_max) out.push_back(p);
}

void Open3dTsdf::query(const std::vector<Eigen::Vector3f>& points, std::vector<DistanceQuery>& out) const {
  out.assign(points.size(), DistanceQuery{});
  parallel_for_each_index(points.size(), [&](size_t i) {
    const Eigen::Vector3f& x = points[i];
    if (!x.allFinite()) return;
    const Eigen::Vector3d g = x.cast<double>() / config_.voxel - Eigen::Vector3d::Constant(0.5);
    const Eigen::Vector3d base = g.array().floor();
    const Eigen::Vector3d f = g - base;
    double d = 0.0;
    Eigen::Vector3d grad = Eigen::Vector3d::Zero();
    for (int c = 0; c < 8; ++c) {
      const int a = c & 1, b = (c >> 1) & 1, e = (c >> 2) & 1;
      const auto value = volume_->distance_at(base.cast<int>() + Eigen::Vector3i(a, b, e));
      if (!value) return;
      const double wx = a ? f.x() : 1.0 - f.x(), wy = b ? f.y() : 1.0 - f.y(), wz = e ? f.z() : 1.0 - f.z();
      d += wx * wy * wz * *value;
      grad += Eigen::Vector3d((a ? 1.0 : -1.0) * wy * wz, (b ? 1.0 : -1.0) * wx * wz,
                              (e ? 1.0 : -1.0) * wx * wy) * *value;
    }
    out[i].observed = true;
    out[i].distance = static_cast<float>(std::abs(d));
    // Open3D's TSDF is positive in free space: away from the surface is up it there, down behind.
    if (grad.norm() > 0.0) out[i].gradient = ((d > 0.0 ? 1.0 : -1.0) * grad.normalized()).cast<float>();
  });
}

void Open3dTsdf::surface_mesh(std::vector<Eigen::Vector3f>& vertices,
                              std::vector<Eigen::Vector3i>& triangles) const {
  volume_->refresh_surface(config_.voxel);
  vertices = volume_->mesh.vertices;
  triangles = volume_->mesh.triangles;
}

size_t Open3dTsdf::memory_bytes() const {
  size_t bytes = 0;
  for (const auto& unit : volume_->tsdf.volume_units_)
    bytes += unit.second.volume_->voxels_.capacity() * sizeof(open3d::geometry::TSDFVoxel);
  const Volume& v = *volume_;
  return bytes + v.samples.capacity() * sizeof(Eigen::Vector3f) +
         v.mesh.vertices.capacity() * sizeof(Eigen::Vector3f) + v.mesh.triangles.capacity() * sizeof(Eigen::Vector3i);
}

}  // namespace sonomap
