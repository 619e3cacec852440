// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/video_encoder.hpp"

#include "harness/support/errors.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// Same bytes on every rerun: no encoder version string or creation time in the container.
const std::vector<std::string> kBitExact{"-fflags", "+bitexact", "-flags:v", "+bitexact",
                                         "-flags:a", "+bitexact", "-map_metadata", "-1"};

std::vector<std::string> ffmpeg_command(std::vector<std::string> inputs, std::vector<std::string> encoding,
                                        const fs::path& out) {
  std::vector<std::string> argv{"ffmpeg", "-hide_banner", "-loglevel", "error", "-nostats"};
  argv.insert(argv.end(), inputs.begin(), inputs.end());
  argv.insert(argv.end(), encoding.begin(), encoding.end());
  argv.insert(argv.end(), kBitExact.begin(), kBitExact.end());
  argv.insert(argv.end(), {"-threads", "1", "-y", out.string()});
  return argv;
}

}  // namespace

void require_ffmpeg(const std::string& why) {
  if (!program_in_path("ffmpeg"))
    throw InputError(why + " needs the ffmpeg program (Debian package ffmpeg; ci/install-deps "
                           "installs it), and there is no ffmpeg in PATH");
}

VideoEncoder::VideoEncoder(fs::path video, int width, int height, double rate_hz)
    : video_(std::move(video)), width_(width), height_(height) {
  require_ffmpeg("a video");
  ffmpeg_ = std::make_unique<PipedProgram>(ffmpeg_command(
      {"-f", "rawvideo", "-pix_fmt", "rgb24", "-video_size", fmt::format("{}x{}", width, height),
       "-framerate", fmt::format("{:.9g}", rate_hz), "-i", "pipe:0"},
      {"-an", "-c:v", "libx264", "-preset", "veryfast", "-crf", "23", "-pix_fmt", "yuv420p",
       "-x264-params", "threads=1:sliced-threads=0"},
      video_));
}

void VideoEncoder::add(const Canvas& frame) {
  if (frame.width() != width_ || frame.height() != height_)
    throw std::logic_error("VideoEncoder: a frame of another size");
  if (!ffmpeg_->write(frame.pixels().data(), frame.pixels().size())) finish();  // says why
  ++frames_;
}

void VideoEncoder::finish() {
  std::string output;
  const int status = ffmpeg_->finish(&output);
  if (status != 0)
    throw std::runtime_error(fmt::format("ffmpeg failed to encode {} (status {}): {}",
                                         video_.string(), status, output));
}

void add_sound_track(const fs::path& video, const fs::path& audio, double duration_s, const fs::path& out) {
  require_ffmpeg("a video's sound track");
  const std::string duration = fmt::format("{:.6f}", duration_s);
  std::string output;
  const int status = run_program(
      ffmpeg_command({"-i", video.string(), "-i", audio.string()},
                     {"-map", "0:v:0", "-map", "1:a:0", "-c:v", "copy", "-c:a", "aac", "-b:a", "192k",
                      "-af", "apad", "-t", duration},
                     out),
      &output);
  if (status != 0)
    throw std::runtime_error(fmt::format("ffmpeg failed to add the sound track {} to {} (status {}): {}",
                                         audio.string(), video.string(), status, output));
}

}  // namespace sonomap::harness
