// SPDX-License-Identifier: GPL-3.0-or-later
// Raster shapes and sonification sectors (docs/conventions.md "Sectors").
#include "core/raster.hpp"

#include <catch2/catch.hpp>
#include <stdexcept>

using namespace sonomap;

namespace {

void set_bin(Circle& circle, int bin, float range) {
  circle.bins[static_cast<size_t>(bin)].range = range;
  circle.bins[static_cast<size_t>(bin)].point = Eigen::Vector3f(range, 0.0f, 1.0f);
}

}  // namespace

TEST_CASE("Default raster shape is 360 one-degree bins by 19 rows of 0.1 m", "[raster]") {
  const RasterConfig config;
  CHECK(config.rows() == 19);
  const Circle circle = make_circle(config);
  const Cylinder cylinder = make_cylinder(config);
  CHECK(circle.size() == 360);
  CHECK(circle.bin_width_deg() == Approx(1.0));
  CHECK(circle.bin_centre_deg(0) == Approx(0.5));
  CHECK(circle.bin_centre_deg(359) == Approx(359.5));
  CHECK(cylinder.azimuth_bins == 360);
  CHECK(cylinder.rows == 19);
  CHECK(cylinder.cells.size() == 360u * 19u);
  CHECK(circle.known_count() == 0);
  CHECK(cylinder.known_count() == 0);
  CHECK(config.row_bottom(0) == Approx(0.1));
  CHECK(config.row_top(18) == Approx(2.0));
}

TEST_CASE("An invalid raster config is rejected naming the field", "[raster]") {
  RasterConfig inverted_band;
  inverted_band.band_min = 2.0;
  inverted_band.band_max = 0.1;
  CHECK_THROWS_WITH(inverted_band.validate(), Catch::Contains("band_min"));
  RasterConfig equal_band;
  equal_band.band_max = equal_band.band_min;
  CHECK_THROWS_AS(equal_band.validate(), std::invalid_argument);
  RasterConfig no_bins;
  no_bins.azimuth_bins = 0;
  CHECK_THROWS_WITH(no_bins.validate(), Catch::Contains("azimuth_bins"));
  RasterConfig flat_rows;
  flat_rows.row_height = 0.0;
  CHECK_THROWS_WITH(flat_rows.validate(), Catch::Contains("row_height"));
  // A micrometre row: 1.9 million rows of 360 cells would take 11 GB.
  RasterConfig thin_rows;
  thin_rows.row_height = 1e-6;
  CHECK_THROWS_WITH(thin_rows.validate(), Catch::Contains("row_height"));
  RasterConfig fine_enough;  // 1 cm rows of tenth-degree bins: 684,000 cells
  fine_enough.row_height = 0.01;
  fine_enough.azimuth_bins = 3600;
  CHECK_NOTHROW(fine_enough.validate());
  RasterConfig nan_range;
  nan_range.max_range = NAN;
  CHECK_THROWS_WITH(nan_range.validate(), Catch::Contains("max_range"));
  CHECK_NOTHROW(RasterConfig{}.validate());
}

TEST_CASE("A sector reports its closest bin, its range and its centre angle", "[raster][sectors]") {
  Circle circle(360);
  set_bin(circle, 3, 2.5f);   // sector 0
  set_bin(circle, 7, 1.5f);   // sector 0, closer
  set_bin(circle, 95, 3.0f);  // sector 9
  set_bin(circle, 359, 0.8f); // sector 35, last bin
  const std::vector<Sector> sectors = circle_sectors(circle);
  REQUIRE(sectors.size() == 36);
  CHECK(sectors[0].known());
  CHECK(sectors[0].bin == 7);
  CHECK(sectors[0].range == 1.5f);
  CHECK(sectors[0].angle_deg == Approx(7.5));
  CHECK(sectors[0].point.x() == 1.5f);
  CHECK(sectors[9].bin == 95);
  CHECK(sectors[9].angle_deg == Approx(95.5));
  CHECK(sectors[35].bin == 359);
  CHECK(sectors[35].angle_deg == Approx(359.5));
  int known = 0;
  for (const Sector& s : sectors) known += s.known() ? 1 : 0;
  CHECK(known == 3);
  CHECK_FALSE(sectors[1].known());
  CHECK(sectors[1].bin == -1);
}

TEST_CASE("Bin 10 belongs to sector 1, not sector 0", "[raster][sectors]") {
  Circle circle(360);
  set_bin(circle, 10, 1.0f);
  const std::vector<Sector> sectors = circle_sectors(circle);
  CHECK_FALSE(sectors[0].known());
  CHECK(sectors[1].bin == 10);
}

TEST_CASE("Equal ranges in a sector pick the first bin counter-clockwise", "[raster][sectors]") {
  Circle circle(360);
  set_bin(circle, 24, 2.0f);
  set_bin(circle, 21, 2.0f);
  CHECK(circle_sectors(circle)[2].bin == 21);
}

TEST_CASE("Sectors on a 720-bin circle group 20 half-degree bins", "[raster][sectors]") {
  Circle circle(720);
  set_bin(circle, 39, 1.0f);  // [19.5, 20) degrees: still sector 1
  set_bin(circle, 40, 0.5f);  // [20, 20.5): sector 2
  const std::vector<Sector> sectors = circle_sectors(circle);
  CHECK(sectors[1].bin == 39);
  CHECK(sectors[1].angle_deg == Approx(19.75));
  CHECK(sectors[2].angle_deg == Approx(20.25));
  CHECK_THROWS_AS(circle_sectors(circle, 7), std::invalid_argument);
  CHECK_THROWS_AS(circle_sectors(circle, 0), std::invalid_argument);
}
