// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/loudness.hpp"

#include <algorithm>
#include <cmath>
#include <ebur128.h>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace sonomap::audio {

namespace {
constexpr double kMinusInf = -std::numeric_limits<double>::infinity();

struct StateDeleter {
  void operator()(ebur128_state* s) const { ebur128_destroy(&s); }
};

void check(int status, const char* what) {
  if (status != EBUR128_SUCCESS)
    throw std::runtime_error(std::string("loudness measurement: ") + what + " failed (libebur128 " +
                             std::to_string(status) + ")");
}
}  // namespace

void LoudnessRules::validate() const {
  if (!(std::isfinite(target_lufs) && target_lufs >= -70.0 && target_lufs <= 0.0))
    throw std::invalid_argument("loudness target must be in [-70, 0] LUFS");
  if (!(std::isfinite(ceiling_dbtp) && ceiling_dbtp >= -60.0 && ceiling_dbtp <= -1.0))
    throw std::invalid_argument("true-peak ceiling must be in [-60, -1] dBTP");
  if (!(std::isfinite(margin_db) && margin_db >= 0.0 && margin_db <= 3.0))
    throw std::invalid_argument("true-peak margin must be in [0, 3] dB");
}

double db_to_amplitude(double db) { return std::pow(10.0, db / 20.0); }
double amplitude_to_db(double a) { return a > 0.0 ? 20.0 * std::log10(a) : kMinusInf; }

LoudnessMeasure measure_loudness(const std::vector<float>& left, const std::vector<float>& right,
                                 double sample_rate) {
  if (left.size() != right.size()) throw std::invalid_argument("loudness: channel lengths differ");
  if (!(sample_rate >= 8000.0 && sample_rate <= 384000.0))
    throw std::invalid_argument("loudness: sample rate out of [8000, 384000] Hz");
  std::unique_ptr<ebur128_state, StateDeleter> state(
      ebur128_init(2, static_cast<unsigned long>(std::lround(sample_rate)),
                   EBUR128_MODE_I | EBUR128_MODE_TRUE_PEAK));
  if (!state) throw std::runtime_error("loudness measurement: libebur128 init failed");
  // Interleave in blocks: no second copy of a long file.
  constexpr size_t kBlock = 4800;
  float frames[2 * kBlock];
  for (size_t start = 0; start < left.size(); start += kBlock) {
    const size_t n = std::min(kBlock, left.size() - start);
    for (size_t i = 0; i < n; ++i) {
      frames[2 * i] = left[start + i];
      frames[2 * i + 1] = right[start + i];
    }
    check(ebur128_add_frames_float(state.get(), frames, n), "adding frames");
  }
  LoudnessMeasure m;
  check(ebur128_loudness_global(state.get(), &m.integrated_lufs), "integrated loudness");
  if (!std::isfinite(m.integrated_lufs)) m.integrated_lufs = kMinusInf;
  double true_peak = 0.0, sample_peak = 0.0;
  for (unsigned ch = 0; ch < 2; ++ch) {
    double tp = 0.0, sp = 0.0;
    check(ebur128_true_peak(state.get(), ch, &tp), "true peak");
    check(ebur128_sample_peak(state.get(), ch, &sp), "sample peak");
    true_peak = std::max(true_peak, tp);
    sample_peak = std::max(sample_peak, sp);
  }
  // The interpolated peak is never below the samples themselves.
  m.sample_peak_dbfs = amplitude_to_db(sample_peak);
  m.true_peak_dbtp = amplitude_to_db(std::max(true_peak, sample_peak));
  return m;
}

static double ceiling_gain_db(const LoudnessMeasure& m, const LoudnessRules& r) {
  if (!std::isfinite(m.true_peak_dbtp)) return std::numeric_limits<double>::infinity();
  return r.ceiling_dbtp - r.margin_db - m.true_peak_dbtp;
}

double loudness_gain_db(const LoudnessMeasure& m, const LoudnessRules& r) {
  const double cap = ceiling_gain_db(m, r);
  if (!std::isfinite(m.integrated_lufs)) return std::isfinite(cap) ? std::min(0.0, cap) : 0.0;
  return std::min(r.target_lufs - m.integrated_lufs, cap);
}

bool peak_limited(const LoudnessMeasure& m, const LoudnessRules& r) {
  if (!std::isfinite(m.true_peak_dbtp)) return false;
  if (!std::isfinite(m.integrated_lufs)) return ceiling_gain_db(m, r) < 0.0;
  return ceiling_gain_db(m, r) < r.target_lufs - m.integrated_lufs;
}

void apply_gain(std::vector<float>& left, std::vector<float>& right, double gain_db) {
  const float g = static_cast<float>(db_to_amplitude(gain_db));
  for (float& x : left) x *= g;
  for (float& x : right) x *= g;
}

LoudnessMeasure with_gain(const LoudnessMeasure& m, double gain_db) {
  return {m.integrated_lufs + gain_db, m.true_peak_dbtp + gain_db, m.sample_peak_dbfs + gain_db};
}

}  // namespace sonomap::audio
