// SPDX-License-Identifier: GPL-3.0-or-later
// Small scenarios built in code for the sim tests. The body stands still at `eye` looking
// along world +x (default head-mounted camera: optical z = body x = world x).
#pragma once

#include "sim/scenario.hpp"

#include <Eigen/Geometry>

namespace sonomap::sim::test {

inline TrajectorySpec still(const Eigen::Vector3d& position,
                            const Eigen::Quaterniond& q = Eigen::Quaterniond::Identity()) {
  TrajectorySpec t;
  t.keyframes.push_back(Keyframe{0.0, position, q});
  return t;
}

// Pose whose +z axis points along world -x (a plane facing the camera at +x).
inline Eigen::Isometry3d facing_minus_x(double x) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, 0.0, 1.0);
  return pose;
}

inline StaticObject plane_object(const std::string& name, const Eigen::Isometry3d& pose, double size = 100.0) {
  StaticObject object;
  object.name = name;
  object.shape.kind = PrimitiveSpec::Kind::Plane;
  object.shape.size = Eigen::Vector3d(size, size, 0.0);
  object.pose = pose;
  return object;
}

// A camera 1 m above the origin facing a large wall at x = distance.
inline Scenario wall_scenario(double distance) {
  Scenario s;
  s.name = "wall";
  s.statics.push_back(plane_object("wall", facing_minus_x(distance)));
  s.body = still(Eigen::Vector3d(0.0, 0.0, 1.0));
  s.frames = 1;
  return s;
}

}  // namespace sonomap::sim::test
