// SPDX-License-Identifier: GPL-3.0-or-later
// The two sounds of the sweep, synthesised deterministically (no downloaded samples):
// a 'tap' (a struck wooden bar: a broadband click of the strike, then a few inharmonic modes
// decaying exponentially; the click carries the high-frequency cues that localise it) and a 'woosh' (noise through a resonance sweeping upwards, swelling and fading).
#pragma once

#include <cstdint>
#include <vector>

namespace sonomap::audio {

struct TapConfig {
  double fundamental_hz = 660.0;  // the pitch that shifts with distance
  double duration_s = 0.1;
  double decay_s = 0.018;  // e-folding time of the fundamental; higher modes decay faster
  double click_s = 0.0005;  // e-folding time of the strike's noise click
  double click_level = 0.6;  // its amplitude relative to the fundamental mode
  double peak = 0.5;         // peak amplitude
  uint64_t seed = 5;         // the click's noise
};

struct WooshConfig {
  double duration_s = 0.25;
  double low_hz = 400.0;  // the resonance sweeps from low_hz to high_hz
  double high_hz = 3000.0;
  double peak = 0.5;
  uint64_t seed = 7;
};

std::vector<float> make_tap(double sample_rate, const TapConfig& config = {});
std::vector<float> make_woosh(double sample_rate, const WooshConfig& config = {});

}  // namespace sonomap::audio
