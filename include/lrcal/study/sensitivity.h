// Global sensitivity analysis: which uncertain inputs a quantity of interest depends on.
//
// Sobol indices (variance-based): for inputs X_1..X_d independent and uniform on the unit cube
// (mapped to the inputs' own ranges by the caller) and Y = f(X), the first-order index
// S_i = Var(E[Y|X_i]) / Var(Y) (the share of the variance X_i explains alone) and the total index
// T_i = E[Var(Y|X_~i)] / Var(Y) (its share including all interactions). Estimated from Saltelli's
// plan: two independent N×d samples A and B and the d matrices AB_i (A with column i taken from
// B), N(d+2) evaluations; S_i by Saltelli et al. (2010), mean((f(B) − f̄)·(f(AB_i) − f(A))) / V
// (f(B) centred on the mean f̄ of f over A and B, which keeps the expectation and removes the
// variance that f's mean would add), and T_i
// by Jansen (1999), mean((f(A) − f(AB_i))²) / (2V), V the variance of f over A and B together.
// Confidence intervals: percentile bootstrap over the N rows (each resample takes whole rows, so
// the estimators' correlations are kept).
//
// Morris elementary effects (screening): r one-at-a-time trajectories on a p-level grid of the
// unit cube, step Δ = p / (2(p − 1)); for each input the mean μ, the mean of absolute values μ*
// (its overall influence) and the standard deviation σ (non-linearity or interactions) of its r
// elementary effects (f(x + Δe_i) − f(x)) / Δ, in the units of Y per unit of the unit cube.
//
// Plans draw from RandomStream (RandomPurpose::kSensitivity): the same seed gives the same plan
// and the same bootstrap on any machine.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace lrcal {

/// Saltelli's plan: points (rows, in (0, 1]^d) in the order A (N rows), B (N), AB_1 (N), …,
/// AB_d (N).
struct SaltelliPlan {
  int base_samples = 0, inputs = 0;
  Eigen::MatrixXd points;  ///< N(d+2) × d
};

/// N base samples of d inputs from `seed`. Throws std::invalid_argument for N < 2 or d < 1.
SaltelliPlan MakeSaltelliPlan(int base_samples, int inputs, std::uint64_t seed);

/// An estimate with its bootstrap confidence interval.
struct IntervalEstimate {
  double estimate = 0, low = 0, high = 0;
};

struct SobolIndices {
  std::vector<IntervalEstimate> first, total;  ///< per input
  double variance = 0;                         ///< V, the variance of f over A and B
};

/// Sobol indices from f at a Saltelli plan's points (`values`, in the plan's order), with
/// percentile-bootstrap intervals at `level` (e.g. 0.95) from `bootstrap` resamples (0: the
/// intervals are the estimate). Throws std::invalid_argument if `values` does not match the plan.
SobolIndices EstimateSobolIndices(const SaltelliPlan& plan, const Eigen::VectorXd& values,
                                  int bootstrap, double level, std::uint64_t seed);

/// Morris' plan: `trajectories` trajectories of d + 1 points each (rows, on the grid {0, 1/(p−1),
/// …, 1}), one input moved by ±Δ at each step; `moved[t·d + s]` is the input moved at step s of
/// trajectory t and `sign` its direction (+1 or −1).
struct MorrisPlan {
  int trajectories = 0, inputs = 0, levels = 0;
  double delta = 0;
  Eigen::MatrixXd points;  ///< trajectories·(d+1) × d
  std::vector<int> moved, sign;
};

/// `levels` must be even and ≥ 2; throws std::invalid_argument otherwise or for r < 2, d < 1.
MorrisPlan MakeMorrisPlan(int trajectories, int inputs, int levels, std::uint64_t seed);

struct MorrisEffects {
  std::vector<double> mu, mu_star, sigma;  ///< per input
};

/// Elementary-effect statistics from f at a Morris plan's points (in its order).
MorrisEffects EstimateMorrisEffects(const MorrisPlan& plan, const Eigen::VectorXd& values);

}  // namespace lrcal
