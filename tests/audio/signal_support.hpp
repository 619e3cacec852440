// SPDX-License-Identifier: GPL-3.0-or-later
// Shared by the audio tests: a dry BRIR set and a pitch measure independent of the FFT code.
#pragma once

#include "audio/brir_set.hpp"

#include <cmath>
#include <complex>
#include <memory>
#include <vector>

namespace {

constexpr double kFs = 48000.0;
constexpr double kPi = 3.14159265358979323846;

// Paper grid, every IR a unit impulse at sample `delay`, both ears.
inline std::shared_ptr<const sonomap::audio::BrirSet> impulse_brirs(size_t length = 64, size_t delay = 0) {
  sonomap::audio::BrirGrid grid = sonomap::audio::BrirGrid::paper();
  std::vector<sonomap::audio::BinauralIr> irs(grid.azimuths_deg.size() * grid.distances_m.size());
  for (auto& ir : irs) {
    ir.left.assign(length, 0.0f);
    ir.right.assign(length, 0.0f);
    ir.left[delay] = ir.right[delay] = 1.0f;
  }
  return std::make_shared<const sonomap::audio::BrirSet>(kFs, grid, std::move(irs));
}

// Frequency (Hz) of the strongest DFT peak of x within [lo, hi], by a fine scan then golden
// section on |X(f)| (a direct DFT: independent of the FFT code under test).
inline double peak_frequency(const std::vector<float>& x, double lo, double hi) {
  auto magnitude = [&](double f) {
    std::complex<double> acc = 0.0;
    const std::complex<double> step = std::polar(1.0, -2.0 * kPi * f / kFs);
    std::complex<double> w = 1.0;
    for (float v : x) {
      acc += double(v) * w;
      w *= step;
    }
    return std::abs(acc);
  };
  double best = lo, best_mag = -1.0;
  for (double f = lo; f <= hi; f += 2.0) {
    const double m = magnitude(f);
    if (m > best_mag) best_mag = m, best = f;
  }
  double a = best - 2.0, b = best + 2.0;
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 40; ++i) {
    const double c = b - g * (b - a), d = a + g * (b - a);
    if (magnitude(c) > magnitude(d)) b = d; else a = c;
  }
  return 0.5 * (a + b);
}

}  // namespace
