// SPDX-License-Identifier: GPL-3.0-or-later
// VDB-GPDF against closed-form geometry: distance field, gradients, mesh, carving of a moved
// object, determinism and bad input. Frames come from the closed-form caster in
// test_vdb_gpdf_scene.hpp, never from the mapper.
#include "core/vdb_gpdf.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>

using namespace sonomap;
using sonomap::test::Box;
using sonomap::test::Scene;

namespace {

// A sample point at `offset` outside a surface point with outward normal n.
struct Probe {
  Eigen::Vector3d point;
  Eigen::Vector3d normal;  // direction away from the nearest surface (exact)
};

const Scene& box_scene() {
  static const Scene s{{{Eigen::Vector3d(-0.3, -0.3, 0.0), Eigen::Vector3d(0.3, 0.3, 0.5)}}, {}};
  return s;
}
const Scene& sphere_scene() {
  static const Scene s{{}, {{Eigen::Vector3d(0.0, 0.0, 0.4), 0.3}}};
  return s;
}

// Points at `offset` from the observed faces of the box (top and four sides).
std::vector<Probe> box_probes(double offset) {
  std::vector<Probe> out;
  for (double a = -0.2; a <= 0.2001; a += 0.1)
    for (double b = -0.2; b <= 0.2001; b += 0.1) {
      out.push_back({Eigen::Vector3d(a, b, 0.5 + offset), Eigen::Vector3d::UnitZ()});
    }
  for (double a = -0.2; a <= 0.2001; a += 0.1)
    for (double z = 0.15; z <= 0.4001; z += 0.125) {
      out.push_back({Eigen::Vector3d(0.3 + offset, a, z), Eigen::Vector3d::UnitX()});
      out.push_back({Eigen::Vector3d(-0.3 - offset, a, z), -Eigen::Vector3d::UnitX()});
      out.push_back({Eigen::Vector3d(a, 0.3 + offset, z), Eigen::Vector3d::UnitY()});
      out.push_back({Eigen::Vector3d(a, -0.3 - offset, z), -Eigen::Vector3d::UnitY()});
    }
  return out;
}

// Points at `offset` from the sphere, elevations 0..70 degrees (the part the orbit sees).
std::vector<Probe> sphere_probes(double offset) {
  std::vector<Probe> out;
  for (int e = 0; e <= 70; e += 10)
    for (int a = 0; a < 360; a += 30) {
      const double el = e * M_PI / 180.0, az = a * M_PI / 180.0;
      const Eigen::Vector3d n(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      out.push_back({Eigen::Vector3d(0.0, 0.0, 0.4) + (0.3 + offset) * n, n});
    }
  return out;
}

template <typename MapperT>
void build(MapperT& mapper, const Scene& scene, int frames = 16) {
  const auto poses = test::orbit(Eigen::Vector3d(0.0, 0.0, 0.25), 1.5, 1.0, frames);
  for (size_t i = 0; i < poses.size(); ++i)
    mapper.integrate(test::render(scene, poses[i], static_cast<int>(i)));
}

double degrees_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

struct FieldError {
  double rmse = 0.0;
  double worst_angle = 0.0;
  int unobserved = 0;
};

template <typename MapperT>
FieldError field_error(const MapperT& mapper, const Scene& scene, const std::vector<Probe>& probes) {
  std::vector<Eigen::Vector3f> pts;
  for (const auto& p : probes) pts.push_back(p.point.cast<float>());
  std::vector<DistanceQuery> q;
  mapper.query(pts, q);
  FieldError e;
  double sum = 0.0;
  int n = 0;
  for (size_t i = 0; i < probes.size(); ++i) {
    if (!q[i].observed) {
      ++e.unobserved;
      continue;
    }
    const double err = q[i].distance - scene.distance(probes[i].point);
    sum += err * err;
    ++n;
    e.worst_angle = std::max(e.worst_angle, degrees_between(q[i].gradient.cast<double>(), probes[i].normal));
  }
  e.rmse = n ? std::sqrt(sum / n) : std::numeric_limits<double>::infinity();
  return e;
}

}  // namespace

TEST_CASE("VDB-GPDF: distances around a box and a sphere are within one global voxel",
          "[vdb_gpdf]") {
  for (const Scene* scene : {&box_scene(), &sphere_scene()}) {
    VdbGpdf map;
    build(map, *scene);
    const bool is_box = scene == &box_scene();
    std::vector<Probe> probes;
    for (double offset : {0.05, 0.1, 0.2, 0.3}) {
      auto p = is_box ? box_probes(offset) : sphere_probes(offset);
      probes.insert(probes.end(), p.begin(), p.end());
    }
    const FieldError e = field_error(map, *scene, probes);
    INFO((is_box ? "box" : "sphere") << ": RMSE " << e.rmse << " m over " << probes.size()
                                     << " probes, unobserved " << e.unobserved);
    CHECK(e.unobserved == 0);
    CHECK(e.rmse < map.config().global_voxel);
  }
}

TEST_CASE("VDB-GPDF: at 0.2 m from a box and a sphere the gradient points away from the "
          "nearest surface within 10 degrees",
          "[vdb_gpdf]") {
  for (const Scene* scene : {&box_scene(), &sphere_scene()}) {
    VdbGpdf map;
    build(map, *scene);
    const bool is_box = scene == &box_scene();
    const FieldError e = field_error(map, *scene, is_box ? box_probes(0.2) : sphere_probes(0.2));
    INFO((is_box ? "box" : "sphere") << ": worst angle " << e.worst_angle << " degrees");
    CHECK(e.unobserved == 0);
    CHECK(e.worst_angle < 10.0);
  }
}

TEST_CASE("VDB-GPDF: every mesh vertex lies within one global voxel of the true surface",
          "[vdb_gpdf]") {
  for (const Scene* scene : {&box_scene(), &sphere_scene()}) {
    VdbGpdf map;
    build(map, *scene);
    std::vector<Eigen::Vector3f> vertices;
    std::vector<Eigen::Vector3i> triangles;
    map.surface_mesh(vertices, triangles);
    REQUIRE(triangles.size() > 100);
    double worst = 0.0;
    Eigen::Vector3f worst_vertex = Eigen::Vector3f::Zero();
    for (const auto& v : vertices) {
      const double d = scene->distance(v.cast<double>());
      if (d > worst) {
        worst = d;
        worst_vertex = v;
      }
    }
    INFO((scene == &box_scene() ? "box" : "sphere")
         << ": worst vertex " << worst_vertex.transpose() << " is " << worst << " m off");
    CHECK(worst < map.config().global_voxel);
  }
}

TEST_CASE("VDB-GPDF: surface samples are dense (no gap over half a voxel on a box face)",
          "[vdb_gpdf]") {
  VdbGpdf map;
  build(map, box_scene());
  std::vector<Eigen::Vector3f> samples;
  map.surface_points(Eigen::Vector3d::Zero(), 5.0, samples);
  // Along a horizontal line across the +x face at mid height, every 1 cm step has a sample
  // within half a voxel (2.5 cm).
  const double half_voxel = 0.5 * map.config().global_voxel;
  for (double y = -0.25; y <= 0.2501; y += 0.01) {
    const Eigen::Vector3d target(0.3, y, 0.25);
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& p : samples) nearest = std::min(nearest, (p.cast<double>() - target).norm());
    INFO("y = " << y);
    CHECK(nearest <= half_voxel);
  }
}

TEST_CASE("VDB-GPDF: two runs and 1 vs 2 threads give identical surfaces and queries",
          "[vdb_gpdf][determinism]") {
  auto run = [](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    VdbGpdf map;
    build(map, sphere_scene(), 6);
    std::vector<Eigen::Vector3f> samples;
    map.surface_points(Eigen::Vector3d::Zero(), 5.0, samples);
    std::vector<Eigen::Vector3f> probes;
    for (const auto& p : sphere_probes(0.1)) probes.push_back(p.point.cast<float>());
    std::vector<DistanceQuery> q;
    map.query(probes, q);
    std::vector<float> out;
    for (const auto& p : samples) out.insert(out.end(), {p.x(), p.y(), p.z()});
    for (const auto& d : q) out.insert(out.end(), {d.distance, d.gradient.x(), d.variance});
    return out;
  };
  const auto a = run(1), b = run(1), c = run(2);
  REQUIRE(a.size() > 1000);
  CHECK(a == b);
  CHECK(a == c);
}

TEST_CASE("VDB-GPDF: bad input is rejected or skipped, never fused", "[vdb_gpdf][bad_input]") {
  const auto poses = test::orbit(Eigen::Vector3d(0.0, 0.0, 0.25), 1.5, 1.0, 4);
  auto surface = [](const VdbGpdf& m) {
    std::vector<Eigen::Vector3f> s;
    m.surface_points(Eigen::Vector3d::Zero(), 5.0, s);
    return s;
  };
  VdbGpdf clean, dirty;
  for (int i = 0; i < 4; ++i) {
    const Frame f = test::render(box_scene(), poses[i], i);
    clean.integrate(f);
    Frame g = f;  // the same frame with non-finite points mixed in: they are skipped
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    g.points_camera.insert(g.points_camera.begin(), Eigen::Vector3f(nan, 0.f, 1.f));
    g.points_camera.push_back(Eigen::Vector3f(0.f, inf, 1.f));
    g.points_camera.push_back(Eigen::Vector3f(0.f, 0.f, -inf));
    dirty.integrate(g);
  }
  CHECK(surface(clean) == surface(dirty));

  const auto before = surface(dirty);
  Frame empty;  // an empty frame changes nothing
  dirty.integrate(empty);
  CHECK(surface(dirty) == before);

  Frame nan_pose = test::render(box_scene(), poses[0], 9);
  nan_pose.world_T_camera.translation().x() = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(dirty.integrate(nan_pose), std::invalid_argument);
  Frame skewed = test::render(box_scene(), poses[0], 10);
  skewed.world_T_camera.linear() *= 1.1;  // not orthonormal
  CHECK_THROWS_AS(dirty.integrate(skewed), std::invalid_argument);
  // The depth image is read beside the points (which voxel centres the camera saw free): one
  // that is not width x height pixels is a broken frame, not a point cloud without an image.
  Frame short_image = test::render(box_scene(), poses[1], 11);
  short_image.depth.pop_back();
  CHECK_THROWS_WITH(dirty.integrate(short_image), Catch::Contains("frame 11") && Catch::Contains("width x height"));
  Frame no_width = test::render(box_scene(), poses[1], 12);
  no_width.width = 0;
  CHECK_THROWS_AS(dirty.integrate(no_width), std::invalid_argument);
  CHECK(surface(dirty) == before);

  VdbGpdfConfig bad;
  bad.global_voxel = 0.0;
  CHECK_THROWS_AS(VdbGpdf(bad), std::invalid_argument);
  bad = VdbGpdfConfig{};
  bad.local_voxel = -0.02;
  CHECK_THROWS_AS(VdbGpdf(bad), std::invalid_argument);
  bad = VdbGpdfConfig{};
  bad.lambda = 0.0;
  CHECK_THROWS_AS(VdbGpdf(bad), std::invalid_argument);
  bad = VdbGpdfConfig{};
  bad.lambda = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(VdbGpdf(bad), std::invalid_argument);
  bad = VdbGpdfConfig{};
  bad.recon_min_weight = 1e300;  // finite as a double, infinite as the grid's float
  CHECK_THROWS_AS(VdbGpdf(bad), std::invalid_argument);
  // Queries at non-finite points read "unobserved", not a guess.
  std::vector<DistanceQuery> q;
  dirty.query({Eigen::Vector3f(std::nanf(""), 0.f, 0.f)}, q);
  CHECK_FALSE(q[0].observed);
  // And far from everything the map knows: unobserved.
  dirty.query({Eigen::Vector3f(50.f, 50.f, 50.f)}, q);
  CHECK_FALSE(q[0].observed);
}
