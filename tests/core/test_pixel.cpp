// SPDX-License-Identifier: GPL-3.0-or-later
// Which pixel a point falls in (core/pixel.hpp): its rounding is std::round's to the bit,
// including halves, signed zeros, the largest doubles below a half and values past any image.
#include "core/pixel.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

using namespace sonomap;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("pixel rounding is std::round's, bit for bit: halves away from zero", "[pixel]") {
  const double below_half = std::nextafter(0.5, 0.0);  // 0.49999999999999994: rounds to 0
  std::vector<double> values = {0.0,   -0.0,  0.5,   -0.5,   1.5,   -1.5,  2.5,   -2.5,  below_half, -below_half,
                                0.3,   -0.3,  639.5, 639.49, 479.5, -0.51, 1e15 + 0.5, 4503599627370497.0,
                                1e300, -1e300, std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::denorm_min()};
  for (int i = -2000; i <= 2000; ++i) {  // every quarter pixel from -500 to 500, and just beside
    values.push_back(i * 0.25);
    values.push_back(std::nextafter(i * 0.25, 1e9));
    values.push_back(std::nextafter(i * 0.25, -1e9));
  }
  for (const double x : values) {
    CAPTURE(x);
    CHECK(same_bits(round_half_away(x), std::round(x)));
  }
  CHECK(std::isnan(round_half_away(std::numeric_limits<double>::quiet_NaN())));
}

TEST_CASE("a point projects into the pixel whose centre is nearest, and not past the image's edge", "[pixel]") {
  const PinholeIntrinsics k{100.0, 100.0, 1.5, 1.5};  // a 4 x 4 image, pixel centres 0..3
  auto at = [&](double u, double v) { return pixel_of(k, 4, 4, Eigen::Vector3d((u - 1.5) / 100.0, (v - 1.5) / 100.0, 1.0)); };
  REQUIRE(at(0.0, 3.0));
  CHECK(at(0.0, 3.0)->u == 0);
  CHECK(at(0.0, 3.0)->v == 3);
  CHECK(at(2.49, 0.51)->u == 2);
  CHECK(at(2.49, 0.51)->v == 1);
  CHECK_FALSE(at(-0.51, 1.0));  // nearest a centre left of the image
  CHECK(at(-0.49, 1.0));        // still pixel 0
  CHECK_FALSE(at(3.51, 1.0));   // nearest pixel 4, outside
  CHECK_FALSE(pixel_of(k, 4, 4, Eigen::Vector3d(0.0, 0.0, -1.0)));  // behind the camera
}
