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
// on the fast path (99% of samples), exact tail and wedges otherwise.
#pragma once

#include <cstdint>
#include <initializer_list>

namespace sonomap::sim {

// What a stream is used for; part of its key so that streams never overlap.
enum class StreamPurpose : std::uint64_t {
  LateralJitter = 1,
  AxialNoise = 2,
  Dropout = 4,
  LocalisationNoise = 5,
  LocalisationDrift = 6,
};

class RandomStream {
 public:
  // Seeded from every word of `key` (mixed with splitmix64), e.g. {seed, sensor, frame, purpose}.
  explicit RandomStream(std::initializer_list<std::uint64_t> key);

  // The next 64 random bits. (Inline, as the samplers below: the noise stages call them per pixel.)
  std::uint64_t bits() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
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

 private:
  // Layer edges x[0] > x[1] = R > ... > x[128] = 0 of equal-area layers under exp(-x^2 / 2),
  // and (x[i+1] / x[i])^2, the inner rectangle's share of layer i.
  struct Ziggurat {
    double x[129];
    double ratio2[128];
  };
  static const Ziggurat& ziggurat();
  double normal_slow(unsigned layer, double u);

  const Ziggurat* table_;  // ziggurat(), looked up once per stream
  std::uint64_t state_;
};

}  // namespace sonomap::sim
