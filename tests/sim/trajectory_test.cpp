// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/trajectory.hpp"

#include <catch2/catch.hpp>

using namespace sonomap::sim;

namespace {

TrajectorySpec two_keyframes() {
  TrajectorySpec t;
  t.keyframes.push_back(Keyframe{1.0, Eigen::Vector3d(0, 0, 1), Eigen::Quaterniond::Identity()});
  t.keyframes.push_back(Keyframe{3.0, Eigen::Vector3d(4, -2, 1),
                                 Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()))});
  return t;
}

double yaw_of(const Eigen::Isometry3d& pose) { return std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)); }

}  // namespace

TEST_CASE("trajectory poses are exact at keyframes", "[sim][trajectory]") {
  const TrajectorySpec t = two_keyframes();
  REQUIRE_NOTHROW(validate(t));
  const Eigen::Isometry3d a = pose_at(t, 1.0), b = pose_at(t, 3.0);
  CHECK((a.translation() - Eigen::Vector3d(0, 0, 1)).norm() < 1e-12);
  CHECK(a.linear().isIdentity(1e-12));
  CHECK((b.translation() - Eigen::Vector3d(4, -2, 1)).norm() < 1e-12);
  CHECK(yaw_of(b) == Approx(M_PI / 2).margin(1e-12));
}

TEST_CASE("trajectory midpoint is the mean position and the half rotation", "[sim][trajectory]") {
  const Eigen::Isometry3d mid = pose_at(two_keyframes(), 2.0);
  CHECK((mid.translation() - Eigen::Vector3d(2, -1, 1)).norm() < 1e-12);
  // Slerp between identity and 90 degrees about z is 45 degrees about z.
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  CHECK((mid.linear() - expected).norm() < 1e-12);
  // A quarter of the way: position a quarter along, 22.5 degrees.
  const Eigen::Isometry3d quarter = pose_at(two_keyframes(), 1.5);
  CHECK((quarter.translation() - Eigen::Vector3d(1, -0.5, 1)).norm() < 1e-12);
  CHECK(yaw_of(quarter) == Approx(M_PI / 8).margin(1e-12));
}

TEST_CASE("trajectory holds the end poses outside its keyframes", "[sim][trajectory]") {
  const TrajectorySpec t = two_keyframes();
  CHECK((pose_at(t, -5.0).translation() - Eigen::Vector3d(0, 0, 1)).norm() < 1e-12);
  CHECK((pose_at(t, 100.0).translation() - Eigen::Vector3d(4, -2, 1)).norm() < 1e-12);
  CHECK(yaw_of(pose_at(t, 100.0)) == Approx(M_PI / 2).margin(1e-12));
}

TEST_CASE("trajectory validation rejects bad keyframes", "[sim][trajectory]") {
  TrajectorySpec empty;
  CHECK_THROWS_AS(validate(empty), std::invalid_argument);

  TrajectorySpec repeated = two_keyframes();
  repeated.keyframes[1].time = 1.0;
  CHECK_THROWS_WITH(validate(repeated), Catch::Contains("keyframe 1"));

  TrajectorySpec decreasing = two_keyframes();
  decreasing.keyframes[1].time = 0.5;
  CHECK_THROWS_AS(validate(decreasing), std::invalid_argument);

  TrajectorySpec not_unit = two_keyframes();
  not_unit.keyframes[0].orientation = Eigen::Quaterniond(2, 0, 0, 0);
  CHECK_THROWS_WITH(validate(not_unit), Catch::Contains("unit quaternion"));

  TrajectorySpec nan_position = two_keyframes();
  nan_position.keyframes[1].position.x() = std::nan("");
  CHECK_THROWS_AS(validate(nan_position), std::invalid_argument);
}
