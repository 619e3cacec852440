// SPDX-License-Identifier: GPL-3.0-or-later
// The paper's depth-only baseline: the rasters from the current frame's points alone, no memory.
// As a Mapper it keeps the latest frame's points in the world and forgets everything else.
#pragma once

#include "core/mapper.hpp"

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sonomap {

class DepthOnlyMapper final : public Mapper {
 public:
  std::string name() const override { return "depth_only"; }

  // Replaces the stored points with frame.points_camera mapped by frame.world_T_camera.
  // A non-finite pose or a rotation that is not orthonormal throws std::invalid_argument and
  // keeps the previous frame's points. Non-finite points are skipped (a depth sensor has no
  // return there), not an error.
  void integrate(const Frame& frame) override;

  // The latest frame's points whose horizontal distance from `center` is at most `radius`
  // (`out` is replaced). Pixels are dense on the surfaces the camera sees.
  void surface_points(const Eigen::Vector3d& center, double radius,
                      std::vector<Eigen::Vector3f>& out) const override;
  void surface_points_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                              double z_max, std::vector<Eigen::Vector3f>& out) const override;

  // No distance field: every query reports observed = false.
  void query(const std::vector<Eigen::Vector3f>& points,
             std::vector<DistanceQuery>& out) const override;

  StageTimes last_stage_times() const override { return times_; }

  const std::vector<Eigen::Vector3f>& points() const { return points_; }
  std::size_t skipped_points() const { return skipped_; }  // non-finite, last frame

 private:
  std::vector<Eigen::Vector3f> points_;
  std::size_t skipped_ = 0;
  StageTimes times_;
};

}  // namespace sonomap
