// SPDX-License-Identifier: GPL-3.0-or-later
// The binaural stream over a walk, checked on its output signal. BRIRs are unit impulses (a
// dry, centred "room"; scaled by 1 / distance where levels matter), so each sound appears in
// the output as synthesised, at its onset: expected times, pitches and directions come from
// the documented schedule and closed forms, loudness from BS.1770 written out in the test.
#include "../harness/audio_measures.hpp"
#include "audio/listen_stream.hpp"
#include "signal_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <cmath>

using namespace sonomap;
using namespace sonomap::audio;

namespace {

Circle circle_at(std::initializer_list<std::pair<int, float>> bins) {
  Circle c(360);
  for (auto [bin, range] : bins) c.bins[static_cast<size_t>(bin)].range = range;
  return c;
}

SweepConfig quiet_sweep() {
  SweepConfig c;
  c.woosh_unknown = false;
  return c;
}

// Plays `circle` over [0, duration) in frame spans of 1/30 s, the head at `head_yaw`.
ListenAudio walk(ListenStream& stream, const Circle& circle, double duration, double body_yaw = 0.0,
                 const HeadYaw& head_yaw = [](double) { return 0.0; }) {
  const int frames = static_cast<int>(std::ceil(duration * 30.0));
  for (int i = 0; i < frames; ++i)
    stream.play(circle, i / 30.0, std::min(duration, (i + 1) / 30.0), body_yaw, head_yaw);
  return stream.finish(duration);
}

// First sample at or after `from_s` above `fraction` of the signal's peak (left ear).
double onset_after(const std::vector<float>& x, double from_s, double fraction) {
  float peak = 0.0f;
  for (float v : x) peak = std::max(peak, std::abs(v));
  size_t i = static_cast<size_t>(std::max(0.0, from_s) * kFs);
  while (i < x.size() && std::abs(x[i]) < fraction * peak) ++i;
  return i / kFs;
}

// Paper grid, unit impulses scaled by 1 / distance (a near tap is louder).
std::shared_ptr<const BrirSet> distance_brirs() {
  BrirGrid grid = BrirGrid::paper();
  std::vector<BinauralIr> irs;
  for (double d : grid.distances_m)
    for (size_t a = 0; a < grid.azimuths_deg.size(); ++a) {
      BinauralIr ir;
      ir.left.assign(64, 0.0f);
      ir.right.assign(64, 0.0f);
      ir.left[0] = ir.right[0] = static_cast<float>(0.4 / d);
      irs.push_back(ir);
    }
  return std::make_shared<const BrirSet>(kFs, grid, std::move(irs));
}

double rms(const std::vector<float>& x, double from_s, double length_s) {
  const size_t a = static_cast<size_t>(from_s * kFs), n = static_cast<size_t>(length_s * kFs);
  double e = 0.0;
  for (size_t i = a; i < a + n && i < x.size(); ++i) e += double(x[i]) * x[i];
  return std::sqrt(e / n);
}

}  // namespace

TEST_CASE("listen: sweeps repeat every period plus pause, taps at the documented sector times",
          "[listen]") {
  ListenConfig listen;
  listen.period_s = 1.0;
  listen.pause_s = 0.5;
  ListenStream stream(impulse_brirs(), quiet_sweep(), listen);
  // One tap in sectors 0, 9, 18 and 27 (bins 5, 95, 185, 275).
  const ListenAudio out = walk(stream, circle_at({{5, 2.0f}, {95, 2.0f}, {185, 2.0f}, {275, 2.0f}}), 4.0);
  REQUIRE(out.left.size() == static_cast<size_t>(4.0 * kFs));
  REQUIRE(out.taps.size() == 12);  // sweeps at 0, 1.5 and 3.0 s
  size_t i = 0;
  for (int k = 0; k < 3; ++k)
    for (int sector : {0, 9, 18, 27}) {
      // docs/sonification.md: sweep k starts at k (period + pause); sector s at s period / 36.
      const double expected = k * 1.5 + sector * 1.0 / 36.0;
      CHECK(out.taps[i].time_s == Approx(expected));
      CHECK(std::abs(onset_after(out.left, expected - 0.02, 0.01) - expected) < 0.001);
      ++i;
    }
  // The pause is silent: the last tap of sweep 0 (at 0.75 s, 0.1 s long) has ended by 0.9 s.
  CHECK(rms(out.left, 0.9, 0.55) == 0.0);
  CHECK(rms(out.right, 2.4, 0.55) == 0.0);
}

TEST_CASE("listen: cutting the walk into frames changes nothing audible (overlap-add)", "[listen]") {
  const Circle c = circle_at({{5, 1.0f}, {15, 2.0f}, {25, 3.0f}, {185, 0.5f}});
  ListenStream whole(impulse_brirs(), quiet_sweep(), {});
  whole.play(c, 0.0, 3.0, 0.0, [](double) { return 0.0; });
  const ListenAudio a = whole.finish(3.0);
  ListenStream framed(impulse_brirs(), quiet_sweep(), {});
  const ListenAudio b = walk(framed, c, 3.0);
  REQUIRE(a.taps.size() == b.taps.size());
  REQUIRE(a.left.size() == b.left.size());
  double diff = 0.0, peak = 0.0;
  for (size_t i = 0; i < a.left.size(); ++i) {
    diff = std::max(diff, double(std::abs(a.left[i] - b.left[i])));
    peak = std::max(peak, double(std::abs(a.left[i])));
  }
  CHECK(peak > 0.1);
  CHECK(diff < 1e-5 * peak);
}

TEST_CASE("listen: world-locked taps keep their world direction as the head turns, head-locked "
          "ones turn with the head", "[listen]") {
  // An obstacle at bin 90 of a body facing 30 degrees: world azimuth 120.5. The head follows
  // the body for the first sweep, then looks 90 degrees further left (world yaw 120).
  const Circle c = circle_at({{90, 1.5f}});
  const HeadYaw head = [](double t) { return t < 2.0 ? 30.0 : 120.0; };
  for (ListenMode mode : {ListenMode::WorldLocked, ListenMode::HeadLocked}) {
    ListenConfig listen;
    listen.mode = mode;
    ListenStream stream(impulse_brirs(), quiet_sweep(), listen);
    const ListenAudio out = walk(stream, c, 4.0, 30.0, head);
    REQUIRE(out.taps.size() == 2);
    for (const ListenTap& t : out.taps) {
      CHECK(t.body_azimuth_deg == Approx(90.5));
      CHECK(t.world_azimuth_deg == Approx(120.5));
    }
    const bool world = mode == ListenMode::WorldLocked;
    CHECK(out.taps[0].head_azimuth_deg == Approx(90.5));
    CHECK(out.taps[1].head_azimuth_deg == Approx(world ? 0.5 : 90.5));
    CHECK(out.taps[1].brir_azimuth_deg == Approx(world ? 0.0 : 90.0));
  }
}

TEST_CASE("listen: near and far taps are shifted by -4 and +4 semitones within 0.2 semitone",
          "[listen]") {
  ListenConfig listen;
  listen.period_s = 3.6;  // sectors 0.1 s apart: each tap rings alone
  ListenStream stream(impulse_brirs(), quiet_sweep(), listen);
  // 0.8 m (near), 2.0 m (unshifted), 3.6 m (far) in sectors 0, 10, 20.
  const ListenAudio out = walk(stream, circle_at({{5, 0.8f}, {105, 2.0f}, {205, 3.6f}}), 3.0);
  REQUIRE(out.taps.size() == 3);
  double f[3];
  for (int i = 0; i < 3; ++i) {
    const size_t at = static_cast<size_t>(std::llround(i * 1.0 * kFs));  // sector 10 i
    const std::vector<float> segment(out.left.begin() + at, out.left.begin() + at + 4800);
    f[i] = peak_frequency(segment, 300.0, 1300.0);
  }
  const double f0 = SweepConfig{}.tap.fundamental_hz;
  CHECK(12.0 * std::log2(f[1] / f0) == Approx(0.0).margin(0.2));
  CHECK(12.0 * std::log2(f[0] / f[1]) == Approx(-4.0).margin(0.2));
  CHECK(12.0 * std::log2(f[2] / f[1]) == Approx(4.0).margin(0.2));
}

TEST_CASE("listen: the stream is at -16 LUFS within 0.5 LU and at most -1 dBTP", "[listen][loudness]") {
  ListenStream stream(distance_brirs(), quiet_sweep(), {});
  Circle c(360);
  for (auto& b : c.bins) b.range = 2.0f;  // a tap in every sector: the target, not the ceiling, sets the gain
  const ListenAudio out = walk(stream, c, 6.0);
  const double lufs = test::integrated_loudness(out.left, out.right);
  CHECK_FALSE(out.peak_limited);
  CHECK(lufs == Approx(-16.0).margin(0.5));
  CHECK(std::max(test::true_peak_db(out.left), test::true_peak_db(out.right)) <= -1.0);
  CHECK(out.loudness.integrated_lufs == Approx(lufs).margin(0.1));
}

TEST_CASE("listen: one gain for the file: a near tap stays 20 dB louder than one 10x as far, and "
          "sparse taps meet the true-peak ceiling instead of the target", "[listen][loudness]") {
  SweepConfig sweep = quiet_sweep();
  sweep.pitch.near_semitones = sweep.pitch.far_semitones = 0.0;  // one tap sound: levels compare
  ListenStream stream(distance_brirs(), sweep, {});
  // Near (0.4 m) in sector 0, far (4.0 m) in sector 18, over 8 s (four sweeps).
  const ListenAudio out = walk(stream, circle_at({{5, 0.4f}, {185, 4.0f}}), 8.0);
  for (int k = 0; k < 4; ++k) {
    const double near = rms(out.left, 2.0 * k, 0.1), far = rms(out.left, 2.0 * k + 1.0, 0.1);
    CHECK(20.0 * std::log10(near / far) == Approx(20.0).margin(0.5));  // 1 / distance: 10x
  }
  CHECK(out.peak_limited);
  const double peak = std::max(test::true_peak_db(out.left), test::true_peak_db(out.right));
  CHECK(peak <= -1.0);
  CHECK(peak >= -1.3);
  CHECK(test::integrated_loudness(out.left, out.right) < -16.0);
}

TEST_CASE("listen: bad settings and out-of-order spans are refused", "[listen]") {
  ListenConfig bad;
  bad.period_s = 0.0;
  CHECK_THROWS_WITH(ListenStream(impulse_brirs(), quiet_sweep(), bad), Catch::Contains("period"));
  bad = {};
  bad.pause_s = -1.0;
  CHECK_THROWS_WITH(ListenStream(impulse_brirs(), quiet_sweep(), bad), Catch::Contains("pause"));
  ListenStream stream(impulse_brirs(), quiet_sweep(), {});
  const Circle c = circle_at({{5, 1.0f}});
  stream.play(c, 0.0, 1.0, 0.0, [](double) { return 0.0; });
  CHECK_THROWS_WITH(stream.play(c, 0.5, 1.0, 0.0, [](double) { return 0.0; }),
                    Catch::Contains("time order"));
  CHECK_THROWS(stream.finish(0.0));
}

namespace {

// A spherical-head-like set: the ear facing the source hears it first (up to 0.66 ms) and
// louder; a front/back level tilt keeps every azimuth's cues distinct.
std::shared_ptr<const BrirSet> lateral_brirs() {
  BrirGrid grid = BrirGrid::paper();
  std::vector<BinauralIr> irs;
  for (size_t d = 0; d < grid.distances_m.size(); ++d)
    for (double az : grid.azimuths_deg) {
      const double s = std::sin(az * kPi / 180.0), c = std::cos(az * kPi / 180.0);
      const long itd = std::lround(0.00066 * s * kFs);  // > 0: left first
      BinauralIr ir;
      ir.left.assign(128, 0.0f);
      ir.right.assign(128, 0.0f);
      ir.left[static_cast<size_t>(40 + std::max(0L, -itd))] = static_cast<float>(1.2 + 0.4 * s + 0.1 * c);
      ir.right[static_cast<size_t>(40 + std::max(0L, itd))] = static_cast<float>(1.2 - 0.4 * s - 0.1 * c);
      irs.push_back(ir);
    }
  return std::make_shared<const BrirSet>(kFs, grid, std::move(irs));
}

}  // namespace

TEST_CASE("localisation: taps that ring alone are heard at their azimuth; masking noise moves "
          "them", "[listen][localisation]") {
  ListenConfig listen;
  listen.period_s = 36 * 0.15;  // each tap (0.1 s) ends before the next
  ListenStream stream(lateral_brirs(), quiet_sweep(), listen);
  Circle c(360);
  for (auto& b : c.bins) b.range = 2.0f;
  ListenAudio out = walk(stream, c, listen.period_s);
  REQUIRE(out.taps.size() == 36);
  const TapLocalisation alone = localise_taps(out, stream.renderer());
  CHECK(alone.taps == 36);
  // Heard at the grid azimuth played: within half a grid step (1.5 degrees) of the bin centre.
  CHECK(alone.median_error_deg <= 1.5);
  CHECK(alone.p90_error_deg <= 1.5);
  // Independent noise in each ear, 6 dB above the taps' peak, hides their cues.
  std::uint32_t state = 12345u;
  auto noise = [&] {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / 16777216.0f - 0.5f;
  };
  float peak = 0.0f;
  for (float v : out.left) peak = std::max(peak, std::abs(v));
  for (size_t i = 0; i < out.left.size(); ++i) {
    out.left[i] += 4.0f * peak * noise();
    out.right[i] += 4.0f * peak * noise();
  }
  const TapLocalisation masked = localise_taps(out, stream.renderer());
  CHECK(masked.median_error_deg > 10.0);
}
