// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/sweep.hpp"

#include "audio/resample.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tbb/parallel_for.h>

namespace sonomap::audio {

const char* to_string(SoundKind kind) { return kind == SoundKind::Tap ? "tap" : "woosh"; }
const char* to_string(SweepMode mode) { return mode == SweepMode::Ranging ? "ranging" : "objects"; }
const char* to_string(LevelMode mode) { return mode == LevelMode::PerFile ? "per-file" : "fixed"; }

double PitchMapping::semitones(double d) const {
  double shift = 0.0;
  if (d < near_below_m) shift = near_semitones;
  else if (d > far_above_m) shift = far_semitones;
  return inverted ? -shift : shift;
}

bool SweepFilter::in_view(double azimuth_deg) const {
  return fov_width_deg >= 360.0 ||
         std::abs(wrap_degrees_180(azimuth_deg - fov_centre_deg)) <= 0.5 * fov_width_deg;
}

bool SweepFilter::in_window(double range_m) const {
  return range_m >= min_range_m && range_m <= max_range_m;
}

static void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("sweep config: " + what);
}

void SweepConfig::validate() const {
  require(std::isfinite(sample_rate) && sample_rate >= 8000 && sample_rate <= 384000,
          "sample_rate must be in [8000, 384000] Hz");
  require(sectors >= 1 && sectors <= 360, "sectors must be in [1, 360]");
  require(std::isfinite(period_s) && period_s > 0.0 && period_s <= 600.0,
          "period must be in (0, 600] s");
  require(sector_onsets_s.empty() || static_cast<int>(sector_onsets_s.size()) == sectors,
          "sector onsets: need one per sector (" + std::to_string(sectors) + ")");
  for (size_t i = 0; i < sector_onsets_s.size(); ++i)
    require(std::isfinite(sector_onsets_s[i]) && sector_onsets_s[i] >= 0.0 &&
                sector_onsets_s[i] <= 600.0 && (i == 0 || sector_onsets_s[i] > sector_onsets_s[i - 1]),
            "sector onsets must be increasing times in [0, 600] s (onset " + std::to_string(i) + ")");
  require(std::isfinite(environment_scale) && environment_scale > 0.0,
          "environment scale must be > 0");
  require(std::isfinite(min_distance_m) && std::isfinite(max_distance_m) && min_distance_m > 0.0 &&
              min_distance_m <= max_distance_m,
          "need 0 < min distance <= max distance");
  require(std::isfinite(woosh_distance_m) && woosh_distance_m > 0.0, "woosh distance must be > 0");
  require(std::isfinite(pitch.near_below_m) && std::isfinite(pitch.far_above_m) &&
              std::abs(pitch.near_semitones) <= 24 && std::abs(pitch.far_semitones) <= 24,
          "pitch: thresholds finite, shifts within +-24 semitones");
  require(std::isfinite(filter.fov_centre_deg) && filter.fov_width_deg > 0.0,
          "field of view: finite centre and width > 0");
  require(filter.min_range_m >= 0.0 && filter.max_range_m >= filter.min_range_m,
          "distance window: need 0 <= min <= max");
  require(filter.max_taps >= 0, "max taps must be >= 0");
  require(std::isfinite(object_jump_m_per_deg) && object_jump_m_per_deg > 0.0,
          "object jump must be > 0 m per degree");
  require(max_objects >= 1, "max objects must be >= 1");
  try {
    loudness.validate();
  } catch (const std::invalid_argument& e) {
    require(false, e.what());
  }
}

void validate_circle(const Circle& circle) {
  if (circle.bins.empty()) throw std::invalid_argument("circle: no bins");
  for (size_t k = 0; k < circle.bins.size(); ++k) {
    const float r = circle.bins[k].range;
    if (!(r == kUnknownRange || (std::isfinite(r) && r >= 0.0f)))
      throw std::invalid_argument("circle: bin " + std::to_string(k) + " has range " +
                                  std::to_string(r) + " (need a finite range >= 0 or unknown)");
  }
}

std::vector<PseudoObject> split_objects(const Circle& circle, double jump_m_per_deg) {
  validate_circle(circle);
  const int n = circle.size();
  const double max_jump = jump_m_per_deg * circle.bin_width_deg();
  auto range = [&](int k) { return circle.bins[static_cast<size_t>((k % n + n) % n)].range; };
  auto joined = [&](int k) {  // bins k and k + 1 belong to one object
    const float a = range(k), b = range(k + 1);
    return a != kUnknownRange && b != kUnknownRange && std::abs(a - b) <= max_jump;
  };
  // Start at a break so that an object crossing bin 0 is not cut in two.
  int start = -1;
  for (int k = 0; k < n && start < 0; ++k)
    if (!joined((k + n - 1) % n)) start = k;
  std::vector<PseudoObject> objects;
  if (start < 0) start = 0;  // one closed ring: every bin joined to the next
  for (int i = 0; i < n;) {
    const int first = (start + i) % n;
    int len = 1;
    while (len < n && joined(first + len - 1)) ++len;
    if (range(first) != kUnknownRange) {
      PseudoObject o;
      o.first_bin = first;
      o.last_bin = (first + len - 1) % n;
      o.nearest_bin = first;
      for (int j = 0; j < len; ++j)
        if (range(first + j) < range(o.nearest_bin)) o.nearest_bin = (first + j) % n;
      o.range_m = range(o.nearest_bin);
      o.azimuth_deg = circle.bin_centre_deg(o.nearest_bin);
      objects.push_back(o);
    }
    i += len;
  }
  std::sort(objects.begin(), objects.end(),
            [](const PseudoObject& a, const PseudoObject& b) { return a.first_bin < b.first_bin; });
  return objects;
}

namespace {

double onset(const SweepConfig& c, int sector) {
  return c.sector_onsets_s.empty() ? sector * c.period_s / c.sectors
                                   : c.sector_onsets_s[static_cast<size_t>(sector)];
}

double nearest_grid(const std::vector<double>& values, double x) {
  return values[nearest_distance_index(values, x)];
}

double nearest_grid_azimuth(const std::vector<double>& values, double az) {
  return values[nearest_azimuth_index(values, az)];
}

SweepEvent tap_event(const SweepConfig& c, const BrirGrid& grid, int sector, double azimuth,
                     double range) {
  SweepEvent e;
  e.time_s = onset(c, sector);
  e.sector = sector;
  e.azimuth_deg = azimuth;
  e.range_m = range;
  const double scaled = std::clamp(range * c.environment_scale, c.min_distance_m, c.max_distance_m);
  e.brir_distance_m = nearest_grid(grid.distances_m, scaled);
  e.brir_azimuth_deg = nearest_grid_azimuth(grid.azimuths_deg, azimuth);
  e.pitch_semitones = c.pitch.semitones(e.brir_distance_m);
  e.sound = SoundKind::Tap;
  return e;
}

// Keeps the `count` nearest taps (ties: earlier first), other events untouched.
void keep_nearest_taps(std::vector<SweepEvent>& events, size_t count) {
  std::vector<size_t> taps;
  for (size_t i = 0; i < events.size(); ++i)
    if (events[i].sound == SoundKind::Tap) taps.push_back(i);
  if (taps.size() <= count) return;
  std::stable_sort(taps.begin(), taps.end(),
                   [&](size_t a, size_t b) { return events[a].range_m < events[b].range_m; });
  std::vector<bool> drop(events.size(), false);
  for (size_t i = count; i < taps.size(); ++i) drop[taps[i]] = true;
  std::vector<SweepEvent> kept;
  for (size_t i = 0; i < events.size(); ++i)
    if (!drop[i]) kept.push_back(events[i]);
  events.swap(kept);
}

}  // namespace

std::vector<SweepEvent> schedule_sweep(const Circle& circle, const SweepConfig& c,
                                       const BrirGrid& grid) {
  c.validate();
  validate_circle(circle);
  if (grid.azimuths_deg.empty() || grid.distances_m.empty())
    throw std::invalid_argument("sweep: empty BRIR grid");
  std::vector<SweepEvent> events;
  const auto sectors = circle_sectors(circle, c.sectors);
  const int bins_per_sector = circle.size() / c.sectors;
  if (c.mode == SweepMode::Ranging) {
    for (int s = 0; s < c.sectors; ++s) {
      const Sector& sector = sectors[static_cast<size_t>(s)];
      if (sector.known()) {
        if (c.filter.in_view(sector.angle_deg) && c.filter.in_window(sector.range))
          events.push_back(tap_event(c, grid, s, sector.angle_deg, sector.range));
      } else if (c.woosh_unknown) {
        const double centre = (s + 0.5) * bins_per_sector * circle.bin_width_deg();
        if (!c.filter.in_view(centre)) continue;
        SweepEvent e;
        e.time_s = onset(c, s);
        e.sector = s;
        e.azimuth_deg = centre;
        e.brir_distance_m = nearest_grid(grid.distances_m, c.woosh_distance_m);
        e.brir_azimuth_deg = nearest_grid_azimuth(grid.azimuths_deg, centre);
        e.sound = SoundKind::Woosh;
        events.push_back(e);
      }
    }
    if (c.filter.max_taps > 0) keep_nearest_taps(events, static_cast<size_t>(c.filter.max_taps));
  } else {
    for (const PseudoObject& o : split_objects(circle, c.object_jump_m_per_deg)) {
      if (!c.filter.in_view(o.azimuth_deg) || !c.filter.in_window(o.range_m)) continue;
      events.push_back(tap_event(c, grid, o.nearest_bin / bins_per_sector, o.azimuth_deg, o.range_m));
    }
    keep_nearest_taps(events, static_cast<size_t>(c.max_objects));
  }
  std::stable_sort(events.begin(), events.end(), [](const SweepEvent& a, const SweepEvent& b) {
    return a.time_s < b.time_s;
  });
  return events;
}

// ---------------------------------------------------------------------------------------------

static std::map<double, std::vector<float>> make_taps(const SweepConfig& c) {
  c.validate();
  const std::vector<float> tap = make_tap(c.sample_rate, c.tap);
  std::map<double, std::vector<float>> out;
  for (double shift : {0.0, c.pitch.near_semitones, c.pitch.far_semitones, -c.pitch.near_semitones,
                       -c.pitch.far_semitones})
    if (!out.count(shift)) out[shift] = shift == 0.0 ? tap : pitch_shift(tap, shift);
  return out;
}

size_t SweepRenderer::longest_sound() const {
  size_t n = woosh_.samples.size();
  for (const auto& [shift, v] : taps_) n = std::max(n, v.samples.size());
  return n;
}

SweepRenderer::SweepRenderer(std::shared_ptr<const BrirSet> brirs, SweepConfig config)
    : config_(std::move(config)),
      taps_([&] {
        std::map<double, Variant> taps;
        for (auto& [shift, samples] : make_taps(config_)) taps[shift].samples = std::move(samples);
        return taps;
      }()),
      woosh_{make_woosh(config_.sample_rate, config_.woosh), {}},
      convolver_((brirs && !brirs->empty() &&
                          std::abs(brirs->sample_rate() - config_.sample_rate) > 1e-6
                      ? throw std::invalid_argument(
                            "sweep: BRIR rate " + std::to_string(brirs->sample_rate()) +
                            " Hz differs from the output rate " +
                            std::to_string(config_.sample_rate) + " Hz (resample on load)")
                      : std::move(brirs)),
                 longest_sound()) {
  for (auto& [shift, v] : taps_) v.spectrum = convolver_.sound_spectrum(v.samples);
  woosh_.spectrum = convolver_.sound_spectrum(woosh_.samples);
}

const SweepRenderer::Variant& SweepRenderer::variant(SoundKind kind, double semitones) const {
  if (kind == SoundKind::Woosh) return woosh_;
  const auto it = taps_.find(semitones);
  if (it == taps_.end())
    throw std::invalid_argument("sweep: no tap variant at " + std::to_string(semitones) +
                                " semitones");
  return it->second;
}

const std::vector<float>& SweepRenderer::sound(SoundKind kind, double semitones) const {
  return variant(kind, semitones).samples;
}

std::vector<SweepEvent> SweepRenderer::schedule(const Circle& circle) const {
  return schedule_sweep(circle, config_, brirs().grid());
}

SweepAudio SweepRenderer::render(const Circle& circle) { return render(schedule(circle)); }

SweepAudio SweepRenderer::render(std::vector<SweepEvent> events) {
  SweepAudio out = mix(std::move(events), period_samples());
  level(out);
  return out;
}

std::vector<SweepEvent> SweepRenderer::loudest_events() const {
  SweepConfig c = config_;
  c.mode = SweepMode::Ranging;
  c.filter = SweepFilter{};
  Circle circle(360);
  for (auto& b : circle.bins) b.range = 0.0f;  // clamped up to the nearest distance
  return schedule_sweep(circle, c, brirs().grid());
}

void SweepRenderer::level(SweepAudio& out) {
  const LoudnessRules& rules = config_.loudness;
  const LoudnessMeasure raw = measure_loudness(out.left, out.right, out.sample_rate);
  if (config_.level == LevelMode::PerFile) {
    out.gain_db = loudness_gain_db(raw, rules);
    out.peak_limited = peak_limited(raw, rules);
  } else {
    if (!fixed_gain_known_) {
      const SweepAudio loudest = mix(loudest_events(), period_samples());
      const LoudnessMeasure m = measure_loudness(loudest.left, loudest.right, loudest.sample_rate);
      fixed_gain_db_ = loudness_gain_db(m, rules);
      fixed_peak_limited_ = peak_limited(m, rules);
      fixed_gain_known_ = true;
    }
    // The last line of defence: a sweep louder than the calibration one is turned down.
    const double cap = rules.ceiling_dbtp - rules.margin_db - raw.true_peak_dbtp;
    out.gain_db = std::min(fixed_gain_db_, cap);
    out.peak_limited = fixed_peak_limited_ || cap < fixed_gain_db_;
  }
  apply_gain(out.left, out.right, out.gain_db);
  out.loudness = with_gain(raw, out.gain_db);
}

size_t SweepRenderer::period_samples() const {
  return static_cast<size_t>(std::ceil(config_.period_s * config_.sample_rate));
}

void SweepRenderer::convolve_block(const std::vector<SweepEvent>& events,
                                   const std::vector<std::pair<size_t, size_t>>& pairs, size_t first,
                                   size_t last) {
  const size_t tasks = (last - first) * 2;
  if (scratch_.size() < tasks) scratch_.resize(tasks);
  tbb::parallel_for(size_t{0}, tasks, [&](size_t t) {
    const size_t i = first + t / 2;
    const Ear ear = static_cast<Ear>(t % 2);
    auto& scratch = scratch_[t];
    if (scratch.size() != convolver_.fft_size()) scratch.assign(convolver_.fft_size(), 0.0f);
    thread_local Spectrum product;
    product.resize(convolver_.fft_size() / 2 + 1);
    convolver_.convolve(variant(events[i].sound, events[i].pitch_semitones).spectrum,
                        convolver_.brir_spectrum(pairs[i].first, pairs[i].second, ear), scratch,
                        product);
  });
}

// Adds one convolved event (its two ears' scratch buffers) at `start` and records its peak.
void SweepRenderer::add_event(SweepAudio& out, SweepEvent& event, size_t start,
                              const AlignedSamples* ears) const {
  const size_t n = convolver_.output_length(variant(event.sound, event.pitch_semitones).samples.size());
  float peak = 0.0f;
  for (int ear = 0; ear < 2; ++ear) {
    float* dst = (ear == 0 ? out.left.data() : out.right.data()) + start;
    const float* src = ears[ear].data();
    for (size_t k = 0; k < n; ++k) dst[k] += src[k], peak = std::max(peak, std::abs(src[k]));
  }
  event.peak_amplitude = peak;
}

SweepAudio SweepRenderer::mix(std::vector<SweepEvent> events, size_t min_length) {
  const BrirSet& set = brirs();
  const double fs = config_.sample_rate;
  // Indices of each event's BRIR and its first output sample.
  std::vector<std::pair<size_t, size_t>> pairs;
  std::vector<size_t> starts;
  size_t length = min_length;
  for (const SweepEvent& e : events) {
    if (!(std::isfinite(e.time_s) && e.time_s >= 0.0 && e.time_s <= 600.0))
      throw std::invalid_argument("sweep: event time out of [0, 600] s");
    pairs.emplace_back(set.nearest_distance(e.brir_distance_m), set.nearest_azimuth(e.brir_azimuth_deg));
    starts.push_back(static_cast<size_t>(std::llround(e.time_s * fs)));
    const size_t n = convolver_.output_length(variant(e.sound, e.pitch_semitones).samples.size());
    length = std::max(length, starts.back() + n);
  }
  convolver_.prepare(pairs);

  SweepAudio out;
  out.sample_rate = fs;
  out.left.assign(length, 0.0f);
  out.right.assign(length, 0.0f);
  // One task per (event, ear), each in its own scratch buffer, a block of events at a time;
  // summed in event order, so the output does not depend on the thread count. Blocks bound the
  // scratch (a buffer of fft_size() samples per task: 36 events of one sweep held 19 MB at once).
  for (size_t first = 0; first < events.size(); first += kEventsPerBlock) {
    const size_t last = std::min(events.size(), first + kEventsPerBlock);
    convolve_block(events, pairs, first, last);
    for (size_t i = first; i < last; ++i) add_event(out, events[i], starts[i], &scratch_[2 * (i - first)]);
  }
  out.events = std::move(events);
  return out;
}

}  // namespace sonomap::audio
