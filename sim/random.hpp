// SPDX-License-Identifier: GPL-3.0-or-later
// Reproducible random streams: std::mt19937_64 seeded from a key (run seed, sensor id, frame,
// purpose, ...), and our own uniform and normal samplers, so sequences are the same with any
// standard library (std::normal_distribution differs between libstdc++ and libc++).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <random>

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

  // Uniform in [0, 1), 53 random bits. (Inline: the noise stages call it per pixel.)
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  // Standard normal (Marsaglia polar method; the spare value is kept for the next call).
  double normal();
  double normal(double sigma) { return sigma * normal(); }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace sonomap::sim
