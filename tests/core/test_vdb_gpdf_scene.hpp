// SPDX-License-Identifier: GPL-3.0-or-later
// Test scenes for the mapping tests with an independent, closed-form ray caster (ray-box and
// ray-sphere intersections) and exact distances, so ground truth never comes from the mapper.
#pragma once

#include "core/types.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace sonomap::test {

struct Box {
  Eigen::Vector3d lo, hi;
};
struct Sphere {
  Eigen::Vector3d centre;
  double radius;
};

struct Scene {
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;

  // Nearest hit t > 0 of o + t d (d unit), or +inf.
  double cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& b : boxes) {  // slabs
      double t0 = -std::numeric_limits<double>::infinity(), t1 = -t0;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12) {
          if (o[a] < b.lo[a] || o[a] > b.hi[a]) t0 = t1 + 1;  // parallel and outside
          continue;
        }
        double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
      }
      if (t0 <= t1 && t0 > 1e-9) best = std::min(best, t0);
    }
    for (const auto& s : spheres) {
      const Eigen::Vector3d oc = o - s.centre;
      const double b = oc.dot(d), c = oc.squaredNorm() - s.radius * s.radius;
      const double disc = b * b - c;
      if (disc < 0) continue;
      const double t = -b - std::sqrt(disc);
      if (t > 1e-9) best = std::min(best, t);
    }
    return best;
  }

  // Exact unsigned distance to the nearest surface.
  double distance(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& b : boxes) {
      const Eigen::Vector3d out = (b.lo - p).cwiseMax(p - b.hi).cwiseMax(0.0);
      double d = out.norm();
      if (d == 0.0) d = std::min((p - b.lo).minCoeff(), (b.hi - p).minCoeff());  // inside
      best = std::min(best, d);
    }
    for (const auto& s : spheres) best = std::min(best, std::abs((p - s.centre).norm() - s.radius));
    return best;
  }
};

// Camera at eye looking at target, world z up; optical frame x right, y down, z forward.
inline Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear().col(0) = x;
  t.linear().col(1) = y;
  t.linear().col(2) = z;
  t.translation() = eye;
  return t;
}

// Deterministic integer hash (splitmix64) for the mixed-pixel model below.
inline uint64_t mix_bits(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// A pinhole depth frame (coarse by default to keep tests fast). Noise-free unless
// `mixed_pixels`: then every pixel reports the depth of a neighbour up to one pixel away
// (chosen by a hash of frame index and pixel), as a structured-light camera's lateral jitter
// does, so at silhouette edges some rays report the background through the object's edge.
inline Frame render(const Scene& scene, const Eigen::Isometry3d& world_T_camera, int index = 0,
                    int width = 160, int height = 120, double max_range = 5.0,
                    bool mixed_pixels = false) {
  Frame f;
  f.index = index;
  f.width = width;
  f.height = height;
  f.depth.assign(static_cast<size_t>(width) * height, 0.0f);
  f.world_T_camera = world_T_camera;
  f.world_T_body = world_T_camera;
  const double fx = 0.82 * width, fy = fx, cx = (width - 1) / 2.0, cy = (height - 1) / 2.0;
  f.intrinsics = PinholeIntrinsics{fx, fy, cx, cy};
  std::vector<float> z(static_cast<size_t>(width) * height, 0.0f);  // exact depth per pixel
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector3d dir_cam = Eigen::Vector3d((u - cx) / fx, (v - cy) / fy, 1.0).normalized();
      const double t = scene.cast(world_T_camera.translation(), world_T_camera.linear() * dir_cam);
      if (t <= max_range) z[static_cast<size_t>(v) * width + u] = static_cast<float>(t * dir_cam.z());
    }
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      int su = u, sv = v;
      if (mixed_pixels) {
        const uint64_t h = mix_bits((static_cast<uint64_t>(index) << 40) ^ (static_cast<uint64_t>(v) << 20) ^ u);
        su = std::clamp(u + static_cast<int>(h % 3) - 1, 0, width - 1);
        sv = std::clamp(v + static_cast<int>((h / 3) % 3) - 1, 0, height - 1);
      }
      const float depth = z[static_cast<size_t>(sv) * width + su];
      if (!(depth > 0.0f)) continue;
      const Eigen::Vector3d ray_cam((u - cx) / fx, (v - cy) / fy, 1.0);  // z = 1: scale by depth
      if ((depth * ray_cam).norm() > max_range) continue;
      f.depth[static_cast<size_t>(v) * width + u] = depth;
      f.points_camera.push_back((depth * ray_cam).cast<float>());
    }
  return f;
}

// A spinning lidar's sweep as a frame without a depth image: `rings` cones of rays at
// elevations lowest_deg, lowest_deg + spacing_deg, ... above the horizontal at the sensor,
// every azimuth_step_deg all around, noise-free, the hits within max_range as points in the
// frame of `world_T_camera` (any pose: a cloud has no image to match).
inline Frame lidar_sweep(const Scene& scene, const Eigen::Vector3d& sensor, const Eigen::Isometry3d& world_T_camera,
                         int index, int rings = 16, double lowest_deg = -15.0, double spacing_deg = 2.0,
                         double azimuth_step_deg = 0.2, double max_range = 5.0) {
  Frame f;
  f.index = index;
  f.world_T_camera = world_T_camera;
  f.world_T_body = world_T_camera;
  const Eigen::Isometry3d camera_T_world = world_T_camera.inverse();
  const int azimuths = static_cast<int>(std::lround(360.0 / azimuth_step_deg));
  for (int r = 0; r < rings; ++r) {
    const double e = (lowest_deg + r * spacing_deg) * M_PI / 180.0;
    for (int a = 0; a < azimuths; ++a) {
      const double az = a * azimuth_step_deg * M_PI / 180.0;
      const Eigen::Vector3d dir(std::cos(e) * std::cos(az), std::cos(e) * std::sin(az), std::sin(e));
      const double t = scene.cast(sensor, dir);
      if (t <= max_range) f.points_camera.push_back((camera_T_world * (sensor + t * dir)).cast<float>());
    }
  }
  return f;
}

// Poses on a circle of `radius` around `target`, `height` above it, all looking at it.
inline std::vector<Eigen::Isometry3d> orbit(const Eigen::Vector3d& target, double radius,
                                            double height, int count) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < count; ++i) {
    const double a = 2.0 * M_PI * i / count;
    poses.push_back(look_at(target + Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), height),
                            target));
  }
  return poses;
}

}  // namespace sonomap::test
