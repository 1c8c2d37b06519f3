#include "lrcal/measurement/noise_model.h"

#include <cmath>
#include <limits>

#include "lrcal/core/error.h"

namespace lrcal {

namespace {}  // namespace

const std::vector<SettingField<NoiseModel>>& NoiseModel::Settings() {
  using N = NoiseModel;
  static const std::vector<SettingField<N>> fields = {
      {{"noise", "sigma", "sigma_mm", "mm", 1e-3, "m", 0, kInf, false, false, "", "",
        "standard deviation of one reading"},
       &N::sigma},
      {{"noise", "repetitions", "repetitions", "", 1, "", 1, 1e6, false, true,
        "readings per configuration", "", "readings averaged per configuration"},
       nullptr,
       &N::repetitions},
      {{"noise", "encoder_sigma", "encoder_sigma_mrad", "mrad", 1e-3, "rad", 0, kInf, false, false,
        "", "",
        "joint-encoder noise, each joint, each reading (the data record the angles without it)"},
       &N::encoder_sigma},
      {{"noise", "form_sigma", "form_sigma_mm", "mm", 1e-3, "m", 0, kInf, false, false, "", "",
        "plane flatness deviation at each configuration's hit point"},
       &N::form_sigma},
      {{"noise", "outlier_fraction", "outlier_fraction", "", 1, "", 0, 1, false, false, "", "",
        "share of readings with a gross error"},
       &N::outlier_fraction},
      {{"noise", "outlier_sigma", "outlier_sigma_mm", "mm", 1e-3, "m", 0, kInf, false, false, "",
        "", "standard deviation of a gross error"},
       &N::outlier_sigma},
  };
  return fields;
}

double NoiseModel::EffectiveReadings() const {
  if (average.IsMean()) return repetitions;
  return repetitions / average.VarianceFactor(repetitions);
}

void NoiseModel::Validate() const {
  CheckSettings(*this, Settings());
  average.CheckCount(repetitions);
  if (!std::isfinite(ranger_offset))
    throw InputError("noise.ranger_offset", "expected a finite offset (m)");
  if (!(std::fabs(ranger_scale) < 0.5))
    throw InputError("noise.ranger_scale", "expected a scale error of magnitude below 0.5");
  if (!(sigma_angle >= 0) || !std::isfinite(sigma_angle))
    throw InputError("noise.sigma_angle", "expected a finite standard deviation >= 0 (rad)");
}

}  // namespace lrcal
