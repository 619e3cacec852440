// SPDX-License-Identifier: GPL-3.0-or-later
// Metrics on hand-made rasters (docs/conventions.md "Metrics"), values worked out by hand.
#include "eval/metrics.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>

using namespace sonomap;
using namespace sonomap::eval;

namespace {

void set(Circle& c, int bin, float range) { c.bins[static_cast<size_t>(bin)].range = range; }

}  // namespace

TEST_CASE("Coverage, RMSE and ghosts of a hand-made circle", "[metrics]") {
  Circle truth(360), estimate(360);
  // Truth: 4 occupied bins.
  set(truth, 0, 2.0f);
  set(truth, 1, 2.0f);
  set(truth, 2, 3.0f);
  set(truth, 3, 1.0f);
  // Estimate: bins 0..2 known in both (errors +0.1, 0, -0.5), bin 3 missed,
  // bin 100 known where the truth is empty.
  set(estimate, 0, 2.1f);
  set(estimate, 1, 2.0f);
  set(estimate, 2, 2.5f);
  set(estimate, 100, 1.5f);
  const RasterMetrics m = compare(estimate, truth);
  CHECK(m.cells == 360);
  CHECK(m.truth_occupied == 4);
  CHECK(m.estimate_known == 4);
  CHECK(m.known_in_both == 3);
  CHECK(m.coverage == Approx(0.75));
  // sqrt((0.01 + 0 + 0.25) / 3) = 0.294392
  CHECK(m.rmse == Approx(0.294392).epsilon(1e-5));
  // Bin 100 (empty truth) and bin 2 (0.5 m closer than the truth, tolerance 0.1 m).
  CHECK(m.ghosts == 2);
}

TEST_CASE("A ghost is more than the tolerance closer than the truth, never farther",
          "[metrics]") {
  Circle truth(360), estimate(360);
  set(truth, 10, 2.0f);
  set(truth, 11, 2.0f);
  set(truth, 12, 2.0f);
  set(estimate, 10, 1.95f);  // 5 cm closer: within 2 voxels
  set(estimate, 11, 1.75f);  // 25 cm closer: a ghost
  set(estimate, 12, 3.0f);   // 1 m farther: wrong, but not a ghost
  CHECK(compare(estimate, truth).ghosts == 1);
  MetricsConfig strict;
  strict.ghost_tolerance = 0.01;
  CHECK(compare(estimate, truth, strict).ghosts == 2);
  MetricsConfig loose;
  loose.ghost_tolerance = 0.3;
  CHECK(compare(estimate, truth, loose).ghosts == 0);
}

TEST_CASE("A perfect estimate has full coverage, zero RMSE and no ghosts", "[metrics]") {
  Circle truth(360);
  for (int k = 0; k < 360; k += 3) set(truth, k, 1.0f + 0.01f * k);
  const RasterMetrics m = compare(truth, truth);
  CHECK(m.coverage == 1.0);
  CHECK(m.rmse == 0.0);
  CHECK(m.ghosts == 0);
  CHECK(m.truth_occupied == 120);
}

TEST_CASE("Undefined metrics are NaN: empty truth, nothing known in both", "[metrics]") {
  Circle truth(360), estimate(360);
  RasterMetrics m = compare(estimate, truth);
  CHECK(std::isnan(m.coverage));
  CHECK(std::isnan(m.rmse));
  CHECK(m.ghosts == 0);
  set(truth, 5, 1.0f);
  m = compare(estimate, truth);
  CHECK(m.coverage == 0.0);
  CHECK(std::isnan(m.rmse));
}

TEST_CASE("The cylinder is compared cell by cell", "[metrics]") {
  Cylinder truth(360, 19), estimate(360, 19);
  truth.at(0, 0).range = 2.0f;
  truth.at(18, 0).range = 3.0f;
  estimate.at(0, 0).range = 2.0f;
  estimate.at(5, 0).range = 1.0f;  // nothing there in the truth: a ghost
  const RasterMetrics m = compare(estimate, truth);
  CHECK(m.cells == 360 * 19);
  CHECK(m.truth_occupied == 2);
  CHECK(m.coverage == Approx(0.5));
  CHECK(m.rmse == 0.0);
  CHECK(m.ghosts == 1);
}

TEST_CASE("Rasters of different shapes are not compared", "[metrics]") {
  CHECK_THROWS_AS(compare(Circle(360), Circle(720)), std::invalid_argument);
  CHECK_THROWS_AS(compare(Cylinder(360, 19), Cylinder(360, 18)), std::invalid_argument);
  MetricsConfig negative;
  negative.ghost_tolerance = -0.1;
  CHECK_THROWS_AS(compare(Circle(360), Circle(360), negative), std::invalid_argument);
}

TEST_CASE("a silhouette sliver counts in the RMSE but not in the RMSE off edges", "[metrics]") {
  // Truth: a wall at 2 m in every bin but bins 10..19, where a box stands at 1 m. Bins 9, 10, 19
  // and 20 sit on the box's silhouette (a 1 m jump to a neighbour). The estimate is right
  // everywhere except bin 10, which reads the wall (a sliver of the box the map missed), and
  // bin 15, 3 cm long.
  Circle truth(360), estimate(360);
  for (int k = 0; k < 360; ++k) {
    truth.bins[k].range = (k >= 10 && k < 20) ? 1.0f : 2.0f;
    estimate.bins[k].range = truth.bins[k].range;
  }
  estimate.bins[10].range = 2.0f;
  estimate.bins[15].range = 1.03f;
  const RasterMetrics m = compare(estimate, truth);
  CHECK(m.edge_cells == 4);
  CHECK(m.rmse == Approx(std::sqrt((1.0 + 0.03 * 0.03) / 360.0)).epsilon(1e-5));
  CHECK(m.rmse_off_edges == Approx(std::sqrt(0.03 * 0.03 / 356.0)).epsilon(1e-4));
}
