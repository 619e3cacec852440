// SPDX-License-Identifier: GPL-3.0-or-later
// The random streams against closed forms: the normal sampler's distribution function (erfc),
// moments of both samplers, and streams that depend only on their key.
#include "sim/random.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace sonomap::sim;

namespace {

// Standard normal distribution function, independent of the sampler: Phi(x) = erfc(-x / sqrt 2) / 2.
double phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

}  // namespace

namespace {

// Mean, variance, fourth moment and the distribution function at 16 points from -4 to 4.2
// (body, wedges, tail beyond 3.44) of n samples, each within 5 standard errors.
void check_standard_normal(const std::vector<double>& x) {
  const double n = static_cast<double>(x.size());
  double sum = 0.0, sum2 = 0.0, sum4 = 0.0;
  for (double v : x) sum += v, sum2 += v * v, sum4 += v * v * v * v;
  const double mean = sum / n, var = sum2 / n - mean * mean;
  CHECK(std::abs(mean) < 5.0 / std::sqrt(n));
  CHECK(var == Approx(1.0).margin(5.0 * std::sqrt(2.0 / n)));        // var of s^2: 2 / n
  CHECK(sum4 / n == Approx(3.0).margin(5.0 * std::sqrt(96.0 / n)));  // E x^4 = 3, var 96 / n
  for (double t : {-4.0, -3.5, -3.0, -2.0, -1.3, -0.7, -0.2, 0.0, 0.1, 0.5, 1.0, 1.7, 2.5, 3.2, 3.6, 4.2}) {
    long below = 0;
    for (double v : x) below += v < t;
    const double p = phi(t), se = std::sqrt(p * (1.0 - p) / n);
    INFO("t = " << t);
    CHECK(static_cast<double>(below) / n == Approx(p).margin(5.0 * se + 1e-7));
  }
}

}  // namespace

TEST_CASE("normal samples follow Phi at every layer, the wedges and the tail", "[sim][random]") {
  RandomStream rng({2024, 0, 7, 99});
  std::vector<double> x(2'000'000);
  for (double& v : x) v = rng.normal();
  check_standard_normal(x);
}

TEST_CASE("32-bit normals (the pixels' sampler) follow Phi too, and depend on their word and index only",
          "[sim][random]") {
  const RandomStream rng({2024, 0, 7, 98});
  std::vector<double> x(2'000'000);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::uint64_t word = rng.bits_at(i / 2);
    x[i] = rng.normal32(static_cast<std::uint32_t>(i % 2 ? word >> 32 : word), i);
  }
  check_standard_normal(x);
  // The counter: bits_at(n) is the n-th bits(), and a sample is the same in any call order.
  RandomStream walk({2024, 0, 7, 98});
  for (std::uint64_t k = 0; k < 5; ++k) CHECK(walk.bits() == rng.bits_at(k));
  CHECK(rng.normal32(12345u, 3) == rng.normal32(12345u, 3));
}

TEST_CASE("uniform samples have mean 1/2 and variance 1/12; streams depend only on their key",
          "[sim][random]") {
  RandomStream rng({1, 2, 3});
  const int n = 1'000'000;
  double sum = 0.0, sum2 = 0.0, lo = 1.0, hi = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform();
    sum += u, sum2 += u * u;
    lo = std::min(lo, u), hi = std::max(hi, u);
  }
  const double mean = sum / n;
  CHECK(mean == Approx(0.5).margin(5.0 * std::sqrt(1.0 / 12.0 / n)));
  CHECK(sum2 / n - mean * mean == Approx(1.0 / 12.0).margin(5.0 * std::sqrt(1.0 / 180.0 / n)));
  CHECK(lo >= 0.0);
  CHECK(hi < 1.0);

  RandomStream a({5, 0, 9, 1}), b({5, 0, 9, 1}), c({5, 0, 9, 2});
  bool same = true, differ = false;
  for (int i = 0; i < 1000; ++i) {
    const double x = a.normal(), y = b.normal(), z = c.normal();
    same = same && x == y;
    differ = differ || x != z;
  }
  CHECK(same);
  CHECK(differ);
}
