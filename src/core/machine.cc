#include "lrcal/core/machine.h"

#include <fstream>

#include "core/cpu_dispatch.h"

namespace lrcal {

std::string CpuModelName() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) break;
    const auto first = line.find_first_not_of(" \t", colon + 1);
    return first == std::string::npos ? "unknown" : line.substr(first);
  }
  return "unknown";
}

const char* KernelVariant() { return IsaName(ActiveIsa()); }

}  // namespace lrcal
