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

}  // namespace

RandomStream::RandomStream(std::initializer_list<std::uint64_t> key) : engine_(mix_key(key)) {}

double RandomStream::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u, v, s;
  do {
    u = 2.0 * uniform() - 1.0;
    v = 2.0 * uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * factor;
  has_spare_ = true;
  return u * factor;
}

}  // namespace sonomap::sim
