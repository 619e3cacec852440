// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/sounds.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace sonomap::audio {

namespace {
constexpr double kPi = 3.14159265358979323846;

void normalise_peak(std::vector<float>& s, double peak) {
  float max = 0.0f;
  for (float x : s) max = std::max(max, std::abs(x));
  if (max > 0.0f)
    for (auto& x : s) x = static_cast<float>(x / max * peak);
}

size_t samples_for(double sample_rate, double seconds, const char* what) {
  if (!(sample_rate >= 8000 && sample_rate <= 384000) || !(seconds > 0.0 && seconds <= 10.0))
    throw std::invalid_argument(std::string(what) + ": sample rate or duration out of range");
  return static_cast<size_t>(std::round(sample_rate * seconds));
}
}  // namespace

std::vector<float> make_tap(double fs, const TapConfig& c) {
  const size_t n = samples_for(fs, c.duration_s, "tap");
  if (!(c.fundamental_hz > 20.0 && c.fundamental_hz < fs / 6.0) || !(c.decay_s > 0.0))
    throw std::invalid_argument("tap: fundamental must be in (20, fs/6) Hz and decay > 0");
  // Free-free bar modes 1 : 2.756 : 5.404, quieter and shorter as they go up.
  const double ratios[] = {1.0, 2.756, 5.404};
  const double amplitudes[] = {1.0, 0.35, 0.12};
  const double decays[] = {1.0, 0.5, 0.3};
  const double attack = 0.001, fade = 0.005;
  std::seed_seq seq{c.seed, uint64_t{0x7a9}};
  std::mt19937_64 rng(seq);
  std::vector<float> s(n, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    const double t = i / fs;
    double modes = 0.0;
    for (int m = 0; m < 3; ++m) {
      const double f = c.fundamental_hz * ratios[m];
      if (f >= 0.45 * fs) continue;
      modes += amplitudes[m] * std::exp(-t / (c.decay_s * decays[m])) * std::sin(2.0 * kPi * f * t);
    }
    if (t < attack) modes *= 0.5 - 0.5 * std::cos(kPi * t / attack);  // the bar swells in
    const double noise = static_cast<double>(rng() >> 11) * 0x1.0p-53 * 2.0 - 1.0;
    double v = modes + c.click_level * std::exp(-t / c.click_s) * noise;
    const double end = n / fs - t;
    if (end < fade) v *= 0.5 - 0.5 * std::cos(kPi * end / fade);  // ends at zero
    s[i] = static_cast<float>(v);
  }
  normalise_peak(s, c.peak);
  return s;
}

std::vector<float> make_woosh(double fs, const WooshConfig& c) {
  const size_t n = samples_for(fs, c.duration_s, "woosh");
  if (!(c.low_hz > 20.0 && c.high_hz > c.low_hz && c.high_hz < 0.45 * fs))
    throw std::invalid_argument("woosh: need 20 < low_hz < high_hz < 0.45 fs");
  std::seed_seq seq{c.seed, uint64_t{0x3007}};
  std::mt19937_64 rng(seq);
  // Two-pole resonator (constant Q) on white noise, centre sweeping up exponentially.
  double y1 = 0.0, y2 = 0.0;
  std::vector<float> s(n);
  for (size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(n > 1 ? i : 0) / std::max<size_t>(1, n - 1);
    const double centre = c.low_hz * std::pow(c.high_hz / c.low_hz, x);
    const double bandwidth = centre / 3.0;
    const double r = std::exp(-kPi * bandwidth / fs);
    const double a1 = 2.0 * r * std::cos(2.0 * kPi * centre / fs), a2 = -r * r;
    const double noise = static_cast<double>(rng() >> 11) * 0x1.0p-53 * 2.0 - 1.0;
    const double y = (1.0 - r) * noise + a1 * y1 + a2 * y2;
    y2 = y1;
    y1 = y;
    s[i] = static_cast<float>(y * std::sin(kPi * x) * std::sin(kPi * x));  // swell and fade
  }
  normalise_peak(s, c.peak);
  return s;
}

}  // namespace sonomap::audio
