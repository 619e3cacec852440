// SPDX-License-Identifier: GPL-3.0-or-later
// Ground-truth rasters against closed forms. Triangles are built here by hand so these tests
// do not depend on the simulator's meshes.
#include "eval/ground_truth.hpp"

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

using namespace sonomap;
using namespace sonomap::eval;

namespace {

constexpr double kDeg = M_PI / 180.0;
using Triangles = std::vector<GroundTruthTriangle>;

// Axis-aligned rectangle as two triangles: a vertical wall from (x0, y0) to (x1, y1), z in [z0, z1].
void add_wall(Triangles& out, double x0, double y0, double x1, double y1, double z0, double z1) {
  const Eigen::Vector3d a(x0, y0, z0), b(x1, y1, z0), c(x1, y1, z1), d(x0, y0, z1);
  out.push_back({a, b, c});
  out.push_back({a, c, d});
}

// Horizontal rectangle [x0, x1] x [y0, y1] at height z.
void add_floor(Triangles& out, double x0, double y0, double x1, double y1, double z) {
  const Eigen::Vector3d a(x0, y0, z), b(x1, y0, z), c(x1, y1, z), d(x0, y1, z);
  out.push_back({a, b, c});
  out.push_back({a, c, d});
}

// Closed box [x0, x1] x [y0, y1] x [0, height].
void add_box(Triangles& out, double x0, double y0, double x1, double y1, double height) {
  add_wall(out, x0, y0, x1, y0, 0.0, height);
  add_wall(out, x1, y0, x1, y1, 0.0, height);
  add_wall(out, x1, y1, x0, y1, 0.0, height);
  add_wall(out, x0, y1, x0, y0, 0.0, height);
  add_floor(out, x0, y0, x1, y1, height);
}

// A wall seen from the origin: perpendicular distance D, the azimuth of its normal foot and
// the azimuth interval [lo, hi] it covers (degrees, body frame, lo <= foot <= hi, hi - lo < 180).
struct WallView {
  double distance, foot_deg, lo_deg, hi_deg;
};

// Closed form: the wall points at azimuth a are at D / cos(a - foot); over the part of the
// wedge [k, k + 1] the wall covers, the minimum is at the angle nearest the foot.
double wall_wedge_minimum(const WallView& wall, double a, double b) {
  double best = INFINITY;
  for (double shift : {-360.0, 0.0, 360.0}) {
    const double lo = std::max(a, wall.lo_deg + shift);
    const double hi = std::min(b, wall.hi_deg + shift);
    if (lo > hi) continue;
    const double foot = wall.foot_deg + shift;
    const double nearest = std::clamp(foot, lo, hi);
    best = std::min(best, wall.distance / std::cos((nearest - foot) * kDeg));
  }
  return best;
}

// The minimum over a disc of radius rho centred at distance L, bearing theta, within the
// wedge [a, b]: L - rho if the bearing is inside, else the near-side hit of the nearest edge
// ray (the hit distance grows with the angle off the bearing); infinity if the ray misses.
double disc_wedge_minimum(double L, double theta, double rho, double a, double b) {
  double phi = INFINITY;
  for (double shift : {-360.0, 0.0, 360.0}) {
    const double t = theta + shift;
    if (t >= a && t <= b) return L - rho;
    phi = std::min({phi, std::abs(t - a), std::abs(t - b)});
  }
  const double off = L * std::sin(phi * kDeg);
  if (phi >= 90.0 || off > rho) return INFINITY;
  return L * std::cos(phi * kDeg) - std::sqrt(rho * rho - off * off);
}

double azimuth_deg(double x, double y) { return std::atan2(y, x) / kDeg; }

}  // namespace

TEST_CASE("In a box room every bin reads D / cos(angle from the wall normal to the nearest "
          "wedge edge), or D when the normal is inside the wedge", "[ground_truth]") {
  // Room x in [-2.5, 2], y in [-2, 3], 2.5 m high, with floor and ceiling (outside the band).
  Triangles room;
  add_wall(room, 2.0, -2.0, 2.0, 3.0, 0.0, 2.5);
  add_wall(room, 2.0, 3.0, -2.5, 3.0, 0.0, 2.5);
  add_wall(room, -2.5, 3.0, -2.5, -2.0, 0.0, 2.5);
  add_wall(room, -2.5, -2.0, 2.0, -2.0, 0.0, 2.5);
  add_floor(room, -2.5, -2.0, 2.0, 3.0, 0.0);
  add_floor(room, -2.5, -2.0, 2.0, 3.0, 2.5);

  const double heading_deg = GENERATE(0.0, 25.0, -130.0);
  RasterOrigin origin;
  origin.position = Eigen::Vector3d(0.3, 0.5, 1.6);
  origin.heading = heading_deg * kDeg;
  RasterConfig config;
  config.max_range = 10.0;
  const GroundTruthRasters truth = ground_truth_rasters(room, origin, config);

  // Each wall from the origin: its distance, normal foot and corner azimuths, in the body frame.
  const double ox = origin.position.x(), oy = origin.position.y();
  auto view = [&](double distance, double foot_world, double x0, double y0, double x1,
                  double y1) {
    double foot = foot_world - heading_deg;
    double lo = azimuth_deg(x0 - ox, y0 - oy) - heading_deg;
    double hi = azimuth_deg(x1 - ox, y1 - oy) - heading_deg;
    while (lo > foot) lo -= 360.0;
    while (lo < foot - 180.0) lo += 360.0;
    while (hi < foot) hi += 360.0;
    while (hi > foot + 180.0) hi -= 360.0;
    while (foot < 0.0) { foot += 360.0; lo += 360.0; hi += 360.0; }
    return WallView{distance, foot, lo, hi};
  };
  const std::vector<WallView> walls = {
      view(2.0 - ox, 0.0, 2.0, -2.0, 2.0, 3.0),        // +x wall, counter-clockwise ends
      view(3.0 - oy, 90.0, 2.0, 3.0, -2.5, 3.0),       // +y wall
      view(ox + 2.5, 180.0, -2.5, 3.0, -2.5, -2.0),    // -x wall
      view(oy + 2.0, 270.0, -2.5, -2.0, 2.0, -2.0)};   // -y wall

  for (int k = 0; k < 360; ++k) {
    double expected = INFINITY;
    for (const WallView& wall : walls) expected = std::min(expected, wall_wedge_minimum(wall, k, k + 1));
    INFO("heading " << heading_deg << ", bin " << k);
    const RasterCell& cell = truth.circle.bins[static_cast<size_t>(k)];
    REQUIRE(cell.known());
    CHECK(cell.range == Approx(expected).margin(1e-5));
    // The closest point is on the walls, in the wedge, at the reported range.
    const Eigen::Vector2d offset(cell.point.x() - ox, cell.point.y() - oy);
    CHECK(offset.norm() == Approx(cell.range).margin(1e-5));
    // Its azimuth is within the closed wedge [k, k + 1]: at most half a degree from the centre.
    const double off_centre =
        std::remainder(azimuth_deg(offset.x(), offset.y()) - heading_deg - (k + 0.5), 360.0);
    CHECK(std::abs(off_centre) <= 0.5 + 1e-4);
    CHECK(cell.point.z() >= 0.1 - 1e-6);  // in the obstacle band (ground z = 0)
    CHECK(cell.point.z() <= 2.0 + 1e-6);
    // Full-height walls: every cylinder row reads the same minimum.
    for (int row = 0; row < truth.cylinder.rows; ++row) {
      CHECK(truth.cylinder.at(row, k).range == Approx(expected).margin(1e-5));
    }
  }
}

TEST_CASE("A wall 1 m away seen at a slant: the wedge minimum, not the centre ray",
          "[ground_truth]") {
  // Wall x = 1; bin 60 covers [60, 61] degrees: 1 / cos 60 = 2.0 m, while the centre ray at
  // 60.5 degrees reads 2.0304 m (3 cm more); bin 80: 1 / cos 80 = 5.759 m vs 6.031 m.
  Triangles wall;
  add_wall(wall, 1.0, -50.0, 1.0, 50.0, 0.0, 2.5);
  RasterConfig config;
  config.max_range = 50.0;
  const GroundTruthRasters truth = ground_truth_rasters(wall, RasterOrigin{}, config);
  CHECK(truth.circle.bins[60].range == Approx(2.0).epsilon(1e-6));
  CHECK(truth.circle.bins[80].range == Approx(1.0 / std::cos(80.0 * kDeg)).epsilon(1e-6));
  CHECK(truth.circle.bins[299].range == Approx(1.0 / std::cos(60.0 * kDeg)).epsilon(1e-6));
  CHECK_FALSE(truth.circle.bins[90].known());   // parallel to the wall: never reaches it
  CHECK_FALSE(truth.circle.bins[180].known());  // behind
}

TEST_CASE("A faceted vertical cylinder reads between the exact discs of radius r and "
          "r cos(pi/N)", "[ground_truth]") {
  // A 64-facet column of radius 0.3 m, 1.45 m tall, centred 2 m away at bearing 40.5 degrees.
  const int facets = 64;
  const double radius = 0.3, height = 1.45, L = 2.0, bearing = 40.5;
  const Eigen::Vector3d centre(L * std::cos(bearing * kDeg), L * std::sin(bearing * kDeg), 0.0);
  Triangles column;
  for (int i = 0; i < facets; ++i) {
    const double a0 = 2.0 * M_PI * i / facets, a1 = 2.0 * M_PI * (i + 1) / facets;
    const Eigen::Vector3d p0 = centre + radius * Eigen::Vector3d(std::cos(a0), std::sin(a0), 0.0);
    const Eigen::Vector3d p1 = centre + radius * Eigen::Vector3d(std::cos(a1), std::sin(a1), 0.0);
    const Eigen::Vector3d up(0.0, 0.0, height);
    column.push_back({p0, p1, p1 + up});
    column.push_back({p0, p1 + up, p0 + up});
    column.push_back({centre + up, p0 + up, p1 + up});  // cap
  }
  const GroundTruthRasters truth = ground_truth_rasters(column, RasterOrigin{}, RasterConfig{});

  const double inscribed = radius * std::cos(M_PI / facets);
  int known = 0;
  for (int k = 0; k < 360; ++k) {
    const double outer = disc_wedge_minimum(L, bearing, radius, k, k + 1);
    const double inner = disc_wedge_minimum(L, bearing, inscribed, k, k + 1);
    const RasterCell& cell = truth.circle.bins[static_cast<size_t>(k)];
    INFO("bin " << k);
    if (std::isinf(outer)) {
      CHECK_FALSE(cell.known());
      continue;
    }
    ++known;
    REQUIRE(cell.known());
    CHECK(cell.range >= outer - 1e-5);
    if (!std::isinf(inner)) CHECK(cell.range <= inner + 1e-5);
  }
  // Angular half-width asin(0.3 / 2) = 8.63 degrees: bins 31..49.
  CHECK(known == 19);
  CHECK(truth.circle.bins[40].range == Approx(L - radius).margin(radius * (1 - std::cos(M_PI / facets)) + 1e-6));
  // Rows up to 1.4-1.5 m see the column; rows from 1.5 m up see nothing.
  for (int row = 0; row < truth.cylinder.rows; ++row) {
    INFO("row " << row);
    CHECK(truth.cylinder.at(row, 40).known() == (row <= 13));
  }
}

TEST_CASE("A column in front of a wall: each bin is the nearest surface anywhere in its wedge",
          "[ground_truth]") {
  // Wall x = 3; a 0.2 m square column x in [1.4, 1.6], y in [-0.1, 0.1]. Its near face spans
  // azimuths +-atan(0.1 / 1.4) = +-4.085 degrees.
  Triangles scene;
  add_wall(scene, 3.0, -4.0, 3.0, 4.0, 0.0, 2.5);
  add_box(scene, 1.4, -0.1, 1.6, 0.1, 2.5);
  const GroundTruthRasters truth = ground_truth_rasters(scene, RasterOrigin{}, RasterConfig{});
  CHECK(truth.circle.bins[0].range == Approx(1.4).epsilon(1e-6));
  CHECK(truth.circle.bins[359].range == Approx(1.4).epsilon(1e-6));
  CHECK(truth.circle.bins[2].range == Approx(1.4 / std::cos(2.0 * kDeg)).epsilon(1e-6));
  // Bin 4 is only a tenth covered by the column: the wedge minimum is still the column
  // (a ray through the bin centre at 4.5 degrees would see the wall at 3.009 m).
  CHECK(truth.circle.bins[4].range == Approx(1.4 / std::cos(4.0 * kDeg)).epsilon(1e-6));
  CHECK(truth.circle.bins[355].range == Approx(1.4 / std::cos(4.0 * kDeg)).epsilon(1e-6));
  CHECK(truth.circle.bins[5].range == Approx(3.0 / std::cos(5.0 * kDeg)).epsilon(1e-6));
  CHECK(truth.circle.bins[354].range == Approx(3.0 / std::cos(5.0 * kDeg)).epsilon(1e-6));
  CHECK(truth.circle.bins[4].point.x() == Approx(1.4f));
}

TEST_CASE("A 1 m box before a wall: cylinder rows below 1 m see the box, rows above the wall",
          "[ground_truth]") {
  Triangles scene;
  add_wall(scene, 3.0, -4.0, 3.0, 4.0, 0.0, 2.5);
  add_box(scene, 1.0, -0.5, 1.5, 0.5, 1.0);
  const GroundTruthRasters truth = ground_truth_rasters(scene, RasterOrigin{}, RasterConfig{});
  CHECK(truth.circle.bins[0].range == Approx(1.0).epsilon(1e-6));
  for (int row = 0; row < truth.cylinder.rows; ++row) {
    INFO("row " << row << " [" << RasterConfig{}.row_bottom(row) << ", "
                << RasterConfig{}.row_top(row) << "]");
    // Row 9 is [1.0, 1.1]: closed, so it touches the box top at exactly 1.0 m.
    const double expected = row <= 9 ? 1.0 : 3.0;
    CHECK(truth.cylinder.at(row, 0).range == Approx(expected).epsilon(1e-6));
    // The box's corners are at most atan(0.5 / 1.0) = 26.6 degrees off ahead: bin 30 sees
    // only the wall, in every row.
    CHECK(truth.cylinder.at(row, 30).range == Approx(3.0 / std::cos(30.0 * kDeg)).epsilon(1e-6));
  }
  // The top face counts only at z = 1.0; row 10 [1.1, 1.2] has no box at all.
  CHECK(truth.cylinder.at(10, 0).point.x() == Approx(3.0f));
}

TEST_CASE("Geometry outside the band or beyond the maximum range is unknown", "[ground_truth]") {
  Triangles scene;
  add_floor(scene, -4.0, -4.0, 4.0, 4.0, 0.05);   // below the band
  add_floor(scene, -4.0, -4.0, 4.0, 4.0, 2.05);   // above it
  add_wall(scene, 6.0, -1.0, 6.0, 1.0, 0.0, 2.0); // 6 m: beyond max_range 5
  const GroundTruthRasters truth = ground_truth_rasters(scene, RasterOrigin{}, RasterConfig{});
  CHECK(truth.circle.known_count() == 0);
  CHECK(truth.cylinder.known_count() == 0);

  // The band follows the origin's ground height: on a 1 m stage the 2.05 m slab is 1.05 above.
  RasterOrigin stage;
  stage.ground_z = 1.0;
  const GroundTruthRasters raised = ground_truth_rasters(scene, stage, RasterConfig{});
  CHECK(raised.circle.known_count() == 360);
  CHECK(raised.circle.bins[123].range == Approx(0.0).margin(1e-9));  // over the origin
  CHECK(raised.cylinder.at(9, 0).known());   // [1.0, 1.1] above 1 m ground: z 2.0 .. 2.1
  CHECK_FALSE(raised.cylinder.at(0, 0).known());
}

TEST_CASE("A surface spanning over the sensor's axis reads 0 in every bin, however large",
          "[ground_truth]") {
  // One large triangle 1 m above the ground (within the band) with the sensor above it, and a
  // wall 2 m ahead: the nearest surface point in every wedge is on the slab, right at the axis.
  // (Its edges are at least 17 m away, beyond max_range: they must not cull it.)
  Triangles scene{{Eigen::Vector3d(-30, -30, 1), Eigen::Vector3d(30, -30, 1), Eigen::Vector3d(0, 40, 1)}};
  add_wall(scene, 2.0, -1.0, 2.0, 1.0, 0.0, 2.5);
  RasterOrigin origin;
  origin.position = Eigen::Vector3d(0.0, 0.0, 1.6);
  const GroundTruthRasters truth = ground_truth_rasters(scene, origin, RasterConfig{});
  for (int k = 0; k < 360; ++k) {
    INFO("bin " << k);
    REQUIRE(truth.circle.bins[static_cast<size_t>(k)].known());
    CHECK(truth.circle.bins[static_cast<size_t>(k)].range == Approx(0.0).margin(1e-9));
    CHECK(truth.circle.bins[static_cast<size_t>(k)].point.z() == Approx(1.0f));
  }
  // Row 9 is [1.0, 1.1] and holds the slab; row 10 sees only the wall.
  CHECK(truth.cylinder.at(9, 0).range == Approx(0.0).margin(1e-9));
  CHECK(truth.cylinder.at(10, 0).range == Approx(2.0).epsilon(1e-6));
  CHECK_FALSE(truth.cylinder.at(10, 180).known());
}

TEST_CASE("Bad ground-truth input is rejected with a clear message", "[ground_truth]") {
  Triangles broken{{Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(NAN, 0, 1), Eigen::Vector3d(1, 1, 1)}};
  CHECK_THROWS_WITH(ground_truth_rasters(broken, RasterOrigin{}, RasterConfig{}),
                    Catch::Contains("triangle 0"));
  RasterConfig inverted;
  inverted.band_min = 2.0;
  inverted.band_max = 1.0;
  CHECK_THROWS_AS(ground_truth_rasters({}, RasterOrigin{}, inverted), std::invalid_argument);
  RasterOrigin nan_origin;
  nan_origin.heading = NAN;
  CHECK_THROWS_AS(ground_truth_rasters({}, nan_origin, RasterConfig{}), std::invalid_argument);
}
