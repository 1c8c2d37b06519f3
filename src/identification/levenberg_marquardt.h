// lrcal's own Levenberg–Marquardt solver and its workspace (private to src/: the Monte-Carlo
// trial and Identify() use it; users call Identify()). The dense kernels it runs on are
// lrcal/core/dense_kernels.h; the damping and stopping rules of its two loops are StepControl.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <vector>

#include "lrcal/core/dense_kernels.h"
#include "lrcal/identification/identification.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/ranger_measurement.h"

namespace lrcal {

/// Marquardt's damping λ and the stopping rules, one object for both loops of the solver (least
/// squares, robust refinement). A step δ from e is small when ‖δ‖ ≤ tol·(‖e‖ + tol), tol =
/// parameter_tolerance; it is predicted to be the last when the observed contraction
/// ‖δ_k‖/‖δ_{k−1}‖ is below ½ and the error it predicts is left, contraction·‖δ_k‖, is within the
/// same tolerance. A cost decrease is small below function_tolerance·cost. Accepting a step
/// divides λ by 10 (0 below 1e-10); rejecting one multiplies it by 10 (from 1e-6), and past 1e12
/// the solver gives up.
class StepControl {
 public:
  /// Near the minimum the cost is resolvable only to ~1e-12 relative (residuals of 0.1 mm on
  /// readings of 1 m): a step whose predicted decrease is below this fraction of the cost is at
  /// the minimum to rounding, and is taken on the model's word.
  static constexpr double kCostResolution = 1e-10;
  struct Verdict {
    bool small_step = false;  ///< within the parameter tolerance
    bool last_step = false;   ///< predicted to leave an error within the tolerance
  };
  StepControl(double parameter_tolerance, double function_tolerance)
      : parameter_tolerance_(parameter_tolerance), function_tolerance_(function_tolerance) {}
  /// Judges a step of norm `step_norm` from an estimate of norm `e_norm`.
  Verdict Judge(double step_norm, double e_norm) const {
    const double tolerance = parameter_tolerance_ * (e_norm + parameter_tolerance_);
    const double contraction = step_norm / previous_step_;
    return {step_norm <= tolerance, std::isfinite(previous_step_) && contraction < 0.5 &&
                                        contraction * step_norm <= tolerance};
  }
  bool SmallDecrease(double cost, double trial_cost) const {
    return cost - trial_cost <= function_tolerance_ * cost;
  }
  /// A step of norm `step_norm` was taken: less damping.
  void Accept(double step_norm) {
    previous_step_ = step_norm;
    lambda_ = lambda_ < 1e-10 ? 0 : lambda_ / 10;
  }
  /// A step was refused: more damping. False when the damping is past any use (give up).
  bool Reject() {
    lambda_ = lambda_ == 0 ? 1e-6 : lambda_ * 10;
    return lambda_ <= 1e12;
  }
  double lambda() const { return lambda_; }

 private:
  double parameter_tolerance_, function_tolerance_;
  double lambda_ = 0;
  double previous_step_ = std::numeric_limits<double>::infinity();
};

/// The bare solver of the Monte-Carlo hot path: no identifiability analysis or covariance,
/// workspace reused between calls (no allocation once warm). Rank deficiency is caught by a pivot
/// test in the Cholesky factorisation of the column-scaled normal matrix.
///
/// Each linearisation stacks the weighted Jacobian rows √w_i·G(q_i) into one m×n matrix and forms
/// GᵀWG by one blocked symmetric rank-k update. Stopping (StepControl): besides a small step or a
/// small cost decrease, the solver stops when the *predicted* remaining error is below
/// parameter_tolerance; the final step is then checked on residuals alone, without a Jacobian.
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
    RowMajorMatrixXd L0;
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
  /// options.LossScale(): the same cost, started from the same point, as the Ceres path (tested to
  /// agree to 1e-8).
  Result Solve(const MeasurementModel& model, const TargetedConfigurations& configs,
               const double* mean_h, const double* weights, const IdentificationOptions& options,
               Eigen::VectorXd* e, const Nominal* nominal = nullptr);
  /// The same for any measurement kind (measurement_kind.h): `measured` and `weights` have
  /// evaluator.num_rows() entries (a configuration's repetitions on each of its rows); `nominal`,
  /// if given, is the evaluator's prediction and Jacobian at e = 0. With a ranger's evaluator
  /// this is the overload above, bit for bit.
  Result Solve(MeasurementEvaluator& evaluator, const double* measured, const double* weights,
               const IdentificationOptions& options, Eigen::VectorXd* e,
               const Nominal* nominal = nullptr);

 private:
  // What one iteration decided.
  enum class Next { kIterate, kStop };
  Result SolveLeastSquares(MeasurementEvaluator& model, const double* mean_h, const double* weights,
                           const IdentificationOptions& options, Eigen::VectorXd* e,
                           const Nominal* nominal);
  // The first linearisation (from `nominal` when given), normal equations and column scaling.
  // False when the solve cannot start (result->termination says why); *cost the cost at e = 0.
  bool StartLeastSquares(MeasurementEvaluator& model, const double* mean_h, const double* weights,
                         const Nominal* nominal, Eigen::VectorXd* e, double* cost, Result* result);
  // The first normal equations (cached per cell when every weight is the same) and the
  // column scaling; false if a column is zero (rank deficiency outright).
  bool FirstNormalEquations(const double* weights, const Nominal* nominal);
  // The scaled, damped step into step_ (the cell's cached factor on the first iteration when
  // it applies); false if the factorisation fails (*termination says how).
  bool LeastSquaresStep(int iteration, double lambda, const Nominal* nominal,
                        Termination* termination);
  // Judges, tries and takes (or refuses) step_ from *e; kStop when the loop ends.
  Next LeastSquaresIteration(MeasurementEvaluator& model, const double* mean_h,
                             StepControl* control, Eigen::VectorXd* e, double* cost,
                             Result* result);

  // The robust refinement from *e to the minimum of ½·Σρ(r_i²); adds its iterations.
  void RefineRobust(MeasurementEvaluator& model, const double* mean_h,
                    const IdentificationOptions& options, Eigen::VectorXd* e, Result* result);
  struct RobustWeights {
    Eigen::VectorXd rho1;       // ρ'(r_i²): the gradient's weights
    Eigen::VectorXd curvature;  // max(0, ρ' + 2sρ''): the model Hessian's weights
  };
  // ½·Σρ(r_i²) of weighted residuals r, and (if `weights`) the per-residual weights.
  static double RobustCost(const IdentificationOptions& options, const Eigen::VectorXd& r,
                           RobustWeights* weights);
  // Gradient, column scaling and the Newton model's matrix at the current J_, r_, robust_w_.
  void FormRobustModel();
  // The reweighted model's matrix Jᵀ·diag(ρ')·J, formed when first needed after FormRobustModel.
  const Eigen::MatrixXd& ReweightedMatrix();
  // The damped step of the Newton model, or of the reweighted model when the Newton model is
  // singular or its last step at this damping was refused; *used_newton says which.
  void RobustStep(double lambda, bool newton_failed, bool* used_newton);
  // The robust cost at e_trial_ from residuals alone (no Jacobian); NaN if a beam is missed.
  double RobustCostAtTrial(MeasurementEvaluator& model, const double* mean_h,
                           const IdentificationOptions& options);
  // One robust iteration from *e (step_ already solved); kStop when the loop ends.
  Next RobustIteration(MeasurementEvaluator& model, const double* mean_h,
                       const IdentificationOptions& options, bool used_newton, StepControl* control,
                       bool* newton_failed, Eigen::VectorXd* e, double* cost, Result* result);

  // Weighted residuals √w·(h̄ − h) and Jacobian √w·G at e into (r, J); returns the cost, NaN if a
  // beam runs parallel to the plane.
  double Linearize(MeasurementEvaluator& model, const double* mean_h, const Eigen::VectorXd& e,
                   Eigen::VectorXd* r, Eigen::MatrixXd* J);
  // The cost alone (no Jacobian).
  double Cost(MeasurementEvaluator& model, const double* mean_h, const Eigen::VectorXd& e);
  // A_ = JᵀJ, g_ = Jᵀr from J_, r_.
  void FormNormalEquations();

  // The ranger's evaluator for the MeasurementModel overload of Solve (warm across solves).
  RangerEvaluator ranger_;
  Eigen::MatrixXd J_, J_trial_;
  Eigen::VectorXd r_, r_trial_, h_, sqrt_w_;
  Eigen::MatrixXd A_, As_;
  RowMajorMatrixXd L_;
  Eigen::VectorXd g_, step_, rhs_, e_trial_, scale_;
  // The first factorisation comes from the cell's Nominal (equal weights, factor cached).
  bool first_factor_cached_ = false;
  // The robust refinement's state.
  RobustWeights robust_w_, robust_w_trial_;
  Eigen::MatrixXd A_reweighted_, J_weighted_;
  bool reweighted_formed_ = false;
  // The evaluator weights J's rows by sqrt_w_ itself (MeasurementEvaluator::WeightJacobianRows).
  bool rows_weighted_ = false;
};

}  // namespace lrcal
