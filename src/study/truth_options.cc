#include "lrcal/study/truth_options.h"

#include <cmath>
#include <limits>

namespace lrcal {

namespace {}  // namespace

const std::vector<SettingField<TruthOptions>>& TruthOptions::Settings() {
  using T = TruthOptions;
  static const std::vector<SettingField<T>> fields = {
      {{"truth", "scale", "scale", "", 1, "", 0, kInf, false, false, "", "",
        "robot_file truth: the file's true errors times this"},
       &T::scale},
      {{"truth", "angle_sigma", "angle_sigma_mrad", "mrad", 1e-3, "rad", 0, kInf, false, false, "",
        "", "random truth: standard deviation of each drawn angle error"},
       &T::angle_sigma},
      {{"truth", "length_sigma", "length_sigma_mm", "mm", 1e-3, "m", 0, kInf, false, false, "", "",
        "random truth: standard deviation of each drawn length error"},
       &T::length_sigma},
  };
  return fields;
}

void TruthOptions::Validate() const {
  CheckSettings(*this, Settings());
  if (ranger_offset && !std::isfinite(*ranger_offset))
    throw SettingError(SettingSpec::Named("truth", "ranger_offset", "ranger_offset_mm"),
                       "expected a finite number (mm)");
  if (ranger_scale && !(std::fabs(*ranger_scale) < kMaxRangerScale))
    throw SettingError(SettingSpec::Named("truth", "ranger_scale", "ranger_scale_ppm"),
                       "expected a scale error in ppm, below 500,000 in magnitude");
}

}  // namespace lrcal
