// SPDX-License-Identifier: GPL-3.0-or-later
// The binaural sweep of the paper ("circular ranging"): the 2D circle is cut into 36 sectors
// of 10 degrees; counter-clockwise from straight ahead each sector plays a 'tap' at its nearest
// range and angle (through the BRIR of that azimuth and distance), or a 'woosh' when it is
// not yet scanned. The "circular ranging of objects" mode plays each pseudo-object (circle split
// at range jumps) once at its nearest point. Output: a stereo buffer and the event list.
#pragma once

#include "audio/brir_set.hpp"
#include "audio/convolver.hpp"
#include "audio/loudness.hpp"
#include "audio/sounds.hpp"
#include "core/raster.hpp"

#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace sonomap::audio {

enum class SweepMode { Ranging, Objects };
enum class SoundKind { Tap, Woosh };
const char* to_string(SoundKind kind);
const char* to_string(SweepMode mode);

// Tap pitch from the BRIR distance: the paper shifts near taps down and far taps up.
struct PitchMapping {
  double near_below_m = 1.5;   // taps closer than this ...
  double near_semitones = -4;  // ... are shifted by this
  double far_above_m = 2.5;    // taps further than this ...
  double far_semitones = 4;    // ... by this
  bool inverted = false;       // parking-sensor convention: near higher, far lower
  double semitones(double brir_distance_m) const;
};

// Which sounds play (both modes).
struct SweepFilter {
  double fov_centre_deg = 0.0;  // azimuth field of view: centre and full width
  double fov_width_deg = 360.0;
  double min_range_m = 0.0;  // distance window on the measured range
  double max_range_m = std::numeric_limits<double>::infinity();
  int max_taps = 0;  // ranging mode: only the N nearest taps (0: all)
  bool in_view(double azimuth_deg) const;
  bool in_window(double range_m) const;
};

// The level of a rendered sweep: one gain per file (loudness.hpp has the rule).
//   PerFile: each sweep is normalised to the loudness target, the true-peak ceiling winning.
//   Fixed:   one gain per renderer, set once from the loudest sweep its BRIR set can play (every
//            sector a tap at the nearest distance) by the same rule, so that levels compare
//            across sweeps; a sweep that would still pass the ceiling is turned down further.
enum class LevelMode { PerFile, Fixed };
const char* to_string(LevelMode mode);

struct SweepConfig {
  SweepMode mode = SweepMode::Ranging;
  double sample_rate = 48000.0;
  int sectors = 36;
  double period_s = 2.0;  // one full turn: sector s starts at s * period / sectors ...
  std::vector<double> sector_onsets_s;  // ... unless given here (one per sector, increasing)
  double environment_scale = 1.0;       // range x scale -> BRIR distance
  double min_distance_m = 0.4;          // clamp of the scaled range (the BRIR grid's span)
  double max_distance_m = 4.0;
  double woosh_distance_m = 2.0;  // unknown sectors: woosh at the sector centre, this far
  bool woosh_unknown = true;
  PitchMapping pitch;
  SweepFilter filter;
  double object_jump_m_per_deg = 0.5;  // objects mode: split where the range jumps more
  int max_objects = 5;                 // objects mode: the N nearest pseudo-objects
  TapConfig tap;
  WooshConfig woosh;
  LevelMode level = LevelMode::PerFile;
  LoudnessRules loudness;
  void validate() const;  // throws std::invalid_argument naming the field
};

struct SweepEvent {
  double time_s = 0.0;  // onset in the output buffer
  int sector = 0;
  double azimuth_deg = 0.0;  // direction of the sound (bin centre, or sector centre for woosh)
  double range_m = std::numeric_limits<double>::quiet_NaN();  // measured range; NaN: unknown
  double brir_distance_m = 0.0;  // the grid distance used
  double brir_azimuth_deg = 0.0;  // the grid azimuth used
  double pitch_semitones = 0.0;
  SoundKind sound = SoundKind::Tap;
  double peak_amplitude = 0.0;  // the event's own rendered sound, both ears, before any gain
};

struct SweepAudio {
  double sample_rate = 0.0;
  std::vector<float> left;
  std::vector<float> right;
  std::vector<SweepEvent> events;
  double gain_db = 0.0;      // the one gain applied to the whole sweep
  LoudnessMeasure loudness;  // of the output, gain included
  bool peak_limited = false;  // the true-peak ceiling, not the loudness target, set the gain
};

// A pseudo-object: a run of known bins without a range jump, and its nearest point.
struct PseudoObject {
  int first_bin = 0;  // counter-clockwise from first_bin to last_bin (may wrap past 359)
  int last_bin = 0;
  int nearest_bin = 0;
  double range_m = 0.0;
  double azimuth_deg = 0.0;
};

// Throws std::invalid_argument unless every range is finite >= 0 or unknown (+inf).
void validate_circle(const Circle& circle);
// Splits the circle where neighbouring bins differ by more than jump_m_per_deg x bin width, or
// where a bin is unknown. Sorted by first bin.
std::vector<PseudoObject> split_objects(const Circle& circle, double jump_m_per_deg);

// The sweep's schedule for a circle (pure: no audio). Events are in time order.
std::vector<SweepEvent> schedule_sweep(const Circle& circle, const SweepConfig& config,
                                       const BrirGrid& grid);

class SweepRenderer {
 public:
  // The BRIR set must be at config.sample_rate (the harness resamples on load).
  SweepRenderer(std::shared_ptr<const BrirSet> brirs, SweepConfig config = {});

  const SweepConfig& config() const { return config_; }
  const BrirSet& brirs() const { return convolver_.brirs(); }
  size_t fft_size() const { return convolver_.fft_size(); }  // the convolution's transform
  std::vector<SweepEvent> schedule(const Circle& circle) const;
  // Renders and levels the sweep (config().level).
  SweepAudio render(const Circle& circle);
  SweepAudio render(std::vector<SweepEvent> events);
  // The loudest sweep the BRIR set can play: every sector a tap at the nearest distance.
  std::vector<SweepEvent> loudest_events() const;
  // The dry sound an event plays (tap pitch variants are made once, at construction).
  const std::vector<float>& sound(SoundKind kind, double semitones) const;
  // The events mixed, before any gain: at least `min_length` samples, longer if the last sound
  // rings on. Fills each event's peak_amplitude. A continuous stream mixes its pieces with this.
  SweepAudio mix(std::vector<SweepEvent> events, size_t min_length);
  void clear_cache() { convolver_.clear_cache(); }
  size_t cached_spectra() const { return convolver_.cached_spectra(); }

 private:
  struct Variant {
    std::vector<float> samples;
    Spectrum spectrum;
  };
  const Variant& variant(SoundKind kind, double semitones) const;
  // Convolves events [first, last) into scratch_ (two buffers per event, left then right).
  void convolve_block(const std::vector<SweepEvent>& events,
                      const std::vector<std::pair<size_t, size_t>>& pairs, size_t first, size_t last);
  void add_event(SweepAudio& out, SweepEvent& event, size_t start, const AlignedSamples* ears) const;
  static constexpr size_t kEventsPerBlock = 8;
  size_t longest_sound() const;
  size_t period_samples() const;
  void level(SweepAudio& audio);

  double fixed_gain_db_ = 0.0;
  bool fixed_gain_known_ = false;
  bool fixed_peak_limited_ = false;
  SweepConfig config_;
  std::map<double, Variant> taps_;  // by pitch shift, semitones
  Variant woosh_;
  BrirConvolver convolver_;
  std::vector<AlignedSamples> scratch_;  // reused between renders
};

}  // namespace sonomap::audio
