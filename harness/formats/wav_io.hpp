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

// Writes a stereo 32-bit float WAV at `path` directly (callers stage it: see StagedFile).
void write_wav(const std::filesystem::path& path, double sample_rate, const std::vector<float>& left,
               const std::vector<float>& right);

// Reads a mono or stereo WAV (mono is copied to both channels). InputError on failure.
StereoAudio read_wav(const std::filesystem::path& path);

}  // namespace sonomap::harness
