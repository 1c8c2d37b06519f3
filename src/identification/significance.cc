#include "lrcal/identification/significance.h"

#include <cmath>
#include <stdexcept>

namespace lrcal {

std::vector<std::string> InsignificantCorrections::Names() const {
  std::vector<std::string> names;
  for (const Term& t : terms) names.push_back(t.name);
  return names;
}

PriorSigmas InsignificantCorrections::Tolerances() const {
  PriorSigmas out;
  for (const Term& t : terms) out.entries.push_back({t.name, std::hypot(t.delta, t.sd)});
  return out;
}

InsignificantCorrections FindInsignificantCorrections(const IdentificationSummary& s,
                                                      const IdentificationOptions& options,
                                                      double k) {
  if (!(k > 0) || !std::isfinite(k))
    throw std::invalid_argument("FindInsignificantCorrections: k must be positive and finite");
  InsignificantCorrections out;
  out.k = k;
  const Eigen::MatrixXd& covariance = FitCovariance(s, options);
  for (std::size_t j = 0; j < s.names.size(); ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    const double sd = std::sqrt(covariance(i, i));
    if (std::abs(s.delta[i]) < k * sd) out.terms.push_back({s.names[j], s.delta[i], sd});
  }
  return out;
}

}  // namespace lrcal
