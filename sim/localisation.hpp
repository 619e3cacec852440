// SPDX-License-Identifier: GPL-3.0-or-later
// Stand-in for a visual-inertial odometry (the paper uses VINS-RGBD): the body pose handed to
// the mapper is the true pose, optionally taken at a time offset, with seeded per-frame white
// noise and a random-walk drift in translation and yaw. Ground truth always uses the true pose.
#pragma once

#include "sim/scenario.hpp"

#include <Eigen/Geometry>
#include <cstdint>

namespace sonomap::sim {

class LocalisationModel {
 public:
  // frame_period: seconds between frames (the random walk's time step).
  // Throws std::invalid_argument for negative or non-finite parameters.
  LocalisationModel(const LocalisationSpec& spec, std::uint64_t seed, std::uint64_t sensor,
                    double frame_period);

  // The estimated world_T_body for `frame` at time t:
  //   position    = true position at (t + time_offset) + drift(frame) + noise(frame)
  //   orientation = Rz(yaw drift(frame) + yaw noise(frame)) * true orientation at (t + time_offset)
  // drift(n) sums per-frame increments N(0, drift sigma * sqrt(frame_period)) for frames 1..n,
  // each drawn from a stream keyed by (seed, sensor, frame), so the result depends only on the
  // frame, not on the order of calls. (Consecutive calls reuse the running sum.)
  Eigen::Isometry3d estimated_body_pose(const TrajectorySpec& body, int frame, double t);

  // True when the estimate is the true pose at (t + time_offset): no noise, no drift.
  bool is_exact() const;

 private:
  struct Drift {
    Eigen::Vector3d translation = Eigen::Vector3d::Zero();
    double yaw = 0.0;
  };
  Drift drift_at(int frame);

  LocalisationSpec spec_;
  std::uint64_t seed_;
  std::uint64_t sensor_;
  double frame_period_;
  int cached_frame_ = 0;  // drift_ holds drift(cached_frame_)
  Drift cached_drift_;
};

}  // namespace sonomap::sim
