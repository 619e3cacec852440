// SPDX-License-Identifier: GPL-3.0-or-later
// The shipped scenes parse and hold what their comments promise: the Cow-and-Lady-sized room,
// obstacle sizes, a full look-around, a person crossing the view.
#include "harness/formats/scenario_yaml.hpp"
#include "sim/primitives.hpp"
#include "sim/trajectory.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <set>

using sonomap::harness::load_scenario;
using sonomap::sim::PrimitiveSpec;
using sonomap::test::shipped;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Bounds {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-1e9);
  Eigen::Vector3d size() const { return hi - lo; }
};

// Axis-aligned bounds of an object's mesh placed at `pose`, in the world.
Bounds world_bounds(const sonomap::sim::TriangleMesh& mesh, const Eigen::Isometry3d& pose) {
  Bounds b;
  for (const auto& v : mesh.vertices) {
    const Eigen::Vector3d w = pose * v.cast<double>();
    b.lo = b.lo.cwiseMin(w);
    b.hi = b.hi.cwiseMax(w);
  }
  return b;
}

const sonomap::sim::StaticObject& find(const sonomap::sim::Scenario& s, const std::string& name) {
  for (const auto& o : s.statics)
    if (o.name == name) return o;
  FAIL("no static object named " << name);
  throw;
}

// Does the camera at `world_T_camera` see world point p inside its image and range?
bool in_view(const sonomap::sim::CameraSpec& c, const Eigen::Isometry3d& world_T_camera,
             const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = world_T_camera.inverse() * p;
  if (q.z() < c.min_range || q.z() > c.max_range) return false;
  const double u = c.fx * q.x() / q.z() + c.cx, v = c.fy * q.y() / q.z() + c.cy;
  return u >= 0 && u < c.width && v >= 0 && v < c.height;
}

}  // namespace

TEST_CASE("room.yaml: the Cow and Lady room with a cow, a person and furniture", "[scenario][scenes]") {
  const auto s = load_scenario(shipped("scenes/room.yaml"));
  CHECK(s.frames == 2700);  // 90 s at 30 Hz
  CHECK(s.camera.rate_hz == 30.0);
  CHECK(s.noise.model == sonomap::sim::NoiseSpec::Model::Kinect);
  CHECK(s.movers.empty());
  CHECK(s.statics.size() == 19);

  const auto& room = find(s, "room");
  CHECK(room.shape.kind == PrimitiveSpec::Kind::Room);
  const Bounds walls = world_bounds(room.mesh, room.pose);
  CHECK(walls.lo.isApprox(Eigen::Vector3d(-3.0, -3.0, 0.0), 1e-6));
  CHECK(walls.hi.isApprox(Eigen::Vector3d(0.5, 3.0, 2.8), 1e-6));

  const auto& cow = find(s, "cow");
  CHECK(cow.shape.kind == PrimitiveSpec::Kind::Mesh);
  CHECK(world_bounds(cow.mesh, Eigen::Isometry3d::Identity()).size().isApprox(Eigen::Vector3d(2.0, 0.7, 1.5), 1e-5));
  const auto& person = find(s, "person");
  CHECK(world_bounds(person.mesh, Eigen::Isometry3d::Identity()).size().isApprox(Eigen::Vector3d(0.35, 0.5, 1.75), 1e-5));

  // Every obstacle stands inside the room, and all but the column within the 0.1-2.0 m band's
  // top; the listener keeps at least 0.3 m (the minimum range) from all of them.
  for (const auto& o : s.statics) {
    if (o.name == "room") continue;
    INFO(o.name);
    const Bounds b = world_bounds(o.mesh, o.pose);
    CHECK((b.lo.array() >= walls.lo.array() - 1e-9).all());
    CHECK((b.hi.array() <= walls.hi.array() + 1e-9).all());
    if (o.name != "column") CHECK(b.hi.z() <= 2.0);
    double clearance = 1e9;
    for (double t = 0.0; t <= 90.0; t += 0.1) {
      const Eigen::Vector3d p = sonomap::sim::pose_at(s.body, t).translation();
      const double dx = std::max({b.lo.x() - p.x(), 0.0, p.x() - b.hi.x()});
      const double dy = std::max({b.lo.y() - p.y(), 0.0, p.y() - b.hi.y()});
      clearance = std::min(clearance, std::hypot(dx, dy));
    }
    CHECK(clearance >= 0.3);
  }

  // The heading sweeps every 10-degree sector at least twice while the listener moves.
  int visits[36] = {};
  int previous = -1;
  for (double t = 0.0; t <= 90.0; t += 0.05) {
    const auto pose = sonomap::sim::pose_at(s.body, t);
    const Eigen::Vector3d x = pose.linear().col(0);
    double deg = std::atan2(x.y(), x.x()) * 180.0 / kPi;
    if (deg < 0) deg += 360.0;
    const int sector = static_cast<int>(deg / 10.0) % 36;
    if (sector != previous) ++visits[sector];
    previous = sector;
  }
  for (int k = 0; k < 36; ++k) CHECK(visits[k] >= 2);
  const double travelled = (sonomap::sim::pose_at(s.body, 11.25).translation() -
                            sonomap::sim::pose_at(s.body, 0.0).translation()).norm();
  CHECK(travelled > 0.5);
}

TEST_CASE("dynamic_person.yaml: a person walks into view, stands, and walks out", "[scenario][scenes]") {
  const auto s = load_scenario(shipped("scenes/dynamic_person.yaml"));
  CHECK(s.frames == 390);  // 13 s at 30 Hz
  REQUIRE(s.movers.size() == 1);
  const auto& person = s.movers[0];
  CHECK(world_bounds(person.mesh, Eigen::Isometry3d::Identity()).size().isApprox(Eigen::Vector3d(0.35, 0.5, 1.75), 1e-5));
  // The person's chest (1.2 m up) as the camera sees it over time.
  const auto chest_seen = [&](double t) {
    const Eigen::Vector3d chest =
        sonomap::sim::pose_at(person.trajectory, t) * Eigen::Vector3d(0, 0, 1.2);
    const Eigen::Isometry3d camera = sonomap::sim::pose_at(s.body, t) * s.camera.body_T_camera;
    return in_view(s.camera, camera, chest);
  };
  CHECK_FALSE(chest_seen(1.0));  // not yet in view
  CHECK(chest_seen(5.0));        // standing in front of the camera
  CHECK(chest_seen(8.0));
  CHECK_FALSE(chest_seen(11.9)); // gone again
  CHECK(person.appear_time <= 1.0);
  CHECK(person.disappear_time >= 11.9);
  CHECK(person.disappear_time < 13.0);  // the last second shows the empty room
}

TEST_CASE("smoke.yaml: a short scene with every primitive, a mesh and a mover", "[scenario][scenes]") {
  const auto s = load_scenario(shipped("scenes/smoke.yaml"));
  CHECK(s.frames == 60);
  CHECK(s.seed == 7u);
  CHECK(s.statics.size() == 5);
  CHECK(s.movers.size() == 1);
  std::set<PrimitiveSpec::Kind> kinds;
  for (const auto& o : s.statics) kinds.insert(o.shape.kind);
  CHECK(kinds.size() == 5);  // room, box, cylinder, sphere, mesh
}

TEST_CASE("large_object_leaves.yaml: a cabinet in view jumps 1.5 m aside between frames 30 and 31",
          "[scenario][scenes]") {
  const auto s = load_scenario(shipped("scenes/large_object_leaves.yaml"));
  CHECK(s.frames == 120);  // 4 s at 30 Hz
  REQUIRE(s.movers.size() == 1);
  const auto& cabinet = s.movers[0];
  CHECK(cabinet.name == "cabinet");
  const auto at = [&](double t) {
    return world_bounds(sonomap::sim::mesh_of(cabinet.shape, cabinet.mesh), sonomap::sim::pose_at(cabinet.trajectory, t));
  };
  const Bounds before = at(30 / 30.0), after = at(31 / 30.0);
  CHECK(before.size().isApprox(Eigen::Vector3d(0.7, 0.9, 1.7), 1e-6));  // float vertices
  CHECK(before.lo.x() == Approx(-1.15));  // the front face 1.35 m ahead of the listener at x = -2.5
  CHECK(after.lo.y() == Approx(before.lo.y() - 1.5));
  CHECK(after.hi.y() < before.lo.y());  // its old place is wholly vacated
  // From frame 31 the camera looks through the old place: the middle of its front face (1.2 m
  // up) and the wall behind it are in view (the room holds nothing else in between); the
  // cabinet's new front face is not.
  const Eigen::Isometry3d camera = sonomap::sim::pose_at(s.body, 31 / 30.0) * s.camera.body_T_camera;
  CHECK(in_view(s.camera, camera, Eigen::Vector3d(-1.15, 0.0, 1.2)));
  CHECK(in_view(s.camera, camera, Eigen::Vector3d(0.45, 0.0, 1.2)));  // the wall behind it
  CHECK_FALSE(in_view(s.camera, camera, Eigen::Vector3d(-1.15, -1.5, 1.2)));  // its new front face
}
