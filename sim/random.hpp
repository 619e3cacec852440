// SPDX-License-Identifier: GPL-3.0-or-later
// Reproducible random streams, our own code end to end so sequences are the same with any
// standard library and any thread count (std::normal_distribution differs between libstdc++
// and libc++, and std::mt19937_64 costs 2.5 kB of state to seed per stream).
//
// Generator: SplitMix64 (Steele, Lea, Flood 2014, "Fast splittable pseudorandom number
// generators"), a counter-based generator: the n-th output is a fixed 64-bit mix of
// key + n * golden gamma, so a stream costs one word, starts in O(1) and passes BigCrush.
// Normals: the ziggurat of Marsaglia & Tsang (2000) in Doornik's form (2005, "An improved
// ziggurat method to generate normal random samples"): 128 layers, one 64-bit draw per sample
// on the fast path (97% of samples), exact tail and wedges otherwise. The per-pixel noise uses
// the same ziggurat on 32 bits (normal32): an integer compare on the fast path, float precision.
#pragma once

#include <cstdint>
#include <initializer_list>

namespace sonomap::sim {

// What a stream is used for; part of its key so that streams never overlap.
enum class StreamPurpose : std::uint64_t {
  LateralJitter = 1,
  AxialNoise = 2,  // per pixel: the low 32 bits give the axial normal, the high 32 the dropout
  Dropout = 4,     // no longer drawn (dropout shares the axial word); kept so keys stay distinct
  SlowNormal = 7,  // the rare wedge and tail draws of normal32, keyed by the pixel
  LocalisationNoise = 5,
  LocalisationDrift = 6,
};

class RandomStream {
 public:
  // Seeded from every word of `key` (mixed with splitmix64), e.g. {seed, sensor, frame, purpose}.
  explicit RandomStream(std::initializer_list<std::uint64_t> key);

  // The next 64 random bits. (Inline, as the samplers below: the noise stages call them per pixel.)
  std::uint64_t bits() { return mix(state_ += kGamma); }
  // The n-th output of bits() from the stream's start (n = 0 first), without stepping through
  // the others: SplitMix64 is a counter, so pixel n of a row can take word n in any order.
  std::uint64_t bits_at(std::uint64_t n) const { return mix(start_ + (n + 1) * kGamma); }
  // Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(bits() >> 11) * 0x1.0p-53; }
  // Standard normal (ziggurat).
  double normal() {
    const std::uint64_t r = bits();
    const unsigned layer = static_cast<unsigned>(r & 127u);
    // u in [-1, 1) from the 53 high bits; the low 7 bits chose the layer.
    const double u = static_cast<double>(r >> 11) * 0x1.0p-52 - 1.0;
    if (u * u < table_->ratio2[layer]) return u * table_->x[layer];  // the layer's inner rectangle
    return normal_slow(layer, u);
  }
  double normal(double sigma) { return sigma * normal(); }

  // A standard normal in float precision from the 32 bits `r` (Marsaglia & Tsang's integer
  // form of the same ziggurat): the low 7 bits pick the layer, the high 25 a signed position
  // s in [-2^24, 2^24); inside the layer's inner rectangle (97% of draws) the sample is
  // s * x[layer] / 2^24. The rare wedge or tail draws further bits from the stream keyed
  // {key(), slow_index}, so a sample depends on its own bits and index only, not on the order
  // of calls.
  float normal32(std::uint32_t r, std::uint64_t slow_index) const {
    const unsigned layer = r & 127u;
    const std::int32_t s = static_cast<std::int32_t>(r) >> 7;  // arithmetic shift keeps the sign
    const std::uint32_t magnitude = static_cast<std::uint32_t>(s < 0 ? -s : s);
    if (magnitude < table_->inner32[layer]) return static_cast<float>(s) * table_->width32[layer];
    return normal32_slow(layer, s, slow_index);
  }
  // Words 0 .. count-1 of the stream (bits_at), split into their low and high 32-bit halves.
  // A plain loop over the counter, so that it vectorises; the counter as an induction
  // variable (+gamma a word), because without AVX-512DQ a 64-bit multiply costs three.
  void words(int count, std::uint32_t* __restrict low, std::uint32_t* __restrict high) const {
    std::uint64_t counter = start_;
    for (int n = 0; n < count; ++n) {
      counter += kGamma;
      const std::uint64_t word = mix(counter);
      low[n] = static_cast<std::uint32_t>(word);
      high[n] = static_cast<std::uint32_t>(word >> 32);
    }
  }
  // normal32 of r[k] for k < count on its fast path only, branch-free so that it vectorises:
  // where slow[k] is 0, out[k] == normal32(r[k], any index); where it is 1 (2.8% of words: the
  // wedges, the tail and the top layer), the caller must call normal32 itself.
  void normal32_fast(const std::uint32_t* __restrict r, int count, float* __restrict out,
                     std::uint32_t* __restrict slow) const {
    const Ziggurat& z = *table_;
    for (int k = 0; k < count; ++k) {
      const unsigned layer = r[k] & 127u;
      const std::int32_t s = static_cast<std::int32_t>(r[k]) >> 7;
      const std::uint32_t magnitude = static_cast<std::uint32_t>(s < 0 ? -s : s);
      out[k] = static_cast<float>(s) * z.width32[layer];
      slow[k] = magnitude >= z.inner32[layer];
    }
  }
 private:
  // Layer edges x[0] > x[1] = R > ... > x[128] = 0 of equal-area layers under exp(-x^2 / 2),
  // and (x[i+1] / x[i])^2, the inner rectangle's share of layer i.
  // For normal32: |s| < inner32[i] iff s / 2^24 lies in layer i's inner rectangle, and
  // width32[i] = x[i] / 2^24.
  struct Ziggurat {
    double x[129];
    double ratio2[128];
    double f[129];  // exp(-x[i]^2 / 2)
    std::uint32_t inner32[128];
    float width32[128];
  };
  static constexpr std::uint64_t kGamma = 0x9e3779b97f4a7c15ULL;  // the golden gamma
  static std::uint64_t mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  RandomStream(std::uint64_t start, const Ziggurat* table) : table_(table), start_(start), state_(start) {}
  static const Ziggurat& ziggurat();
  double normal_slow(unsigned layer, double u);
  float normal32_slow(unsigned layer, std::int32_t s, std::uint64_t slow_index) const;

  const Ziggurat* table_;  // ziggurat(), looked up once per stream
  std::uint64_t start_;    // the key: the counter before the first draw
  std::uint64_t state_;
};

}  // namespace sonomap::sim
