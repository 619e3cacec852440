// SPDX-License-Identifier: GPL-3.0-or-later
// evaluate_frame: the one per-frame evaluation `run` uses and any program's rasters can be
// scored with. Truth is closed-form geometry: a wall 2 m ahead.
#include "eval/evaluate_frame.hpp"

#include <catch2/catch.hpp>
#include <cmath>

using namespace sonomap;

namespace {

// A 4 m wide, 3 m high wall across x = 2 (y in [-2, 2], z in [0, 3]).
std::vector<eval::GroundTruthTriangle> wall_ahead() {
  const Eigen::Vector3d a(2, -2, 0), b(2, 2, 0), c(2, 2, 3), d(2, -2, 3);
  return {{a, b, c}, {a, c, d}};
}

// The circle a perfect map of that wall gives from (0, 0): per bin whose wedge meets the wall
// (|azimuth| < 45 deg), its closest point, 2 / cos of the wedge's azimuth nearest to ahead.
Circle perfect_circle(const RasterConfig& config) {
  Circle circle = make_circle(config);
  for (int k = 0; k < config.azimuth_bins; ++k) {
    const double lo = k * config.bin_width_deg(), hi = lo + config.bin_width_deg();
    double closest = NAN;
    if (lo < 45.0) closest = 2.0 / std::cos(lo * M_PI / 180.0);
    if (hi > 315.0) closest = 2.0 / std::cos((360.0 - hi) * M_PI / 180.0);
    if (std::isfinite(closest)) circle.bins[k].range = static_cast<float>(closest);
  }
  return circle;
}

}  // namespace

TEST_CASE("evaluate_frame scores an estimate against the exact truth seen from the true pose",
          "[evaluate_frame]") {
  eval::EvaluationConfig config;
  config.raster.azimuth_bins = 36;
  const auto triangles = wall_ahead();
  const RasterOrigin origin{Eigen::Vector3d(0, 0, 1.0), 0.0, 0.0};
  const Circle circle = perfect_circle(config.raster);
  const Cylinder cylinder = make_cylinder(config.raster);  // nothing known

  const auto e = eval::evaluate_frame(circle, cylinder, eval::FrameTruth{&triangles, origin},
                                      nullptr, origin, config);
  REQUIRE(e.has_truth);
  // Bins of 10 degrees: 0..50 and 310..360 reach the wall (its corners are at +-45 degrees).
  CHECK(e.truth.circle.bins[0].range == Approx(2.0));
  CHECK(e.circle.truth_occupied == 10);
  CHECK(e.circle.estimate_known == 10);
  CHECK(e.circle.coverage == Approx(1.0));
  CHECK(e.circle.rmse == Approx(0.0).margin(1e-5));
  CHECK(e.circle.ghosts == 0);
  // An empty cylinder covers none of the wall's cells and invents nothing.
  CHECK(e.cylinder.truth_occupied > 0);
  CHECK(e.cylinder.coverage == 0.0);
  CHECK(e.cylinder.estimate_known == 0);
  CHECK_FALSE(e.edf.has_value());  // no mapper, no EDF comparison
  CHECK(e.times.size() == 1);      // "truth"
}

TEST_CASE("evaluate_frame judges from the true pose, not the estimate's", "[evaluate_frame]") {
  eval::EvaluationConfig config;
  config.raster.azimuth_bins = 36;
  const auto triangles = wall_ahead();
  const RasterOrigin estimate{Eigen::Vector3d(0, 0, 1.0), 0.0, 0.0};
  const RasterOrigin truth{Eigen::Vector3d(1.0, 0, 1.0), 0.0, 0.0};  // 1 m closer in truth
  const auto e = eval::evaluate_frame(perfect_circle(config.raster), make_cylinder(config.raster),
                                      eval::FrameTruth{&triangles, truth}, nullptr, estimate, config);
  CHECK(e.truth.circle.bins[0].range == Approx(1.0));
  CHECK(e.circle.ghosts == 0);               // the estimate is farther, not closer
  CHECK(e.circle.rmse > 0.5);
}

TEST_CASE("without truth evaluate_frame counts the known cells and leaves the metrics undefined",
          "[evaluate_frame]") {
  eval::EvaluationConfig config;
  config.raster.azimuth_bins = 36;
  const RasterOrigin origin{Eigen::Vector3d(0, 0, 1.0), 0.0, 0.0};
  const auto e = eval::evaluate_frame(perfect_circle(config.raster), make_cylinder(config.raster),
                                      std::nullopt, nullptr, origin, config);
  CHECK_FALSE(e.has_truth);
  CHECK(std::isnan(e.circle.coverage));
  CHECK(std::isnan(e.circle.rmse));
  CHECK(e.circle.estimate_known == 10);
  CHECK(e.truth.circle.known_count() == 0);
  CHECK(e.times.empty());
}
