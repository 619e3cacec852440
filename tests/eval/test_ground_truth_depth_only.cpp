// SPDX-License-Identifier: GPL-3.0-or-later
// The depth-only baseline on a noise-free frame against the exact ground truth. The depth
// image is ray-cast here in closed form (a box room and a pillar), independent of sim/.
#include "core/depth_only.hpp"
#include "core/rasteriser.hpp"
#include "eval/ground_truth.hpp"
#include "eval/metrics.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

using namespace sonomap;
using namespace sonomap::eval;

namespace {

constexpr double kDeg = M_PI / 180.0;
using Box = Eigen::AlignedBox3d;

// Distance along `dir` from `from` (inside `room`) to the room's walls.
double exit_distance(const Box& room, const Eigen::Vector3d& from, const Eigen::Vector3d& dir) {
  double t = INFINITY;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] > 0) t = std::min(t, (room.max()[a] - from[a]) / dir[a]);
    if (dir[a] < 0) t = std::min(t, (room.min()[a] - from[a]) / dir[a]);
  }
  return t;
}

// Distance along `dir` from `from` (outside `box`) to the box, infinity if missed (slab method).
double entry_distance(const Box& box, const Eigen::Vector3d& from, const Eigen::Vector3d& dir) {
  double t_in = -INFINITY, t_out = INFINITY;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0.0) {
      if (from[a] < box.min()[a] || from[a] > box.max()[a]) return INFINITY;
      continue;
    }
    const double t0 = (box.min()[a] - from[a]) / dir[a];
    const double t1 = (box.max()[a] - from[a]) / dir[a];
    t_in = std::max(t_in, std::min(t0, t1));
    t_out = std::min(t_out, std::max(t0, t1));
  }
  return (t_in > 0.0 && t_in <= t_out) ? t_in : INFINITY;
}

void add_quad(std::vector<GroundTruthTriangle>& out, const Eigen::Vector3d& a,
              const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  out.push_back({a, b, c});
  out.push_back({a, c, d});
}

// The six faces of an axis-aligned box as triangles.
void add_box_faces(std::vector<GroundTruthTriangle>& out, const Box& box) {
  const Eigen::Vector3d lo = box.min(), hi = box.max();
  auto corner = [&](int x, int y, int z) {
    return Eigen::Vector3d(x ? hi.x() : lo.x(), y ? hi.y() : lo.y(), z ? hi.z() : lo.z());
  };
  add_quad(out, corner(0, 0, 0), corner(1, 0, 0), corner(1, 1, 0), corner(0, 1, 0));
  add_quad(out, corner(0, 0, 1), corner(1, 0, 1), corner(1, 1, 1), corner(0, 1, 1));
  add_quad(out, corner(0, 0, 0), corner(1, 0, 0), corner(1, 0, 1), corner(0, 0, 1));
  add_quad(out, corner(0, 1, 0), corner(1, 1, 0), corner(1, 1, 1), corner(0, 1, 1));
  add_quad(out, corner(0, 0, 0), corner(0, 1, 0), corner(0, 1, 1), corner(0, 0, 1));
  add_quad(out, corner(1, 0, 0), corner(1, 1, 0), corner(1, 1, 1), corner(1, 0, 1));
}

}  // namespace

TEST_CASE("Depth-only circle on a noise-free frame: every known bin is in [truth, truth + 1 cm]",
          "[ground_truth][depth_only]") {
  // Room x in [-2.5, 2], y in [-2, 3], 2.5 m high; a 2.5 m pillar x in [1.2, 1.4], y in [0.3, 0.6].
  const Box room(Eigen::Vector3d(-2.5, -2.0, 0.0), Eigen::Vector3d(2.0, 3.0, 2.5));
  const Box pillar(Eigen::Vector3d(1.2, 0.3, 0.0), Eigen::Vector3d(1.4, 0.6, 2.5));

  // Body at 1.5 m, heading 20 degrees; head-mounted Kinect-like camera (640 x 480, f = 525)
  // looking along body x: optical z = body x, optical x = -body y, optical y = -body z.
  Eigen::Isometry3d world_T_body = Eigen::Isometry3d::Identity();
  world_T_body.translation() = Eigen::Vector3d(0.3, 0.5, 1.5);
  world_T_body.linear() = Eigen::AngleAxisd(20.0 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d body_T_camera = Eigen::Isometry3d::Identity();
  body_T_camera.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Frame frame;
  frame.world_T_camera = world_T_body * body_T_camera;
  frame.world_T_body = world_T_body;
  const double f = 525.0, cx = 319.5, cy = 239.5;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const Eigen::Vector3d ray_camera((u - cx) / f, (v - cy) / f, 1.0);  // z-depth 1
      const Eigen::Vector3d ray = frame.world_T_camera.linear() * ray_camera;
      const Eigen::Vector3d from = frame.world_T_camera.translation();
      const double depth = std::min(exit_distance(room, from, ray), entry_distance(pillar, from, ray));
      if (depth <= 5.0) frame.points_camera.push_back((depth * ray_camera).cast<float>());
    }
  }

  DepthOnlyMapper baseline;
  baseline.integrate(frame);
  const RasterConfig config;
  const RasterOrigin origin = raster_origin(world_T_body);
  std::vector<Eigen::Vector3f> surface;
  baseline.surface_points(origin.position, config.max_range, surface);
  Rasteriser rasteriser(config);
  rasteriser.reset(origin);
  rasteriser.add(surface);

  std::vector<GroundTruthTriangle> triangles;
  add_box_faces(triangles, room);
  add_box_faces(triangles, pillar);
  const GroundTruthRasters truth = ground_truth_rasters(triangles, origin, config);

  // Samples lie on the true surfaces, inside the band and the wedge, so a bin's minimum over
  // them can never undercut the true wedge minimum (1e-5: float storage of the points).
  // Upward, the pixel columns are vertical planes (level camera) spaced at most 1/f rad =
  // 0.109 degrees in azimuth, so a sample lies within 1/f of the wedge edge where the minimum
  // is; on a surface at range r seen at incidence a, the range grows by at most
  // r tan(a) / f. Here the worst is the +x wall at the edge of the 62.7 degree field of view:
  // r = 1.7 / cos 51.4 = 2.72 m, tan 51.4 = 1.25: 6.5 mm. Hence a tolerance of 1 cm.
  const double tolerance = 0.01;
  int known = 0;
  for (int k = 0; k < 360; ++k) {
    const RasterCell& estimate = rasteriser.circle().bins[static_cast<size_t>(k)];
    if (!estimate.known()) continue;
    ++known;
    const RasterCell& exact = truth.circle.bins[static_cast<size_t>(k)];
    INFO("bin " << k);
    REQUIRE(exact.known());
    CHECK(estimate.range >= exact.range - 1e-5);
    CHECK(estimate.range <= exact.range + tolerance);
  }
  // The horizontal field of view is 2 atan(320 / 525) = 62.7 degrees: 63 or 64 bins.
  CHECK(known >= 62);
  CHECK(known <= 64);

  const RasterMetrics circle = compare(rasteriser.circle(), truth.circle);
  CHECK(circle.truth_occupied == 360);  // a closed room
  CHECK(circle.coverage < 0.2);         // the paper: depth-only covers under 20% of the circle
  CHECK(circle.ghosts == 0);
  CHECK(circle.rmse < tolerance);

  // Cylinder: never below the truth. The camera's vertical field (+-24.5 degrees) covers the
  // rows [1.2, 1.8] m at every visible range (>= 0.9 m), so those rows also meet the tolerance.
  for (int row = 0; row < rasteriser.cylinder().rows; ++row) {
    for (int k = 0; k < 360; ++k) {
      const RasterCell& estimate = rasteriser.cylinder().at(row, k);
      if (!estimate.known()) continue;
      const RasterCell& exact = truth.cylinder.at(row, k);
      INFO("row " << row << ", bin " << k);
      REQUIRE(exact.known());
      CHECK(estimate.range >= exact.range - 1e-5);
      if (row >= 11 && row <= 16) CHECK(estimate.range <= exact.range + tolerance);
    }
  }
  CHECK(compare(rasteriser.cylinder(), truth.cylinder).coverage < 0.2);
}
