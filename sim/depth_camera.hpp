// SPDX-License-Identifier: GPL-3.0-or-later
// Pinhole z-depth camera: traces the world, reports z-depth and incidence per pixel, applies
// the range limits and back-projects valid pixels.
#pragma once

#include "sim/scenario.hpp"
#include "sim/world.hpp"

#include <Eigen/Core>
#include <vector>

namespace sonomap::sim {

// A depth image on its way through the sensor model. Row-major, width*height values.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> z;              // z-depth in metres; 0 = no return
  std::vector<float> incidence;  // angle between the ray and the surface normal, [0, pi/2] radians
};

class DepthCamera {
 public:
  // Throws std::invalid_argument for invalid intrinsics or ranges (validate(CameraSpec)).
  explicit DepthCamera(const CameraSpec& spec);

  // The exact z-depth of the first surface along each pixel's ray, before range limits
  // (0 where nothing is hit), and the incidence angle there.
  // `image` is overwritten, its buffers reused (no allocation from the second frame on).
  void trace(const World& world, const Eigen::Isometry3d& world_T_camera, DepthImage& image) const;
  DepthImage trace(const World& world, const Eigen::Isometry3d& world_T_camera) const {
    DepthImage image;
    trace(world, world_T_camera, image);
    return image;
  }

  // Pixels whose z-depth lies outside [min_range, max_range] become 0 ("no return").
  DepthImage clip_to_range(DepthImage image) const;

  // The valid pixels (z > 0) as points in the optical frame: x = (u - cx) z / fx, y = (v - cy) z / fy.
  std::vector<Eigen::Vector3f> back_project(const std::vector<float>& depth) const;

  const CameraSpec& spec() const { return spec_; }

 private:
  CameraSpec spec_;
};

}  // namespace sonomap::sim
