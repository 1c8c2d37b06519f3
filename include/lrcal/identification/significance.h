// Which corrections of a fit the data tell apart from zero (identify --only-significant): those
// within K standard deviations are held at nominal and the rest refitted; what is known of a held
// term's deviation then enters every accuracy statement as its tolerance.
#pragma once

#include <string>
#include <vector>

#include "lrcal/identification/identification.h"
#include "lrcal/identification/prior.h"

namespace lrcal {

struct InsignificantCorrections {
  double k = 0;  ///< the threshold, in standard deviations
  struct Term {
    std::string name;
    double delta = 0;  ///< the full fit's correction (SI)
    double sd = 0;     ///< its standard deviation (SI, FitCovariance)
  };
  std::vector<Term> terms;  ///< |delta| < k·sd, in the fit's parameter order
  std::vector<std::string> Names() const;
  /// Each held term's possible deviation from nominal, √(δ² + sd²): the root mean square of its
  /// true deviation given the full fit (δ_true ~ N(δ, sd²)), as a tolerance (prior.h keys).
  PriorSigmas Tolerances() const;
};

/// The corrections of the usable fit `s` smaller than `k` (> 0) of their standard deviations,
/// with the covariance the options choose (FitCovariance). Throws std::invalid_argument for a k
/// that is not a positive finite number.
InsignificantCorrections FindInsignificantCorrections(const IdentificationSummary& s,
                                                      const IdentificationOptions& options,
                                                      double k);

}  // namespace lrcal
