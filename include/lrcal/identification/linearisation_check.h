// Does a fit's stated covariance hold? The covariance of a least-squares estimate,
// Σ = σ²·(GᵀWG)⁻¹, is the linearised model's: it holds while the model is close to linear over
// the region the estimate is uncertain in. Where it is not — a term the data barely see, uncertain
// by millimetres, whose error bends the predictions of the well-determined combinations — the
// estimate's error δ is larger than Σ says in exactly those combinations, and δᵀ·Σ⁻¹·δ, which
// averages n (a χ²(n) law) for a linear model, averages more.
//
// The check predicts that excess from the model's second derivatives (the parameter-effects
// curvature of Bates & Watts, 1980, taken in expectation): with d₁ = Σ_k s_k·z_k·v_k the
// linearised error (v_k, s_k² the eigenvectors and eigenvalues of Σ, z_k independent standard
// normals), the second-order term of the estimate is d₂ = −(GᵀWG)⁻¹·GᵀW·½·f''[d₁, d₁], and by
// Isserlis' theorem
//
//   E[d₂ᵀ·Σ⁻¹·d₂] = ( |Σ_j c_jj|² + 2·Σ_{j,k} |c_jk|² ) / σ²,
//   c_jk = P·½·f''[s_j·v_j, s_k·v_k],
//
// |·| the W-weighted norm and P the W-orthogonal projection onto G's columns. The directional
// second derivatives are central differences one standard deviation wide (four predictions per
// pair of directions): the curvature averaged over the region of interest, not at a point. The
// cross term E[d₁ᵀΣ⁻¹d₂] vanishes (odd moments), and the intrinsic curvature's part (the
// residual's bending away from G's columns, which moves the estimate only through the residuals)
// is left out: it is usually far smaller (Bates & Watts), so the predicted excess is a lower
// bound in principle and, in the Monte-Carlo tests, within a few percent of the observed one.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "lrcal/measurement/measurement_kind.h"

namespace lrcal {

/// The second-order check of a fit's covariance (the file comment). Dimensionless.
struct LinearisationCheck {
  /// False when not asked for (IdentificationOptions::check_linearisation), when the fit is not
  /// usable or has no covariance (no σ and no residual degrees of freedom), or when a prediction
  /// is undefined one standard deviation from the estimate (`message` says which).
  bool computed = false;
  /// Predicted E[δᵀ·Σ⁻¹·δ] − n: what the model's curvature adds to the χ²(n) of the estimate.
  double excess = std::numeric_limits<double>::quiet_NaN();
  int num_parameters = 0;
  /// The pairs of directions the excess sums over: all n(n+1)/2 up to kMaxFullTerms terms; above,
  /// the pairs that include one of the kMaxFullTerms least certain directions (the others' terms
  /// scale with the product of two small variances).
  int pairs = 0;
  static constexpr int kMaxFullTerms = 40;
  /// Above this fraction of n the covariance is called optimistic: its ellipsoid then holds
  /// about (1 + excess/n) times less of the estimate's error than it states.
  static constexpr double kMaxRelativeExcess = 0.1;
  std::string message;
  /// The direction in the estimated terms (unit, n values, an eigenvector of the covariance)
  /// that contributes most to the excess — each pair's part counted for the less certain of its
  /// two directions — and its standard deviation (the terms' mixed SI units).
  Eigen::VectorXd worst_direction;
  double worst_direction_sigma = 0;

  /// excess / n.
  double RelativeExcess() const { return excess / num_parameters; }
  /// Computed and excess ≤ kMaxRelativeExcess·n.
  bool Holds() const { return computed && RelativeExcess() <= kMaxRelativeExcess; }
  /// One or two lines for lrcal identify's text; "" when not asked for. With the terms' names (n
  /// of them), a covariance called optimistic names the terms of the worst direction.
  std::string Explain(const std::vector<std::string>& names = {}) const;
};

/// The check at estimate `e` of a fit whose rows `evaluator` predicts, each weighed by
/// `weights[i]` (the solver's), with covariance `covariance` (n × n) formed with per-reading σ
/// `sigma` (> 0). Never throws for a defined fit; a prediction that fails away from the estimate
/// leaves the result not computed, with its message.
LinearisationCheck CheckLinearisation(MeasurementEvaluator& evaluator,
                                      const std::vector<double>& weights, const Eigen::VectorXd& e,
                                      const Eigen::MatrixXd& covariance, double sigma);

}  // namespace lrcal
