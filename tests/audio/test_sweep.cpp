// SPDX-License-Identifier: GPL-3.0-or-later
// The sweep, checked on its output signal. BRIRs here are unit impulses (a dry, centred
// "room"), so every sound appears in the output exactly as synthesised, at its onset: the
// expected values come from the schedule's definition and from closed forms.
#include "audio/sweep.hpp"
#include "signal_support.hpp"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cmath>
#include <complex>

using namespace sonomap;
using namespace sonomap::audio;

namespace {


Circle circle_with(std::initializer_list<std::pair<int, float>> bins) {
  Circle c(360);
  for (auto [bin, range] : bins) c.bins[bin].range = range;
  return c;
}

double correlation(const float* a, const float* b, size_t n) {
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = 0; i < n; ++i) ab += a[i] * b[i], aa += a[i] * a[i], bb += b[i] * b[i];
  return ab / std::sqrt(aa * bb + 1e-30);
}

}  // namespace

TEST_CASE("the first taps of a sweep are ahead, then to the left", "[sweep]") {
  Circle c(360);
  for (auto& b : c.bins) b.range = 2.0f;
  SweepConfig config;
  const auto events = schedule_sweep(c, config, BrirGrid::paper());
  REQUIRE(events.size() == 36);
  // Sector 0 holds [0, 10) degrees: straight ahead; sector 1 the next 10 degrees to the left.
  CHECK(events[0].time_s == 0.0);
  CHECK(events[0].azimuth_deg >= 0.0);
  CHECK(events[0].azimuth_deg < 10.0);
  CHECK(events[1].azimuth_deg >= 10.0);
  CHECK(events[1].azimuth_deg < 20.0);
  CHECK(events[9].azimuth_deg >= 90.0);  // a quarter turn later: the left side
  CHECK(events[9].azimuth_deg < 100.0);
  for (size_t i = 1; i < events.size(); ++i) {
    CHECK(events[i].time_s > events[i - 1].time_s);
    CHECK(events[i].azimuth_deg > events[i - 1].azimuth_deg);
  }
}

TEST_CASE("each sector taps its nearest bin at the nearest BRIR distance", "[sweep]") {
  // Sector 4 (bins 40..49): nearest at bin 47, 1.13 m -> BRIR 1.2 m; x2 scale for sector 20.
  Circle c = circle_with({{41, 3.0f}, {47, 1.13f}, {49, 2.0f}, {203, 0.05f}, {351, 9.0f}});
  SweepConfig config;
  config.woosh_unknown = false;
  auto events = schedule_sweep(c, config, BrirGrid::paper());
  REQUIRE(events.size() == 3);
  CHECK(events[0].sector == 4);
  CHECK(events[0].azimuth_deg == Approx(47.5));
  CHECK(events[0].range_m == Approx(1.13));
  CHECK(events[0].brir_distance_m == Approx(1.2));
  CHECK(events[0].brir_azimuth_deg == Approx(48.0));  // grid every 3 degrees
  CHECK(events[0].pitch_semitones == -4);              // below 1.5 m
  CHECK(events[1].brir_distance_m == Approx(0.4));     // clamped up to the grid's 0.4 m
  CHECK(events[2].brir_distance_m == Approx(4.0));     // clamped down to 4.0 m
  CHECK(events[2].pitch_semitones == 4);               // beyond 2.5 m
  CHECK(events[2].brir_azimuth_deg == Approx(-9.0));   // 351.5 degrees = -8.5 -> -9
  config.environment_scale = 2.0;
  events = schedule_sweep(c, config, BrirGrid::paper());
  CHECK(events[0].brir_distance_m == Approx(2.4));  // 2.26 m -> 2.4 m
  CHECK(events[0].pitch_semitones == 0);
  config.pitch.inverted = true;
  config.environment_scale = 1.0;
  events = schedule_sweep(c, config, BrirGrid::paper());
  CHECK(events[0].pitch_semitones == 4);  // parking-sensor convention: near is higher
}

TEST_CASE("onsets in the output follow the sweep schedule within 1 ms", "[sweep]") {
  Circle c(360);
  for (int s = 0; s < 36; s += 4) c.bins[s * 10 + 3].range = 1.0f + 0.1f * (s % 7);
  SweepConfig config;
  config.woosh_unknown = false;
  config.period_s = 1.5;
  SweepRenderer renderer(impulse_brirs(), config);
  const SweepAudio out = renderer.render(c);
  REQUIRE(out.events.size() == 9);
  float peak = 0.0f;
  for (float v : out.left) peak = std::max(peak, std::abs(v));
  REQUIRE(peak > 0.1f);
  for (const SweepEvent& e : out.events) {
    const double expected = e.sector * 1.5 / 36.0;
    CHECK(e.time_s == Approx(expected));
    // First sample above 1% of the peak after the previous sound has died away.
    const size_t from = static_cast<size_t>(std::max(0.0, expected - 0.02) * kFs);
    size_t onset = from;
    while (onset < out.left.size() && std::abs(out.left[onset]) < 0.01f * peak) ++onset;
    CHECK(std::abs(onset / kFs - expected) < 0.001);
  }
}

TEST_CASE("per-sector onsets can be given explicitly", "[sweep]") {
  SweepConfig config;
  config.woosh_unknown = false;
  for (int s = 0; s < 36; ++s) config.sector_onsets_s.push_back(0.1 * s * s / 36.0);
  const auto events = schedule_sweep(circle_with({{125, 1.0f}}), config, BrirGrid::paper());
  REQUIRE(events.size() == 1);
  CHECK(events[0].time_s == Approx(0.1 * 12 * 12 / 36.0));
  config.sector_onsets_s[5] = config.sector_onsets_s[4];
  CHECK_THROWS_AS(schedule_sweep(circle_with({}), config, BrirGrid::paper()), std::invalid_argument);
}

TEST_CASE("unknown sectors play the woosh, known ones the tap", "[sweep]") {
  // Sector 0 known, sector 9 unknown and alone in a quiet stretch.
  Circle c(360);
  for (int bin = 0; bin < 360; ++bin)
    if (bin / 10 != 9 && bin / 10 != 8 && bin / 10 != 10 && bin / 10 != 11) c.bins[bin].range = 2.0f;
  SweepConfig config;
  config.period_s = 36 * 0.3;  // 0.3 s between sectors: sounds never overlap
  SweepRenderer renderer(impulse_brirs(), config);
  const SweepAudio out = renderer.render(c);
  const std::vector<float>& woosh = renderer.sound(SoundKind::Woosh, 0.0);
  const std::vector<float>& tap = renderer.sound(SoundKind::Tap, 0.0);
  int wooshes = 0;
  for (const SweepEvent& e : out.events) {
    const size_t at = static_cast<size_t>(std::llround(e.time_s * kFs));
    const bool unknown = e.sector >= 8 && e.sector <= 11;
    CHECK((e.sound == SoundKind::Woosh) == unknown);
    if (e.sector == 9) {
      ++wooshes;
      CHECK(std::isnan(e.range_m));
      CHECK(correlation(out.left.data() + at, woosh.data(), woosh.size()) > 0.999);
      CHECK(std::abs(correlation(out.left.data() + at, tap.data(), tap.size())) < 0.3);
    }
    if (e.sector == 20) {
      CHECK(correlation(out.right.data() + at, tap.data(), tap.size()) > 0.999);
      CHECK(std::abs(correlation(out.right.data() + at, woosh.data(), tap.size())) < 0.3);
    }
  }
  CHECK(wooshes == 1);
}

TEST_CASE("shifted taps are 2^(+-4/12) apart in pitch, within 1%", "[sweep]") {
  SweepConfig config;
  config.woosh_unknown = false;
  config.period_s = 36 * 0.3;
  // 1.0 m -> -4 semitones, 2.0 m -> unshifted, 3.5 m -> +4 semitones.
  const Circle c = circle_with({{5, 1.0f}, {105, 2.0f}, {205, 3.5f}});
  SweepRenderer renderer(impulse_brirs(), config);
  const SweepAudio out = renderer.render(c);
  REQUIRE(out.events.size() == 3);
  const double f0 = config.tap.fundamental_hz;
  double measured[3];
  for (int i = 0; i < 3; ++i) {
    const size_t at = static_cast<size_t>(std::llround(out.events[i].time_s * kFs));
    const std::vector<float> segment(out.left.begin() + at, out.left.begin() + at + 6000);
    measured[i] = peak_frequency(segment, 0.6 * f0, 1.5 * f0);
  }
  CHECK(out.events[0].pitch_semitones == -4);
  CHECK(out.events[2].pitch_semitones == 4);
  CHECK(measured[1] == Approx(f0).epsilon(0.01));
  CHECK(measured[0] / measured[1] == Approx(std::pow(2.0, -4.0 / 12.0)).epsilon(0.01));
  CHECK(measured[2] / measured[1] == Approx(std::pow(2.0, 4.0 / 12.0)).epsilon(0.01));
}

TEST_CASE("object mode plays three separated objects once each, at their nearest points",
          "[sweep][objects]") {
  Circle c(360);
  // Three walls seen at a slant (range grows away from the foot point), far apart in angle;
  // everything else unknown. A fourth object crosses bin 0 and is the farthest.
  for (int k = 20; k <= 40; ++k) c.bins[k].range = 1.0f + 0.02f * std::abs(k - 31);
  for (int k = 100; k <= 130; ++k) c.bins[k].range = 2.0f + 0.02f * std::abs(k - 122);
  for (int k = 250; k <= 270; ++k) c.bins[k].range = 3.0f + 0.02f * std::abs(k - 255);
  SweepConfig config;
  config.mode = SweepMode::Objects;
  config.period_s = 36 * 0.3;
  SweepRenderer renderer(impulse_brirs(), config);
  SweepAudio out = renderer.render(c);
  REQUIRE(out.events.size() == 3);
  const double azimuths[] = {31.5, 122.5, 255.5}, ranges[] = {1.0, 2.0, 3.0};
  for (int i = 0; i < 3; ++i) {
    CHECK(out.events[i].sound == SoundKind::Tap);
    CHECK(out.events[i].azimuth_deg == Approx(azimuths[i]));
    CHECK(out.events[i].range_m == Approx(ranges[i]));
    CHECK(out.events[i].sector == static_cast<int>(azimuths[i]) / 10);
  }
  // Exactly three sounds in the signal: count rising edges of the 5 ms energy envelope.
  float peak = 0.0f;
  for (float v : out.left) peak = std::max(peak, std::abs(v));
  int sounds = 0;
  bool active = false;
  const size_t hop = 240;
  for (size_t i = 0; i + hop < out.left.size(); i += hop) {
    float m = 0.0f;
    for (size_t k = i; k < i + hop; ++k) m = std::max(m, std::abs(out.left[k]));
    if (!active && m > 0.05f * peak) ++sounds, active = true;
    if (active && m < 0.001f * peak) active = false;
  }
  CHECK(sounds == 3);

  // A range jump > 0.5 m per degree splits one run into two objects.
  for (int k = 131; k <= 140; ++k) c.bins[k].range = 2.8f;
  CHECK(split_objects(c, 0.5).size() == 4);
  // Objects crossing bin 0 stay one object; only the N nearest are played.
  for (int k = 350; k < 360; ++k) c.bins[k].range = 3.8f;
  for (int k = 0; k < 5; ++k) c.bins[k].range = 3.7f;
  const auto objects = split_objects(c, 0.5);
  REQUIRE(objects.size() == 5);
  CHECK(objects.back().first_bin == 350);
  CHECK(objects.back().last_bin == 4);
  CHECK(objects.back().nearest_bin == 0);
  config.max_objects = 2;
  const auto events = schedule_sweep(c, config, BrirGrid::paper());
  REQUIRE(events.size() == 2);
  CHECK(events[0].range_m == Approx(1.0));
  CHECK(events[1].range_m == Approx(2.0));
}

TEST_CASE("filters: field of view, distance window and tap count", "[sweep]") {
  Circle c(360);
  for (int k = 0; k < 360; ++k) c.bins[k].range = 0.5f + 0.01f * k;  // 0.5 .. 4.09 m
  SweepConfig config;
  config.filter.fov_centre_deg = 90.0;
  config.filter.fov_width_deg = 60.0;
  auto events = schedule_sweep(c, config, BrirGrid::paper());
  REQUIRE(!events.empty());
  for (const auto& e : events) CHECK(std::abs(e.azimuth_deg - 90.0) <= 30.0);
  CHECK(events.size() == 6);  // sectors 6..11 have their nearest bins at 60.5 .. 110.5
  config.filter = {};
  config.filter.min_range_m = 0.95;
  config.filter.max_range_m = 2.05;
  events = schedule_sweep(c, config, BrirGrid::paper());
  for (const auto& e : events) CHECK((e.range_m >= 0.95 && e.range_m <= 2.05));
  CHECK(events.size() == 11);  // nearest bins 50, 60, ..., 150 (1.0 .. 2.0 m)
  config.filter = {};
  config.filter.max_taps = 3;
  events = schedule_sweep(c, config, BrirGrid::paper());
  REQUIRE(events.size() == 3);
  CHECK(events[2].range_m == Approx(0.5f + 0.01f * 20));
}

TEST_CASE("a circle with NaN ranges or a BRIR set at another rate is refused", "[sweep]") {
  Circle c(360);
  c.bins[17].range = NAN;
  CHECK_THROWS_AS(schedule_sweep(c, SweepConfig{}, BrirGrid::paper()), std::invalid_argument);
  c.bins[17].range = -1.0f;
  CHECK_THROWS_AS(schedule_sweep(c, SweepConfig{}, BrirGrid::paper()), std::invalid_argument);
  BrirGrid grid{{0.0}, {1.0}};
  auto at_44k = std::make_shared<const BrirSet>(
      44100.0, grid, std::vector<BinauralIr>{{std::vector<float>(8, 0.0f), std::vector<float>(8, 0.0f)}});
  CHECK_THROWS_AS(SweepRenderer(at_44k, SweepConfig{}), std::invalid_argument);
}

TEST_CASE("rendering is deterministic and independent of the thread count", "[sweep]") {
  Circle c(360);
  for (int k = 0; k < 200; ++k) c.bins[k].range = 0.4f + 0.02f * k;
  SweepRenderer renderer(impulse_brirs(256, 10), SweepConfig{});
  SweepAudio one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = renderer.render(c);
  }
  renderer.clear_cache();
  two = renderer.render(c);
  CHECK(one.left == two.left);
  CHECK(one.right == two.right);
}

TEST_CASE("a range plays the nearest grid distance: exactly on a grid value that value, a "
          "midpoint the larger one",
          "[sweep]") {
  // A grid with 1.0 m, as float SOFA files give it (1.0f, 0.5f are exact; 1.5 via float).
  const std::vector<double> half_metres{0.5, double(1.0f), double(1.5f), 2.0};
  CHECK(nearest_distance_index(half_metres, 1.0) == 1);
  CHECK(nearest_distance_index(half_metres, 0.76) == 1);
  CHECK(nearest_distance_index(half_metres, 0.74) == 0);
  // The paper's grid (0.4 m steps, built as sums): 1.0 m is halfway between 0.8 and 1.2.
  const BrirGrid paper = BrirGrid::paper();
  CHECK(paper.distances_m[nearest_distance_index(paper.distances_m, 1.0)] == Approx(1.2));
  CHECK(paper.distances_m[nearest_distance_index(paper.distances_m, 0.99)] == Approx(0.8));
  CHECK(paper.distances_m[nearest_distance_index(paper.distances_m, 1.2)] == Approx(1.2));
  // The same grid read back from float files: 0.8f and 1.2f are not 0.8 and 1.2.
  std::vector<double> from_floats;
  for (double d : paper.distances_m) from_floats.push_back(double(float(d)));
  CHECK(from_floats[nearest_distance_index(from_floats, 1.0)] == Approx(1.2));
  // The schedule and the renderer agree: a tap at exactly 1.0 m on a 0.5 m grid uses 1.0 m.
  BrirGrid grid = paper;
  grid.distances_m = half_metres;
  SweepConfig config;
  const auto events = schedule_sweep(circle_with({{5, 1.0f}}), config, grid);
  REQUIRE(!events.empty());
  CHECK(events.front().brir_distance_m == 1.0);
}
