// SPDX-License-Identifier: GPL-3.0-or-later
// The binaural stream over a whole walk: what a wearer hears. Sweeps repeat every period (plus
// an optional pause); each tap takes its range from the circle the map had at the tap's own
// time (the caller hands in each frame's circle for the time span it holds), and its direction
// relative to the head at that moment:
//
//   world-locked: head azimuth = body yaw + bin azimuth - head yaw   (an obstacle stays put in
//                 the world while the head turns)
//   head-locked:  head azimuth = bin azimuth                          (the paper's sweep: the
//                 sound scene turns with the listener)
//
// Pieces are mixed by overlap-add into one buffer (a tap's reverb rings on across frame and
// sweep boundaries: no gaps, no clicks), and the finished stream gets one constant gain by the
// loudness rules (loudness.hpp), so a near tap stays louder than a far one.
#pragma once

#include "audio/sweep.hpp"

#include <functional>
#include <memory>
#include <vector>

namespace sonomap::audio {

enum class ListenMode { WorldLocked, HeadLocked };
const char* to_string(ListenMode mode);

struct ListenConfig {
  double period_s = 2.0;  // one sweep round the circle
  double pause_s = 0.0;   // silence after each sweep: sweep k starts at k * (period + pause)
  ListenMode mode = ListenMode::WorldLocked;
  double fade_out_s = 0.02;  // the stream ends at the run's end: the last reverb fades out
  double cycle_s() const { return period_s + pause_s; }
  void validate() const;  // throws std::invalid_argument naming the field
};

// One sound of the stream (a tap, or a woosh for an unscanned sector).
struct ListenTap {
  double time_s = 0.0;  // onset in the stream
  int sweep = 0;
  int sector = 0;
  double body_azimuth_deg = 0.0;   // the raster's bin azimuth, relative to the body
  double world_azimuth_deg = 0.0;  // body yaw + body azimuth
  double head_yaw_deg = 0.0;       // the head's world yaw at the onset
  double head_azimuth_deg = 0.0;   // the direction played, relative to the head
  double range_m = 0.0;            // NaN for a woosh
  double brir_distance_m = 0.0;
  double brir_azimuth_deg = 0.0;
  double pitch_semitones = 0.0;
  SoundKind sound = SoundKind::Tap;
  double level_dbfs = 0.0;  // the tap's own peak in the written stream (file gain included)
};

struct ListenAudio {
  double sample_rate = 0.0;
  std::vector<float> left;
  std::vector<float> right;
  std::vector<ListenTap> taps;  // in time order
  double gain_db = 0.0;         // the one gain of the file
  LoudnessMeasure loudness;     // of the written stream
  bool peak_limited = false;
};

// The head's world yaw (degrees) at a time of the walk.
using HeadYaw = std::function<double(double time_s)>;

class ListenStream {
 public:
  // `sweep` sets the taps (sectors, pitch, filters, loudness rules); its period is replaced by
  // listen.period_s. The BRIR set must be at sweep.sample_rate.
  ListenStream(std::shared_ptr<const BrirSet> brirs, SweepConfig sweep, ListenConfig listen);

  // Plays the sounds whose onsets fall in [from_s, to_s) from `circle` (centred on the body,
  // bin azimuths counter-clockwise from the body's heading, which has world yaw body_yaw_deg).
  // Calls must come in time order, spans not overlapping.
  void play(const Circle& circle, double from_s, double to_s, double body_yaw_deg,
            const HeadYaw& head_yaw_deg);
  // The stream cut to `duration_s` (the last fade_out_s faded), levelled by the loudness rules.
  ListenAudio finish(double duration_s);

  const SweepRenderer& renderer() const { return renderer_; }
  const ListenConfig& config() const { return listen_; }

 private:
  std::vector<ListenTap> schedule(const Circle& circle, double from_s, double to_s,
                                  double body_yaw_deg, const HeadYaw& head_yaw_deg) const;
  void add(const SweepAudio& piece, size_t start);

  ListenConfig listen_;
  SweepRenderer renderer_;
  double played_to_s_ = 0.0;
  std::vector<float> left_, right_;
  std::vector<ListenTap> taps_;
};

// The direction of each tap as a listener's cues would place it: interaural time difference
// (the lag of the cross-correlation peak within +-1 ms) and level difference of the mixed
// stream in a window round the tap's direct sound, matched against the same cues of the BRIR
// set itself (the tap alone through each grid azimuth at the tap's distance). Woosh: NaN.
struct TapLocalisation {
  std::vector<double> estimated_azimuth_deg;  // one per tap, relative to the head
  std::vector<double> error_deg;              // |estimate - played|, NaN for a woosh
  double median_error_deg = 0.0;              // over the taps; NaN without taps
  double p90_error_deg = 0.0;
  int taps = 0;
};
TapLocalisation localise_taps(const ListenAudio& audio, const SweepRenderer& renderer);

}  // namespace sonomap::audio
