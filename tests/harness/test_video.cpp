// SPDX-License-Identifier: GPL-3.0-or-later
// run --video: run.mp4 measured with ffprobe (Debian's ffmpeg package), not with sonomap's code.
#include "cli_support.hpp"
#include "run_support.hpp"
#include "test_scenario_files.hpp"
#include "../skip.hpp"

#include "harness/app/video_encoder.hpp"
#include "harness/app/video_maker.hpp"
#include "harness/formats/wav_io.hpp"
#include "harness/support/subprocess.hpp"

#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

namespace fs = std::filesystem;
using sonomap::test::ScratchDir;

namespace {

constexpr double kSmokeRateHz = 30.0;  // scenes/smoke.yaml: sensor.rate

// ffprobe's key=value lines for one stream ("v:0", "a:0"); empty when there is no such stream.
std::map<std::string, std::string> probe(const fs::path& file, const std::string& stream) {
  std::string output;
  const int status = sonomap::harness::run_program(
      {"ffprobe", "-v", "error", "-select_streams", stream, "-count_frames", "-show_entries",
       "stream=codec_type,nb_read_frames,r_frame_rate,duration", "-of", "default=noprint_wrappers=1",
       file.string()},
      &output);
  REQUIRE(status == 0);
  std::map<std::string, std::string> values;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);)
    if (const auto eq = line.find('='); eq != std::string::npos) values[line.substr(0, eq)] = line.substr(eq + 1);
  return values;
}

double rate_of(const std::string& fraction) {  // "30/1"
  const auto slash = fraction.find('/');
  return std::stod(fraction.substr(0, slash)) / std::stod(fraction.substr(slash + 1));
}

bool have_ffmpeg() {
  return sonomap::harness::program_in_path("ffmpeg") && sonomap::harness::program_in_path("ffprobe");
}

}  // namespace

TEST_CASE("run --video: one picture per sensor frame at the sensor's rate, the run's length, "
          "and listen.wav as its sound track, as long as the video within one frame",
          "[video]") {
  if (!have_ffmpeg()) SONOMAP_SKIP("ffmpeg/ffprobe not installed (ci/install-deps installs them)");
  ScratchDir scratch("video-run");
  const int frames = 12;
  auto o = sonomap::test::smoke_run(scratch.path() / "out", "vdb_gpdf", frames);
  o.every = 5;
  o.video = true;
  sonomap::harness::run_scenario(o);
  const fs::path mp4 = o.out / "run.mp4";
  REQUIRE(fs::is_regular_file(mp4));
  CHECK_FALSE(fs::exists(o.out / "run.video-only.mp4"));
  const auto video = probe(mp4, "v:0");
  CHECK(video.at("codec_type") == "video");
  CHECK(std::stoi(video.at("nb_read_frames")) == frames);
  CHECK(rate_of(video.at("r_frame_rate")) == Approx(kSmokeRateHz));
  CHECK(std::stod(video.at("duration")) == Approx(frames / kSmokeRateHz).margin(0.5 / kSmokeRateHz));
  // --video implies --listen: the stream the wearer hears is the sound track.
  CHECK(fs::is_regular_file(o.out / "listen.wav"));
  const auto audio = probe(mp4, "a:0");
  REQUIRE(audio.count("duration"));
  CHECK(audio.at("codec_type") == "audio");
  CHECK(std::stod(audio.at("duration")) == Approx(std::stod(video.at("duration"))).margin(1.0 / kSmokeRateHz));
}

TEST_CASE("run --video: two runs give byte-identical run.mp4", "[video][determinism]") {
  if (!have_ffmpeg()) SONOMAP_SKIP("ffmpeg/ffprobe not installed (ci/install-deps installs them)");
  ScratchDir scratch("video-determinism");
  std::vector<std::string> files;
  for (int k = 0; k < 2; ++k) {
    auto o = sonomap::test::smoke_run(scratch.path() / ("out" + std::to_string(k)), "vdb_gpdf", 8);
    o.every = 3;
    o.video = true;
    sonomap::harness::run_scenario(o);
    files.push_back(sonomap::test::text_of(o.out / "run.mp4"));
  }
  CHECK(files[0].size() > 1000);
  CHECK(files[0] == files[1]);
}

TEST_CASE("a sound track is padded or cut to the video's length: equal within one frame",
          "[video]") {
  if (!have_ffmpeg()) SONOMAP_SKIP("ffmpeg/ffprobe not installed (ci/install-deps installs them)");
  ScratchDir scratch("video-sound");
  const int frames = 15;
  const double rate = 25.0, sample_rate = 48000.0;
  const fs::path silent = scratch.path() / "silent.mp4";
  sonomap::harness::VideoEncoder encoder(silent, 64, 48, rate);
  for (int i = 0; i < frames; ++i) {
    sonomap::harness::Canvas frame(64, 48, {static_cast<std::uint8_t>(10 * i), 0, 0});
    encoder.add(frame);
  }
  encoder.finish();
  // A 440 Hz tone shorter (0.3 s) and longer (1.7 s) than the 0.6 s video.
  for (double seconds : {0.3, 1.7}) {
    INFO("sound track of " << seconds << " s");
    std::vector<float> tone(static_cast<size_t>(seconds * sample_rate));
    for (size_t i = 0; i < tone.size(); ++i) tone[i] = 0.25f * std::sin(2 * M_PI * 440.0 * i / sample_rate);
    const fs::path wav = scratch.path() / "tone.wav", out = scratch.path() / "with-sound.mp4";
    sonomap::harness::write_wav(wav, sample_rate, tone, tone);
    sonomap::harness::add_sound_track(silent, wav, frames / rate, out);
    const auto video = probe(out, "v:0"), audio = probe(out, "a:0");
    REQUIRE(audio.count("duration"));
    CHECK(std::stoi(video.at("nb_read_frames")) == frames);
    CHECK(std::stod(audio.at("duration")) == Approx(std::stod(video.at("duration"))).margin(1.0 / rate));
    CHECK(std::stod(video.at("duration")) == Approx(frames / rate).margin(0.5 / rate));
  }
}

TEST_CASE("run --video without ffmpeg: exit 2 naming ffmpeg, nothing written", "[video][cli]") {
  ScratchDir scratch("video-no-ffmpeg");
  const fs::path out = scratch.path() / "out";
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", (scratch.path() / "no-programs-here").c_str(), 1);
  const auto r = sonomap::test::run_sonomap({"run", sonomap::test::shipped("scenes/smoke.yaml").string(),
                                             "--out", out.string(), "--frames", "2", "--pictures", "-1",
                                             "--sweeps", "-1", "--video"});
  ::setenv("PATH", path.c_str(), 1);
  CHECK(r.status == 2);
  CHECK(r.output.find("ffmpeg") != std::string::npos);
  CHECK(sonomap::test::nothing_written(out));
}

TEST_CASE("the circle panel marks the sector the sweep plays at the frame's time", "[video]") {
  // Sector s of 36 starts s * 2 s / 36 into each 2 s sweep (audio/sweep.hpp) and spans
  // bearings [10 s, 10 s + 10) degrees counter-clockwise from ahead; the panel shows ahead up.
  sonomap::RasterConfig raster;
  sonomap::harness::RunVideo video(fs::temp_directory_path(), "probe", "none", raster, 1, {});
  const int w = sonomap::harness::RunVideo::kWidth / 2, h = sonomap::harness::RunVideo::kHeight / 2;
  const double cx = w + w / 2.0, top = 24, cy = top + (h - top) / 2.0;
  const double radius = 0.46 * (h - top) + 4.5;  // the mark just outside the ring
  for (int sector : {0, 9, 20, 35}) {
    sonomap::Frame frame;
    frame.time = 4.0 + (sector + 0.5) * 2.0 / 36;  // the third sweep, mid-sector
    const sonomap::harness::Canvas picture = video.draw(frame);
    auto marked = [&](double bearing_deg) {
      const double b = bearing_deg * M_PI / 180.0;
      const auto rgb = picture.at(static_cast<int>(std::lround(cx - radius * std::sin(b))),
                                  static_cast<int>(std::lround(cy - radius * std::cos(b))));
      return rgb[0] > 200 && rgb[1] > 150 && rgb[2] < 80;  // yellow
    };
    INFO("sector " << sector);
    CHECK(marked(sector * 10.0 + 5.0));
    CHECK_FALSE(marked(sector * 10.0 + 5.0 + 90.0));
    CHECK_FALSE(marked(sector * 10.0 + 5.0 - 30.0));
  }
}
