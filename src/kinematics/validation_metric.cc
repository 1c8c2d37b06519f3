#include "lrcal/kinematics/validation_metric.h"

#include <array>
#include <string>

namespace lrcal {

const char* ValidationColumnName(int k) {
  static const std::array<std::string, kNumValidationColumns> names = [] {
    std::array<std::string, kNumValidationColumns> n;
    for (int c = 0; c < kNumValidationColumns; ++c)
      n[c] =
          std::string(NameOf(kValidationMetricNames, MetricOfColumn(c))) + "_" + kAxisNames[c % 3];
    return n;
  }();
  return names.at(k).c_str();
}

}  // namespace lrcal
