// SPDX-License-Identifier: GPL-3.0-or-later
// The EDF circle (core/edf_raster.hpp) against closed-form geometry. The field comes from
// PlaneField below, the exact distance to vertical walls written out in this file, so the EDF
// code is checked independently of VDB-GPDF; one test then reads a real VDB-GPDF map of a box
// built from the closed-form caster of test_vdb_gpdf_scene.hpp.
#include "core/depth_only.hpp"
#include "core/edf_raster.hpp"
#include "core/vdb_gpdf.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

using namespace sonomap;

namespace {

constexpr double kDeg = M_PI / 180.0;

// Vertical walls {x : n.x = offset, x.z <= top} (n horizontal, unit; infinitely wide and deep).
// The field is the exact unsigned distance to the nearest wall, sqrt(d^2 + above^2) with d the
// distance to the wall's plane and above the height over its top edge; its gradient points
// from the wall's closest point to x. `observed` limits where the "map" knows anything.
class PlaneField final : public Mapper {
 public:
  struct Wall {
    Eigen::Vector3d normal;
    double offset;
    double top = std::numeric_limits<double>::infinity();
  };
  std::vector<Wall> walls;
  std::function<bool(const Eigen::Vector3d&)> observed = [](const Eigen::Vector3d&) { return true; };
  mutable int query_calls = 0;

  std::string name() const override { return "plane_field"; }
  void integrate(const Frame&) override {}
  void surface_points(const Eigen::Vector3d&, double, std::vector<Eigen::Vector3f>& out) const override {
    out.clear();
  }
  void query(const std::vector<Eigen::Vector3f>& points, std::vector<DistanceQuery>& out) const override {
    ++query_calls;
    out.assign(points.size(), DistanceQuery{});
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = points[i].cast<double>();
      if (!observed(p)) continue;
      double best = std::numeric_limits<double>::infinity();
      for (const Wall& w : walls) {
        const double d = w.normal.dot(p) - w.offset;
        const double above = std::max(0.0, p.z() - w.top);
        const double dist = std::hypot(d, above);
        if (dist < best) {
          best = dist;
          const Eigen::Vector3d away = d * w.normal + above * Eigen::Vector3d::UnitZ();
          out[i].gradient = (dist > 0 ? Eigen::Vector3d(away / dist) : w.normal).cast<float>();
        }
      }
      out[i].observed = true;
      out[i].distance = static_cast<float>(best);
    }
  }
};

// A wall 2 m ahead of the world origin along +x (its free side faces -x).
PlaneField wall_ahead() {
  PlaneField f;
  f.walls.push_back({-Eigen::Vector3d::UnitX(), -2.0});  // -x = -2  <=>  x = 2
  return f;
}

// A 4 x 4 m room centred on the world origin.
PlaneField square_room() {
  PlaneField f;
  f.walls = {{Eigen::Vector3d::UnitX(), -2.0}, {-Eigen::Vector3d::UnitX(), -2.0},
             {Eigen::Vector3d::UnitY(), -2.0}, {-Eigen::Vector3d::UnitY(), -2.0}};
  return f;
}

// A listener at (0, 0, 1) whose bin k is centred on the world bearing k degrees (1-degree
// bins centred at k + 0.5 from the heading, so the heading is -0.5 degrees).
RasterOrigin listener_at_origin() { return RasterOrigin{Eigen::Vector3d(0.0, 0.0, 1.0), -0.5 * kDeg, 0.0}; }

// Signed world bearing of bin k in (-180, 180].
double bearing(int k) { return k <= 180 ? k : k - 360; }

}  // namespace

TEST_CASE("EDF: facing a wall 2 m ahead, the bin at the wall reads slip 0 and range 2 m",
          "[edf_raster]") {
  const PlaneField field = wall_ahead();
  EdfRasterConfig config;  // sample_radius 1 m, tolerance 5 cm, max range 5 m
  const EdfRaster e = edf_raster(field, listener_at_origin(), 360, config);
  REQUIRE(e.bins.size() == 360);
  REQUIRE(e.traced.size() == 360);
  // Bin 0 looks straight at the wall: the closest point of its sample point is along the ray.
  CHECK(e.bins[0].sample_observed);
  CHECK(e.bins[0].slip_deg == Approx(0.0).margin(1e-3));
  CHECK(e.bins[0].sample_distance == Approx(1.0).margin(1e-5));  // 2 m - the 1 m radius
  CHECK(e.bins[0].end == TraceEnd::Hit);
  REQUIRE(e.traced.bins[0].known());
  CHECK(std::abs(e.traced.bins[0].range - 2.0) <= config.hit_tolerance);
  CHECK(e.traced.bins[0].point.x() == Approx(e.traced.bins[0].range).margin(1e-5));
}

TEST_CASE("EDF: a bin 60 degrees off the wall normal slips 60 degrees and ranges 2 / cos 60 = 4 m",
          "[edf_raster]") {
  const PlaneField field = wall_ahead();
  EdfRasterConfig config;
  const EdfRaster e = edf_raster(field, listener_at_origin(), 360, config);
  for (int k : {60, 300}) {
    INFO("bin " << k);
    // The closest point on a plane is along its normal, whatever the ray's bearing.
    CHECK(e.bins[k].slip_deg == Approx(60.0).margin(1e-3));
    REQUIRE(e.traced.bins[k].known());
    CHECK(std::abs(e.traced.bins[k].range - 4.0) <= config.hit_tolerance);
  }
  // Every bin: slip = |bearing| (the only surface is along +x); rays that meet the wall within
  // 5 m (|bearing| <= acos(2 / 5) = 66.4 degrees) range 2 / cos, the others are unknown.
  const double reach_deg = std::acos(2.0 / config.max_range) / kDeg;
  for (int k = 0; k < 360; ++k) {
    INFO("bin " << k);
    const double b = std::abs(bearing(k));
    CHECK(e.bins[k].slip_deg == Approx(b).margin(1e-3));
    if (b < reach_deg - 0.5) {
      REQUIRE(e.traced.bins[k].known());
      // Short of the hit by at most tolerance * (1 / cos - 1) (the last step's remainder).
      const double exact = 2.0 / std::cos(b * kDeg);
      CHECK(e.traced.bins[k].range <= exact + 1e-4);
      CHECK(e.traced.bins[k].range >= exact - config.hit_tolerance * (1.0 / std::cos(b * kDeg) - 1.0) - 1e-4);
    } else if (b > reach_deg + 0.5) {
      CHECK_FALSE(e.traced.bins[k].known());
      CHECK(e.bins[k].end == TraceEnd::OutOfRange);
    }
  }
}

TEST_CASE("EDF: at the centre of a square room slip is 0 at the wall normals and 45 at the diagonals",
          "[edf_raster]") {
  const PlaneField field = square_room();
  EdfRasterConfig config;
  const EdfRaster e = edf_raster(field, listener_at_origin(), 360, config);
  for (int k : {0, 90, 180, 270}) CHECK(e.bins[k].slip_deg == Approx(0.0).margin(1e-3));
  for (int k : {45, 135, 225, 315}) CHECK(e.bins[k].slip_deg == Approx(45.0).margin(1e-3));
  for (int k = 0; k < 360; ++k) {
    INFO("bin " << k);
    // Closed form: the nearest wall of a point on the circle is the one its ray is closest to
    // in bearing, so the slip is the angle to the nearest axis and the ray meets that wall at
    // 2 / cos(slip).
    const double a = k * kDeg;
    const double to_axis = std::acos(std::max(std::abs(std::cos(a)), std::abs(std::sin(a))));
    CHECK(e.bins[k].slip_deg == Approx(to_axis / kDeg).margin(1e-3));
    REQUIRE(e.traced.bins[k].known());
    CHECK(std::abs(e.traced.bins[k].range - 2.0 / std::cos(to_axis)) <= config.hit_tolerance);
  }
  // Bin k slips min(k mod 90, 90 - k mod 90): 0 and 45 four times each, 1..44 eight times,
  // so 4 + 8 v slips are <= v: the 180th (median) is 22, the 324th (90th percentile) 40.
  const SlipStats s = slip_stats(e);
  CHECK(s.observed == 360);
  CHECK(s.median_deg == Approx(22.0).margin(1e-3));
  CHECK(s.p90_deg == Approx(40.0).margin(1e-3));
}

TEST_CASE("EDF: a knee-high wall under the sensor's ray is found by a ray traced at knee height",
          "[edf_raster]") {
  // A wall 0.5 m high 1 m ahead, a full wall 2 m ahead; the sensor at 1.5 m.
  PlaneField field = wall_ahead();
  field.walls.push_back({-Eigen::Vector3d::UnitX(), -1.0, 0.5});
  const RasterOrigin eye{Eigen::Vector3d(0.0, 0.0, 1.5), -0.5 * kDeg, 0.0};
  EdfRasterConfig config;
  // At the sensor's height the ray passes 1 m over the low wall and meets the full one.
  const EdfRaster high = edf_raster(field, eye, 360, config);
  REQUIRE(high.traced.bins[0].known());
  CHECK(std::abs(high.traced.bins[0].range - 2.0) <= config.hit_tolerance);
  // Rays at 0.25 m and 1.5 m: the bin keeps the nearest hit, the low wall at 1 m.
  config.trace_heights = {0.25, 1.5};
  const EdfRaster both = edf_raster(field, eye, 360, config);
  REQUIRE(both.traced.bins[0].known());
  CHECK(std::abs(both.traced.bins[0].range - 1.0) <= config.hit_tolerance);
  CHECK(both.traced.bins[0].point.z() == Approx(0.25));
  CHECK(both.bins[0].end == TraceEnd::Hit);
  // 60 degrees off: the low wall at 1 / cos 60 = 2 m.
  REQUIRE(both.traced.bins[60].known());
  CHECK(std::abs(both.traced.bins[60].range - 2.0) <= config.hit_tolerance);
  // Bins facing away hit nothing at either height.
  CHECK_FALSE(both.traced.bins[180].known());
  CHECK(both.bins[180].end == TraceEnd::OutOfRange);
  // The slip is read on the sample circle at the sensor's height: with a radius of 0.8 m, from
  // (0.8, 0, 1.5) the closest surface is the low wall's top edge, 0.2 m ahead and 1 m down
  // (1.02 m; the full wall is 1.2 m away): atan2(1, 0.2) = 78.7 degrees off the ray.
  config.sample_radius = 0.8;
  const EdfRaster sampled = edf_raster(field, eye, 360, config);
  CHECK(sampled.bins[0].sample_distance == Approx(std::hypot(0.2, 1.0)).margin(1e-5));
  CHECK(sampled.bins[0].slip_deg == Approx(std::atan2(1.0, 0.2) / kDeg).margin(1e-3));
}

TEST_CASE("EDF: the field is queried once for the circle and once per tracing step, for all bins",
          "[edf_raster]") {
  const PlaneField field = square_room();
  EdfRasterConfig config;
  const EdfRaster e = edf_raster(field, listener_at_origin(), 360, config);
  int longest = 0;
  for (const EdfBin& b : e.bins) longest = std::max(longest, b.steps);
  CHECK(field.query_calls == 1 + longest);
  CHECK(longest <= config.max_steps);

  // Two computations are identical (no state carried between calls).
  const EdfRaster again = edf_raster(field, listener_at_origin(), 360, config);
  for (int k = 0; k < 360; ++k) CHECK(again.traced.bins[k].range == e.traced.bins[k].range);
}

TEST_CASE("EDF: where the field is unobserved the values are unknown, never guessed",
          "[edf_raster]") {
  SECTION("the map knows only x < 1.5 m: the wall at 2 m is never reached") {
    PlaneField field = wall_ahead();
    field.observed = [](const Eigen::Vector3d& p) { return p.x() < 1.5; };
    const EdfRaster e = edf_raster(field, listener_at_origin(), 360, {});
    // Sample points (radius 1 m) are inside the known part: their slip is known ...
    CHECK(e.bins[0].slip_deg == Approx(0.0).margin(1e-3));
    // ... but every ray towards the wall walks out of the known part before it hits.
    for (int k = 0; k < 360; ++k) CHECK_FALSE(e.traced.bins[k].known());
    CHECK(e.bins[0].end == TraceEnd::Unobserved);
  }
  SECTION("the map knows only y > 0: sample points on the right have no slip") {
    PlaneField field = square_room();
    field.observed = [](const Eigen::Vector3d& p) { return p.y() > 0.0; };
    const EdfRaster e = edf_raster(field, RasterOrigin{Eigen::Vector3d(0.0, 0.1, 1.0), -0.5 * kDeg, 0.0}, 360, {});
    CHECK(std::isfinite(e.bins[90].slip_deg));
    CHECK(std::isnan(e.bins[270].slip_deg));
    CHECK_FALSE(e.bins[270].sample_observed);
    CHECK(std::isnan(e.bins[270].sample_distance));
    CHECK_FALSE(e.traced.bins[270].known());
    CHECK(slip_stats(e).observed < 360);
  }
  SECTION("a mapper without a field (depth only): nothing is known") {
    DepthOnlyMapper depth_only;
    const EdfRaster e = edf_raster(depth_only, listener_at_origin(), 360, {});
    CHECK(e.traced.known_count() == 0);
    for (const EdfBin& b : e.bins) {
      CHECK_FALSE(b.sample_observed);
      CHECK(std::isnan(b.slip_deg));
      CHECK(b.end == TraceEnd::Unobserved);
    }
    const SlipStats s = slip_stats(e);
    CHECK(s.observed == 0);
    CHECK(std::isnan(s.median_deg));
    CHECK(std::isnan(s.p90_deg));
  }
}

TEST_CASE("EDF: a ray grazing a wall gives up after max_steps (unknown)", "[edf_raster]") {
  // Wall 2 m ahead, the ray 89.5 degrees off its normal: it would meet the wall 229 m away,
  // each step closes only 1 - cos(89.5) of the gap, so it runs out of steps first.
  const PlaneField field = wall_ahead();
  EdfRasterConfig config;
  config.max_steps = 8;
  config.max_range = 1000.0;
  const EdfRaster e = edf_raster(field, RasterOrigin{Eigen::Vector3d(0.0, 0.0, 1.0), 89.0 * kDeg, 0.0}, 360, config);
  CHECK(e.bins[0].end == TraceEnd::StepLimit);
  CHECK(e.bins[0].steps == 8);
  CHECK_FALSE(e.traced.bins[0].known());
}

TEST_CASE("EDF: slip statistics are nearest-rank percentiles over the known bins", "[edf_raster]") {
  EdfRaster e;
  e.bins.resize(12);  // slips 1..10 degrees and two unknown bins
  for (int i = 0; i < 10; ++i) e.bins[static_cast<size_t>(i)].slip_deg = static_cast<float>(10 - i);
  const SlipStats s = slip_stats(e);
  CHECK(s.observed == 10);
  CHECK(s.median_deg == 5.0);
  CHECK(s.p90_deg == 9.0);
}

TEST_CASE("EDF: bad configuration or origin is rejected", "[edf_raster][bad_input]") {
  const PlaneField field = wall_ahead();
  const RasterOrigin o = listener_at_origin();
  EdfRasterConfig c;
  c.sample_radius = 0.0;
  CHECK_THROWS_AS(edf_raster(field, o, 360, c), std::invalid_argument);
  c = {};
  c.hit_tolerance = NAN;
  CHECK_THROWS_AS(edf_raster(field, o, 360, c), std::invalid_argument);
  c = {};
  c.max_range = -1.0;
  CHECK_THROWS_AS(edf_raster(field, o, 360, c), std::invalid_argument);
  c = {};
  c.trace_heights = {0.5, NAN};
  CHECK_THROWS_AS(edf_raster(field, o, 360, c), std::invalid_argument);
  c = {};
  c.max_steps = 0;
  CHECK_THROWS_AS(edf_raster(field, o, 360, c), std::invalid_argument);
  CHECK_THROWS_AS(edf_raster(field, o, 0, {}), std::invalid_argument);
  RasterOrigin bad = o;
  bad.position.x() = NAN;
  CHECK_THROWS_AS(edf_raster(field, bad, 360, {}), std::invalid_argument);
  bad = o;
  bad.heading = INFINITY;
  CHECK_THROWS_AS(edf_raster(field, bad, 360, {}), std::invalid_argument);
  bad = o;
  bad.ground_z = NAN;
  CHECK_THROWS_AS(edf_raster(field, bad, 360, {}), std::invalid_argument);
}

TEST_CASE("EDF on a VDB-GPDF map of a box: the traced range at the face is exact within a voxel",
          "[edf_raster][vdb_gpdf]") {
  // A 0.6 x 0.6 x 0.5 m box seen from an orbit of 16 noise-free frames.
  const test::Scene scene{{{Eigen::Vector3d(-0.3, -0.3, 0.0), Eigen::Vector3d(0.3, 0.3, 0.5)}}, {}};
  VdbGpdf map;
  const auto poses = test::orbit(Eigen::Vector3d(0.0, 0.0, 0.25), 1.5, 1.0, 16);
  for (size_t i = 0; i < poses.size(); ++i) map.integrate(test::render(scene, poses[i], static_cast<int>(i)));

  // The listener 1 m in front of the +x face at mid-height, bin 0 centred on -x.
  const Eigen::Vector3d eye(1.3, 0.0, 0.25);
  const RasterOrigin origin{eye, M_PI - 0.5 * kDeg, 0.0};
  EdfRasterConfig config;
  config.sample_radius = 0.5;
  const EdfRaster e = edf_raster(map, origin, 360, config);
  const double voxel = map.config().global_voxel;
  // Bins within 10 degrees of the face normal meet the face (|y| <= tan 10 = 0.18 < 0.3).
  for (int k : {0, 1, 5, 9, 350, 355, 359}) {
    INFO("bin " << k);
    const double a = origin.heading + (k + 0.5) * kDeg;
    const Eigen::Vector3d ray(std::cos(a), std::sin(a), 0.0);
    const double exact = scene.cast(eye, ray);
    REQUIRE(e.traced.bins[k].known());
    CHECK(std::abs(e.traced.bins[k].range - exact) <= voxel);
  }
  // The sample point of bin 0 is 0.5 m off the face: its closest surface is straight ahead.
  REQUIRE(e.bins[0].sample_observed);
  CHECK(std::abs(e.bins[0].sample_distance - scene.distance(e.bins[0].sample_point.cast<double>())) <= voxel);
  CHECK(e.bins[0].slip_deg < 10.0);
}
