// SPDX-License-Identifier: GPL-3.0-or-later
// Keyframed poses: the one interpolation function shared by the simulator and ground truth.
#pragma once

#include "sim/scenario.hpp"

#include <Eigen/Geometry>

namespace sonomap::sim {

// Throws std::invalid_argument for an empty trajectory, keyframe times that are not finite and
// strictly increasing, non-finite positions, or orientations that are not unit quaternions.
void validate(const TrajectorySpec& trajectory);

// The pose at time t: position linear in time and orientation slerped between the bracketing
// keyframes (LinearSlerp). Before the first / after the last keyframe the end pose holds.
// Assumes a validated trajectory.
Eigen::Isometry3d pose_at(const TrajectorySpec& trajectory, double t);

}  // namespace sonomap::sim
