// SPDX-License-Identifier: GPL-3.0-or-later
// The ray-traced world (Embree 3, kept out of this header): the static geometry as one scene
// instanced once, and each moving object as its own scene and instance, moved per frame.
#pragma once

#include "sim/scenario.hpp"

#include <Eigen/Geometry>
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
  // Unit geometric normal of the hit triangle in the world frame (either side); zero if no hit.
  std::vector<Eigen::Vector3f> normal_world;
};

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

  // Traces one ray per pixel (4x4 packets, rows of packets spread over TBB threads).
  // Every ray is independent, so the result does not depend on the thread count.
  RayHits cast(const PinholeRays& rays) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sonomap::sim
