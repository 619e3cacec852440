// SPDX-License-Identifier: GPL-3.0-or-later
// The open3d mapper (Open3D's ScalableTSDFVolume) against closed-form geometry: a wall seen
// head-on (frames from the independent ray caster in test_vdb_gpdf_scene.hpp).
#include "core/open3d_tsdf.hpp"
#include "core/rasteriser.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace sonomap;

namespace {

// A wall whose face is the plane x = 2, 6 m wide and 3 m high, standing on z = 0.
const test::Scene& wall() {
  static const test::Scene s{{{Eigen::Vector3d(2.0, -3.0, 0.0), Eigen::Vector3d(2.3, 3.0, 3.0)}}, {}};
  return s;
}

const Eigen::Vector3d kEye(0.0, 0.0, 1.5);

// The camera at the eye looking along +x, turned by `yaw` about z.
Eigen::Isometry3d looking(double yaw) {
  return test::look_at(kEye, kEye + Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0));
}

void build(Open3dTsdf& map) {
  int index = 0;
  for (double yaw : {-0.3, 0.0, 0.3}) map.integrate(test::render(wall(), looking(yaw), index++));
}

}  // namespace

TEST_CASE("open3d mapper: a wall 2 m ahead reads 2 m in the circle", "[open3d]") {
  Open3dTsdf map;
  build(map);
  Rasteriser rasteriser;
  std::vector<Eigen::Vector3f> surface;
  map.surface_points(kEye, rasteriser.config().max_range, surface);
  rasteriser.reset(RasterOrigin{kEye, 0.0, 0.0});  // heading +x, ground at z = 0
  rasteriser.add(surface);
  const Circle& circle = rasteriser.circle();
  // Bins within 30 degrees of ahead (azimuth counter-clockwise from ahead): the wall plane is at
  // 2 / cos(azimuth) m along the bin's centre direction.
  int checked = 0;
  for (int k = 0; k < circle.size(); ++k) {
    const double azimuth = circle.bin_centre_deg(k) * M_PI / 180.0;
    if (std::cos(azimuth) < std::cos(30.0 * M_PI / 180.0)) continue;
    INFO("bin " << k);
    REQUIRE(circle.bins[k].known());
    CHECK(circle.bins[k].range == Approx(2.0 / std::cos(azimuth)).margin(0.5 * map.config().voxel));
    ++checked;
  }
  CHECK(checked == 60);
  // Nothing behind the listener: the wall is the only surface.
  CHECK_FALSE(circle.bins[180].known());
}

TEST_CASE("open3d mapper: distances in front of the wall and bad frames", "[open3d]") {
  Open3dTsdf map;
  build(map);
  std::vector<Eigen::Vector3f> points;
  for (double d : {0.04, 0.08, 0.12}) points.emplace_back(static_cast<float>(2.0 - d), 0.1f, 1.4f);
  std::vector<DistanceQuery> q;
  map.query(points, q);
  for (size_t i = 0; i < points.size(); ++i) {
    REQUIRE(q[i].observed);
    CHECK(q[i].distance == Approx(wall().distance(points[i].cast<double>())).margin(0.5 * map.config().voxel));
    CHECK(q[i].gradient.x() < -0.9f);  // away from the wall: back towards the listener
  }
  std::vector<DistanceQuery> far;
  map.query({Eigen::Vector3f(-3.0f, 0.0f, 1.5f)}, far);
  CHECK_FALSE(far[0].observed);

  Frame no_intrinsics = test::render(wall(), looking(0.0), 9);
  no_intrinsics.intrinsics = PinholeIntrinsics{};
  CHECK_THROWS_AS(map.integrate(no_intrinsics), std::invalid_argument);
  Frame short_image = test::render(wall(), looking(0.0), 10);
  short_image.depth.pop_back();
  CHECK_THROWS_AS(map.integrate(short_image), std::invalid_argument);
  Open3dTsdfConfig bad;
  bad.voxel = 0.0;
  CHECK_THROWS_AS(Open3dTsdf(bad), std::invalid_argument);
}
