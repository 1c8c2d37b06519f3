// How good is a chosen design? An upper bound on what any k of the N candidates can reach, from
// the continuous relaxation of the selection problem, so that "the chosen design reaches X % of
// the best possible" is a proven statement, not a comparison with other heuristics.
//
// Relaxation: weights 0 ≤ w_i ≤ 1 with Σ w_i = k on the candidates' rows g_i of G, information
// M(w) = Σ w_i g_i g_iᵀ. Every k-subset S is a feasible w, so the relaxed optimum bounds the best
// subset. The bounds used are valid for *any* feasible w (no convergence needed for validity):
//   E (λ_min(M), concave): for any Z ⪰ 0 with trace 1, λ_min(G_SᵀG_S) ≤ tr(Z G_SᵀG_S)
//     ≤ the sum of the k largest g_iᵀ Z g_i. Z is taken from the relaxation's iterates (the
//     eigenvector of λ_min, and a soft-min mixture of the low eigenvectors).
//   D (log det M) and A (−tr M⁻¹), concave and smooth: f(S) ≤ f(w) + Σ_top-k ∇f(w) − ∇f(w)ᵀw
//     (the supergradient inequality maximised over the feasible set: the Frank–Wolfe gap).
// The relaxation is solved by projected gradient ascent on the capped simplex; the best bound
// over the iterations is kept. Efficiencies: E σ_min / √bound; D exp((log det − bound)/n);
// A bound_on_trace / tr (GᵀG)⁻¹. The other criteria (O1, O2, O4, O5) have no certificate.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/design/experiment_design.h"

namespace lrcal {

struct DesignCertificate {
  bool available = false;  ///< false for criteria without a relaxation bound, or k < n
  /// The best any k of the candidates can reach, in the criterion's own units (E: σ_min; D: log
  /// det GᵀG; A: −tr (GᵀG)⁻¹), an upper bound.
  double bound = 0;
  double achieved = 0;    ///< the chosen design's score, same units
  double efficiency = 0;  ///< in (0, 1]: see the file comment
  int iterations = 0;     ///< relaxation iterations spent
  /// "the chosen design reaches 99.8 % of the best possible E (σ_min ≤ 0.4425 for any 50 of
  /// these 101 candidates)", or why there is no certificate.
  std::string ToString(DesignCriterion criterion, int k, int candidates) const;
};

/// Certifies the design `chosen` (row indices into G, N×n, as SelectConfigurations uses) for
/// `criterion`. `iterations` bounds the relaxation's work (each costs one n×n eigen- or Cholesky
/// decomposition and an N·n² product).
DesignCertificate CertifyDesign(const Eigen::MatrixXd& G, const std::vector<int>& chosen,
                                DesignCriterion criterion, int iterations = 1500);

/// The relaxation's bound alone (no chosen design): the upper bound on `criterion` over every
/// k-subset of G's rows. NaN when unavailable.
double DesignUpperBound(const Eigen::MatrixXd& G, int k, DesignCriterion criterion,
                        int iterations = 1500);

/// The relaxation's solution rounded to a design: the k candidates with the largest weights
/// (ascending indices); empty when the criterion has no relaxation. A start for exchange.
std::vector<int> RelaxedDesign(const Eigen::MatrixXd& G, int k, DesignCriterion criterion,
                               int iterations = 300);

}  // namespace lrcal
