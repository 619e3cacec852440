// SPDX-License-Identifier: GPL-3.0-or-later
// Statistics over seeds: the Student t quantile against published table values, the interval
// of a sample computed by hand, and the verdict's direction per metric.
#include "harness/report/stats.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace sonomap::harness;

TEST_CASE("the 95% Student t quantile matches the published table", "[stats]") {
  // Two-sided 95% (one-sided 0.975) quantiles, e.g. NIST/SEMATECH e-Handbook table 1.3.6.7.2.
  CHECK(student_t95(1) == Approx(12.706204736174707).epsilon(1e-9));
  CHECK(student_t95(2) == Approx(4.302652729911275).epsilon(1e-9));
  CHECK(student_t95(3) == Approx(3.182446305284263).epsilon(1e-9));
  CHECK(student_t95(10) == Approx(2.228138851986274).epsilon(1e-9));
  CHECK(student_t95(30) == Approx(2.042272456301238).epsilon(1e-9));
  CHECK(student_t95(1000) == Approx(1.962339080826).epsilon(1e-9));
  CHECK(std::isnan(student_t95(0)));
}

TEST_CASE("three seeds give the hand-computed mean, sd and t interval", "[stats]") {
  // 0.10, 0.12, 0.17: mean 0.13, deviations -0.03, -0.01, 0.04, squares sum 0.0026,
  // sd = sqrt(0.0026 / 2) = 0.036055513; half width 4.302652730 * sd / sqrt(3) = 0.089565...
  const SampleStats s = describe({0.10, 0.12, 0.17});
  CHECK(s.n == 3);
  CHECK(s.mean == Approx(0.13).epsilon(1e-12));
  CHECK(s.sd == Approx(std::sqrt(0.0013)).epsilon(1e-12));
  const double half = 4.302652729911275 * std::sqrt(0.0013) / std::sqrt(3.0);
  CHECK(s.ci_low == Approx(0.13 - half).epsilon(1e-9));
  CHECK(s.ci_high == Approx(0.13 + half).epsilon(1e-9));

  const SampleStats one = describe({0.5});
  CHECK(one.mean == 0.5);
  CHECK(std::isnan(one.sd));
  CHECK(std::isnan(one.ci_low));
  CHECK(describe({}).n == 0);
}

TEST_CASE("a paired verdict says better or worse only when the interval excludes zero", "[stats]") {
  const SampleStats up = describe({0.02, 0.03, 0.025});       // clearly above zero
  const SampleStats around = describe({-0.02, 0.03, 0.001});  // straddles zero
  CHECK(paired_verdict(up, "circle_mean_coverage") == "better");
  CHECK(paired_verdict(up, "circle_mean_rmse") == "worse");
  CHECK(paired_verdict(up, "cylinder_final_ghosts") == "worse");
  CHECK(paired_verdict(around, "circle_mean_rmse") == "no difference at 3 seeds");
  CHECK(paired_verdict(describe({0.1}), "circle_mean_rmse") == "too few seeds (1)");
  CHECK(better_direction("median_integrate_ms") == Better::lower);
  CHECK(better_direction("edf_slip_mean_p90_deg") == Better::lower);
}
