// SPDX-License-Identifier: GPL-3.0-or-later
// Statistics over seeds for the report: each (scenario, variant) as a sample of independent
// seeds (mean, standard deviation, 95% Student t interval), and each pair of variants as paired
// differences over the same (scenario, seed), with a verdict that says which is better only
// when the interval excludes zero.
#pragma once

#include <string>
#include <vector>

namespace sonomap::harness {

// The two-sided 95% quantile of Student's t with `df` >= 1 degrees of freedom: t such that
// P(|T| <= t) = 0.95 (12.706 for df = 1, 4.303 for df = 2, 1.960 as df grows).
double student_t95(int df);

struct SampleStats {
  int n = 0;
  double mean = 0.0;  // NaN when n = 0
  double sd = 0.0;    // sample standard deviation (n - 1); NaN when n < 2
  double ci_low = 0.0, ci_high = 0.0;  // mean -/+ t95(n - 1) sd / sqrt(n); NaN when n < 2
};

SampleStats describe(const std::vector<double>& sample);

// Which way a rollup.csv metric is better: coverage up; RMSE, ghosts, slip and times down.
enum class Better { higher, lower, unknown };
Better better_direction(const std::string& metric);

// The verdict on the differences (candidate - baseline) of `metric`: "better" or "worse" when
// the 95% interval excludes zero (the metric's direction decides which), "no difference at N
// seeds" when it does not, "too few seeds" with fewer than 2 (`unit` names what was paired).
std::string paired_verdict(const SampleStats& differences, const std::string& metric,
                           const std::string& unit = "seeds");

}  // namespace sonomap::harness
