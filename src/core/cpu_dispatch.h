// Run-time choice of instruction set for lrcal's two hot kernels (the batch readings/Jacobian
// kernel and the normal matrix), so that the default, portable build runs AVX2 or AVX-512 code
// where the CPU has it.
//
// Bit-reproducibility is kept on purpose: both kernels are elementwise or sum in explicit,
// fixed partial-sum lanes, and the project compiles with -ffp-contract=off (no fused
// multiply-adds), so every variant returns the same bits; cpu_dispatch_test.cc checks that for
// each variant this CPU can run. LRCAL_ISA=default|avx2|avx512 in the environment forces a
// variant (never one the CPU lacks).
#pragma once

#include <vector>

namespace lrcal {

enum class Isa { kDefault, kAvx2, kAvx512 };

/// The variant in use: the best the CPU supports, or LRCAL_ISA if set (and supported).
Isa ActiveIsa();
/// Every variant this CPU can run.
std::vector<Isa> SupportedIsas();
const char* IsaName(Isa isa);

}  // namespace lrcal
