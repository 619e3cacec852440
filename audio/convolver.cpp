// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/convolver.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <tbb/parallel_for.h>

namespace sonomap::audio {

static const BrirSet& checked(const std::shared_ptr<const BrirSet>& brirs) {
  if (!brirs || brirs->empty()) throw std::invalid_argument("BrirConvolver: empty BRIR set");
  return *brirs;
}

BrirConvolver::BrirConvolver(std::shared_ptr<const BrirSet> brirs, size_t max_sound_length)
    : brirs_(std::move(brirs)),
      max_sound_length_(max_sound_length),
      fft_(next_fast_size(max_sound_length + checked(brirs_).ir_length())),
      cache_(brirs_->distance_count() * brirs_->azimuth_count() * 2) {}

size_t BrirConvolver::key(size_t d, size_t a, Ear ear) const {
  if (d >= brirs_->distance_count() || a >= brirs_->azimuth_count())
    throw std::invalid_argument("BrirConvolver: BRIR index out of range");
  return (d * brirs_->azimuth_count() + a) * 2 + static_cast<size_t>(ear);
}

static Spectrum spectrum_of(const RealFft& fft, const std::vector<float>& samples) {
  AlignedSamples padded(fft.size(), 0.0f);
  std::copy(samples.begin(), samples.end(), padded.begin());
  Spectrum out(fft.bins());
  fft.forward(padded.data(), out.data());
  return out;
}

Spectrum BrirConvolver::sound_spectrum(const std::vector<float>& sound) const {
  if (sound.size() > max_sound_length_)
    throw std::invalid_argument("BrirConvolver: sound of " + std::to_string(sound.size()) +
                                " samples exceeds the planned " +
                                std::to_string(max_sound_length_));
  Spectrum s = spectrum_of(fft_, sound);
  // Fold the inverse transform's 1/N into the sound once, not into every product.
  const float scale = 1.0f / static_cast<float>(fft_.size());
  for (auto& v : s) v *= scale;
  return s;
}

void BrirConvolver::prepare(const std::vector<std::pair<size_t, size_t>>& pairs) {
  std::vector<size_t> missing;
  for (const auto& [d, a] : pairs)
    for (Ear ear : {Ear::Left, Ear::Right}) {
      const size_t k = key(d, a, ear);
      if (!cache_[k] && std::find(missing.begin(), missing.end(), k) == missing.end())
        missing.push_back(k);
    }
  // Each task fills its own slot: no locking, same result for any thread count.
  tbb::parallel_for(size_t{0}, missing.size(), [&](size_t i) {
    const size_t k = missing[i];
    const size_t pair = k / 2;
    const BinauralIr& ir = brirs_->at(pair / brirs_->azimuth_count(), pair % brirs_->azimuth_count());
    cache_[k] = std::make_unique<Spectrum>(spectrum_of(fft_, ir.ear(static_cast<Ear>(k % 2))));
  });
}

const Spectrum& BrirConvolver::brir_spectrum(size_t d, size_t a, Ear ear) const {
  const auto& slot = cache_[key(d, a, ear)];
  if (!slot) throw std::logic_error("BrirConvolver: spectrum not prepared");
  return *slot;
}

void BrirConvolver::convolve(const Spectrum& sound, const Spectrum& brir, AlignedSamples& scratch,
                             Spectrum& product) const {
  const size_t bins = fft_.bins();
  if (sound.size() != bins || brir.size() != bins || product.size() != bins ||
      scratch.size() != fft_.size())
    throw std::invalid_argument("BrirConvolver::convolve: buffer sizes do not match the plan");
  // Written out: std::complex's operator* checks for NaN/inf (a libcall per bin, 5x slower).
  const float* a = reinterpret_cast<const float*>(sound.data());
  const float* b = reinterpret_cast<const float*>(brir.data());
  float* p = reinterpret_cast<float*>(product.data());
  for (size_t k = 0; k < 2 * bins; k += 2) {
    p[k] = a[k] * b[k] - a[k + 1] * b[k + 1];
    p[k + 1] = a[k] * b[k + 1] + a[k + 1] * b[k];
  }
  fft_.inverse(product.data(), scratch.data());
}

size_t BrirConvolver::cached_spectra() const {
  return static_cast<size_t>(std::count_if(cache_.begin(), cache_.end(),
                                           [](const auto& p) { return p != nullptr; }));
}

void BrirConvolver::clear_cache() {
  for (auto& p : cache_) p.reset();
}

}  // namespace sonomap::audio
