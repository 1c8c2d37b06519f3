// The reference solver: Ceres' Levenberg–Marquardt on the same analytic cost as lrcal's own
// solver (levenberg_marquardt.h), tested to agree with it to 1e-9 (least squares) and 1e-8
// (robust losses). Private to src/identification: users call Identify() with
// IdentificationOptions::Solver::kCeres.
#pragma once

#include <Eigen/Core>
#include <string>

#include "lrcal/identification/identification.h"

namespace lrcal {

/// Least squares from e = 0 with all configurations in one residual block (Ceres' per-block
/// overhead paid once), then, with a robust loss, the refinement from that estimate with one
/// block per configuration (Ceres applies a loss to a whole block's squared norm). Fills e,
/// the iterations of both solves and Ceres' messages.
Termination SolveWithCeres(const MeasurementModel& model, const MeasurementSet& data,
                           const IdentificationOptions& options, Eigen::VectorXd* e,
                           int* iterations, std::string* message);

/// Priors as Ceres sees them: one residual √w_p·(0 − e_k) per term k = terms[p] (prior.h).
struct CeresPriors {
  std::vector<int> terms;
  std::vector<double> weights;
};

/// The same for any measurement kind (measurement_kind.h), on its evaluator's analytic Jacobian:
/// least squares with every value in one block, the priors (if any) in another; a robust loss
/// (kinds with one value per configuration) one block per configuration, beside the priors'.
Termination SolveWithCeres(const MeasurementKind& kind, const MeasuredValues& data,
                           const CeresPriors& priors, const IdentificationOptions& options,
                           Eigen::VectorXd* e, int* iterations, std::string* message);

}  // namespace lrcal
