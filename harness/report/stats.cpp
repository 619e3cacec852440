// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/report/stats.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

namespace sonomap::harness {

namespace {

// P(|T| <= t) for Student's t with an integer number of degrees of freedom, by the finite
// series in theta = atan(t / sqrt(df)) (Abramowitz & Stegun 26.7.3 and 26.7.4).
double central_t_probability(double t, int df) {
  const double theta = std::atan(t / std::sqrt(static_cast<double>(df)));
  const double c2 = std::cos(theta) * std::cos(theta), s = std::sin(theta);
  if (df % 2 == 1) {
    if (df == 1) return 2.0 * theta / M_PI;
    double term = std::cos(theta), sum = term;  // cos, then (2/3) cos^3, (2*4)/(3*5) cos^5, ...
    for (int k = 3; k <= df - 2; k += 2) {
      term *= c2 * (k - 1) / k;
      sum += term;
    }
    return 2.0 / M_PI * (theta + s * sum);
  }
  double term = 1.0, sum = 1.0;  // 1, cos^2 / 2, (1*3)/(2*4) cos^4, ...
  for (int k = 2; k <= df - 2; k += 2) {
    term *= c2 * (k - 1) / k;
    sum += term;
  }
  return s * sum;
}

}  // namespace

double student_t95(int df) {
  if (df < 1) return std::numeric_limits<double>::quiet_NaN();
  double lo = 0.0, hi = 20.0;  // t95 is 12.71 at df = 1 and falls with df
  for (int i = 0; i < 200 && hi - lo > 1e-13; ++i) {
    const double mid = 0.5 * (lo + hi);
    (central_t_probability(mid, df) < 0.95 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

SampleStats describe(const std::vector<double>& sample) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  SampleStats s;
  s.n = static_cast<int>(sample.size());
  s.mean = s.sd = s.ci_low = s.ci_high = nan;
  if (s.n == 0) return s;
  double sum = 0.0;
  for (double v : sample) sum += v;
  s.mean = sum / s.n;
  if (s.n < 2) return s;
  double squares = 0.0;
  for (double v : sample) squares += (v - s.mean) * (v - s.mean);
  s.sd = std::sqrt(squares / (s.n - 1));
  const double half = student_t95(s.n - 1) * s.sd / std::sqrt(static_cast<double>(s.n));
  s.ci_low = s.mean - half;
  s.ci_high = s.mean + half;
  return s;
}

Better better_direction(const std::string& metric) {
  const auto has = [&](const char* part) { return metric.find(part) != std::string::npos; };
  if (has("coverage")) return Better::higher;
  if (has("rmse") || has("ghosts") || has("slip") || has("_ms")) return Better::lower;
  return Better::unknown;
}

std::string paired_verdict(const SampleStats& d, const std::string& metric, const std::string& unit) {
  if (d.n < 2 || !std::isfinite(d.ci_low)) return fmt::format("too few {} ({})", unit, d.n);
  const bool up = d.ci_low > 0.0, down = d.ci_high < 0.0;
  if (!up && !down) return fmt::format("no difference at {} {}", d.n, unit);
  switch (better_direction(metric)) {
    case Better::higher: return up ? "better" : "worse";
    case Better::lower: return down ? "better" : "worse";
    case Better::unknown: break;
  }
  return up ? "higher" : "lower";
}

}  // namespace sonomap::harness
