// IdentificationOptions' settings (settings.h), apart from the solvers so that the readers of
// user files (and their fuzz targets) need no solver to check them.
#include <limits>

#include "lrcal/identification/identification.h"

namespace lrcal {

const std::vector<SettingField<IdentificationOptions>>& IdentificationOptions::Settings() {
  using O = IdentificationOptions;
  constexpr double kNoMax = std::numeric_limits<double>::infinity();
  static const std::vector<SettingField<O>> fields = {
      {{"identification", "max_iterations", "max_iterations", "", 1, "", 1, 1e4, false, true,
        "iterations", "", "iterations of the least-squares solve"},
       nullptr,
       &O::max_iterations},
      {{"identification", "max_robust_iterations", "max_robust_iterations", "", 1, "", 1, 1e6,
        false, true, "iterations", "", "iterations of the robust refinement"},
       nullptr,
       &O::max_robust_iterations},
      {{"identification", "parameter_tolerance", "parameter_tolerance", "", 1, "", 0, kNoMax, false,
        false, "", "", "stop when the step is below this times (|e| + this)"},
       &O::parameter_tolerance},
      {{"identification", "function_tolerance", "function_tolerance", "", 1, "", 0, kNoMax, false,
        false, "", "", "stop when the cost decreases by less than this fraction"},
       &O::function_tolerance},
      {{"identification", "sigma", "sigma_mm", "mm", 1e-3, "m", 0, kNoMax, false, false, "", "",
        "known noise of one reading, for the given-sigma covariance and the fit check (0: "
        "unknown)"},
       &O::sigma},
      {{"identification", "loss_scale", "loss_scale_mm", "mm", 1e-3, "m", 0, kNoMax, true, false,
        "", "",
        "robust loss scale on each configuration's residual sqrt(R)*(mean h - h); e.g. 1.345 "
        "sigma for Huber, 2.385 sigma for Cauchy (95 % efficiency)"},
       &O::loss_scale},
      {{"identification", "loss_scale_sigma", "loss_scale_sigma", "σ", 1, "σ", 0, kNoMax, false,
        false, "", "not used: the scale is loss_scale_mm",
        "the robust loss scale in multiples of one reading's sigma (which must be given), in "
        "place of the scale in mm; 1.345 for Huber, 2.385 for Cauchy (95 % efficiency)"},
       &O::loss_scale_sigma},
  };
  return fields;
}

void IdentificationOptions::Validate() const {
  CheckSettings(*this, Settings());
  const SettingSpec encoder{"identification",
                            "encoder_sigma",
                            "encoder_sigma_mrad",
                            "mrad",
                            1e-3,
                            "rad",
                            0,
                            std::numeric_limits<double>::infinity(),
                            false,
                            false,
                            "",
                            "",
                            "standard deviation of each recorded joint value"};
  if (!encoder.Allows(encoder_sigma)) throw SettingError(encoder, encoder_sigma);
  if (encoder_sigma > 0 && !(sigma > 0))
    throw SettingError(encoder,
                       "errors in variables are weighed against the readings' noise: "
                       "give the noise of one reading as well");
  if (loss_scale_sigma > 0 && !(sigma > 0))
    throw SettingError(FindSetting(Settings(), "loss_scale_sigma")->spec,
                       "a loss scale in multiples of sigma needs the readings' noise: give the "
                       "noise of one reading as well, or the scale in mm");
  if (!priors.empty() && !(sigma > 0))
    throw SettingError(SettingSpec::Named("identification", "priors", "prior_sigma"),
                       "priors are weighed against the readings' noise: give the noise of one "
                       "reading as well");
}

}  // namespace lrcal
