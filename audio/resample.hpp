// SPDX-License-Identifier: GPL-3.0-or-later
// Band-limited resampling with libsamplerate (sinc, best quality): sample-rate conversion of
// impulse responses, and pitch shifting by playing a resampled sound at the original rate.
#pragma once

#include <vector>

namespace sonomap::audio {

// Resamples `input` by `ratio` = output rate / input rate. Throws std::invalid_argument for a
// ratio outside libsamplerate's [1/256, 256] or a non-finite input.
std::vector<float> resample(const std::vector<float>& input, double ratio);

// The same sound shifted by `semitones` (frequencies x 2^(semitones/12)); duration scales by
// the inverse factor.
std::vector<float> pitch_shift(const std::vector<float>& input, double semitones);

}  // namespace sonomap::audio
