// SPDX-License-Identifier: GPL-3.0-or-later
// One interface for every map, so an A/B run swaps the mapper and nothing else.
#pragma once

#include "core/types.hpp"

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sonomap {

// Result of a distance query at one point.
struct DistanceQuery {
  bool observed = false;           // false: the map knows nothing here; distance is not guessed
  float distance = 0.0f;           // metres (unsigned for VDB-GPDF's global field)
  Eigen::Vector3f gradient = Eigen::Vector3f::Zero();  // unit, pointing away from the surface
  float variance = 0.0f;
};

// Wall time of the mapper's own stages in the last integrate(), milliseconds.
struct StageTimes {
  std::vector<std::pair<std::string, double>> stages;
};

class Mapper {
 public:
  virtual ~Mapper() = default;
  virtual std::string name() const = 0;
  // Fuses one frame (points in the camera frame, frame.world_T_camera as the pose).
  // Frames with invalid poses or points are rejected with std::invalid_argument, map untouched.
  virtual void integrate(const Frame& frame) = 0;
  // Surface samples in the world within `radius` (horizontal) of `center`, dense enough that
  // neighbouring samples of one continuous surface are at most about half a voxel apart.
  virtual void surface_points(const Eigen::Vector3d& center, double radius,
                              std::vector<Eigen::Vector3f>& out) const = 0;
  // Distance field queries (batched). Maps without a field report observed = false.
  virtual void query(const std::vector<Eigen::Vector3f>& points,
                     std::vector<DistanceQuery>& out) const = 0;
  virtual StageTimes last_stage_times() const { return {}; }
};

}  // namespace sonomap
