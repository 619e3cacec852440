// SPDX-License-Identifier: GPL-3.0-or-later
// Room acoustics of the synthesised BRIRs, with an omnidirectional "head" (every HRIR a unit
// impulse) so that the expected values are closed forms of the geometry: 1/r spreading, mirror
// images, Sabine/Eyring, Schroeder decay.
#include "audio/brir_synth.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <numeric>
#include <stdexcept>

using namespace sonomap::audio;

namespace {

constexpr double kFs = 48000.0;
constexpr double kC = 343.0;

// Six directions (+-x, +-y, +-z), each HRIR a unit impulse: an omni receiver per ear.
HrirSet omni_hrirs() {
  HrirSet h;
  h.sample_rate = kFs;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {1, -1}) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[axis] = sign;
      h.directions.push_back(d);
      BinauralIr ir{std::vector<float>(32, 0.0f), std::vector<float>(32, 0.0f)};
      ir.left[0] = ir.right[0] = 1.0f;
      h.irs.push_back(ir);
    }
  return h;
}

double energy(const std::vector<float>& x, size_t from, size_t to) {
  double e = 0.0;
  for (size_t i = from; i < std::min(to, x.size()); ++i) e += double(x[i]) * x[i];
  return e;
}

// Energy of the arrival at `seconds`, in a +-0.5 ms window (the fractional-delay kernel).
double arrival_energy(const std::vector<float>& x, double seconds) {
  const long c = std::lround(seconds * kFs), w = 24;
  return energy(x, static_cast<size_t>(std::max(0L, c - w)), static_cast<size_t>(c + w));
}

// RT60 from Schroeder backward integration: the -5 .. -25 dB span of the energy decay curve,
// fitted by least squares and extrapolated to 60 dB (T20).
double schroeder_rt60(const std::vector<float>& x) {
  std::vector<double> edc(x.size());
  double acc = 0.0;
  for (size_t i = x.size(); i-- > 0;) edc[i] = (acc += double(x[i]) * x[i]);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double db = 10.0 * std::log10(edc[i] / edc[0]);
    if (db > -5.0 || db < -25.0) continue;
    const double t = i / kFs;
    sx += t, sy += db, sxx += t * t, sxy += t * db, ++n;
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);  // dB per second
  return -60.0 / slope;
}

}  // namespace

TEST_CASE("Sabine and Eyring: closed forms and their agreement for small absorption", "[room]") {
  ShoeboxRoom room;  // 5 x 4 x 3 m: V = 60 m^3, S = 94 m^2
  CHECK(room.volume() == Approx(60.0));
  CHECK(room.surface() == Approx(94.0));
  CHECK(sabine_rt60(room, 0.2) == Approx(0.161 * 60.0 / (94.0 * 0.2)));
  CHECK(eyring_rt60(room, 0.2) < sabine_rt60(room, 0.2));  // Eyring: -ln(1 - a) > a
  CHECK(eyring_rt60(room, 0.01) == Approx(sabine_rt60(room, 0.01)).epsilon(0.01));
  CHECK(eyring_absorption(room, eyring_rt60(room, 0.3)) == Approx(0.3));
  CHECK(sabine_absorption(room, sabine_rt60(room, 0.3)) == Approx(0.3));
}

TEST_CASE("synthetic BRIR: RT60 by Schroeder integration within 10% of the target", "[room]") {
  const HrirSet hrirs = omni_hrirs();
  for (double target : {0.3, 0.6}) {
    BrirSynthConfig config;
    config.rt60 = target;
    config.max_order = 2;
    config.length_s = 1.2 * target;
    const BrirSynthesizer synth(hrirs, config);
    const BinauralIr ir = synth.synthesize(40.0, 2.0);
    INFO("target " << target);
    CHECK(schroeder_rt60(ir.left) == Approx(target).epsilon(0.10));
    CHECK(schroeder_rt60(ir.right) == Approx(target).epsilon(0.10));
  }
  // Per-band RT60s: white noise carries most of its energy above 3 kHz, so a longer decay in
  // the 4 and 8 kHz bands lengthens the broadband decay well beyond the other bands' 0.3 s.
  BrirSynthConfig config;
  config.max_order = 1;
  config.rt60 = 0.3;
  config.band_rt60 = {0.3, 0.3, 0.3, 0.3, 0.3, 0.6, 0.6};
  config.length_s = 0.7;
  const BinauralIr banded = BrirSynthesizer(hrirs, config).synthesize(0.0, 1.0);
  CHECK(schroeder_rt60(banded.left) > 0.45);
  CHECK(schroeder_rt60(banded.left) < 0.65);
}

TEST_CASE("direct sound falls 6 dB per doubling of distance, the D/R ratio falls too", "[room]") {
  BrirSynthConfig config;
  config.rt60 = 0.4;
  config.max_order = 2;
  config.length_s = 0.4;
  const BrirSynthesizer synth(omni_hrirs(), config);
  double previous_level = 0.0, previous_drr = 1e9;
  for (double d : {0.4, 0.8, 1.6, 3.2}) {
    const BinauralIr ir = synth.synthesize(90.0, d);
    const double direct = arrival_energy(ir.left, d / kC);
    const size_t end_direct = static_cast<size_t>(std::lround(d / kC * kFs)) + 24;
    const double reverberant = energy(ir.left, end_direct, ir.left.size());
    const double level = 10.0 * std::log10(direct);
    const double drr = 10.0 * std::log10(direct / reverberant);
    INFO("distance " << d << " m: direct " << level << " dB, DRR " << drr << " dB");
    if (d > 0.4) {
      CHECK(previous_level - level == Approx(6.02).margin(2.0));
      CHECK(drr < previous_drr);
    }
    previous_level = level;
    previous_drr = drr;
  }
}

TEST_CASE("first-order image sources: the floor echo arrives on the mirror path with beta/r",
          "[room]") {
  BrirSynthConfig config;
  config.room.max_corner = {10.0, 10.0, 3.0};
  config.listener = {5.0, 5.0, 1.2};
  config.rt60 = 0.5;
  config.max_order = 1;
  config.late_tail = false;
  config.length_s = 0.1;
  const BrirSynthesizer synth(omni_hrirs(), config);
  const BinauralIr ir = synth.synthesize(0.0, 1.0);
  // Floor image of a source 1 m ahead at 1.2 m height: path sqrt(1 + 2.4^2) = 2.6 m.
  const double floor_path = std::sqrt(1.0 + 2.4 * 2.4);
  const double beta = std::sqrt(1.0 - synth.absorption());
  const double expected = beta / floor_path;  // amplitude; the window holds the whole kernel
  CHECK(std::sqrt(arrival_energy(ir.left, floor_path / kC)) == Approx(expected).epsilon(0.05));
  CHECK(std::sqrt(arrival_energy(ir.left, 1.0 / kC)) == Approx(1.0).epsilon(0.05));
  // Nothing arrives before the direct sound.
  CHECK(energy(ir.left, 0, static_cast<size_t>(1.0 / kC * kFs) - 24) < 1e-6);
}

TEST_CASE("the late tail is interaurally decorrelated and reproducible", "[room]") {
  BrirSynthConfig config;
  config.rt60 = 0.4;
  config.max_order = 1;
  config.length_s = 0.3;
  const BrirSynthesizer synth(omni_hrirs(), config);
  const BinauralIr a = synth.synthesize(0.0, 2.0), b = synth.synthesize(0.0, 2.0);
  CHECK(a.left == b.left);
  // Omni ears: early parts are identical, the tail (last 200 ms) is not.
  const size_t from = a.left.size() - static_cast<size_t>(0.2 * kFs);
  double lr = 0, ll = 0, rr = 0;
  for (size_t i = from; i < a.left.size(); ++i)
    lr += a.left[i] * a.right[i], ll += a.left[i] * a.left[i], rr += a.right[i] * a.right[i];
  CHECK(std::abs(lr / std::sqrt(ll * rr)) < 0.1);
  config.seed = 2;
  const BinauralIr c = BrirSynthesizer(omni_hrirs(), config).synthesize(0.0, 2.0);
  CHECK(c.left != a.left);
}

TEST_CASE("bad room configurations are refused with a clear error", "[room]") {
  BrirSynthConfig config;
  config.listener = {6.0, 1.0, 1.0};  // outside the 5 m room
  CHECK_THROWS_WITH(validate(config), Catch::Contains("listener"));
  config = {};
  config.rt60 = 0.01;
  CHECK_THROWS_AS(validate(config), std::invalid_argument);
  config = {};
  config.rt60 = 0.012;  // Eyring needs absorption > 0.999 in a 5 x 4 x 3 room
  CHECK_THROWS_WITH(validate(config), Catch::Contains("too short"));
  config = {};
  config.max_order = -1;
  CHECK_THROWS_AS(validate(config), std::invalid_argument);
  config = {};
  config.room.max_corner = {0.2, 0.2, 0.2};  // image sources centimetres from the ears
  CHECK_THROWS_WITH(validate(config), Catch::Contains("room sides"));
  config.room.max_corner = {1e300, 4.0, 3.0};  // the listener's position lost to rounding
  CHECK_THROWS_WITH(validate(config), Catch::Contains("room corners"));
  config = {};
  config.listener = {0.1, 2.0, 1.5};
  CHECK_THROWS_WITH(validate(config), Catch::Contains("0.25 m from every wall"));
  config = {};
  config.rt60 = 20.0;
  CHECK_THROWS_WITH(validate(config), Catch::Contains("rt60"));
  HrirSet h = omni_hrirs();
  h.sample_rate = 44100.0;
  CHECK_THROWS_WITH(BrirSynthesizer(h, BrirSynthConfig{}), Catch::Contains("resample"));
}

TEST_CASE("an IR too short for the direct sound is refused, not rendered silent", "[room]") {
  BrirSynthConfig config;
  config.length_s = 0.005;  // 240 samples: a source 2 m away arrives after 280
  const BrirSynthesizer synth(omni_hrirs(), config);
  CHECK_NOTHROW(synth.synthesize(0.0, 0.4));  // 56 + 8 + 32 samples fit
  CHECK_THROWS_WITH(synth.synthesize(0.0, 2.0), Catch::Contains("direct sound"));
  CHECK_THROWS_WITH(synth.synthesize(BrirGrid::paper()), Catch::Contains("direct sound"));
  CHECK(synth.min_length_s(2.0) == Approx((std::ceil(2.0 / kC * kFs) + 8 + 32) / kFs));
  // Without a length, the IR holds the farthest grid distance whatever the RT60.
  config.length_s = 0.0;
  config.rt60 = 0.02;
  config.room.max_corner = {1.0, 1.0, 1.0};
  const BrirSynthesizer short_room(omni_hrirs(), config);
  CHECK_NOTHROW(short_room.synthesize(0.0, 4.0));
}

TEST_CASE("a grid made on demand holds only what was looked up, with the whole grid's level",
          "[room][memory]") {
  BrirSynthConfig config;
  config.rt60 = 0.2;
  config.max_order = 1;
  config.length_s = 0.05;
  BrirGrid grid;
  grid.azimuths_deg = {-90.0, 0.0, 90.0};
  grid.distances_m = {0.4, 1.0, 2.0};
  auto synth = std::make_shared<const BrirSynthesizer>(omni_hrirs(), config);
  // Truth: every point synthesised and the set scaled to its loudest ear (normalise_to_reference).
  BrirSet whole = synth->synthesize(grid);
  const double factor = whole.normalise_to_reference();
  REQUIRE(factor != 1.0);
  const BrirSet lazy = BrirSynthesizer::synthesize_on_demand(synth, grid);
  CHECK(lazy.made_count() == 0);
  CHECK(lazy.ir_length() == whole.ir_length());
  CHECK(lazy.at(2, 1).left == whole.at(2, 1).left);
  CHECK(lazy.at(0, 2).right == whole.at(0, 2).right);
  CHECK(lazy.at(2, 1).left == whole.at(2, 1).left);  // a second lookup: the same response
  CHECK(lazy.made_count() == 2);
  BrirSet again = BrirSynthesizer::synthesize_on_demand(synth, grid);
  CHECK_THROWS_AS(again.normalise_to_reference(), std::logic_error);  // already at the reference
}
