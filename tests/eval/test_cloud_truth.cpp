// SPDX-License-Identifier: GPL-3.0-or-later
// Truth from a reference cloud against the exact truth of the same scene: the scene's triangles
// are sampled here (midpoint subdivision, independent of the code under test) and the cloud truth
// must lie between the exact minimum over each cell and the exact minimum over the cell shrunk
// by the covering radius plus that radius (the bound stated in eval/cloud_truth.hpp).
#include "eval/cloud_truth.hpp"
#include "eval/ground_truth.hpp"
#include "sim/world_geometry.hpp"

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

using namespace sonomap;
using namespace sonomap::eval;

namespace {

// A 4 x 4 x 2.5 m room with a turned box, a column and a ball.
sim::Scenario furnished_room() {
  sim::Scenario scenario;
  auto add = [&](sim::PrimitiveSpec::Kind kind, Eigen::Vector3d size, double radius,
                 Eigen::Vector3d at, double yaw_deg) {
    sim::StaticObject object;
    object.shape.kind = kind;
    object.shape.size = size;
    object.shape.radius = radius;
    object.pose.translate(at);
    object.pose.rotate(Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
    scenario.statics.push_back(object);
  };
  add(sim::PrimitiveSpec::Kind::Room, {4.0, 4.0, 2.5}, 0.0, {0.0, 0.0, 0.0}, 0.0);
  add(sim::PrimitiveSpec::Kind::Box, {0.6, 0.6, 0.8}, 0.0, {1.2, -0.8, 0.0}, 30.0);
  add(sim::PrimitiveSpec::Kind::Cylinder, {1.0, 1.0, 2.5}, 0.2, {1.0, 1.0, 0.0}, 0.0);
  add(sim::PrimitiveSpec::Kind::Sphere, {1.0, 1.0, 1.0}, 0.3, {-1.0, 0.6, 0.3}, 0.0);
  return scenario;
}

// Each triangle halved along its edges (into four) until its longest edge is at most `spacing`;
// the corners of the pieces are the samples. A point of a piece is within its longest edge of
// a corner, so the covering radius is at most `spacing`.
void subdivide(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double spacing,
               std::vector<Eigen::Vector3f>& out) {
  if (std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}) <= spacing) {
    for (const Eigen::Vector3d* p : {&a, &b, &c}) out.push_back(p->cast<float>());
    return;
  }
  const Eigen::Vector3d ab = (a + b) / 2.0, bc = (b + c) / 2.0, ca = (c + a) / 2.0;
  subdivide(a, ab, ca, spacing, out);
  subdivide(ab, b, bc, spacing, out);
  subdivide(ca, bc, c, spacing, out);
  subdivide(ab, bc, ca, spacing, out);
}

std::vector<Eigen::Vector3f> sample_surface(const std::vector<sim::WorldTriangle>& triangles, double spacing) {
  std::vector<Eigen::Vector3f> points;
  for (const sim::WorldTriangle& t : triangles) subdivide(t[0], t[1], t[2], spacing, points);
  return points;
}

// The exact minimum horizontal distance over the triangles inside the cell shrunk by `margin`:
// z in [lo + margin, hi - margin], at least `margin` inside both edge lines of the wedge
// [a0, a1] (radians, origin at 0, heading 0). The shrunk wedge does not contain the axis, so the
// minimum over each clipped convex piece lies on its boundary.
double shrunk_cell_minimum(const std::vector<sim::WorldTriangle>& triangles, double lo, double hi,
                           double a0, double a1, double margin) {
  using Piece = std::vector<Eigen::Vector3d>;
  // Keeps the part of the piece where f(p) >= 0 (f affine).
  auto cut = [](const Piece& in, auto f) {
    Piece out;
    for (std::size_t i = 0; i < in.size(); ++i) {
      const Eigen::Vector3d& a = in[i];
      const Eigen::Vector3d& b = in[(i + 1) % in.size()];
      if (f(a) >= 0.0) out.push_back(a);
      if ((f(a) >= 0.0) != (f(b) >= 0.0)) out.push_back(a + (b - a) * (f(a) / (f(a) - f(b))));
    }
    return out;
  };
  const Eigen::Vector2d d0(std::cos(a0), std::sin(a0)), d1(std::cos(a1), std::sin(a1));
  double best = INFINITY;
  for (const sim::WorldTriangle& t : triangles) {
    Piece piece{t[0], t[1], t[2]};
    piece = cut(piece, [&](const Eigen::Vector3d& p) { return p.z() - (lo + margin); });
    piece = cut(piece, [&](const Eigen::Vector3d& p) { return (hi - margin) - p.z(); });
    piece = cut(piece, [&](const Eigen::Vector3d& p) { return d0.x() * p.y() - d0.y() * p.x() - margin; });
    piece = cut(piece, [&](const Eigen::Vector3d& p) { return p.x() * d1.y() - p.y() * d1.x() - margin; });
    for (std::size_t i = 0; i < piece.size(); ++i) {
      const Eigen::Vector2d a = piece[i].head<2>(), b = piece[(i + 1) % piece.size()].head<2>();
      const double length2 = (b - a).squaredNorm();
      const double s = length2 > 0.0 ? std::clamp(-a.dot(b - a) / length2, 0.0, 1.0) : 0.0;
      best = std::min(best, (a + s * (b - a)).norm());
    }
  }
  return best;
}

}  // namespace

TEST_CASE("Cloud truth lies within the covering radius of the exact truth, bin by bin",
          "[cloud_truth]") {
  const std::vector<sim::WorldTriangle> triangles = sim::world_triangles(furnished_room(), 0.0);
  RasterConfig config;
  config.azimuth_bins = 72;  // 5-degree wedges: wide enough for whole cells to survive shrinking
  const RasterOrigin origin{};  // at (0, 0, 0), heading +x, floor at z = 0
  const GroundTruthRasters exact = ground_truth_rasters(triangles, origin, config);
  // This file's sampler and the one `render --format rosbag` uses (which promises the same
  // covering radius), at two spacings.
  // Only what reaches the band is sampled (floor and ceiling are outside it): faster, same truth.
  std::vector<sim::WorldTriangle> in_band;
  for (const sim::WorldTriangle& t : triangles)
    if (std::max({t[0].z(), t[1].z(), t[2].z()}) >= config.band_min &&
        std::min({t[0].z(), t[1].z(), t[2].z()}) <= config.band_max)
      in_band.push_back(t);
  for (const bool ours : {true, false}) for (double spacing : {0.05, 0.03}) {
    INFO((ours ? "test sampler" : "eval::surface_samples") << ", spacing " << spacing << " m");
    const std::vector<Eigen::Vector3f> samples =
        ours ? sample_surface(in_band, spacing) : surface_samples(in_band, spacing);
    const GroundTruthRasters cloud = cloud_truth_rasters(samples, origin, config);
    int within = 0;
    double worst = 0.0;
    for (int k = 0; k < config.azimuth_bins; ++k) {
      INFO("bin " << k);
      const double w = 2.0 * M_PI / config.azimuth_bins;
      const double r_exact = exact.circle.bins[k].range, r_cloud = cloud.circle.bins[k].range;
      const double r_shrunk = shrunk_cell_minimum(triangles, config.band_min, config.band_max, k * w,
                                                  (k + 1) * w, spacing);
      // Samples lie on the surface, inside the cell: never nearer than the exact minimum
      // (float rounding of the samples aside).
      CHECK(r_cloud >= r_exact - 1e-5);
      // A sample within `spacing` of the shrunk cell's nearest point lies inside the cell.
      REQUIRE(std::isfinite(r_shrunk));
      CHECK(r_cloud <= r_shrunk + spacing + 1e-5);
      worst = std::max(worst, r_cloud - r_exact);
      within += r_cloud - r_exact <= spacing ? 1 : 0;
    }
    // The bound is loose only where the nearest surface meets a wedge edge at a slant.
    UNSCOPED_INFO("worst cloud - exact: " << worst << " m; bins within spacing: " << within);
    CHECK(within >= config.azimuth_bins * 9 / 10);
  }
}

TEST_CASE("Cloud truth puts points in closed rows and half-open wedges", "[cloud_truth]") {
  RasterConfig config;  // 360 bins
  config.band_min = 0.0;
  config.band_max = 2.0;
  config.row_height = 0.25;  // row edges exact in binary
  RasterOrigin origin;
  origin.position = Eigen::Vector3d(1.0, 2.0, 1.5);
  origin.heading = M_PI / 2.0;  // looking along +y
  origin.ground_z = 0.5;
  // 2 m ahead (bin 0), 1 m above the ground (the edge of rows 3 and 4); 3 m to the left,
  // 0.57 degrees past 90 (bin 90); one below the band and one beyond max_range.
  const std::vector<Eigen::Vector3f> points{{1.0f, 4.0f, 1.5f}, {-2.0f, 1.97f, 1.0f},
                                            {1.0f, 3.0f, 0.4f}, {1.0f, 8.0f, 1.0f}};
  const GroundTruthRasters truth = cloud_truth_rasters(points, origin, config);
  CHECK(truth.circle.bins[0].range == Approx(2.0));
  CHECK(truth.circle.bins[90].range == Approx(std::hypot(3.0, 0.03)));
  CHECK(truth.circle.known_count() == 2);
  CHECK(truth.cylinder.at(3, 0).range == Approx(2.0));
  CHECK(truth.cylinder.at(4, 0).range == Approx(2.0));
  CHECK_FALSE(truth.cylinder.at(2, 0).known());
  CHECK_FALSE(truth.cylinder.at(5, 0).known());
  CHECK_THROWS_AS(cloud_truth_rasters({{NAN, 0.0f, 0.0f}}, origin, config), std::invalid_argument);
}
