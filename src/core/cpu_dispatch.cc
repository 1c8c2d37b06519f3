#include "core/cpu_dispatch.h"

#include <algorithm>
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
    case Isa::kAvx512OnAvx2:
      return "avx512-on-avx2";
  }
  return "?";
}

std::vector<Isa> SupportedIsas() {
  std::vector<Isa> out = {Isa::kDefault};
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) {
    out.push_back(Isa::kAvx2);
    out.push_back(Isa::kAvx512OnAvx2);
  }
  if (__builtin_cpu_supports("avx512f")) out.push_back(Isa::kAvx512);
#endif
  return out;
}

Isa ActiveIsa() {
  static const Isa isa = [] {
    const std::vector<Isa> supported = SupportedIsas();
    if (const char* forced = std::getenv("LRCAL_ISA")) {
      for (Isa i : supported)
        if (std::string(forced) == IsaName(i)) return i;
    }
    const auto has = [&](Isa i) {
      return std::find(supported.begin(), supported.end(), i) != supported.end();
    };
    return has(Isa::kAvx512) ? Isa::kAvx512 : has(Isa::kAvx2) ? Isa::kAvx2 : Isa::kDefault;
  }();
  return isa;
}

}  // namespace lrcal
