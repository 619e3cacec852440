// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/listen_stream.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::audio {

const char* to_string(ListenMode mode) {
  return mode == ListenMode::WorldLocked ? "world_locked" : "head_locked";
}

void ListenConfig::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("listen config: " + what);
  };
  require(std::isfinite(period_s) && period_s >= 0.1 && period_s <= 60.0,
          "period must be in [0.1, 60] s");
  require(std::isfinite(pause_s) && pause_s >= 0.0 && pause_s <= 60.0,
          "pause must be in [0, 60] s");
  require(std::isfinite(fade_out_s) && fade_out_s >= 0.0 && fade_out_s <= 1.0,
          "fade-out must be in [0, 1] s");
}

static SweepConfig with_period(SweepConfig sweep, const ListenConfig& listen) {
  listen.validate();
  sweep.period_s = listen.period_s;
  return sweep;
}

ListenStream::ListenStream(std::shared_ptr<const BrirSet> brirs, SweepConfig sweep,
                           ListenConfig listen)
    : listen_(listen), renderer_(std::move(brirs), with_period(std::move(sweep), listen)) {}

std::vector<ListenTap> ListenStream::schedule(const Circle& circle, double from_s, double to_s,
                                              double body_yaw_deg, const HeadYaw& head_yaw) const {
  const std::vector<SweepEvent> sweep = renderer_.schedule(circle);
  const BrirGrid& grid = renderer_.brirs().grid();
  const double cycle = listen_.cycle_s();
  double last_onset = 0.0;
  for (const SweepEvent& e : sweep) last_onset = std::max(last_onset, e.time_s);
  std::vector<ListenTap> taps;
  const int first = std::max(0, static_cast<int>(std::floor((from_s - last_onset) / cycle)));
  for (int k = first; k * cycle < to_s; ++k)
    for (const SweepEvent& e : sweep) {
      const double t = k * cycle + e.time_s;
      if (t < from_s || t >= to_s) continue;
      ListenTap tap;
      tap.time_s = t;
      tap.sweep = k;
      tap.sector = e.sector;
      tap.body_azimuth_deg = e.azimuth_deg;
      tap.world_azimuth_deg = wrap_degrees_180(body_yaw_deg + e.azimuth_deg);
      tap.head_yaw_deg = head_yaw(t);
      tap.head_azimuth_deg = listen_.mode == ListenMode::WorldLocked
                                 ? wrap_degrees_180(tap.world_azimuth_deg - tap.head_yaw_deg)
                                 : wrap_degrees_180(e.azimuth_deg);
      tap.range_m = e.range_m;
      tap.brir_distance_m = e.brir_distance_m;
      tap.brir_azimuth_deg =
          grid.azimuths_deg[nearest_azimuth_index(grid.azimuths_deg, tap.head_azimuth_deg)];
      tap.pitch_semitones = e.pitch_semitones;
      tap.sound = e.sound;
      taps.push_back(tap);
    }
  std::stable_sort(taps.begin(), taps.end(),
                   [](const ListenTap& a, const ListenTap& b) { return a.time_s < b.time_s; });
  return taps;
}

void ListenStream::play(const Circle& circle, double from_s, double to_s, double body_yaw_deg,
                        const HeadYaw& head_yaw) {
  if (!(std::isfinite(from_s) && std::isfinite(to_s) && from_s >= played_to_s_ - 1e-9 &&
        to_s >= from_s))
    throw std::invalid_argument("listen stream: spans must come in time order");
  if (!std::isfinite(body_yaw_deg)) throw std::invalid_argument("listen stream: body yaw not finite");
  played_to_s_ = to_s;
  std::vector<ListenTap> taps = schedule(circle, from_s, to_s, body_yaw_deg, head_yaw);
  if (taps.empty()) return;
  // Each onset on its own sample of the stream; the piece starts at the first one.
  const double fs = renderer_.config().sample_rate;
  const long long start = std::llround(taps.front().time_s * fs);
  std::vector<SweepEvent> events;
  for (const ListenTap& t : taps) {
    SweepEvent e;
    e.time_s = static_cast<double>(std::llround(t.time_s * fs) - start) / fs;
    e.sector = t.sector;
    e.azimuth_deg = t.head_azimuth_deg;
    e.range_m = t.range_m;
    e.brir_distance_m = t.brir_distance_m;
    e.brir_azimuth_deg = t.brir_azimuth_deg;
    e.pitch_semitones = t.pitch_semitones;
    e.sound = t.sound;
    events.push_back(e);
  }
  const SweepAudio piece = renderer_.mix(std::move(events), 0);
  for (size_t i = 0; i < taps.size(); ++i) {
    taps[i].level_dbfs = piece.events[i].peak_amplitude;  // linear until finish() knows the gain
    taps_.push_back(taps[i]);
  }
  add(piece, static_cast<size_t>(start));
}

void ListenStream::add(const SweepAudio& piece, size_t start) {
  const size_t end = start + piece.left.size();
  if (left_.size() < end) {
    left_.resize(end, 0.0f);
    right_.resize(end, 0.0f);
  }
  for (size_t k = 0; k < piece.left.size(); ++k) {
    left_[start + k] += piece.left[k];
    right_[start + k] += piece.right[k];
  }
}

ListenAudio ListenStream::finish(double duration_s) {
  if (!(std::isfinite(duration_s) && duration_s > 0.0 && duration_s <= 86400.0))
    throw std::invalid_argument("listen stream: duration must be in (0, 86400] s");
  const double fs = renderer_.config().sample_rate;
  const size_t n = static_cast<size_t>(std::llround(duration_s * fs));
  ListenAudio out;
  out.sample_rate = fs;
  out.left = std::move(left_);
  out.right = std::move(right_);
  out.left.resize(n, 0.0f);
  out.right.resize(n, 0.0f);
  const size_t fade = std::min(n, static_cast<size_t>(std::llround(listen_.fade_out_s * fs)));
  for (size_t k = 0; k < fade; ++k) {  // raised cosine down to 0 at the last sample
    const double x = static_cast<double>(k + 1) / static_cast<double>(fade);
    const float g = static_cast<float>(0.5 * (1.0 + std::cos(M_PI * x)));
    out.left[n - fade + k] *= g;
    out.right[n - fade + k] *= g;
  }
  const LoudnessRules& rules = renderer_.config().loudness;
  const LoudnessMeasure raw = measure_loudness(out.left, out.right, fs);
  out.gain_db = loudness_gain_db(raw, rules);
  out.peak_limited = peak_limited(raw, rules);
  apply_gain(out.left, out.right, out.gain_db);
  out.loudness = with_gain(raw, out.gain_db);
  for (ListenTap& t : taps_)
    if (t.time_s < duration_s) {
      t.level_dbfs = amplitude_to_db(t.level_dbfs) + out.gain_db;
      out.taps.push_back(t);
    }
  taps_.clear();
  left_.clear();
  right_.clear();
  played_to_s_ = 0.0;
  return out;
}

}  // namespace sonomap::audio
