// SPDX-License-Identifier: GPL-3.0-or-later
// Hand-placed points give hand-computed bins (docs/conventions.md "Azimuth", "Bins", "The circle
// and the cylinder").
#include "../vector_isas.hpp"
#include "core/rasteriser.hpp"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

using namespace sonomap;

namespace {

constexpr double kDeg = M_PI / 180.0;

// A point at `azimuth_deg` (world, counter-clockwise from +x), horizontal range r, height z.
Eigen::Vector3f polar(double azimuth_deg, double r, double z) {
  return Eigen::Vector3f(static_cast<float>(r * std::cos(azimuth_deg * kDeg)),
                         static_cast<float>(r * std::sin(azimuth_deg * kDeg)),
                         static_cast<float>(z));
}

Rasteriser at_origin(const RasterConfig& config = {}) {
  Rasteriser r(config);
  r.reset(RasterOrigin{});
  return r;
}

// Indices of the known bins.
std::vector<int> known_bins(const Circle& circle) {
  std::vector<int> bins;
  for (int k = 0; k < circle.size(); ++k) {
    if (circle.bins[static_cast<size_t>(k)].known()) bins.push_back(k);
  }
  return bins;
}

}  // namespace

TEST_CASE("A point 2 m straight ahead at 1.05 m height reads 2 m in bin 0, row 9", "[rasteriser]") {
  Rasteriser r = at_origin();
  r.add(Eigen::Vector3f(2.0f, 0.0f, 1.05f));
  CHECK(known_bins(r.circle()) == std::vector<int>{0});
  CHECK(r.circle().bins[0].range == Approx(2.0));
  CHECK(r.circle().bins[0].point.isApprox(Eigen::Vector3f(2.0f, 0.0f, 1.05f)));
  CHECK(r.cylinder().known_count() == 1);
  CHECK(r.cylinder().at(9, 0).range == Approx(2.0));  // (1.05 - 0.1) / 0.1 = 9.5
}

TEST_CASE("359.9 degrees falls in bin 359 and 0.1 degrees in bin 0", "[rasteriser]") {
  Rasteriser r = at_origin();
  r.add(polar(0.1, 3.0, 1.0));
  r.add(polar(-0.1, 2.0, 1.0));
  CHECK(known_bins(r.circle()) == std::vector<int>{0, 359});
  CHECK(r.circle().bins[0].range == Approx(3.0).epsilon(1e-6));
  CHECK(r.circle().bins[359].range == Approx(2.0).epsilon(1e-6));
}

TEST_CASE("Points exactly on bin edges belong to the bin above the edge", "[rasteriser]") {
  Rasteriser r = at_origin();
  r.add(Eigen::Vector3f(0.0f, 2.0f, 1.0f));    // 90 degrees: left
  r.add(Eigen::Vector3f(-2.0f, 0.0f, 1.0f));   // 180: behind
  r.add(Eigen::Vector3f(0.0f, -2.0f, 1.0f));   // 270: right
  r.add(Eigen::Vector3f(1.5f, 1.5f, 1.0f));    // 45 (atan2 rounding must not give 44.999...)
  r.add(Eigen::Vector3f(3.0f, 0.0f, 1.0f));    // 0
  CHECK(known_bins(r.circle()) == std::vector<int>{0, 45, 90, 180, 270});

  // Behind with y = -0: atan2 gives -180 degrees, which is 180, not 359 or 360.
  Rasteriser behind = at_origin();
  behind.add(Eigen::Vector3f(-2.0f, -0.0f, 1.0f));
  CHECK(known_bins(behind.circle()) == std::vector<int>{180});
  // A hair clockwise of straight ahead is the last bin.
  Rasteriser right_of_ahead = at_origin();
  right_of_ahead.add(Eigen::Vector3f(2.0f, -1e-4f, 1.0f));
  CHECK(known_bins(right_of_ahead.circle()) == std::vector<int>{359});
}

TEST_CASE("Only points in the obstacle band above the ground count", "[rasteriser]") {
  Rasteriser r = at_origin();
  r.add(polar(10.5, 1.0, 0.05));   // ground clutter below 0.1 m
  r.add(polar(20.5, 1.0, 2.05));   // above the band
  r.add(polar(30.5, 1.0, 0.1));    // bottom edge: in
  r.add(polar(40.5, 1.0, 2.0));    // top edge: in, last row
  CHECK(known_bins(r.circle()) == std::vector<int>{30, 40});
  CHECK(r.cylinder().at(0, 30).known());
  CHECK(r.cylinder().at(18, 40).known());
  CHECK(r.cylinder().known_count() == 2);

  // The band is measured from the origin's ground height.
  Rasteriser raised(RasterConfig{});
  RasterOrigin on_a_stage;
  on_a_stage.ground_z = 1.0;
  raised.reset(on_a_stage);
  raised.add(polar(10.5, 1.0, 1.05));  // 0.05 m above this ground: out
  raised.add(polar(20.5, 1.0, 1.55));  // 0.55 m: row 4
  CHECK(known_bins(raised.circle()) == std::vector<int>{20});
  CHECK(raised.cylinder().at(4, 20).known());
}

TEST_CASE("Points beyond the maximum range are ignored, at it are kept", "[rasteriser]") {
  Rasteriser r = at_origin();
  r.add(Eigen::Vector3f(5.01f, 0.0f, 1.0f));
  r.add(Eigen::Vector3f(0.0f, 5.0f, 1.0f));
  CHECK(known_bins(r.circle()) == std::vector<int>{90});
  CHECK(r.circle().bins[90].range == 5.0f);
}

TEST_CASE("A point on the sensor's vertical axis has no azimuth and is skipped", "[rasteriser]") {
  Rasteriser r(RasterConfig{});
  RasterOrigin origin;
  origin.position = Eigen::Vector3d(1.0, 2.0, 1.6);
  r.reset(origin);
  r.add(Eigen::Vector3f(1.0f, 2.0f, 1.0f));  // below the sensor, 1 m above the ground
  CHECK(r.circle().known_count() == 0);
  CHECK(r.cylinder().known_count() == 0);
}

TEST_CASE("Non-finite points are skipped", "[rasteriser]") {
  Rasteriser r = at_origin();
  r.add(Eigen::Vector3f(NAN, 1.0f, 1.0f));
  r.add(Eigen::Vector3f(2.0f, INFINITY, 1.0f));
  r.add(Eigen::Vector3f(2.0f, 0.0f, NAN));
  CHECK(r.circle().known_count() == 0);
}

TEST_CASE("The heading rotates the bins: ahead of the body is bin 0 whatever the yaw",
          "[rasteriser]") {
  Rasteriser r(RasterConfig{});
  RasterOrigin facing_world_y;
  facing_world_y.heading = M_PI / 2;  // body x along world +y
  r.reset(facing_world_y);
  r.add(Eigen::Vector3f(0.0f, 3.0f, 1.0f));   // world +y: ahead
  r.add(Eigen::Vector3f(-2.0f, 0.0f, 1.0f));  // world -x: to the body's left
  r.add(Eigen::Vector3f(1.0f, 0.0f, 1.0f));   // world +x: to the body's right
  CHECK(known_bins(r.circle()) == std::vector<int>{0, 90, 270});
  CHECK(r.circle().bins[0].range == Approx(3.0));

  Rasteriser thirty(RasterConfig{});
  RasterOrigin yawed;
  yawed.heading = 30.0 * kDeg;
  yawed.position = Eigen::Vector3d(1.0, -1.0, 1.5);
  thirty.reset(yawed);
  // World azimuth 45.5 from the origin -> 15.5 in the body frame.
  thirty.add(polar(45.5, 2.0, 1.0) + Eigen::Vector3f(1.0f, -1.0f, 0.0f));
  CHECK(known_bins(thirty.circle()) == std::vector<int>{15});
  CHECK(thirty.circle().bins[15].range == Approx(2.0).epsilon(1e-6));
}

TEST_CASE("Each cell keeps the closest point, the cylinder keeps it per row", "[rasteriser]") {
  Rasteriser r = at_origin();
  r.add(polar(10.5, 3.0, 0.55));  // row 4
  r.add(polar(10.5, 2.0, 1.55));  // row 14, closer
  r.add(polar(10.7, 2.5, 0.52));  // row 4, closer than 3 m
  r.add(polar(10.2, 4.0, 1.58));  // row 14, farther
  const RasterCell& bin = r.circle().bins[10];
  CHECK(bin.range == Approx(2.0).epsilon(1e-6));
  CHECK(bin.point.z() == Approx(1.55));
  CHECK(r.cylinder().at(4, 10).range == Approx(2.5).epsilon(1e-6));
  CHECK(r.cylinder().at(4, 10).point.z() == Approx(0.52));
  CHECK(r.cylinder().at(14, 10).range == Approx(2.0).epsilon(1e-6));
  CHECK(r.cylinder().known_count() == 2);
}

TEST_CASE("Of points at equal range in one cell the first added stays, also among many added at once",
          "[rasteriser]") {
  // 40 000 points on a 4 m ring at 1.05 m (row 9), then in bin 30 three pairs at 2.5 m:
  // equal horizontal range, heights 1.01 and 1.09 in one row, the pairs far apart in the list.
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 40000; ++i) points.push_back(polar(360.0 * (i + 0.5) / 40000.0, 4.0, 1.05));
  const Eigen::Vector3f first = polar(30.5, 2.5, 1.01), second = polar(30.5, 2.5, 1.09);
  points[100] = first;
  points[39000] = second;
  points[20000] = second;
  points[30000] = first;
  const Eigen::Vector3f nearer = polar(40.5, 2.0, 1.09), farther_first = polar(40.5, 2.2, 1.01);
  points[50] = farther_first;
  points[35000] = nearer;

  Rasteriser at_once = at_origin(), one_thread = at_origin(), one_by_one = at_origin();
  at_once.add(points);  // in parts, one per thread, when there are several
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one_thread.add(points);
  }
  for (const Eigen::Vector3f& p : points) one_by_one.add(p);
  for (const Rasteriser* r : {&at_once, &one_thread, &one_by_one}) {
    CHECK(r->circle().bins[30].range == Approx(2.5).epsilon(1e-6));
    CHECK(r->circle().bins[30].point == first);
    CHECK(r->cylinder().at(9, 30).point == first);
    CHECK(r->circle().bins[40].point == nearer);
    CHECK(r->cylinder().at(9, 40).point == nearer);
    CHECK(r->circle().bins[200].range == Approx(4.0).epsilon(1e-6));
    CHECK(r->cylinder().known_count() == 360);
  }
}

TEST_CASE("reset starts an empty raster around the new origin", "[rasteriser]") {
  Rasteriser r = at_origin();
  r.add(Eigen::Vector3f(2.0f, 0.0f, 1.0f));
  RasterOrigin moved;
  moved.position = Eigen::Vector3d(2.0, 1.0, 1.6);
  r.reset(moved);
  CHECK(r.circle().known_count() == 0);
  CHECK(r.cylinder().known_count() == 0);
  r.add(Eigen::Vector3f(2.0f, 0.0f, 1.0f));  // now 1 m to the right
  CHECK(known_bins(r.circle()) == std::vector<int>{270});
  CHECK(r.circle().bins[270].range == Approx(1.0));

  RasterOrigin broken;
  broken.heading = NAN;
  CHECK_THROWS_AS(r.reset(broken), std::invalid_argument);
  CHECK_THROWS_AS(Rasteriser(RasterConfig{360, 2.0, 0.1}), std::invalid_argument);
}

TEST_CASE("A half-degree circle splits each degree in two", "[rasteriser]") {
  RasterConfig fine;
  fine.azimuth_bins = 720;
  Rasteriser r = at_origin(fine);
  r.add(polar(10.25, 2.0, 1.0));
  r.add(polar(10.75, 2.0, 1.0));
  CHECK(known_bins(r.circle()) == std::vector<int>{20, 21});
}

TEST_CASE("Every direction lands in the bin floor(atan2 / bin width) gives, also a hair off an edge",
          "[rasteriser]") {
  // 20 000 directions: spread over the circle, and 1e-7 to 1e-3 degrees either side of every
  // 36th edge, where the rasteriser's fast arctangent must hand over to the exact one.
  std::vector<double> azimuths;
  for (int i = 0; i < 14000; ++i) azimuths.push_back(-180.0 + 360.0 * (i + 0.37) / 14000.0);
  for (int edge = -180; edge < 180; edge += 36)
    for (double off : {1e-7, 1e-6, 1e-5, 1e-4, 5e-4, 1e-3, 2e-3, 3e-3})
      for (double sign : {-1.0, 1.0}) azimuths.push_back(edge + sign * off);
  for (int bins : {360, 720, 7}) {
    RasterConfig config;
    config.azimuth_bins = bins;
    Rasteriser r = at_origin(config);
    // One point alone, and 8 copies at once (the batch pass's vector lanes, not its tail).
    for (double azimuth : azimuths) for (size_t copies : {1, 8}) {
      r.reset(RasterOrigin{});
      const Eigen::Vector3f p = polar(azimuth, 3.0, 1.0);
      r.add(std::vector<Eigen::Vector3f>(copies, p));
      const double deg = std::atan2(static_cast<double>(p.y()), static_cast<double>(p.x())) / kDeg;
      const double position = (deg < 0.0 ? deg + 360.0 : deg) / (360.0 / bins);
      const int expected = static_cast<int>(std::floor(position)) % bins;
      if (std::abs(position - std::round(position)) < 1e-8) continue;  // the edge rule has its own test
      INFO("azimuth " << azimuth << ", " << bins << " bins, " << copies << " copies");
      REQUIRE(known_bins(r.circle()) == std::vector<int>{expected});
    }
  }
}

TEST_CASE("Every height lands in the row floor((height - band_min) / row height) gives, also a "
          "float's step off a row edge", "[rasteriser]") {
  // Heights spread over the band, and every row edge with the floats just under, on and over
  // it, where the rasteriser's quotient by a product must hand over to the divided one.
  for (double row_height : {0.1, 0.07, 0.25}) {
    RasterConfig config;
    config.row_height = row_height;
    std::vector<float> heights;
    for (int i = 0; i < 4000; ++i) heights.push_back(static_cast<float>(0.1 + 1.9 * (i + 0.29) / 4000.0));
    for (int edge = 0; edge <= config.rows(); ++edge) {
      const float z = static_cast<float>(config.row_bottom(edge));
      heights.insert(heights.end(), {std::nextafter(z, 0.0f), z, std::nextafter(z, 3.0f)});
    }
    Rasteriser r(config);
    for (float z : heights) for (size_t copies : {1, 8}) {
      r.reset(RasterOrigin{});
      r.add(std::vector<Eigen::Vector3f>(copies, Eigen::Vector3f(2.0f, 0.5f, z)));
      const double height = static_cast<double>(z);
      if (height < config.band_min || height > config.band_max) continue;  // another test's rule
      int expected = static_cast<int>(std::floor((height - config.band_min) / row_height));
      if (expected == config.rows() && height <= config.row_top(config.rows() - 1) + 1e-9) --expected;
      INFO("height " << z << ", row height " << row_height << ", " << copies << " copies");
      int row = -1;
      for (int k = 0; k < config.rows(); ++k)
        if (r.cylinder().at(k, 14).known()) row = k;
      CHECK(row == (expected < config.rows() ? expected : -1));
      CHECK(r.circle().bins[14].known());
    }
  }
}

TEST_CASE("The baseline, AVX2 and AVX-512 copies of the batch pass fill every cell to the same bit",
          "[rasteriser]") {
  // 50 000 points around a listener at (1.3, -0.7) facing 37 degrees: every azimuth, ranges
  // from the axis to beyond the maximum, heights from under the band to over it, and points
  // not finite among them (so the parts run in parallel, and every branch of the pass runs).
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 50000; ++i) {
    const double golden = 0.6180339887498949 * i;
    const double range = 7.0 * (golden - std::floor(golden)), height = -0.3 + 2.4 * std::fmod(0.7548776662 * i, 1.0);
    points.push_back(Eigen::Vector3f(1.3f, -0.7f, 0.1f) + polar(360.0 * std::fmod(0.5698402910 * i, 1.0), range, height));
    if (i % 997 == 0) points.back()[i % 3] = nan;
  }
  RasterOrigin origin;
  origin.position = Eigen::Vector3d(1.3, -0.7, 1.7);
  origin.heading = 37.0 * kDeg;
  origin.ground_z = 0.1;
  const auto rasterised = [&](VectorIsa isa) {
    const ScopedVectorIsa code(isa);
    Rasteriser r{RasterConfig{}};
    r.reset(origin);
    r.add(points);
    return std::make_pair(r.circle(), r.cylinder());
  };
  const auto baseline = rasterised(VectorIsa::Baseline);
  CHECK(baseline.first.known_count() == 360);
  CHECK(baseline.second.known_count() > 360 * 10);
  for (VectorIsa isa : vector_isas_beside_baseline()) {
    INFO(name_of(isa));
    const auto copy = rasterised(isa);
    CHECK(same_bits(copy.first.bins, baseline.first.bins));
    CHECK(same_bits(copy.second.cells, baseline.second.cells));
  }
}
