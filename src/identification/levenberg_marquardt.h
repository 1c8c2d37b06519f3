// lrcal's own Levenberg–Marquardt solver, its workspace and the small dense kernels it runs on
// (private to src/: the Monte-Carlo trial and Identify() use it; users call Identify()).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/cpu_dispatch.h"
#include "lrcal/identification/identification.h"
#include "measurement/batch_evaluation.h"

namespace lrcal {

/// The bare solver of the Monte-Carlo hot path: no identifiability analysis or covariance,
/// workspace reused between calls (no allocation once warm). Rank deficiency is caught by a pivot
/// test in the Cholesky factorisation of the column-scaled normal matrix.
///
/// Each linearisation stacks the weighted Jacobian rows √w_i·G(q_i) into one m×n matrix and forms
/// GᵀWG by one blocked symmetric rank-k update. Stopping: besides a small step or a small cost
/// decrease, the solver stops when the *predicted* remaining error — the last step times the
/// observed contraction |δ_k|/|δ_{k−1}| — is below parameter_tolerance; the final step is then
/// checked on residuals alone, without a Jacobian.
class LevenbergMarquardt {
 public:
  struct Result {
    Termination termination = Termination::kInvalidInput;
    int iterations = 0;
    double initial_cost = 0, final_cost = 0;
  };
  /// The model at e = 0 (readings and Jacobian rows per configuration, unweighted): the same for
  /// every trial of a Monte-Carlo cell, so it is computed once per cell.
  struct Nominal {
    std::vector<double> h;
    Eigen::MatrixXd G;    ///< m×n
    Eigen::MatrixXd GtG;  ///< GᵀG (unweighted), used when every weight is the same
    /// Cholesky factor of D·GᵀG·D, D = diag(GᵀG)^(-1/2): the first (scaled, undamped) system of
    /// every trial, whatever the common weight. Empty if not set, or if GᵀG is (near) singular.
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> L0;
    Eigen::VectorXd D;
    /// Fills GtG, D and L0 from G.
    void Factorize();
  };
  /// Solves for e (resized to model.num_parameters(), started at 0). `mean_h` and `weights`
  /// have configs.size() entries (weights = repetitions). `nominal`, if given, must be the model
  /// at e = 0 on these configurations.
  ///
  /// With a robust loss (options.loss) the least-squares estimate is then refined to the minimum
  /// of ½·Σ ρ(r_i²), r_i the weighted residual, ρ Ceres' HuberLoss / CauchyLoss of scale
  /// options.loss_scale: the same cost, started from the same point, as the Ceres path (tested to
  /// agree to 1e-8).
  Result Solve(const MeasurementModel& model, const ConfigurationSet& configs, const double* mean_h,
               const double* weights, const IdentificationOptions& options, Eigen::VectorXd* e,
               const Nominal* nominal = nullptr);

 private:
  Result SolveLeastSquares(const MeasurementModel& model, const ConfigurationSet& configs,
                           const double* mean_h, const double* weights,
                           const IdentificationOptions& options, Eigen::VectorXd* e,
                           const Nominal* nominal);
  // The robust refinement from *e to the minimum of ½·Σρ(r_i²); adds its iterations.
  void RefineRobust(const MeasurementModel& model, const double* mean_h,
                    const IdentificationOptions& options, Eigen::VectorXd* e, Result* result);
  struct RobustWeights {
    Eigen::VectorXd rho1;       // ρ'(r_i²): the gradient's weights
    Eigen::VectorXd curvature;  // max(0, ρ' + 2sρ''): the model Hessian's weights
  };
  // ½·Σρ(r_i²) of weighted residuals r, and (if `weights`) the per-residual weights.
  static double RobustCost(const IdentificationOptions& options, const Eigen::VectorXd& r,
                           RobustWeights* weights);
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  // Weighted residuals √w·(h̄ − h) and Jacobian √w·G at e into (r, J); returns the cost, NaN if a
  // beam runs parallel to the plane.
  double Linearize(const MeasurementModel& model, const double* mean_h, const Eigen::VectorXd& e,
                   Eigen::VectorXd* r, Eigen::MatrixXd* J);
  // The cost alone (no Jacobian).
  double Cost(const MeasurementModel& model, const double* mean_h, const Eigen::VectorXd& e);
  // A_ = JᵀJ, g_ = Jᵀr from J_, r_.
  void FormNormalEquations();
  BatchEvaluator batch_;
  Eigen::MatrixXd J_, J_trial_;
  Eigen::VectorXd r_, r_trial_, h_, sqrt_w_;
  Eigen::MatrixXd A_, As_;
  RowMajorMatrix L_;
  Eigen::VectorXd g_, step_, rhs_, e_trial_, scale_;
  ModelPoint point_;
};

/// Solves L·Lᵀ·x = b for a row-major Cholesky factor L (from CholeskySolve).
void CholeskySubstitute(
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& L,
    const Eigen::VectorXd& b, Eigen::VectorXd* x);

/// A = JᵀJ (n×n, both triangles) for a column-major m×n J. Each entry is summed in 8 fixed
/// partial sums (index mod 8) added in a fixed order, so the result has the same bits whatever
/// vector width the compiler uses (SSE2, AVX2, AVX-512) — and it vectorises without
/// -ffast-math.
void NormalMatrix(const Eigen::MatrixXd& J, Eigen::MatrixXd* A);
/// The same with a chosen instruction-set variant (cpu_dispatch.h), for tests and benchmarks.
void NormalMatrix(const Eigen::MatrixXd& J, Eigen::MatrixXd* A, Isa isa);

/// Solves the symmetric positive definite system A·x = b in place by a plain Cholesky
/// factorisation (faster than Eigen's LLT at these sizes). Returns false if a pivot is not
/// positive, or below `min_pivot` × the largest diagonal entry.
/// L is row-major so that the inner products run over contiguous memory.
bool CholeskySolve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                   Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>* L,
                   Eigen::VectorXd* x, double min_pivot = 0);

}  // namespace lrcal
