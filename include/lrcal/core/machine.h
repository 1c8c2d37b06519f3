// The machine that computed a result, for provenance: timings and benchmark figures mean little
// without the CPU they came from, and the run manifest, `lrcal --version` and the benchmarks
// record both answers below.
#pragma once

#include <string>

namespace lrcal {

/// The CPU's model name as Linux reports it ("model name" in /proc/cpuinfo, e.g. "AMD EPYC"), or
/// "unknown" where there is none.
std::string CpuModelName();

/// The instruction-set variant the dense kernels (dense_kernels.h) and the batch evaluators run
/// in this process: "default" (baseline x86-64), "avx2" or "avx512", the best the CPU has, unless
/// LRCAL_ISA in the environment forced another it has (also "avx512-on-avx2": the AVX-512
/// variant's code compiled for AVX2, for tests). Every variant gives the same bits.
const char* KernelVariant();

}  // namespace lrcal
