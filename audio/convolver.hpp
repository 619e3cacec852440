// SPDX-License-Identifier: GPL-3.0-or-later
// FFT convolution (FFTW3 float) of short sounds with the BRIRs of a set. The BRIR spectra are
// computed once and cached per (distance, azimuth, ear): rendering a sweep then costs one
// complex product and one inverse FFT per sound and ear.
#pragma once

#include "audio/brir_set.hpp"
#include "audio/fft.hpp"

#include <memory>
#include <utility>
#include <vector>

namespace sonomap::audio {

class BrirConvolver {
 public:
  // Sounds up to `max_sound_length` samples can be convolved without wrap-around.
  BrirConvolver(std::shared_ptr<const BrirSet> brirs, size_t max_sound_length);

  const BrirSet& brirs() const { return *brirs_; }
  size_t fft_size() const { return fft_.size(); }
  size_t output_length(size_t sound_length) const { return sound_length + brirs_->ir_length() - 1; }

  // Zero-padded spectrum of a sound (length <= max_sound_length).
  Spectrum sound_spectrum(const std::vector<float>& sound) const;
  // Caches the spectra of these (distance index, azimuth index) pairs, both ears (parallel).
  void prepare(const std::vector<std::pair<size_t, size_t>>& pairs);
  // A cached spectrum; throws std::logic_error if it was not prepared.
  const Spectrum& brir_spectrum(size_t distance_index, size_t azimuth_index, Ear ear) const;
  // out[0 .. length) = (sound * brir)[0 .. length), length <= fft_size(). Thread-safe;
  // `scratch` must hold fft_size() samples and `product` bins() values.
  void convolve(const Spectrum& sound, const Spectrum& brir, AlignedSamples& scratch,
                Spectrum& product) const;
  size_t cached_spectra() const;
  void clear_cache();

 private:
  size_t key(size_t distance_index, size_t azimuth_index, Ear ear) const;
  std::shared_ptr<const BrirSet> brirs_;
  size_t max_sound_length_;
  RealFft fft_;
  std::vector<std::unique_ptr<Spectrum>> cache_;  // one slot per (distance, azimuth, ear)
};

}  // namespace sonomap::audio
