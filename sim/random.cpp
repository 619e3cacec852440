// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/random.hpp"

#include <cmath>

namespace sonomap::sim {

namespace {

// splitmix64 (Steele, Lea, Flood 2014): decorrelates nearby keys such as consecutive frames.
std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

std::uint64_t mix_key(std::initializer_list<std::uint64_t> key) {
  std::uint64_t h = 0x5eed5eed5eed5eedULL;
  for (std::uint64_t word : key) h = splitmix64(h ^ splitmix64(word));
  return h;
}

// Doornik (2005): R, the start of the tail, and V, the area of each of the 128 layers
// (the base layer includes the tail beyond R).
constexpr double kTailStart = 3.442619855899;
constexpr double kLayerArea = 9.91256303526217e-3;

double density(double x) { return std::exp(-0.5 * x * x); }

}  // namespace

RandomStream::RandomStream(std::initializer_list<std::uint64_t> key)
    : table_(&ziggurat()), start_(mix_key(key)), state_(start_) {}

const RandomStream::Ziggurat& RandomStream::ziggurat() {
  // Built once (thread-safe static initialisation) from exp, log and sqrt only.
  static const Ziggurat table = [] {
    Ziggurat z{};
    z.x[0] = kLayerArea / density(kTailStart);  // the base layer's equivalent width
    z.x[1] = kTailStart;
    for (int i = 2; i < 128; ++i)
      z.x[i] = std::sqrt(-2.0 * std::log(kLayerArea / z.x[i - 1] + density(z.x[i - 1])));
    z.x[128] = 0.0;
    for (int i = 0; i <= 128; ++i) z.f[i] = density(z.x[i]);
    for (int i = 0; i < 128; ++i) {
      z.ratio2[i] = (z.x[i + 1] / z.x[i]) * (z.x[i + 1] / z.x[i]);
      // |s| < inner32 iff |s| / 2^24 < x[i+1] / x[i]: the smallest integer not below the edge.
      z.inner32[i] = static_cast<std::uint32_t>(std::ceil(0x1.0p24 * (z.x[i + 1] / z.x[i])));
      z.width32[i] = static_cast<float>(z.x[i] * 0x1.0p-24);
    }
    return z;
  }();
  return table;
}

// The rare cases: the base layer's tail beyond R (Marsaglia 1964), or a layer's wedge
// (accepted under the density, else a fresh sample).
double RandomStream::normal_slow(unsigned layer, double u) {
  const Ziggurat& z = *table_;
  for (;;) {
    if (layer == 0) {
      double x, y;
      do {
        x = std::log(1.0 - uniform()) / kTailStart;  // 1 - uniform() is in (0, 1]
        y = std::log(1.0 - uniform());
      } while (-2.0 * y < x * x);
      return u < 0.0 ? x - kTailStart : kTailStart - x;
    }
    // The wedge: accept x if a point uniform in height between the layer's edges lies under
    // the density (one exp; the edges' densities are tabulated).
    const double x = u * z.x[layer];
    if (z.f[layer + 1] + uniform() * (z.f[layer] - z.f[layer + 1]) < density(x)) return x;
    // Rejected: a fresh draw, the same as normal() (which may take the fast path).
    const std::uint64_t r = bits();
    layer = static_cast<unsigned>(r & 127u);
    u = static_cast<double>(r >> 11) * 0x1.0p-52 - 1.0;
    if (u * u < z.ratio2[layer]) return u * z.x[layer];
  }
}

float RandomStream::normal32_slow(unsigned layer, std::int32_t s, std::uint64_t slow_index) const {
  // A stream of its own per (stream, index), started with two mixes instead of a full key.
  const std::uint64_t salt = static_cast<std::uint64_t>(StreamPurpose::SlowNormal) * kGamma;
  RandomStream more(mix(start_ ^ mix(slow_index + salt)), table_);
  return static_cast<float>(more.normal_slow(layer, static_cast<double>(s) * 0x1.0p-24));
}

}  // namespace sonomap::sim
