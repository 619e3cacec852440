// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::sim {

namespace {

constexpr double kUnitQuaternionTolerance = 1e-6;

Eigen::Isometry3d make_pose(const Eigen::Vector3d& position, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = position;
  return pose;
}

}  // namespace

void validate(const TrajectorySpec& trajectory) {
  const auto& keys = trajectory.keyframes;
  if (keys.empty()) throw std::invalid_argument("trajectory: no keyframes (at least one is needed)");
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const std::string where = "trajectory keyframe " + std::to_string(i) + ": ";
    if (!std::isfinite(keys[i].time)) throw std::invalid_argument(where + "time is not finite");
    if (i > 0 && !(keys[i].time > keys[i - 1].time))
      throw std::invalid_argument(where + "time " + std::to_string(keys[i].time) +
                                  " is not greater than the previous keyframe's " +
                                  std::to_string(keys[i - 1].time));
    if (!keys[i].position.allFinite()) throw std::invalid_argument(where + "position is not finite");
    const double norm = keys[i].orientation.coeffs().norm();
    if (!std::isfinite(norm) || std::abs(norm - 1.0) > kUnitQuaternionTolerance)
      throw std::invalid_argument(where + "orientation is not a unit quaternion (norm " +
                                  std::to_string(norm) + ")");
  }
}

Eigen::Isometry3d pose_at(const TrajectorySpec& trajectory, double t) {
  const auto& keys = trajectory.keyframes;
  if (keys.empty()) throw std::invalid_argument("pose_at: trajectory has no keyframes");
  if (!(t > keys.front().time)) return make_pose(keys.front().position, keys.front().orientation);
  if (!(t < keys.back().time)) return make_pose(keys.back().position, keys.back().orientation);
  // First keyframe strictly after t; its predecessor is at or before t.
  const auto next = std::upper_bound(keys.begin(), keys.end(), t,
                                     [](double time, const Keyframe& k) { return time < k.time; });
  const Keyframe& a = *(next - 1);
  const Keyframe& b = *next;
  const double s = (t - a.time) / (b.time - a.time);
  const Eigen::Vector3d position = (1.0 - s) * a.position + s * b.position;
  const Eigen::Quaterniond orientation =
      a.orientation.normalized().slerp(s, b.orientation.normalized());
  return make_pose(position, orientation);
}

HeadKeyframe HeadSpec::at(double t) const {
  if (keyframes.empty()) return {t, 0.0, 0.0};
  if (t <= keyframes.front().time) return {t, keyframes.front().yaw_deg, keyframes.front().pitch_deg};
  if (t >= keyframes.back().time) return {t, keyframes.back().yaw_deg, keyframes.back().pitch_deg};
  const auto next = std::upper_bound(keyframes.begin(), keyframes.end(), t,
                                     [](double time, const HeadKeyframe& k) { return time < k.time; });
  const HeadKeyframe& a = *(next - 1);
  const HeadKeyframe& b = *next;
  const double w = (t - a.time) / (b.time - a.time);
  return {t, a.yaw_deg + w * (b.yaw_deg - a.yaw_deg), a.pitch_deg + w * (b.pitch_deg - a.pitch_deg)};
}

}  // namespace sonomap::sim
