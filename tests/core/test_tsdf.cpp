// SPDX-License-Identifier: GPL-3.0-or-later
// The TSDF peer against closed-form geometry (frames from test_vdb_gpdf_scene.hpp).
#include "core/tsdf.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace sonomap;

namespace {
const test::Scene& tsdf_box() {
  static const test::Scene s{{{Eigen::Vector3d(-0.3, -0.3, 0.0), Eigen::Vector3d(0.3, 0.3, 0.5)}}, {}};
  return s;
}
void build(Tsdf& map, int frames = 16) {
  const auto poses = test::orbit(Eigen::Vector3d(0.0, 0.0, 0.25), 1.5, 1.0, frames);
  for (size_t i = 0; i < poses.size(); ++i)
    map.integrate(test::render(tsdf_box(), poses[i], static_cast<int>(i)));
}
}  // namespace

TEST_CASE("TSDF: distances 2.5 and 5 cm above the box top (inside the band) are within one voxel",
          "[tsdf]") {
  Tsdf map;
  build(map);
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
  Tsdf map;
  build(map);
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
  std::vector<Eigen::Vector3f> after;
  a.surface_points(Eigen::Vector3d::Zero(), 5.0, after);
  CHECK(after == sa);

  TsdfConfig bad;
  bad.voxel = 0.0;
  CHECK_THROWS_AS(Tsdf(bad), std::invalid_argument);
  bad = TsdfConfig{};
  bad.truncation = -1.0;
  CHECK_THROWS_AS(Tsdf(bad), std::invalid_argument);
}
