// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/fft.hpp"

#include <algorithm>

#include <fftw3.h>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace sonomap::audio {

void* fftw_aligned_alloc(size_t bytes) { return fftwf_malloc(bytes == 0 ? 1 : bytes); }
void fftw_aligned_free(void* p) { fftwf_free(p); }

size_t next_power_of_two(size_t n) {
  size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

size_t next_fast_size(size_t n) {
  size_t best = next_power_of_two(std::max<size_t>(n, 2));
  for (size_t p2 = 2; p2 < best; p2 *= 2)
    for (size_t p3 = p2; p3 < best; p3 *= 3)
      for (size_t p5 = p3; p5 < best; p5 *= 5)
        if (p5 >= n) best = p5;
  return best;
}

namespace {
struct PlanPair {
  fftwf_plan forward;
  fftwf_plan inverse;
};

// Plans live for the whole process: one pair per size, shared by every RealFft.
PlanPair plans_for(size_t n) {
  static std::mutex mutex;
  // Never destroyed (plans may be executed until exit); reachable, so not a leak to LSan.
  static auto* plans_by_size = new std::map<size_t, PlanPair>;
  auto& plans = *plans_by_size;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = plans.find(n);
  if (it != plans.end()) return it->second;
  float* real = fftwf_alloc_real(n);
  fftwf_complex* spectrum = fftwf_alloc_complex(n / 2 + 1);
  PlanPair pair{
      fftwf_plan_dft_r2c_1d(static_cast<int>(n), real, spectrum, FFTW_ESTIMATE),
      fftwf_plan_dft_c2r_1d(static_cast<int>(n), spectrum, real, FFTW_ESTIMATE)};
  fftwf_free(real);
  fftwf_free(spectrum);
  if (!pair.forward || !pair.inverse) throw std::runtime_error("FFTW: cannot plan a transform");
  plans.emplace(n, pair);
  return pair;
}
}  // namespace

RealFft::RealFft(size_t size) : size_(size) {
  if (size == 0 || size % 2 != 0 || size > (size_t{1} << 30))
    throw std::invalid_argument("RealFft: size must be even and positive");
  const PlanPair p = plans_for(size);
  forward_plan_ = p.forward;
  inverse_plan_ = p.inverse;
}

void RealFft::forward(const float* in, std::complex<float>* out) const {
  // r2c out of place leaves the input intact; the cast is FFTW's signature, not a write.
  fftwf_execute_dft_r2c(static_cast<fftwf_plan>(forward_plan_), const_cast<float*>(in),
                        reinterpret_cast<fftwf_complex*>(out));
}

void RealFft::inverse(std::complex<float>* in, float* out) const {
  fftwf_execute_dft_c2r(static_cast<fftwf_plan>(inverse_plan_),
                        reinterpret_cast<fftwf_complex*>(in), out);
}

}  // namespace sonomap::audio
