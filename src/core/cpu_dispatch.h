// Run-time choice of instruction set for lrcal's two hot kernels (the batch readings/Jacobian
// kernel and the normal matrix), so that the default, portable build runs AVX2 or AVX-512 code
// where the CPU has it.
//
// Bit-reproducibility is kept on purpose: both kernels are elementwise or sum in explicit,
// fixed partial-sum lanes, and the project compiles with -ffp-contract=off (no fused
// multiply-adds), so every variant returns the same bits; cpu_dispatch_test.cc checks that for
// each variant this CPU can run. LRCAL_ISA=default|avx2|avx512|avx512-on-avx2 in the environment
// forces a variant (never one the CPU lacks).
//
// avx512-on-avx2 exists for the tests, and is never chosen unless forced: the AVX-512 variant's
// kernels (the same source, eight lanes per vector: blocks of eight configurations, the normal
// matrix's 2 × 8 entries per pass) compiled for AVX2, which GCC lowers to pairs of four-lane
// registers. A machine without AVX-512 (CI's) thereby runs, under the sanitizers too, every line
// of the code an AVX-512 machine runs; only the compiler's choice of AVX-512 instructions for it
// is left untested there.
#pragma once

#include <vector>

namespace lrcal {

enum class Isa {
  kDefault,      ///< baseline x86-64 (SSE2), or the only variant off x86-64
  kAvx2,         ///< AVX2 (four doubles a vector)
  kAvx512,       ///< AVX-512 F (eight doubles a vector)
  kAvx512OnAvx2  ///< the AVX-512 variant's eight-lane kernels compiled for AVX2 (tests only)
};

/// The variant in use: LRCAL_ISA if set (and supported), otherwise the best the CPU supports
/// (kAvx512, else kAvx2, else kDefault; never kAvx512OnAvx2).
Isa ActiveIsa();
/// Every variant this CPU can run, kDefault first (kAvx512OnAvx2 wherever kAvx2 runs).
std::vector<Isa> SupportedIsas();
const char* IsaName(Isa isa);

}  // namespace lrcal
