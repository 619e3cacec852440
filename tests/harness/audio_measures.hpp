// SPDX-License-Identifier: GPL-3.0-or-later
// Audio measures written out from their standards for the tests, independent of the code under
// test (libebur128, FFTW): ITU-R BS.1770-4 integrated loudness at 48 kHz (the published
// K-weighting coefficients, 400 ms blocks with 75% overlap, -70 LUFS absolute and -10 LU
// relative gates) and a true peak by 4x windowed-sinc interpolation.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace sonomap::test {

// BS.1770-4 Table 1 and 2: the two K-weighting biquads at 48 kHz.
inline std::vector<double> k_weighted(const std::vector<float>& x) {
  struct Biquad {
    double b0, b1, b2, a1, a2;
  };
  const Biquad stages[2] = {
      {1.53512485958697, -2.69169618940638, 1.19839281085285, -1.69065929318241, 0.73248077421585},
      {1.0, -2.0, 1.0, -1.99004745483398, 0.99007225036621}};
  std::vector<double> y(x.begin(), x.end());
  for (const Biquad& s : stages) {
    double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
    for (double& v : y) {
      const double out = s.b0 * v + s.b1 * x1 + s.b2 * x2 - s.a1 * y1 - s.a2 * y2;
      x2 = x1, x1 = v, y2 = y1, y1 = out, v = out;
    }
  }
  return y;
}

// Integrated loudness (LUFS) of a 48 kHz stereo signal; -inf if no block passes the gates.
inline double integrated_loudness(const std::vector<float>& left, const std::vector<float>& right) {
  const std::vector<double> l = k_weighted(left), r = k_weighted(right);
  const size_t block = 19200, step = 4800;  // 400 ms, 75% overlap
  std::vector<double> powers;                // mean square summed over channels, per block
  for (size_t start = 0; start + block <= l.size(); start += step) {
    double z = 0.0;
    for (size_t i = start; i < start + block; ++i) z += l[i] * l[i] + r[i] * r[i];
    powers.push_back(z / block);
  }
  auto loudness = [](double power) { return -0.691 + 10.0 * std::log10(power); };
  auto gated_mean = [&](double threshold) {
    double sum = 0.0;
    int n = 0;
    for (double p : powers)
      if (loudness(p) > threshold) sum += p, ++n;
    return n ? sum / n : 0.0;
  };
  const double absolute = gated_mean(-70.0);
  if (absolute <= 0.0) return -INFINITY;
  return loudness(gated_mean(loudness(absolute) - 10.0));
}

// Largest magnitude of x and of its values interpolated at 1/4, 2/4, 3/4 of every sample
// step (Hann-windowed sinc, 32 taps each side), as dB re full scale.
inline double true_peak_db(const std::vector<float>& x) {
  constexpr double kPi = 3.14159265358979323846;
  constexpr int kHalf = 32;
  double peak = 0.0;
  for (float v : x) peak = std::max(peak, double(std::abs(v)));
  for (int phase = 1; phase < 4; ++phase) {
    const double frac = phase / 4.0;
    double kernel[2 * kHalf];
    for (int k = 0; k < 2 * kHalf; ++k) {
      const double t = (k - kHalf + 1) - frac;  // sample offset from the interpolated point
      const double w = 0.5 + 0.5 * std::cos(kPi * t / (kHalf + 1));
      kernel[k] = std::sin(kPi * t) / (kPi * t) * w;
    }
    for (size_t n = 0; n + 1 < x.size(); ++n) {
      double acc = 0.0;
      for (int k = 0; k < 2 * kHalf; ++k) {
        const long i = static_cast<long>(n) + k - kHalf + 1;
        if (i >= 0 && i < static_cast<long>(x.size())) acc += kernel[k] * x[i];
      }
      peak = std::max(peak, std::abs(acc));
    }
  }
  return 20.0 * std::log10(peak);
}

}  // namespace sonomap::test
