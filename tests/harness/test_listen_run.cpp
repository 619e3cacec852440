// SPDX-License-Identifier: GPL-3.0-or-later
// `run --listen` heard through measured ears (the MIT KEMAR HRIRs of Debian's libmysofa1): a
// post at +90 degrees (the camera looks left, so the map holds it) reaches the left ear first
// and louder; once the head has turned 90 degrees left it is straight ahead in world-locked
// mode and still at +90 in head-locked mode. Interaural time and level differences are measured
// here on listen.wav read back (cross-correlation, energies), not by the code that rendered it;
// the loudness by BS.1770 written out (audio_measures.hpp).
#include "audio_measures.hpp"
#include "harness/app/run.hpp"
#include "harness/formats/run_summary.hpp"
#include "harness/formats/wav_io.hpp"
#include "run_support.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>

using namespace sonomap;
namespace fs = std::filesystem;

namespace {

constexpr double kFs = 48000.0;

// The post 1.5 m to the left of a body that stands still facing +x; the head looks ahead until
// 2.9 s and 90 degrees left from 3.1 s. Sweeps start at 0, 2 and 4 s.
const std::string kPostScene =
    "name: post_left\n"
    "frames: 60\n"
    "sensor:\n"
    "  width: 80\n"
    "  height: 60\n"
    "  intrinsics: {fx: 60, fy: 60, cx: 39.5, cy: 29.5}\n"
    "  rate: 10\n"
    "  mounting: {yaw: 90}\n"
    "  noise: {model: none}\n"
    "body:\n"
    "  interpolation: linear_slerp\n"
    "  keyframes:\n"
    "    - {time: 0.0, position: [0.0, 0.0, 1.5], yaw: 0}\n"
    "head:\n"
    "  relative_to: body\n"
    "  keyframes:\n"
    "    - {time: 2.9, yaw: 0}\n"
    "    - {time: 3.1, yaw: 90}\n"
    "static:\n"
    "  - name: post\n"
    "    cylinder: {radius: 0.1, height: 2.5}\n"
    "    pose: {position: [0.0, 1.5, 0.0]}\n";

struct Cues {
  double itd_ms = 0.0;  // > 0: the left ear leads
  double ild_db = 0.0;  // > 0: louder on the left
};

// The cues of the first sound in [from_s, to_s): its onset is the first sample where either
// ear passes a fifth of the span's peak; ITD is the lag of the interaural cross-correlation's
// peak (within +-1 ms) over [onset - 0.5 ms, onset + 2.5 ms), ILD the energy ratio there.
Cues first_sound_cues(const harness::StereoAudio& a, double from_s, double to_s) {
  const size_t from = static_cast<size_t>(from_s * kFs), to = static_cast<size_t>(to_s * kFs);
  float peak = 0.0f;
  for (size_t i = from; i < to; ++i) peak = std::max({peak, std::abs(a.left[i]), std::abs(a.right[i])});
  REQUIRE(peak > 0.0f);
  size_t onset = from;
  while (std::abs(a.left[onset]) < 0.2f * peak && std::abs(a.right[onset]) < 0.2f * peak) ++onset;
  const size_t w0 = onset - 24, n = 144;
  long best_lag = 0;
  double best = -1e300;
  for (long lag = -48; lag <= 48; ++lag) {  // right[i + lag] against left[i]
    double c = 0.0;
    for (size_t i = 0; i < n; ++i) c += double(a.left[w0 + i]) * a.right[w0 + i + lag];
    if (c > best) best = c, best_lag = lag;
  }
  double el = 0.0, er = 0.0;
  for (size_t i = 0; i < n; ++i)
    el += double(a.left[w0 + i]) * a.left[w0 + i], er += double(a.right[w0 + i]) * a.right[w0 + i];
  return {1000.0 * best_lag / kFs, 10.0 * std::log10(el / er)};
}

harness::StereoAudio listen_to_post(const test::ScratchDir& dir, const std::string& mode) {
  harness::RunOptions o;
  o.scenario = dir.write("post.yaml", kPostScene);
  o.out = dir.path() / ("run-" + mode);
  o.overrides = {"listen.woosh=false", "listen.mode=" + mode, "edf.enabled=false"};
  o.picture_frames = {-1};
  o.sweep_frames = {-1};
  o.listen = true;
  o.quiet = true;
  harness::run_scenario(o);
  return harness::read_wav(o.out / "listen.wav");
}

}  // namespace

TEST_CASE("listen.wav: a post at +90 degrees reaches the left ear 0.5-0.8 ms first and louder; "
          "after the head turns 90 degrees left it is ahead (world-locked) or still left "
          "(head-locked)", "[listen][run]") {
  test::ScratchDir dir("listen-post");
  const harness::StereoAudio world = listen_to_post(dir, "world_locked");
  REQUIRE(world.left.size() == static_cast<size_t>(6.0 * kFs));
  const Cues before = first_sound_cues(world, 0.0, 2.0);
  CHECK(before.itd_ms >= 0.5);
  CHECK(before.itd_ms <= 0.8);
  CHECK(before.ild_db > 3.0);
  const Cues after = first_sound_cues(world, 4.0, 6.0);
  CHECK(std::abs(after.itd_ms) <= 0.1);
  CHECK(std::abs(after.ild_db) < 3.0);

  const harness::StereoAudio head = listen_to_post(dir, "head_locked");
  const Cues locked = first_sound_cues(head, 4.0, 6.0);
  CHECK(locked.itd_ms >= 0.5);
  CHECK(locked.itd_ms <= 0.8);
  CHECK(locked.ild_db > 3.0);
  UNSCOPED_INFO("ITD before " << before.itd_ms << " ms, ILD " << before.ild_db << " dB; after (world) "
                << after.itd_ms << " ms, " << after.ild_db << " dB; after (head) " << locked.itd_ms
                << " ms, " << locked.ild_db << " dB");
}

TEST_CASE("listen.wav of the smoke walk: -16 LUFS within 0.5 LU, true peak <= -1 dBTP, every "
          "tap in listen_events.csv and the level in summary.json", "[listen][run]") {
  test::ScratchDir dir("listen-smoke");
  harness::RunOptions o = test::smoke_run(dir.path() / "run", "vdb_gpdf", 60);
  o.listen = true;
  o.overrides.push_back("edf.enabled=false");
  harness::run_scenario(o);
  const harness::StereoAudio a = harness::read_wav(o.out / "listen.wav");
  REQUIRE(a.left.size() == static_cast<size_t>(2.0 * kFs));  // 60 frames at 30 Hz
  const double lufs = test::integrated_loudness(a.left, a.right);
  CHECK(lufs == Approx(-16.0).margin(0.5));
  CHECK(std::max(test::true_peak_db(a.left), test::true_peak_db(a.right)) <= -1.0);
  const harness::RunSummary s = harness::read_run_summary(o.out);
  REQUIRE(s.listen);
  CHECK(s.listen->loudness_lufs == Approx(lufs).margin(0.1));
  CHECK(s.listen->mode == "world_locked");
  std::ifstream events(o.out / "listen_events.csv");
  std::string line;
  int rows = -1;  // the header
  while (std::getline(events, line)) ++rows;
  CHECK(rows == s.listen->taps);
  CHECK(rows == 36);  // one sweep of 2 s: every sector a tap or a woosh
}
