// SPDX-License-Identifier: GPL-3.0-or-later
// The depth-only baseline keeps exactly the latest frame's points, placed in the world.
#include "core/depth_only.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>

using namespace sonomap;

namespace {

// Camera at (1, 2, 1.5) looking along world +x, optical x = world -y, optical y = world -z.
Frame frame_looking_along_x(std::vector<Eigen::Vector3f> points_camera, int index = 0) {
  Frame frame;
  frame.index = index;
  Eigen::Matrix3d r;
  r << 0, 0, 1,
      -1, 0, 0,
       0, -1, 0;
  frame.world_T_camera.linear() = r;
  frame.world_T_camera.translation() = Eigen::Vector3d(1.0, 2.0, 1.5);
  frame.points_camera = std::move(points_camera);
  return frame;
}

}  // namespace

TEST_CASE("A point 2 m ahead of the camera, 0.5 m right and 0.2 m up lands where the pose says",
          "[depth_only]") {
  DepthOnlyMapper mapper;
  CHECK(mapper.name() == "depth_only");
  mapper.integrate(frame_looking_along_x({Eigen::Vector3f(0.5f, -0.2f, 2.0f)}));
  REQUIRE(mapper.points().size() == 1);
  // Ahead +2 in x, right 0.5 is world -y, up 0.2 is world +z.
  CHECK(mapper.points()[0].isApprox(Eigen::Vector3f(3.0f, 1.5f, 1.7f), 1e-6f));
}

TEST_CASE("Only the latest frame is kept: no memory", "[depth_only]") {
  DepthOnlyMapper mapper;
  mapper.integrate(frame_looking_along_x({{0, 0, 1}, {0, 0, 2}, {0, 0, 3}}, 0));
  CHECK(mapper.points().size() == 3);
  mapper.integrate(frame_looking_along_x({{0, 0, 4}}, 1));
  REQUIRE(mapper.points().size() == 1);
  CHECK(mapper.points()[0].x() == Approx(5.0f));
}

TEST_CASE("surface_points keeps points within a horizontal radius, at any height",
          "[depth_only]") {
  DepthOnlyMapper mapper;
  // World points (2, 2, 1.5), (4, 2, 1.5) and (2, 2, 0.5): camera z = world x - 1.
  mapper.integrate(frame_looking_along_x({{0, 0, 1}, {0, 0, 3}, {0, 1, 1}}));
  std::vector<Eigen::Vector3f> out{{9, 9, 9}};
  mapper.surface_points(Eigen::Vector3d(1.0, 2.0, 10.0), 1.5, out);
  REQUIRE(out.size() == 2);  // both at horizontal distance 1, whatever their height
  CHECK(out[0].z() == Approx(1.5f));
  CHECK(out[1].z() == Approx(0.5f));
  mapper.surface_points(Eigen::Vector3d(1.0, 2.0, 0.0), 3.0, out);
  CHECK(out.size() == 3);  // (4, 2) is exactly 3 m away: included
}

TEST_CASE("Non-finite points are skipped, bad poses rejected with the map untouched",
          "[depth_only]") {
  DepthOnlyMapper mapper;
  mapper.integrate(frame_looking_along_x({{0, 0, 1}, {NAN, 0, 1}, {0, INFINITY, 2}}));
  CHECK(mapper.points().size() == 1);
  CHECK(mapper.skipped_points() == 2);

  Frame nan_pose = frame_looking_along_x({{0, 0, 5}, {0, 0, 6}}, 7);
  nan_pose.world_T_camera.translation().x() = NAN;
  CHECK_THROWS_AS(mapper.integrate(nan_pose), std::invalid_argument);
  Frame scaled = frame_looking_along_x({{0, 0, 5}, {0, 0, 6}}, 8);
  scaled.world_T_camera.linear() *= 2.0;
  CHECK_THROWS_AS(mapper.integrate(scaled), std::invalid_argument);
  Frame mirrored = frame_looking_along_x({{0, 0, 5}, {0, 0, 6}}, 9);
  mirrored.world_T_camera.linear().col(0) *= -1.0;
  CHECK_THROWS_AS(mapper.integrate(mirrored), std::invalid_argument);
  REQUIRE(mapper.points().size() == 1);  // still the first frame
  CHECK(mapper.points()[0].x() == Approx(2.0f));
}

TEST_CASE("The baseline has no distance field: every query is unobserved", "[depth_only]") {
  DepthOnlyMapper mapper;
  mapper.integrate(frame_looking_along_x({{0, 0, 1}}));
  std::vector<DistanceQuery> out;
  mapper.query({{2, 2, 1.5}, {0, 0, 0}}, out);
  REQUIRE(out.size() == 2);
  CHECK_FALSE(out[0].observed);
  CHECK_FALSE(out[1].observed);
}
