// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/vector_isa.hpp"

#include <atomic>
#include <stdexcept>

namespace sonomap {

namespace {

VectorIsa best_supported() {
  for (VectorIsa isa : {VectorIsa::Avx512, VectorIsa::Avx2})
    if (supported(isa)) return isa;
  return VectorIsa::Baseline;
}

std::atomic<VectorIsa>& current() {
  static std::atomic<VectorIsa> isa{best_supported()};
  return isa;
}

}  // namespace

bool supported(VectorIsa isa) {
#ifdef SONOMAP_X86_KERNELS
  if (isa == VectorIsa::Avx2) return __builtin_cpu_supports("avx2");
  if (isa == VectorIsa::Avx512)
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw");
#endif
  return isa == VectorIsa::Baseline;
}

VectorIsa vector_isa() { return current().load(std::memory_order_relaxed); }

const char* name_of(VectorIsa isa) {
  switch (isa) {
    case VectorIsa::Avx2:
      return "AVX2";
    case VectorIsa::Avx512:
      return "AVX-512";
    case VectorIsa::Baseline:
      break;
  }
  return "baseline";
}

ScopedVectorIsa::ScopedVectorIsa(VectorIsa isa) : previous_(vector_isa()) {
  if (!supported(isa)) throw std::invalid_argument("ScopedVectorIsa: this CPU lacks the instruction set asked for");
  current().store(isa);
}

ScopedVectorIsa::~ScopedVectorIsa() { current().store(previous_); }

}  // namespace sonomap
