// SPDX-License-Identifier: GPL-3.0-or-later
// The BRIR convolver against the definition of convolution: out[n] = sum_k sound[k] brir[n - k],
// summed directly in double (no FFT), and its transform size against a brute-force search.
#include "audio/convolver.hpp"
#include "audio/fft.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

using namespace sonomap::audio;

namespace {

// True when n is even and has no prime factor above 5 (trial division).
bool even_and_5_smooth(size_t n) {
  if (n == 0 || n % 2 != 0) return false;
  for (size_t p : {2, 3, 5})
    while (n % p == 0) n /= p;
  return n == 1;
}

std::vector<float> noise(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> x(n);
  for (float& v : x) v = u(rng);
  return x;
}

}  // namespace

TEST_CASE("the transform size is the smallest even size with no prime factor above 5 that "
          "holds the samples",
          "[convolver]") {
  for (size_t n : {1, 2, 3, 7, 11, 97, 400, 401, 1000, 24001, 34000, 65536, 65537, 100003}) {
    size_t expected = n;
    while (!even_and_5_smooth(expected)) ++expected;
    INFO("n = " << n);
    CHECK(next_fast_size(n) == expected);
  }
  CHECK(next_fast_size(34000) == 34560);  // 2^8 3^3 5: a power of two would take 65,536
}

TEST_CASE("a sound convolved with a BRIR is the direct convolution, without wrap-around, for "
          "a transform size that is not a power of two",
          "[convolver]") {
  // 300 + 100 - 1 = 399 output samples: the transform is 400 = 2^4 5^2 points.
  const size_t ir_length = 300, sound_length = 100;
  BrirGrid grid;
  grid.azimuths_deg = {0.0};
  grid.distances_m = {1.0};
  BinauralIr ir{noise(ir_length, 1), noise(ir_length, 2)};
  auto brirs = std::make_shared<const BrirSet>(48000.0, grid, std::vector<BinauralIr>{ir});
  BrirConvolver convolver(brirs, sound_length);
  REQUIRE(convolver.fft_size() == 400);
  const std::vector<float> sound = noise(sound_length, 3);
  convolver.prepare({{0, 0}});
  AlignedSamples scratch(convolver.fft_size(), 0.0f);
  Spectrum product(convolver.fft_size() / 2 + 1);
  for (Ear ear : {Ear::Left, Ear::Right}) {
    convolver.convolve(convolver.sound_spectrum(sound), convolver.brir_spectrum(0, 0, ear), scratch, product);
    const std::vector<float>& h = ir.ear(ear);
    double worst = 0.0;
    for (size_t n = 0; n < convolver.output_length(sound_length); ++n) {
      double direct = 0.0;
      for (size_t k = 0; k < sound_length; ++k)
        if (n >= k && n - k < ir_length) direct += double(sound[k]) * h[n - k];
      worst = std::max(worst, std::abs(direct - scratch[n]));
    }
    CHECK(worst < 1e-4);  // sums of up to 100 products of values in [-1, 1], in float
  }
}
