// SPDX-License-Identifier: GPL-3.0-or-later
// H.264 MP4 from RGB frames through Debian's ffmpeg program: raw frames go down a pipe to its
// stdin (no temporary pictures), with flags that make the file the same on every rerun
// (single-threaded x264, bit-exact muxing, no metadata or timestamps).
#pragma once

#include "harness/app/video_canvas.hpp"
#include "harness/support/subprocess.hpp"

#include <filesystem>
#include <memory>
#include <optional>

namespace sonomap::harness {

// Throws InputError (exit 2) naming ffmpeg when the program is not installed.
void require_ffmpeg(const std::string& why);

class VideoEncoder {
 public:
  // Writes `video` (silent), frames of width x height at rate_hz. Throws std::runtime_error
  // if ffmpeg cannot be started.
  VideoEncoder(std::filesystem::path video, int width, int height, double rate_hz);
  void add(const Canvas& frame);  // the canvas must be width x height
  int frames() const { return frames_; }
  // Closes the stream; throws std::runtime_error with ffmpeg's message if encoding failed.
  void finish();

 private:
  std::filesystem::path video_;
  int width_, height_, frames_ = 0;
  std::unique_ptr<PipedProgram> ffmpeg_;
};

// `out`: `video` with `audio` (a WAV) as its AAC sound track, padded with silence or cut to
// `duration_s`; the video stream is copied. Throws std::runtime_error if ffmpeg fails.
void add_sound_track(const std::filesystem::path& video, const std::filesystem::path& audio,
                     double duration_s, const std::filesystem::path& out);

}  // namespace sonomap::harness
