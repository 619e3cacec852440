// SPDX-License-Identifier: GPL-3.0-or-later
// Levels of the sweeps sonomap writes, measured on the WAV read back with measures written out
// from their standards (audio_measures.hpp), not with the code that set the gain: no sample
// above -1 dBFS and no true peak above -1 dBTP in the loudest case, the loudness target met
// where the ceiling allows it; and the late reverberation of a source straight ahead is as
// loud at both ears. BRIRs from the measured MIT KEMAR HRIRs (Debian's libmysofa1).
#include "audio/brir_synth.hpp"
#include "audio/sweep.hpp"
#include "audio_measures.hpp"
#include "harness/app/sonify.hpp"
#include "harness/formats/sofa_io.hpp"
#include "harness/formats/wav_io.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <complex>
#include <fstream>

using namespace sonomap;
using namespace sonomap::audio;
namespace fs = std::filesystem;

namespace {

constexpr double kFs = 48000.0;
constexpr double kPi = 3.14159265358979323846;
const fs::path kKemar = "/usr/share/libmysofa/default.sofa";  // Debian libmysofa1, a dependency

// Every bin of the circle at `range` metres.
Circle full_circle(float range) {
  Circle c(360);
  for (auto& b : c.bins) b.range = range;
  return c;
}

double peak_of(const harness::StereoAudio& a) {
  double p = 0.0;
  for (const auto* ch : {&a.left, &a.right})
    for (float x : *ch) p = std::max(p, double(std::abs(x)));
  return p;
}

// Energy of x[from, to) in [f_lo, f_hi], by a direct DFT every 2 Hz (no FFT code involved).
double band_energy(const std::vector<float>& x, size_t from, size_t to, double f_lo, double f_hi) {
  double e = 0.0;
  for (double f = f_lo; f <= f_hi; f += 2.0) {
    std::complex<double> acc = 0.0;
    const std::complex<double> step = std::polar(1.0, -2.0 * kPi * f / kFs);
    std::complex<double> w = 1.0;
    for (size_t n = from; n < to; ++n) acc += double(x[n]) * w, w *= step;
    e += std::norm(acc);
  }
  return e;
}

double energy(const std::vector<float>& x, size_t from) {
  double e = 0.0;
  for (size_t i = from; i < x.size(); ++i) e += double(x[i]) * x[i];
  return e;
}

double db(double ratio) { return 10.0 * std::log10(ratio); }

}  // namespace

TEST_CASE("no sweep peaks above -1 dBFS: every sector a tap at 0.4 m in a 1 m room with a 3 s "
          "RT60, per-file and fixed levels, at the default target and one the ceiling must cap",
          "[sweep][loudness][kemar]") {
  const sonomap::test::ScratchDir scratch("sweep-peak");
  BrirSynthConfig room;
  room.room.max_corner = {1.0, 1.0, 1.0};  // the smallest room accepted
  room.rt60 = 3.0;                         // the largest RT60 accepted
  room.max_order = 3;
  const BrirSynthesizer synth(harness::read_hrir_set(kKemar, kFs), room);
  BrirGrid grid;  // the nearest distance and one azimuth per sector: the loudest sweep
  for (int a = -175; a <= 180; a += 10) grid.azimuths_deg.push_back(a);
  grid.distances_m = {0.4, 4.0};
  // As synthesised, not normalised: the level rules must hold for any set.
  auto brirs = std::make_shared<const BrirSet>(synth.synthesize(grid));

  for (LevelMode mode : {LevelMode::PerFile, LevelMode::Fixed})
    for (double target : {-16.0, -3.0}) {
      SweepConfig config;
      config.level = mode;
      config.loudness.target_lufs = target;
      SweepRenderer renderer(brirs, config);
      const SweepAudio out = renderer.render(full_circle(0.2f));
      const fs::path wav = scratch.path() / (std::string(to_string(mode)) + ".wav");
      harness::write_sweep(out, wav);
      const harness::StereoAudio back = harness::read_wav(wav);
      const double peak = peak_of(back);
      const double true_peak =
          std::max(sonomap::test::true_peak_db(back.left), sonomap::test::true_peak_db(back.right));
      INFO(to_string(mode) << ", target " << target << " LUFS: gain " << out.gain_db
                           << " dB, sample peak " << 20 * std::log10(peak) << " dBFS, true peak "
                           << true_peak << " dBTP");
      CHECK(out.events.size() == 36);
      CHECK(20.0 * std::log10(peak) <= -1.0);
      CHECK(true_peak <= -1.0);
      // The case is a loud one: without its gain this sweep would pass full scale.
      CHECK(peak / std::pow(10.0, out.gain_db / 20.0) > 1.0);
      // -3 LUFS cannot be reached under -1 dBTP with taps: the ceiling set the gain.
      if (target == -3.0) CHECK(out.peak_limited);
      // The events file carries the one gain applied.
      std::ifstream events(harness::events_path_for(wav));
      std::string header, row;
      std::getline(events, header);
      std::getline(events, row);
      CHECK(header.find(",gain_db,loudness_lufs,true_peak_dbtp") != std::string::npos);
      char gain[32];
      std::snprintf(gain, sizeof gain, ",%.2f,", out.gain_db);
      CHECK(row.find(gain) != std::string::npos);
    }
}

TEST_CASE("a per-file sweep meets the loudness target within 0.5 LU unless the true-peak "
          "ceiling sets its gain",
          "[sweep][loudness][kemar]") {
  const sonomap::test::ScratchDir scratch("sweep-loudness");
  BrirSynthConfig room;
  room.rt60 = 0.4;
  room.max_order = 2;
  const BrirSynthesizer synth(harness::read_hrir_set(kKemar, kFs), room);
  BrirGrid grid;
  for (int a = -177; a <= 180; a += 3) grid.azimuths_deg.push_back(a);
  grid.distances_m = {0.4, 1.2, 2.0, 4.0};
  auto brirs = std::make_shared<const BrirSet>(synth.synthesize(grid));
  SweepConfig config;
  SweepRenderer renderer(brirs, config);
  int normalised = 0;
  for (float range : {0.4f, 1.2f, 2.0f, 4.0f}) {
    const SweepAudio out = renderer.render(full_circle(range));
    const fs::path wav = scratch.path() / "sweep.wav";
    harness::write_sweep(out, wav);
    const harness::StereoAudio back = harness::read_wav(wav);
    const double lufs = sonomap::test::integrated_loudness(back.left, back.right);
    const double true_peak =
        std::max(sonomap::test::true_peak_db(back.left), sonomap::test::true_peak_db(back.right));
    INFO("taps at " << range << " m: gain " << out.gain_db << " dB, " << lufs << " LUFS, true peak "
                    << true_peak << " dBTP, peak limited " << out.peak_limited);
    CHECK(true_peak <= -1.0);
    if (out.peak_limited) {
      CHECK(true_peak > -1.0 - config.loudness.margin_db - 0.2);  // it went as far as it could
      CHECK(lufs < config.loudness.target_lufs);
    } else {
      ++normalised;
      CHECK(std::abs(lufs - config.loudness.target_lufs) <= 0.5);
    }
  }
  CHECK(normalised >= 2);  // the default target is reachable for most sweeps
}

TEST_CASE("the late reverberation of a source straight ahead is as loud at both ears, in every "
          "band, and each direction has its own",
          "[brir][kemar]") {
  BrirSynthConfig room;  // the default room: 5 x 4 x 3 m, RT60 0.5 s, order 3
  const BrirSynthesizer synth(harness::read_hrir_set(kKemar, kFs), room);
  const size_t late = static_cast<size_t>(0.05 * kFs);  // after 50 ms
  for (double d : {0.4, 0.8, 1.2, 2.0, 3.2}) {
    const BinauralIr ir = synth.synthesize(0.0, d);
    const double lean = db(energy(ir.left, late) / energy(ir.right, late));
    const double band = db(band_energy(ir.left, 0, ir.left.size(), 450.0, 600.0) /
                           band_energy(ir.right, 0, ir.right.size(), 450.0, 600.0));
    const double late_band = db(band_energy(ir.left, late, ir.left.size(), 450.0, 600.0) /
                                band_energy(ir.right, late, ir.right.size(), 450.0, 600.0));
    INFO(d << " m ahead: late energy L/R " << lean << " dB, 450-600 Hz " << band
           << " dB (late part " << late_band << " dB)");
    CHECK(std::abs(lean) <= 1.0);
    CHECK(std::abs(band) <= 1.0);
    CHECK(std::abs(late_band) <= 1.0);
  }
  // Two directions do not share a tail: their late parts are uncorrelated.
  const BinauralIr a = synth.synthesize(0.0, 1.2), b = synth.synthesize(30.0, 1.2);
  const size_t from = static_cast<size_t>(0.1 * kFs);
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = from; i < a.left.size(); ++i)
    ab += a.left[i] * b.left[i], aa += a.left[i] * a.left[i], bb += b.left[i] * b.left[i];
  CHECK(std::abs(ab / std::sqrt(aa * bb)) < 0.1);
}
