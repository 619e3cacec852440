// SPDX-License-Identifier: GPL-3.0-or-later
// WAV files with libsndfile: 32-bit float stereo out, any WAV in (for tests and tools).
#pragma once

#include <filesystem>
#include <vector>

namespace sonomap::harness {

struct StereoAudio {
  double sample_rate = 0.0;
  std::vector<float> left;
  std::vector<float> right;
};

// -1 dBFS: no sample sonomap writes is larger in magnitude.
constexpr float kWavCeiling = 0.891250908f;  // the float just below 10^(-1/20)

// Writes a stereo 32-bit float WAV at `path` directly (callers stage it: see StagedFile), with
// no PEAK chunk (it holds a timestamp). std::logic_error, and nothing written, if a sample is
// above kWavCeiling or not finite: the caller's level rules failed.
void write_wav(const std::filesystem::path& path, double sample_rate, const std::vector<float>& left,
               const std::vector<float>& right);

// Reads a mono or stereo WAV (mono is copied to both channels). InputError on failure.
StereoAudio read_wav(const std::filesystem::path& path);

}  // namespace sonomap::harness
