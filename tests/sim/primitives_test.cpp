// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/primitives.hpp"
#include "sim/trajectory.hpp"
#include "sim/world_geometry.hpp"

#include <catch2/catch.hpp>

using namespace sonomap::sim;

namespace {

// Signed volume by the divergence theorem: positive when every normal faces out.
double signed_volume(const TriangleMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].cast<double>().dot(m.vertices[t[1]].cast<double>().cross(m.vertices[t[2]].cast<double>())) / 6.0;
  return v;
}

PrimitiveSpec shape(PrimitiveSpec::Kind kind) {
  PrimitiveSpec s;
  s.kind = kind;
  return s;
}

}  // namespace

TEST_CASE("box stands on z = 0, centred in x and y, normals out, room faces in", "[sim][primitives]") {
  PrimitiveSpec box = shape(PrimitiveSpec::Kind::Box);
  box.size = Eigen::Vector3d(2.0, 3.0, 4.0);
  const TriangleMesh m = triangulate(box);
  CHECK(m.triangles.size() == 12);
  for (const auto& v : m.vertices) {
    CHECK(std::abs(v.x()) == Approx(1.0));
    CHECK(std::abs(v.y()) == Approx(1.5));
    CHECK((v.z() == 0.0f || v.z() == 4.0f));
  }
  CHECK(signed_volume(m) == Approx(24.0));
  box.kind = PrimitiveSpec::Kind::Room;
  CHECK(signed_volume(triangulate(box)) == Approx(-24.0));
}

TEST_CASE("cylinder has its base at z = 0, vertices on the circle, exact polygon volume", "[sim][primitives]") {
  PrimitiveSpec c = shape(PrimitiveSpec::Kind::Cylinder);
  c.radius = 0.3;
  c.height = 1.8;
  c.segments = 16;
  const TriangleMesh m = triangulate(c);
  CHECK(m.triangles.size() == 4u * 16u);
  for (const auto& v : m.vertices) {
    const double r = std::hypot(v.x(), v.y());
    CHECK((r == Approx(0.3) || r < 1e-9));
    CHECK((v.z() == 0.0f || v.z() == Approx(1.8)));
  }
  // A regular 16-gon of circumradius r has area (16/2) r^2 sin(2 pi / 16).
  CHECK(signed_volume(m) == Approx(8.0 * 0.09 * std::sin(2 * M_PI / 16) * 1.8).epsilon(1e-6));
}

TEST_CASE("sphere vertices lie on the sphere and the mesh is closed and outward", "[sim][primitives]") {
  PrimitiveSpec s = shape(PrimitiveSpec::Kind::Sphere);
  s.radius = 0.7;
  s.segments = 32;
  const TriangleMesh m = triangulate(s);
  for (const auto& v : m.vertices) CHECK(v.cast<double>().norm() == Approx(0.7).epsilon(1e-6));
  const double sphere_volume = 4.0 / 3.0 * M_PI * 0.7 * 0.7 * 0.7;
  const double v = signed_volume(m);
  CHECK(v > 0.97 * sphere_volume);  // inscribed polyhedron: a little smaller, never larger
  CHECK(v < sphere_volume);
}

TEST_CASE("plane is size.x by size.y in xy with normal +z", "[sim][primitives]") {
  PrimitiveSpec p = shape(PrimitiveSpec::Kind::Plane);
  p.size = Eigen::Vector3d(4.0, 2.0, 0.0);
  const TriangleMesh m = triangulate(p);
  REQUIRE(m.triangles.size() == 2);
  double area = 0.0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3f n = (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    CHECK(n.z() > 0.0f);
    area += 0.5 * n.norm();
  }
  CHECK(area == Approx(8.0));
}

TEST_CASE("bad primitives and meshes are rejected, naming the culprit", "[sim][primitives]") {
  PrimitiveSpec c = shape(PrimitiveSpec::Kind::Cylinder);
  c.radius = -1.0;
  CHECK_THROWS_AS(triangulate(c), std::invalid_argument);
  c.radius = 1.0;
  c.segments = 2;
  CHECK_THROWS_AS(triangulate(c), std::invalid_argument);
  CHECK_THROWS_AS(triangulate(shape(PrimitiveSpec::Kind::Mesh)), std::invalid_argument);

  TriangleMesh m = triangulate(shape(PrimitiveSpec::Kind::Box));
  m.vertices[5].y() = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH(validate(m), Catch::Contains("vertex 5"));
  m = triangulate(shape(PrimitiveSpec::Kind::Box));
  m.triangles[7].z() = 8;
  CHECK_THROWS_WITH(validate(m), Catch::Contains("triangle 7"));
}

TEST_CASE("world triangles place statics by pose and movers by trajectory while present", "[sim][world]") {
  Scenario s;
  StaticObject wall;
  wall.shape = shape(PrimitiveSpec::Kind::Plane);
  wall.pose.translation() = Eigen::Vector3d(1, 2, 3);
  s.statics.push_back(wall);
  MovingObject mover;
  mover.shape = shape(PrimitiveSpec::Kind::Box);
  mover.trajectory.keyframes = {Keyframe{0.0, Eigen::Vector3d(0, 0, 0), Eigen::Quaterniond::Identity()},
                                Keyframe{2.0, Eigen::Vector3d(4, 0, 0), Eigen::Quaterniond::Identity()}};
  mover.appear_time = 0.5;
  mover.disappear_time = 1.5;
  s.movers.push_back(mover);

  CHECK(world_triangles(s, 0.25).size() == 2);
  CHECK(world_triangles(s, 1.5).size() == 2);  // gone at disappear_time
  const auto at_one = world_triangles(s, 1.0);
  REQUIRE(at_one.size() == 14);
  for (int c = 0; c < 3; ++c) CHECK(at_one[0][c].z() == Approx(3.0));
  // The box (unit cube, z in [0, 1]) is at x = 2 at t = 1: every x in [1.5, 2.5].
  for (std::size_t i = 2; i < at_one.size(); ++i)
    for (int c = 0; c < 3; ++c) CHECK(std::abs(at_one[i][c].x() - 2.0) == Approx(0.5));
}
