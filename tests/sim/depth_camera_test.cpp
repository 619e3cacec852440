// SPDX-License-Identifier: GPL-3.0-or-later
// Exact (noise-free) depth against closed-form geometry.
#include "scenes.hpp"
#include "sim/cloud_frame.hpp"
#include "sim/depth_camera.hpp"
#include "sim/simulation.hpp"
#include "sim/world.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace sonomap::sim;
using sonomap::Frame;

namespace {

float depth_at(const Frame& f, int u, int v) { return f.depth[static_cast<std::size_t>(v) * f.width + u]; }

int returns(const Frame& f) {
  int n = 0;
  for (float z : f.depth) n += z > 0.0f;
  return n;
}

}  // namespace

TEST_CASE("a wall 2 m ahead reads 2 m at the centre pixel and everywhere (z-depth)", "[sim][camera]") {
  Simulation sim(test::wall_scenario(2.0));
  const Frame f = sim.render(0);
  REQUIRE(f.width == 640);
  REQUIRE(f.height == 480);
  CHECK(depth_at(f, 320, 240) == Approx(2.0).epsilon(1e-5));
  // z-depth, not range along the ray: the corners read 2 m too, although their rays are longer.
  CHECK(depth_at(f, 0, 0) == Approx(2.0).epsilon(1e-5));
  CHECK(depth_at(f, 639, 479) == Approx(2.0).epsilon(1e-5));
  float lo = 1e9f, hi = 0.0f;
  for (float z : f.depth) {
    lo = std::min(lo, z);
    hi = std::max(hi, z);
  }
  CHECK(lo == Approx(2.0).epsilon(1e-5));
  CHECK(hi == Approx(2.0).epsilon(1e-5));
  CHECK(f.points_camera.size() == 640u * 480u);
}

// Rays are cast in tiles of 4 x 2 or 4 x 4 pixels; at 643 x 482 the last tiles of each row and
// column hang over the image's edge, and the wall must still fill the image to its last pixel.
TEST_CASE("a wall 2 m ahead fills an image whose size is no multiple of the ray tiles", "[sim][camera]") {
  Scenario s = test::wall_scenario(2.0);
  s.camera.width = 643;
  s.camera.height = 482;
  s.camera.cx = 321.0;
  s.camera.cy = 240.5;
  Simulation sim(s);
  const Frame f = sim.render(0);
  REQUIRE(f.depth.size() == 643u * 482u);
  CHECK(depth_at(f, 642, 481) == Approx(2.0).epsilon(1e-5));
  CHECK(depth_at(f, 642, 0) == Approx(2.0).epsilon(1e-5));
  CHECK(depth_at(f, 0, 481) == Approx(2.0).epsilon(1e-5));
  const auto off_wall = std::count_if(f.depth.begin(), f.depth.end(), [](float z) { return std::abs(z - 2.0f) > 2e-5f; });
  CHECK(off_wall == 0);
  CHECK(f.points_camera.size() == 643u * 482u);
}

TEST_CASE("walls beyond max range or nearer than min range read no return", "[sim][camera]") {
  Scenario far = test::wall_scenario(5.5);
  far.camera.max_range = 5.0;
  Simulation sim_far(far);
  const Frame f = sim_far.render(0);
  CHECK(returns(f) == 0);
  CHECK(f.points_camera.empty());

  Scenario near = test::wall_scenario(0.25);
  near.camera.min_range = 0.3;
  Simulation sim_near(near);
  CHECK(returns(sim_near.render(0)) == 0);

  Scenario inside = test::wall_scenario(4.9);
  inside.camera.max_range = 5.0;
  Simulation sim_inside(inside);
  CHECK(returns(sim_inside.render(0)) == 640 * 480);
}

TEST_CASE("points of a slanted wall lie on the wall in the world", "[sim][camera]") {
  // A wall through (3, 0, 1) whose normal is turned 30 degrees about z from -x.
  Scenario s = test::wall_scenario(3.0);
  Eigen::Isometry3d pose = test::facing_minus_x(3.0);
  pose.linear() = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()) * pose.linear();
  s.statics[0].pose = pose;
  s.camera.width = 160;
  s.camera.height = 120;
  s.camera.fx = s.camera.fy = 130.0;
  s.camera.cx = 79.5;
  s.camera.cy = 59.5;
  Simulation sim(s);
  const Frame f = sim.render(0);
  const Eigen::Vector3d normal = pose.linear().col(2);
  REQUIRE(f.points_camera.size() == 160u * 120u);
  for (const Eigen::Vector3f& p : f.points_camera) {
    const Eigen::Vector3d world = sim.true_camera_pose(f.time) * p.cast<double>();
    CHECK(std::abs(normal.dot(world - pose.translation())) < 1e-5 * 4.0);
  }
  // The centre ray (optical axis, along world +x) meets the plane at x = 3 exactly.
  s.camera.cx = 80.0;
  s.camera.cy = 60.0;
  Simulation centred(s);
  CHECK(depth_at(centred.render(0), 80, 60) == Approx(3.0).epsilon(1e-5));
  // ... at an incidence of 30 degrees (the angle the wall was turned by).
  World world(centred.scenario());
  const DepthImage traced = DepthCamera(s.camera).trace(world, centred.true_camera_pose(0.0));
  CHECK(traced.incidence[60 * 160 + 80] == Approx(M_PI / 6).margin(1e-5));
}

TEST_CASE("a sphere's silhouette radius in pixels matches the pinhole formula", "[sim][camera]") {
  const double distance = 3.0, radius = 0.5, f = 525.0;
  Scenario s;
  StaticObject ball;
  ball.shape.kind = PrimitiveSpec::Kind::Sphere;
  ball.shape.radius = radius;
  ball.shape.segments = 128;
  ball.pose.translation() = Eigen::Vector3d(distance, 0.0, 1.0);
  s.statics.push_back(ball);
  s.body = test::still(Eigen::Vector3d(0.0, 0.0, 1.0));
  s.camera.width = 641;
  s.camera.height = 481;
  s.camera.cx = 320.0;  // the optical axis through a pixel centre, aimed at the sphere centre
  s.camera.cy = 240.0;
  s.camera.fx = s.camera.fy = f;
  Simulation sim(s);
  const Frame frame = sim.render(0);
  // Silhouette of a sphere centred on the axis: a circle of radius f R / sqrt(D^2 - R^2) px.
  // The 128-facet mesh lies inside the true sphere by at most R (1 - cos(pi/128)).
  const double r_true = f * radius / std::sqrt(distance * distance - radius * radius);
  const double r_inner = r_true * std::cos(M_PI / 128);
  REQUIRE(std::floor(r_inner) == std::floor(r_true));
  const int expected = 2 * static_cast<int>(std::floor(r_true)) + 1;
  int row = 0, column = 0;
  for (int u = 0; u < 641; ++u) row += depth_at(frame, u, 240) > 0.0f;
  for (int v = 0; v < 481; ++v) column += depth_at(frame, 320, v) > 0.0f;
  CHECK(row == expected);
  CHECK(column == expected);
}

TEST_CASE("a moving box is where its trajectory says, and only while present", "[sim][camera][moving]") {
  // Background wall at x = 5; a 0.5 m cube (front face at x = 2.75) crossing from y = +2
  // to y = -2 between t = 0 and t = 2, present for t in [0.5, 1.5).
  Scenario s = test::wall_scenario(5.0);
  MovingObject box;
  box.name = "box";
  box.shape.kind = PrimitiveSpec::Kind::Box;
  box.shape.size = Eigen::Vector3d(0.5, 0.5, 2.0);
  box.trajectory.keyframes = {Keyframe{0.0, Eigen::Vector3d(3.0, 2.0, 0.0), Eigen::Quaterniond::Identity()},
                              Keyframe{2.0, Eigen::Vector3d(3.0, -2.0, 0.0), Eigen::Quaterniond::Identity()}};
  box.appear_time = 0.5;
  box.disappear_time = 1.5;
  s.movers.push_back(box);
  s.frames = 60;
  s.camera.max_range = 6.0;
  Simulation sim(s);
  const auto& cam = s.camera;

  // Frames 12 (t = 0.4) and 45 (t = 1.5): absent, the whole centre row sees the wall.
  for (int frame : {12, 45}) {
    const Frame f = sim.render(frame);
    for (int u = 0; u < cam.width; ++u) REQUIRE(depth_at(f, u, 240) == Approx(5.0).epsilon(1e-5));
  }
  // Present: the box centre at y(t) = 2 - 2t projects to u = cx + fx (-y) / 2.75.
  for (int frame : {21, 30, 37}) {
    const double t = frame / 30.0;
    const double y = 2.0 - 2.0 * t;
    const int u = static_cast<int>(std::lround(cam.cx - cam.fx * y / 2.75));
    const Frame f = sim.render(frame);
    CHECK(depth_at(f, u, 240) == Approx(2.75).epsilon(1e-5));
    // Rays passing 0.1 m clear of the box's sides (y +- 0.25 over x in [2.75, 3.25]) see the wall.
    for (double edge : {y + 0.35, y - 0.35}) {
      const bool outward = (edge > y) == (edge > 0.0);  // |ray y| grows with x on the far side
      const double slope = edge / (outward ? 2.75 : 3.25);
      const int us = static_cast<int>(std::lround(cam.cx - cam.fx * slope));
      if (us >= 0 && us < cam.width) CHECK(depth_at(f, us, 240) == Approx(5.0).epsilon(1e-5));
    }
  }
}

TEST_CASE("frames carry the time step and the true poses", "[sim][camera]") {
  Scenario s = test::wall_scenario(2.0);
  s.frames = 10;
  s.camera.rate_hz = 20.0;
  s.body.keyframes.push_back(Keyframe{1.0, Eigen::Vector3d(1.0, 0.0, 1.0), Eigen::Quaterniond::Identity()});
  Simulation sim(s);
  CHECK(sim.frame_count() == 10);
  const Frame f = sim.render(4);
  CHECK(f.time == Approx(0.2));
  const Eigen::Isometry3d world_T_body_true = sim.true_body_pose(f.time);
  CHECK(world_T_body_true.translation().x() == Approx(0.2));
  // No localisation error configured: the given pose is the true pose.
  CHECK(f.world_T_body.isApprox(world_T_body_true));
  CHECK(f.world_T_camera.isApprox(world_T_body_true * s.camera.body_T_camera));
  // Walking 0.2 m towards the wall at x = 2 leaves 1.8 m.
  CHECK(depth_at(f, 320, 240) == Approx(1.8).epsilon(1e-5));
}

TEST_CASE("an empty world returns nothing, a lone mover is still seen", "[sim][camera][moving]") {
  Scenario s;
  s.body = test::still(Eigen::Vector3d(0.0, 0.0, 1.0));
  s.camera.width = 64;
  s.camera.height = 48;
  s.camera.fx = s.camera.fy = 52.5;
  s.camera.cx = 32.0;
  s.camera.cy = 24.0;
  {
    Simulation empty(s);
    CHECK(returns(empty.render(0)) == 0);
  }
  MovingObject ball;
  ball.shape.kind = PrimitiveSpec::Kind::Sphere;
  ball.shape.radius = 0.5;
  ball.shape.segments = 64;
  ball.trajectory = test::still(Eigen::Vector3d(3.0, 0.0, 1.0));
  s.movers.push_back(ball);
  Simulation lone(s);
  const Frame f = lone.render(0);
  CHECK(returns(f) > 0);
  // The pixel on the optical axis sees the near pole region of the sphere: 2.5 m, within the
  // facet sagitta R (1 - cos(pi / 64)) = 0.6 mm.
  CHECK(depth_at(f, 32, 24) == Approx(2.5).margin(1e-3));
}

TEST_CASE("the incidence angle is acos within float rounding, the same with any libm", "[sim][camera]") {
  // Truth: the C library's double acos. Our polynomial must agree to 2.2e-8 rad (plus the float
  // result's rounding), on both signs of the cosine, and stay in [0, pi/2].
  double worst = 0.0;
  for (int i = -100000; i <= 100000; ++i) {
    const float c = static_cast<float>(i) / 100000.0f;
    const double exact = std::acos(std::min(1.0, std::abs(static_cast<double>(c))));
    const float angle = incidence_angle(c);
    worst = std::max(worst, std::abs(angle - exact) - 0.5 * std::abs(std::nextafter(angle, 4.0f) - angle));
    REQUIRE(angle >= 0.0f);
    REQUIRE(angle <= static_cast<float>(M_PI / 2));
  }
  CHECK(worst < 2.3e-8);
  CHECK(incidence_angle(1.0f) == 0.0f);
  CHECK(incidence_angle(2.0f) == 0.0f);  // rounding beyond 1 is clamped
}

TEST_CASE("a wall 2 m ahead as a lidar's rings: every 8th row's 640 points, on lines 2 m away, no image",
          "[sim][camera]") {
  Simulation sim(test::wall_scenario(2.0));
  Frame rings = sim.render(0);
  keep_cloud(rings, 8);
  CHECK(rings.depth.empty());  // a cloud: the mappers get no image beside it
  REQUIRE(rings.points_camera.size() == 60u * 640u);  // rows 0, 8, ..., 472
  int off_wall = 0, off_ring = 0;
  for (const Eigen::Vector3f& p : rings.points_camera) {
    off_wall += std::abs(p.z() - 2.0f) > 1e-4f;
    // Back on the image, each point lies on a row that is a multiple of 8 (y = (v - cy) z / fy).
    const double row = p.y() / p.z() * rings.intrinsics.fy + rings.intrinsics.cy;
    off_ring += std::abs(row - 8.0 * std::round(row / 8.0)) > 1e-3;
  }
  CHECK(off_wall == 0);
  CHECK(off_ring == 0);
  Frame cloud = sim.render(0);
  keep_cloud(cloud);  // every row: the image's points, without the image
  CHECK(cloud.depth.empty());
  CHECK(cloud.points_camera.size() == 640u * 480u);
  CHECK_THROWS_AS(keep_cloud(cloud, 0), std::invalid_argument);
}
