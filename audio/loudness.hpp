// SPDX-License-Identifier: GPL-3.0-or-later
// Loudness of a stereo (binaural) signal after ITU-R BS.1770 / EBU R128, measured with
// libebur128 (pure computation: no files), and the one rule that sets a file's gain:
//
//   gain = target loudness - measured loudness, but never more than puts the true peak
//          (4x oversampled) at the ceiling: when the two conflict, the true-peak ceiling wins.
//
// The gain is one constant for a whole file, so a near obstacle stays louder than a far one.
#pragma once

#include <vector>

namespace sonomap::audio {

struct LoudnessRules {
  double target_lufs = -16.0;  // integrated loudness for headphone listening
  double ceiling_dbtp = -1.0;  // no file exceeds this true peak (and so this sample peak)
  // The gain aims this far below the ceiling: true-peak estimators differ by a few hundredths
  // of a dB (interpolation filters), and the promise is the ceiling whoever measures.
  double margin_db = 0.1;
  void validate() const;  // throws std::invalid_argument naming the field
};

struct LoudnessMeasure {
  double integrated_lufs = 0.0;   // -inf: silent, or too short to gate (< 400 ms)
  double true_peak_dbtp = 0.0;    // max over both channels, 4x oversampled; -inf: silent
  double sample_peak_dbfs = 0.0;  // max |sample| over both channels; -inf: silent
};

// Measures a stereo signal (equal channel lengths).
LoudnessMeasure measure_loudness(const std::vector<float>& left, const std::vector<float>& right,
                                 double sample_rate);

// The gain (dB) that brings `m` to the rules' target, capped by the true-peak ceiling (less the
// margin). A silent or unmeasurable loudness gives the ceiling's cap alone, at most 0 dB.
double loudness_gain_db(const LoudnessMeasure& m, const LoudnessRules& rules);
// True when the ceiling, not the target, set loudness_gain_db.
bool peak_limited(const LoudnessMeasure& m, const LoudnessRules& rules);

// Multiplies both channels by 10^(gain_db / 20).
void apply_gain(std::vector<float>& left, std::vector<float>& right, double gain_db);

// A measure after a gain: every level moves by the gain (linear scaling).
LoudnessMeasure with_gain(const LoudnessMeasure& m, double gain_db);

double db_to_amplitude(double db);
double amplitude_to_db(double amplitude);  // -inf for 0

}  // namespace sonomap::audio
