// SPDX-License-Identifier: GPL-3.0-or-later
// The TSDF peer against closed-form geometry (frames from test_vdb_gpdf_scene.hpp): the
// projective path (frames with a depth image) and the ray-traced one (points only) alike.
#include "core/tsdf.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>

using namespace sonomap;

namespace {
const test::Scene& tsdf_box() {
  static const test::Scene s{{{Eigen::Vector3d(-0.3, -0.3, 0.0), Eigen::Vector3d(0.3, 0.3, 0.5)}}, {}};
  return s;
}
// The frames as a depth camera gives them, or as an unorganised cloud (points, no image).
enum class Input { kImage, kCloud };
void build(Tsdf& map, int frames = 16, Input input = Input::kImage) {
  const auto poses = test::orbit(Eigen::Vector3d(0.0, 0.0, 0.25), 1.5, 1.0, frames);
  for (size_t i = 0; i < poses.size(); ++i) {
    Frame f = test::render(tsdf_box(), poses[i], static_cast<int>(i));
    if (input == Input::kCloud) f.depth.clear();
    map.integrate(f);
  }
}
}  // namespace

TEST_CASE("TSDF: distances 2.5 and 5 cm above the box top (inside the band) are within one voxel",
          "[tsdf]") {
  const Input input = GENERATE(Input::kImage, Input::kCloud);
  INFO((input == Input::kImage ? "depth image (projective)" : "points only (ray traced)"));
  Tsdf map;
  build(map, 16, input);
  std::vector<Eigen::Vector3f> pts;
  for (double off : {0.025, 0.05})
    for (double a = -0.2; a <= 0.2001; a += 0.1)
      for (double b = -0.2; b <= 0.2001; b += 0.1) pts.emplace_back(a, b, 0.5 + off);
  std::vector<DistanceQuery> q;
  map.query(pts, q);
  double sum = 0.0;
  for (size_t i = 0; i < pts.size(); ++i) {
    REQUIRE(q[i].observed);
    const double err = q[i].distance - tsdf_box().distance(pts[i].cast<double>());
    sum += err * err;
    // Above the top face, away from the surface is up.
    CHECK(q[i].gradient.z() > std::cos(10.0 * M_PI / 180.0));
  }
  const double rmse = std::sqrt(sum / pts.size());
  INFO("RMSE " << rmse);
  CHECK(rmse < map.config().voxel);
}

TEST_CASE("TSDF: surface samples lie within one voxel of the top face", "[tsdf]") {
  const Input input = GENERATE(Input::kImage, Input::kCloud);
  INFO((input == Input::kImage ? "depth image (projective)" : "points only (ray traced)"));
  Tsdf map;
  build(map, 16, input);
  std::vector<Eigen::Vector3f> samples;
  map.surface_points(Eigen::Vector3d::Zero(), 5.0, samples);
  int on_top = 0;
  for (const auto& p : samples)
    if (std::abs(p.x()) < 0.2 && std::abs(p.y()) < 0.2 && p.z() > 0.3) {
      ++on_top;
      CHECK(std::abs(p.z() - 0.5) < map.config().voxel);
    }
  CHECK(on_top > 50);
}

TEST_CASE("TSDF: deterministic, and bad input rejected without touching the map", "[tsdf]") {
  Tsdf a, b;
  build(a, 4);
  build(b, 4);
  std::vector<Eigen::Vector3f> sa, sb;
  a.surface_points(Eigen::Vector3d::Zero(), 5.0, sa);
  b.surface_points(Eigen::Vector3d::Zero(), 5.0, sb);
  REQUIRE(!sa.empty());
  CHECK(sa == sb);

  Frame f = test::render(tsdf_box(), test::orbit(Eigen::Vector3d(0, 0, 0.25), 1.5, 1.0, 4)[1], 5);
  f.world_T_camera.translation().z() = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(a.integrate(f), std::invalid_argument);
  a.integrate(Frame{});  // empty: nothing to fuse
  // A depth image that is not width x height pixels.
  Frame cropped = test::render(tsdf_box(), test::orbit(Eigen::Vector3d(0, 0, 0.25), 1.5, 1.0, 4)[1], 6);
  cropped.depth.pop_back();
  CHECK_THROWS_AS(a.integrate(cropped), std::invalid_argument);
  std::vector<Eigen::Vector3f> after;
  a.surface_points(Eigen::Vector3d::Zero(), 5.0, after);
  CHECK(after == sa);

  TsdfConfig bad;
  bad.voxel = 0.0;
  CHECK_THROWS_AS(Tsdf(bad), std::invalid_argument);
  bad = TsdfConfig{};
  bad.truncation = -1.0;
  CHECK_THROWS_AS(Tsdf(bad), std::invalid_argument);
  bad = TsdfConfig{};
  bad.min_weight = 1e300;  // finite as a double, infinite as the grid's float
  CHECK_THROWS_AS(Tsdf(bad), std::invalid_argument);
}

TEST_CASE("TSDF: 1 and 2 threads give the same map, voxel for voxel", "[tsdf][determinism]") {
  auto run = [](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Tsdf map;
    build(map, 6);
    std::vector<float> out;
    for (auto v = map.grid().cbeginValueOn(); v; ++v) {
      const openvdb::Coord c = v.getCoord();
      out.insert(out.end(), {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()),
                              (*v)[0], (*v)[1]});
    }
    std::vector<Eigen::Vector3f> samples;
    map.surface_points(Eigen::Vector3d::Zero(), 5.0, samples);
    for (const auto& p : samples) out.insert(out.end(), {p.x(), p.y(), p.z()});
    return out;
  };
  const auto a = run(1), b = run(1), c = run(2);
  REQUIRE(a.size() > 10000);
  CHECK(a == b);
  CHECK(a == c);
}

TEST_CASE("TSDF: a wall 2 m ahead, seen once, holds the distance along the ray within the band",
          "[tsdf]") {
  // The plane x = 2 seen head-on from the origin: a voxel centre c in front of it (closer than
  // the truncation) holds |c| (1 - 2 / c.x), the distance along its ray to the wall, and
  // voxels deeper than the truncation behind the wall are never touched.
  const test::Scene wall{{{Eigen::Vector3d(2.0, -3.0, -3.0), Eigen::Vector3d(2.3, 3.0, 3.0)}}, {}};
  TsdfConfig config;
  config.space_carving = false;
  Tsdf map(config);
  map.integrate(test::render(wall, test::look_at(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()), 0, 320, 240));
  const double voxel = config.voxel;
  int checked = 0;
  for (auto v = map.grid().cbeginValueOn(); v; ++v) {
    const openvdb::Coord ijk = v.getCoord();
    const Eigen::Vector3d c = (Eigen::Vector3d(ijk.x(), ijk.y(), ijk.z()) + Eigen::Vector3d::Constant(0.5)) * voxel;
    INFO("voxel centre " << c.transpose());
    CHECK((*v)[1] == 1.0f);
    const double along_ray = c.norm() * (1.0 - 2.0 / c.x());
    CHECK(along_ray < config.truncation + 1e-6);
    CHECK(along_ray > -config.truncation - 1e-6);  // no carving: the band only
    // Every pixel of the wall measured z = 2 m, so whichever pixel the centre falls in, the
    // value is exact (to float rounding).
    CHECK((*v)[0] == Approx(along_ray).margin(1e-4));
    ++checked;
  }
  CHECK(checked > 1000);
}
