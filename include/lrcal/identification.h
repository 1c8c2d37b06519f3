// Identification of the geometric parameters (and plane terms) from laser-plane readings.
//
// Least squares on the distance residuals r_i = √R_i·(h̄_i − h(e, q_i)), h̄_i the mean of R_i
// readings at configuration i (equal-weight readings: the same estimate as using every reading),
// starting from the nominal model e = 0. Two solvers, tested to agree to 1e-9:
//  - kLevenbergMarquardt: lrcal's own Levenberg–Marquardt on the analytic Jacobian, normal
//    equations accumulated in one pass, no allocation per iteration once the workspace is warm.
//    The Monte-Carlo hot path.
//  - kCeres: Ceres' Levenberg–Marquardt on the same analytic cost (one residual block for all
//    configurations). The reference path; it also offers robust losses (Huber, Cauchy).
// A rank-deficient parameter set is detected before solving (identifiability.h) and reported as
// Termination::kRankDeficient with the dependencies, unless the options say to fix the suggested
// parameters and go on.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/batch_evaluation.h"
#include "lrcal/cpu_dispatch.h"
#include "lrcal/identifiability.h"
#include "lrcal/measurement_model.h"

namespace lrcal {

/// Readings to identify from: one entry per configuration.
struct MeasurementSet {
  ConfigurationSet configs;
  std::vector<double> mean_h;      ///< m, mean of the readings at each configuration
  std::vector<int> repetitions;    ///< number of readings averaged (the residual weight)
  int size() const { return configs.size(); }
};

enum class RobustLoss { kNone, kHuber, kCauchy };

struct IdentificationOptions {
  enum class Solver { kLevenbergMarquardt, kCeres };
  /// lrcal's own LM is the fast default; kCeres is the reference and the only one with losses.
  Solver solver = Solver::kLevenbergMarquardt;
  RobustLoss loss = RobustLoss::kNone;
  /// Scale of the robust loss (m), applied to each configuration's weighted residual
  /// √R·(h̄ − h): residuals beyond it are down-weighted.
  double loss_scale = 1e-3;
  int max_iterations = 100;
  /// Stop when the step is below parameter_tolerance·(‖e‖ + parameter_tolerance). Ceres'
  /// defaults stop measurably short of the minimum on this problem (DESIGN.md); 1e-12 reaches
  /// it to rounding.
  double parameter_tolerance = 1e-12;
  /// Stop when the cost decreases by less than this fraction.
  double function_tolerance = 1e-16;
  /// Per-reading standard deviation (m) if known, for the "given σ" covariance; 0 = unknown.
  double sigma = 0;
  /// What to do with a rank-deficient parameter set: stop (kRankDeficient) or fix the
  /// identifiability analysis' suggested parameters at nominal and identify the rest.
  bool fix_dependent_parameters = false;
  IdentifiabilityOptions identifiability;
  /// Checks the fields; returns "" or a message naming the bad field.
  std::string Validate() const;
};

enum class Termination {
  kConverged,        ///< a tolerance was met: the estimate is the least-squares minimum
  kMaxIterations,    ///< stopped at max_iterations without meeting a tolerance
  kRankDeficient,    ///< the parameter set is not identifiable from these configurations
  kBeamMissed,       ///< at some iterate the model's beam ran parallel to the plane
  kNumericalFailure, ///< non-finite cost or a failed factorisation
  kInvalidInput,     ///< too few readings, bad options
};
const char* TerminationName(Termination t);

struct IdentificationSummary {
  std::vector<std::string> names;  ///< estimated quantities (parameter_set.h)
  Eigen::VectorXd nominal;   ///< their nominal values (link values; 0 for u; f0 for plane_f), SI
  Eigen::VectorXd estimate;  ///< nominal + delta
  Eigen::VectorXd delta;     ///< the identified errors e, SI
  Eigen::VectorXd std_residual;  ///< √diag of covariance_residual
  Eigen::VectorXd std_given;     ///< √diag of covariance_given (empty unless sigma > 0)
  Eigen::MatrixXd covariance_residual;  ///< σ̂²·(GᵀWG)⁻¹, σ̂² = Σ r²/(m − n)
  Eigen::MatrixXd covariance_given;     ///< σ²·(GᵀWG)⁻¹ with the given per-reading σ
  Eigen::MatrixXd correlation;          ///< from covariance_residual
  double sigma_hat = 0;        ///< m, residual-based per-reading σ estimate
  double initial_cost = 0;     ///< ½Σr² at the nominal model (m²)
  double final_cost = 0;       ///< ½Σr² at the estimate (m²)
  double residual_rms = 0;     ///< m, RMS of h̄_i − h(e, q_i) over configurations
  int iterations = 0;
  int num_configurations = 0;
  Termination termination = Termination::kInvalidInput;
  std::string message;                   ///< why it stopped, in words
  std::vector<std::string> fixed;        ///< parameters fixed because of rank deficiency
  IdentifiabilityReport identifiability; ///< of the parameter set at the nominal model
  std::string solver;                    ///< "lrcal-lm" or "ceres"

  bool IsSolutionUsable() const { return termination == Termination::kConverged; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

/// Identifies the model's parameter set from `data`.
IdentificationSummary Identify(const MeasurementModel& model, const MeasurementSet& data,
                               const IdentificationOptions& options = {});

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
  /// at e = 0 on these configurations. On return `normal_matrix()` holds GᵀWG at the last
  /// linearisation point (within one final step of e).
  Result Solve(const MeasurementModel& model, const ConfigurationSet& configs,
               const double* mean_h, const double* weights, const IdentificationOptions& options,
               Eigen::VectorXd* e, const Nominal* nominal = nullptr);
  const Eigen::MatrixXd& normal_matrix() const { return A_; }

 private:
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
void CholeskySubstitute(const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& L,
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
