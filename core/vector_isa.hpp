// SPDX-License-Identifier: GPL-3.0-or-later
// The instruction set of the vectorised loops: the sensor's per-pixel loops (noise rows, ray
// incidence), the rasteriser's first pass, the point binning's batch pass and the GP kernel
// sums (core/gp.cpp, in vector types). Each loop is written once (SONOMAP_VECTOR_LOOP) and
// compiled three times: for the baseline x86-64 instruction set and, inside
// SONOMAP_AVX2_KERNEL and SONOMAP_AVX512_KERNEL functions, for AVX2 and AVX-512, chosen at run
// time (kernel_for). All give the same bits:
// only IEEE basic operations, sqrt and floor, and no fused multiply-add (it rounds once where
// the baseline rounds twice; "fma" is not in the AVX2 target, and these files build with
// -ffp-contract=off, so the AVX-512 code, whose instruction set has it, never contracts).
// Tests compare the copies on the same input, bit for bit.
#pragma once

namespace sonomap {

enum class VectorIsa { Baseline, Avx2, Avx512 };

// Whether this CPU (and build) can run `isa`.
bool supported(VectorIsa isa);

// The instruction set in use: the best supported one, unless a ScopedVectorIsa limits it.
VectorIsa vector_isa();

// "baseline", "AVX2" or "AVX-512" (for reports).
const char* name_of(VectorIsa isa);

// Limits the vectorised loops to `isa` (which must be supported) while it lives,
// process-wide: tests use it to run the baseline, AVX2 and AVX-512 copies on the same input.
class ScopedVectorIsa {
 public:
  explicit ScopedVectorIsa(VectorIsa isa);
  ~ScopedVectorIsa();
  ScopedVectorIsa(const ScopedVectorIsa&) = delete;
  ScopedVectorIsa& operator=(const ScopedVectorIsa&) = delete;

 private:
  VectorIsa previous_;
};

// The kernel compiled for `isa`.
template <typename Kernel>
Kernel kernel_for(VectorIsa isa, Kernel baseline, Kernel avx2, Kernel avx512) {
  return isa == VectorIsa::Avx512 ? avx512 : isa == VectorIsa::Avx2 ? avx2 : baseline;
}

}  // namespace sonomap

// A loop body inlined into every copy (kernels must call only such functions in hot loops).
#define SONOMAP_VECTOR_LOOP inline __attribute__((always_inline))
// The AVX2 and AVX-512 copies of a kernel: flatten inlines everything it calls, so that is
// compiled for the kernel's instruction set too. Elsewhere than x86 they are baseline copies,
// never chosen (supported() is false).
#if defined(__x86_64__) || defined(__i386__)
#define SONOMAP_X86_KERNELS 1
#define SONOMAP_AVX2_KERNEL __attribute__((target("avx2"), flatten))
#define SONOMAP_AVX512_KERNEL __attribute__((target("avx512f,avx512dq,avx512vl,avx512bw"), flatten))
#else
#define SONOMAP_AVX2_KERNEL __attribute__((flatten))
#define SONOMAP_AVX512_KERNEL __attribute__((flatten))
#endif
