#include "core/cpu_dispatch.h"

#include <cstdlib>
#include <string>

namespace lrcal {

const char* IsaName(Isa isa) {
  switch (isa) {
    case Isa::kDefault:
      return "default";
    case Isa::kAvx2:
      return "avx2";
    case Isa::kAvx512:
      return "avx512";
  }
  return "?";
}

std::vector<Isa> SupportedIsas() {
  std::vector<Isa> out = {Isa::kDefault};
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) out.push_back(Isa::kAvx2);
  if (__builtin_cpu_supports("avx512f")) out.push_back(Isa::kAvx512);
#endif
  return out;
}

Isa ActiveIsa() {
  static const Isa isa = [] {
    const std::vector<Isa> supported = SupportedIsas();
    Isa best = supported.back();
    if (const char* forced = std::getenv("LRCAL_ISA")) {
      for (Isa i : supported)
        if (std::string(forced) == IsaName(i)) return i;
    }
    return best;
  }();
  return isa;
}

}  // namespace lrcal
