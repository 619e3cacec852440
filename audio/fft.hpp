// SPDX-License-Identifier: GPL-3.0-or-later
// Real FFTs with FFTW3 (single precision). Plans are made once per size with FFTW_ESTIMATE
// under a lock (FFTW planning is not thread-safe) and then executed on any FFTW-aligned
// arrays, which is thread-safe.
#pragma once

#include <complex>
#include <cstddef>
#include <new>
#include <vector>

namespace sonomap::audio {

void* fftw_aligned_alloc(size_t bytes);
void fftw_aligned_free(void* p);

// std::allocator twin that returns FFTW-aligned memory (SIMD plans need it).
template <class T>
struct FftwAllocator {
  using value_type = T;
  FftwAllocator() = default;
  template <class U>
  FftwAllocator(const FftwAllocator<U>&) {}
  T* allocate(size_t n) {
    void* p = fftw_aligned_alloc(n * sizeof(T));
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t) { fftw_aligned_free(p); }
  template <class U>
  bool operator==(const FftwAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const FftwAllocator<U>&) const { return false; }
};

using AlignedSamples = std::vector<float, FftwAllocator<float>>;
using Spectrum = std::vector<std::complex<float>, FftwAllocator<std::complex<float>>>;

class RealFft {
 public:
  explicit RealFft(size_t size);  // size even, > 0
  size_t size() const { return size_; }
  size_t bins() const { return size_ / 2 + 1; }
  // size() samples -> bins() complex values.
  void forward(const float* in, std::complex<float>* out) const;
  // bins() complex values -> size() samples, unnormalised (x size()); destroys `in`.
  void inverse(std::complex<float>* in, float* out) const;

 private:
  size_t size_;
  void* forward_plan_;
  void* inverse_plan_;
};

// Smallest power of two >= n.
size_t next_power_of_two(size_t n);
// The smallest even size >= n with no prime factor above 5 (FFTW transforms these about as
// fast as powers of two, and they pad far less: 34,000 samples take 34,560, not 65,536).
size_t next_fast_size(size_t n);

}  // namespace sonomap::audio
