// SPDX-License-Identifier: GPL-3.0-or-later
// localise_taps (listen_stream.hpp): where would the cues of the mixed stream place each tap?
#include "audio/listen_stream.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace sonomap::audio {
namespace {

constexpr double kMaxItdS = 0.001;     // cross-correlation lags searched: +-1 ms
constexpr double kBeforeS = 0.0005;    // window: from just before the direct sound ...
constexpr double kAfterS = 0.004;      // ... to 4 ms after it (the onset the ear localises)
constexpr double kItdScaleS = 0.00005;  // cue distance: 50 us of ITD weighs as ...
constexpr double kIldScaleDb = 1.0;     // ... 1 dB of ILD

struct Cues {
  double itd_s = 0.0;  // > 0: the right ear lags (source on the left)
  double ild_db = 0.0;  // > 0: louder on the left
};

// The cues are read on the first difference of the signals (a gentle high-pass, +6 dB per
// octave): the tap's strike click carries the direction, while its low tonal mode repeats every
// 1.5 ms and would give the cross-correlation a peak per period.
std::vector<float> differenced(const float* x, size_t n) {
  std::vector<float> d(n, 0.0f);
  for (size_t i = 1; i < n; ++i) d[i] = x[i] - x[i - 1];
  return d;
}

Cues cues_of(const float* left_raw, const float* right_raw, size_t n, double fs) {
  const std::vector<float> l = differenced(left_raw, n), r = differenced(right_raw, n);
  const float* left = l.data();
  const float* right = r.data();
  const long max_lag = static_cast<long>(std::lround(kMaxItdS * fs));
  double best = -std::numeric_limits<double>::infinity();
  long best_lag = 0;
  for (long lag = -max_lag; lag <= max_lag; ++lag) {
    double c = 0.0;
    for (long i = std::max(0L, -lag); i < static_cast<long>(n) && i + lag < static_cast<long>(n); ++i)
      c += double(left[i]) * right[i + lag];
    if (c > best) best = c, best_lag = lag;
  }
  double el = 1e-30, er = 1e-30;
  for (size_t i = 0; i < n; ++i) el += double(left[i]) * left[i], er += double(right[i]) * right[i];
  return {best_lag / fs, 10.0 * std::log10(el / er)};
}

// The tap alone through one BRIR, samples [from, from + n) of the convolution.
std::vector<float> convolve_window(const std::vector<float>& sound, const std::vector<float>& ir,
                                   size_t from, size_t n) {
  std::vector<float> out(n, 0.0f);
  for (size_t j = 0; j < n; ++j) {
    const size_t m = from + j;
    double acc = 0.0;
    const size_t k0 = m >= ir.size() ? m - ir.size() + 1 : 0;
    for (size_t k = k0; k <= m && k < sound.size(); ++k) acc += double(sound[k]) * ir[m - k];
    out[j] = static_cast<float>(acc);
  }
  return out;
}

// The cues of every grid azimuth at one distance and pitch, and where the window starts.
struct Templates {
  size_t window_start = 0;  // samples after the onset
  size_t window_length = 0;
  std::vector<Cues> cues;   // per grid azimuth
};

Templates make_templates(const SweepRenderer& renderer, size_t distance, double semitones) {
  const BrirSet& set = renderer.brirs();
  const double fs = set.sample_rate();
  // The direct sound arrives where the frontal response first reaches a tenth of its peak.
  const BinauralIr& front = set.at(distance, set.nearest_azimuth(0.0));
  float peak = 0.0f;
  for (const auto* ear : {&front.left, &front.right})
    for (float v : *ear) peak = std::max(peak, std::abs(v));
  size_t arrival = 0;
  while (arrival < front.left.size() && std::abs(front.left[arrival]) < 0.1f * peak &&
         std::abs(front.right[arrival]) < 0.1f * peak)
    ++arrival;
  Templates t;
  const size_t before = static_cast<size_t>(std::lround(kBeforeS * fs));
  t.window_start = arrival > before ? arrival - before : 0;
  t.window_length = static_cast<size_t>(std::lround((kBeforeS + kAfterS) * fs));
  const std::vector<float>& tap = renderer.sound(SoundKind::Tap, semitones);
  for (size_t a = 0; a < set.azimuth_count(); ++a) {
    const BinauralIr& ir = set.at(distance, a);
    const auto l = convolve_window(tap, ir.left, t.window_start, t.window_length);
    const auto r = convolve_window(tap, ir.right, t.window_start, t.window_length);
    t.cues.push_back(cues_of(l.data(), r.data(), t.window_length, fs));
  }
  return t;
}

double percentile(std::vector<double> v, double p) {  // nearest rank
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, rank > 0 ? rank - 1 : 0)];
}

}  // namespace

TapLocalisation localise_taps(const ListenAudio& audio, const SweepRenderer& renderer) {
  const BrirSet& set = renderer.brirs();
  const double fs = audio.sample_rate;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::map<std::pair<size_t, double>, Templates> templates;
  TapLocalisation out;
  std::vector<double> errors;
  for (const ListenTap& tap : audio.taps) {
    out.estimated_azimuth_deg.push_back(nan);
    out.error_deg.push_back(nan);
    if (tap.sound != SoundKind::Tap) continue;
    const size_t d = set.nearest_distance(tap.brir_distance_m);
    auto it = templates.find({d, tap.pitch_semitones});
    if (it == templates.end())
      it = templates.emplace(std::pair{d, tap.pitch_semitones},
                             make_templates(renderer, d, tap.pitch_semitones)).first;
    const Templates& t = it->second;
    const size_t from = static_cast<size_t>(std::llround(tap.time_s * fs)) + t.window_start;
    if (from + t.window_length > audio.left.size()) continue;  // cut off by the run's end
    const Cues c = cues_of(audio.left.data() + from, audio.right.data() + from, t.window_length, fs);
    size_t best = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    for (size_t a = 0; a < t.cues.size(); ++a) {
      const double dt = (c.itd_s - t.cues[a].itd_s) / kItdScaleS;
      const double dl = (c.ild_db - t.cues[a].ild_db) / kIldScaleDb;
      if (dt * dt + dl * dl < best_cost) best_cost = dt * dt + dl * dl, best = a;
    }
    const double estimate = set.grid().azimuths_deg[best];
    out.estimated_azimuth_deg.back() = estimate;
    out.error_deg.back() = std::abs(wrap_degrees_180(estimate - tap.head_azimuth_deg));
    errors.push_back(out.error_deg.back());
  }
  out.taps = static_cast<int>(errors.size());
  out.median_error_deg = percentile(errors, 0.5);
  out.p90_error_deg = percentile(errors, 0.9);
  return out;
}

}  // namespace sonomap::audio
