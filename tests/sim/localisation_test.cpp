// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/localisation.hpp"
#include "sim/trajectory.hpp"

#include <catch2/catch.hpp>

using namespace sonomap::sim;

namespace {

TrajectorySpec walk() {
  TrajectorySpec t;
  t.keyframes = {Keyframe{0.0, Eigen::Vector3d(0, 0, 1), Eigen::Quaterniond::Identity()},
                 Keyframe{10.0, Eigen::Vector3d(10, 0, 1), Eigen::Quaterniond::Identity()}};
  return t;
}

}  // namespace

TEST_CASE("a time offset hands over the true pose at the offset time", "[sim][localisation]") {
  LocalisationSpec spec;
  spec.time_offset = 0.25;
  LocalisationModel model(spec, 1, 0, 1.0 / 30.0);
  const Eigen::Isometry3d given = model.estimated_body_pose(walk(), 30, 1.0);
  CHECK(given.translation().x() == Approx(1.25));
  CHECK(given.linear().isIdentity(1e-12));
}

TEST_CASE("random-walk drift spreads as sigma sqrt(t)", "[sim][localisation]") {
  // Translation drift 0.1 m/sqrt(s) and yaw drift 0.05 rad/sqrt(s): after 5 s the x error has
  // variance 0.1^2 * 5 and the yaw error 0.05^2 * 5, over independent seeds.
  LocalisationSpec spec;
  spec.translation_drift = 0.1;
  spec.yaw_drift = 0.05;
  const int runs = 2000, frame = 150;  // 5 s at 30 Hz
  double sum_x2 = 0.0, sum_yaw2 = 0.0;
  for (int seed = 0; seed < runs; ++seed) {
    LocalisationModel model(spec, static_cast<std::uint64_t>(seed), 0, 1.0 / 30.0);
    const Eigen::Isometry3d given = model.estimated_body_pose(walk(), frame, 5.0);
    const double dx = given.translation().x() - 5.0;
    const double yaw = std::atan2(given.linear()(1, 0), given.linear()(0, 0));
    sum_x2 += dx * dx;
    sum_yaw2 += yaw * yaw;
  }
  // Sample variance of 2000 normals: relative standard error sqrt(2/2000) = 3.2%.
  CHECK(sum_x2 / runs == Approx(0.01 * 5.0).epsilon(0.15));
  CHECK(sum_yaw2 / runs == Approx(0.0025 * 5.0).epsilon(0.15));
}

TEST_CASE("drift of a frame does not depend on the order frames are asked for", "[sim][localisation]") {
  LocalisationSpec spec;
  spec.translation_drift = 0.1;
  spec.yaw_noise = 0.01;
  LocalisationModel forward(spec, 9, 0, 1.0 / 30.0), backward(spec, 9, 0, 1.0 / 30.0);
  std::vector<Eigen::Isometry3d> poses;
  for (int f = 0; f <= 40; f += 10) poses.push_back(forward.estimated_body_pose(walk(), f, f / 30.0));
  for (int k = 4; k >= 0; --k)
    CHECK(backward.estimated_body_pose(walk(), 10 * k, 10 * k / 30.0).isApprox(poses[k], 0.0));
  CHECK((poses[0].translation() - Eigen::Vector3d(0, 0, 1)).norm() == 0.0);  // no drift yet at frame 0
}

TEST_CASE("negative localisation parameters are rejected", "[sim][localisation]") {
  LocalisationSpec spec;
  spec.yaw_drift = -0.1;
  CHECK_THROWS_WITH(LocalisationModel(spec, 1, 0, 0.1), Catch::Contains("yaw_drift"));
}

TEST_CASE("white pose noise has the configured sigma and no drift", "[sim][localisation]") {
  LocalisationSpec spec;
  spec.translation_noise = 0.02;
  spec.yaw_noise = 0.01;
  LocalisationModel model(spec, 5, 0, 1.0 / 30.0);
  const int frames = 3000;
  double sum_y = 0.0, sum_y2 = 0.0, sum_yaw2 = 0.0;
  for (int f = 0; f < frames; ++f) {
    const double t = f / 300.0;  // stays inside the walk
    const Eigen::Isometry3d given = model.estimated_body_pose(walk(), f, t);
    const double dy = given.translation().y();  // the walk is along x at y = 0
    const double yaw = std::atan2(given.linear()(1, 0), given.linear()(0, 0));
    sum_y += dy;
    sum_y2 += dy * dy;
    sum_yaw2 += yaw * yaw;
  }
  // 3000 samples: relative standard error of the std sqrt(1 / 6000) = 1.3%.
  CHECK(std::sqrt(sum_y2 / frames) == Approx(0.02).epsilon(0.05));
  CHECK(std::abs(sum_y / frames) < 4.0 * 0.02 / std::sqrt(frames));
  CHECK(std::sqrt(sum_yaw2 / frames) == Approx(0.01).epsilon(0.05));
}
