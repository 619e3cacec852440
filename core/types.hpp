// SPDX-License-Identifier: GPL-3.0-or-later
// Plain data shared by every module: frames from a depth sensor, and the raster origin.
// Frames follow docs/conventions.md: world z up; camera optical frame x right,
// y down, z forward; body frame x forward, y left, z up.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sonomap {

// Pinhole intrinsics of a depth image, in pixels: pixel (u, v) at depth z is the optical-frame
// point ((u - cx) z / fx, (v - cy) z / fy, z). All zero when the source gave none.
struct PinholeIntrinsics {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  bool valid() const {
    return std::isfinite(fx) && std::isfinite(fy) && fx > 0.0 && fy > 0.0 && std::isfinite(cx) &&
           std::isfinite(cy);
  }
};

// One depth frame as the mapper sees it.
struct Frame {
  int index = 0;
  double time = 0.0;  // seconds since the start of the run (fixed time step)
  int width = 0;
  int height = 0;
  // Row-major z-depth in metres, width*height values. 0 means "no return" (out of range,
  // invalidated by the noise model, or nothing hit). Never NaN.
  std::vector<float> depth;
  PinholeIntrinsics intrinsics;  // of `depth` (projective integrators need them)
  // The valid pixels back-projected into the camera optical frame (x right, y down, z forward).
  std::vector<Eigen::Vector3f> points_camera;
  // Camera pose in the world as handed to the mapper (the localisation estimate: a real
  // mapper never knows the true pose, which stays with the evaluator) ...
  Eigen::Isometry3d world_T_camera = Eigen::Isometry3d::Identity();
  // ... and the body (listener) pose that goes with it; rasters are centred on the body
  // position with the body heading.
  Eigen::Isometry3d world_T_body = Eigen::Isometry3d::Identity();
};

// Where a raster is centred: a position and a heading (yaw of the body x axis, radians),
// with the ground height the obstacle band is measured from.
struct RasterOrigin {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double heading = 0.0;
  double ground_z = 0.0;
};

// A run of surface samples read where they lie (in a map, or in scratch its caller holds).
struct SampleSpan {
  const Eigen::Vector3f* points = nullptr;
  std::size_t count = 0;
};

// Heading psi = yaw of the body x axis in the world.
inline double heading_of(const Eigen::Isometry3d& world_T_body) {
  const Eigen::Vector3d x = world_T_body.linear().col(0);
  return std::atan2(x.y(), x.x());
}

inline RasterOrigin raster_origin(const Eigen::Isometry3d& world_T_body, double ground_z = 0.0) {
  return RasterOrigin{world_T_body.translation(), heading_of(world_T_body), ground_z};
}

}  // namespace sonomap
