// SPDX-License-Identifier: GPL-3.0-or-later
// Comparing the copies of the vectorised loops (core/vector_isa.hpp) bit for bit.
#pragma once

#include "core/vector_isa.hpp"

#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

// The instruction sets whose copies a test can compare with the baseline's on this CPU; each
// one the CPU lacks is named in a warning.
inline std::vector<sonomap::VectorIsa> vector_isas_beside_baseline() {
  std::vector<sonomap::VectorIsa> isas;
  for (sonomap::VectorIsa isa : {sonomap::VectorIsa::Avx2, sonomap::VectorIsa::Avx512}) {
    if (sonomap::supported(isa))
      isas.push_back(isa);
    else
      WARN(sonomap::name_of(isa) << " is not on this CPU: its copy of the loops is not compared");
  }
  return isas;
}

// Whether a and b hold the same bytes.
template <typename T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}
