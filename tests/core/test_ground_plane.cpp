// SPDX-License-Identifier: GPL-3.0-or-later
// RANSAC ground plane on synthetic clouds whose plane is known exactly.
#include "core/ground_plane.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <stdexcept>

using namespace sonomap;

namespace {

constexpr double kDeg = M_PI / 180.0;

// Uniform in [lo, hi) from the top 53 bits (no std:: distribution: identical on every library).
double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

struct Cloud {
  std::vector<Eigen::Vector3f> points;
  Eigen::Vector3d normal;  // the true ground plane: normal . p = normal . anchor
  Eigen::Vector3d anchor;
};

// A 6 m x 6 m ground tilted by `tilt_deg` about the axis (1, 1, 0), through (0, 0, -1.2),
// with +-5 mm noise; plus 35% clutter above it (furniture, walls) and 5% below (multipath).
Cloud tilted_ground_with_outliers(double tilt_deg, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Eigen::Matrix3d tilt =
      Eigen::AngleAxisd(tilt_deg * kDeg, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  Cloud cloud{{}, tilt * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0, -1.2)};
  auto on_plane = [&](double u, double v, double above) -> Eigen::Vector3f {
    return (cloud.anchor + tilt * Eigen::Vector3d(u, v, above)).cast<float>();
  };
  for (int i = 0; i < 3000; ++i) {
    cloud.points.push_back(on_plane(uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -0.005, 0.005)));
  }
  for (int i = 0; i < 1750; ++i) {
    cloud.points.push_back(on_plane(uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, 0.1, 2.0)));
  }
  for (int i = 0; i < 250; ++i) {
    cloud.points.push_back(on_plane(uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -0.6, -0.1)));
  }
  return cloud;
}

}  // namespace

TEST_CASE("RANSAC finds a 12-degree tilted ground with 40% outliers within 1 cm and 0.5 degrees",
          "[ground_plane]") {
  const Cloud cloud = tilted_ground_with_outliers(12.0, 7);
  const GroundPlane plane = estimate_ground_plane(cloud.points);
  const double angle = std::acos(std::min(1.0, plane.normal.dot(cloud.normal))) / kDeg;
  CHECK(angle < 0.5);
  CHECK(std::abs(plane.tilt_deg() - 12.0) < 0.5);
  // Heights of points on the true plane, across the whole area, read 0 within 1 cm.
  for (double u : {-3.0, 0.0, 3.0}) {
    for (double v : {-3.0, 0.0, 3.0}) {
      const Eigen::Vector3d tangent_u = cloud.normal.unitOrthogonal();
      const Eigen::Vector3d tangent_v = cloud.normal.cross(tangent_u);
      const Eigen::Vector3d p = cloud.anchor + u * tangent_u + v * tangent_v;
      CHECK(std::abs(plane.height_of(p)) < 0.01);
    }
  }
  CHECK(plane.inliers >= 3000);
  CHECK(plane.inliers < 3000 + 100);  // only clutter within 3 cm of the ground may join
  CHECK(plane.rms < 0.01);
}

TEST_CASE("A level floor inside walls is found at its height, walls are not ground",
          "[ground_plane]") {
  std::mt19937_64 rng(3);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 1000; ++i) {  // floor at z = 0.2
    points.emplace_back(uniform(rng, -2, 2), uniform(rng, -2, 2), 0.2f);
  }
  for (int i = 0; i < 4000; ++i) {  // four walls reaching the floor, 2.5 m high: 80% of points
    const double s = uniform(rng, -2, 2), z = uniform(rng, 0.2, 2.7);
    switch (i % 4) {
      case 0: points.emplace_back(2.0, s, z); break;
      case 1: points.emplace_back(-2.0, s, z); break;
      case 2: points.emplace_back(s, 2.0, z); break;
      default: points.emplace_back(s, -2.0, z); break;
    }
  }
  const GroundPlane plane = estimate_ground_plane(points);
  CHECK(plane.tilt_deg() < 0.5);
  CHECK(plane.z_at(0.0, 0.0) == Approx(0.2).margin(0.01));
  CHECK(plane.z_at(1.5, -1.5) == Approx(0.2).margin(0.01));
}

TEST_CASE("The estimate is deterministic for a seed", "[ground_plane]") {
  const Cloud cloud = tilted_ground_with_outliers(5.0, 11);
  GroundPlaneConfig config;
  config.seed = 42;
  const GroundPlane a = estimate_ground_plane(cloud.points, config);
  const GroundPlane b = estimate_ground_plane(cloud.points, config);
  CHECK(a.normal == b.normal);
  CHECK(a.offset == b.offset);
  CHECK(a.inliers == b.inliers);
}

TEST_CASE("No ground in the data is an error, not a guess", "[ground_plane]") {
  CHECK_THROWS_AS(estimate_ground_plane({}), std::invalid_argument);
  const std::vector<Eigen::Vector3f> two = {{0, 0, 0}, {1, 0, 0}, {NAN, 0, 0}};
  CHECK_THROWS_WITH(estimate_ground_plane(two), Catch::Contains("at least 3"));
  std::vector<Eigen::Vector3f> wall;  // only a vertical plane
  for (int i = 0; i < 100; ++i) wall.emplace_back(1.0f, 0.01f * i, 0.02f * (i % 7));
  CHECK_THROWS_AS(estimate_ground_plane(wall), std::invalid_argument);
  GroundPlaneConfig bad;
  bad.lowest_fraction = 0.0;
  CHECK_THROWS_WITH(estimate_ground_plane(wall, bad), Catch::Contains("lowest_fraction"));
}
