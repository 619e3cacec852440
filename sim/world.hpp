// SPDX-License-Identifier: GPL-3.0-or-later
// The ray-traced world (Embree 3, kept out of this header): the static geometry as one scene
// instanced once, and each moving object as its own scene and instance, moved per frame.
#pragma once

#include "sim/scenario.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace sonomap::sim {

// A pinhole camera's rays: one per pixel centre (u, v) = (column, row), direction
// ((u - cx) / fx, (v - cy) / fy, 1) in the camera optical frame (x right, y down, z forward).
struct PinholeRays {
  Eigen::Isometry3d world_T_camera = Eigen::Isometry3d::Identity();
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;

  // The rays of a camera's pixels from a pose.
  static PinholeRays of(const CameraSpec& camera, const Eigen::Isometry3d& world_T_camera) {
    PinholeRays rays;
    rays.world_T_camera = world_T_camera;
    rays.width = camera.width;
    rays.height = camera.height;
    rays.fx = camera.fx;
    rays.fy = camera.fy;
    rays.cx = camera.cx;
    rays.cy = camera.cy;
    return rays;
  }
};

// Per ray (row-major), what it hit first.
struct RayHits {
  int width = 0;
  int height = 0;
  // Ray parameter of the hit along the direction above. Its optical z component is 1, so this
  // is the hit's z-depth in metres. +infinity where nothing was hit.
  std::vector<float> z;
  // Angle between the ray and the hit triangle's geometric normal (either side), [0, pi/2]
  // radians (incidence_angle); 0 where nothing was hit.
  std::vector<float> incidence;
};

// acos(|cos_angle|) clamped to [0, pi/2], our own code so that it is the same with every libm:
// Abramowitz & Stegun 4.4.46, acos(x) = sqrt(1 - x) (a0 + a1 x + ... + a7 x^7) on [0, 1],
// absolute error <= 2.2e-8 rad (below a float's rounding above 0.2 rad), in double.
// Inline and branch-free (Estrin's scheme), so a packet's angles overlap in the pipeline.
inline float incidence_angle(float cos_angle) {
  constexpr double a0 = 1.5707963050, a1 = -0.2145988016, a2 = 0.0889789874, a3 = -0.0501743046,
                   a4 = 0.0308918810, a5 = -0.0170881256, a6 = 0.0066700901, a7 = -0.0012624911;
  const double c = std::abs(static_cast<double>(cos_angle));
  const double x = c < 1.0 ? c : 1.0;  // std::min(1.0, c), on values so that loops vectorise
  const double x2 = x * x;
  const double p = (a0 + a1 * x) + x2 * (a2 + a3 * x) + x2 * x2 * ((a4 + a5 * x) + x2 * (a6 + a7 * x));
  return static_cast<float>(std::sqrt(1.0 - x) * p);
}

// The rays of the packets World::cast traces by default on this CPU (World::Packet::Native):
// 16 where Embree traces 16-ray packets natively, else 8. For reports.
int native_packet_rays();

class World {
 public:
  // Builds the Embree scenes from the scenario's meshes (mesh_of: empty meshes of primitives
  // are triangulated). Throws std::invalid_argument for invalid meshes or trajectories and
  // std::runtime_error if Embree fails.
  explicit World(const Scenario& scenario);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // Places every moving object at its pose at time t; objects absent at t are disabled.
  void set_time(double t);

  // Embree's ray packets: 16 rays (4x4 pixels) or 8 (4x2). Native: 16 where Embree says it
  // traces 16 rays natively (its AVX-512 kernels), else 8 (AVX2 and below).
  enum class Packet { Native, Rays8, Rays16 };

  // Traces one ray per pixel (packets of pixel tiles, rows of tiles spread over TBB threads)
  // into `hits`, reusing its buffers. Every ray is independent, so the result depends neither
  // on the thread count nor on the packet; the incidence angles are computed by vectorised
  // row loops (core/vector_isa.hpp), the same bits with any instruction set.
  void cast(const PinholeRays& rays, RayHits& hits, Packet packet = Packet::Native) const;
  RayHits cast(const PinholeRays& rays) const {
    RayHits hits;
    cast(rays, hits);
    return hits;
  }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sonomap::sim
