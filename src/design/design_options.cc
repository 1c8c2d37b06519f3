// The settings of sampling and selection (settings.h), apart from the samplers and the solvers
// so that the study reader (and its fuzz target) needs neither.
#include <limits>

#include "lrcal/design/configuration_sampling.h"
#include "lrcal/design/experiment_design.h"

namespace lrcal {

const std::vector<SettingField<SamplingOptions>>& SamplingOptions::Settings() {
  using O = SamplingOptions;
  static const std::vector<SettingField<O>> fields = {
      {{"pool", "min_jacobian_singular_value", "min_singular_value", "", 1, "", 0,
        std::numeric_limits<double>::infinity(), false, false, "", "",
        "reject arm configurations whose geometric Jacobian has a smaller singular value"},
       &O::min_jacobian_singular_value},
      {{"pool", "max_attempts_per_configuration", "max_attempts", "", 1, "", 1, 1e9, false, true,
        "attempts per configuration", "",
        "give up after this many attempts per requested configuration"},
       nullptr,
       &O::max_attempts_per_configuration},
  };
  return fields;
}

void SamplingOptions::Validate() const {
  CheckSettings(*this, Settings());
  ranger.Validate();
}

const std::vector<SettingField<SelectionOptions>>& SelectionOptions::Settings() {
  using O = SelectionOptions;
  static const std::vector<SettingField<O>> fields = {
      {{"selection", "samples", "samples", "", 1, "", 1, 1e6, false, true, "random subsets", "",
        "random subsets tried by the sampled method (the paper's case 1)"},
       nullptr,
       &O::samples},
      {{"selection", "restarts", "restarts", "", 1, "", 1, 1000, false, true, "starts", "",
        "exchange: starts (the greedy designs, the relaxation's, then kicks of the best)"},
       nullptr,
       &O::restarts},
      {{"selection", "exhaustive_limit", "exhaustive_limit", "", 1, "", 1,
        std::numeric_limits<double>::infinity(), false, false, "", "",
        "most subsets the exhaustive method will enumerate"},
       &O::exhaustive_limit},
  };
  return fields;
}

void SelectionOptions::Validate() const { CheckSettings(*this, Settings()); }

}  // namespace lrcal
