#include "identification/levenberg_marquardt.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace lrcal {

void LevenbergMarquardt::Nominal::Factorize() {
  NormalMatrix(G, &GtG);
  const int n = static_cast<int>(GtG.rows());
  D = GtG.diagonal().cwiseSqrt().cwiseInverse();
  Eigen::MatrixXd scaled = D.asDiagonal() * GtG * D.asDiagonal();
  Eigen::VectorXd unused;
  if (!D.allFinite() || !CholeskySolve(scaled, Eigen::VectorXd::Zero(n), &L0, &unused, 1e-13))
    L0.resize(0, 0);
}

double LevenbergMarquardt::Linearize(MeasurementEvaluator& model, const double* mean_h,
                                     const Eigen::VectorXd& e, Eigen::VectorXd* r,
                                     Eigen::MatrixXd* J) {
  const int n = model.num_parameters(), m = model.num_rows();
  J->resize(m, n);
  r->resize(m);
  h_.resize(m);
  if (!model.Predict(e.data(), h_.data(), J->data()))
    return std::numeric_limits<double>::quiet_NaN();
  if (!rows_weighted_) ScaleRows(sqrt_w_, J);
  *r = sqrt_w_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(mean_h, m) - h_);
  return 0.5 * r->squaredNorm();
}

double LevenbergMarquardt::Cost(MeasurementEvaluator& model, const double* mean_h,
                                const Eigen::VectorXd& e) {
  const int m = model.num_rows();
  h_.resize(m);
  if (!model.Predict(e.data(), h_.data(), nullptr)) return std::numeric_limits<double>::quiet_NaN();
  return 0.5 *
         sqrt_w_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(mean_h, m) - h_).squaredNorm();
}

bool LevenbergMarquardt::StartLeastSquares(MeasurementEvaluator& model, const double* mean_h,
                                           const double* weights, const Nominal* nominal,
                                           Eigen::VectorXd* e, double* cost, Result* result) {
  const int n = model.num_parameters(), m = model.num_rows();
  e->setZero(n);
  rows_weighted_ = false;
  if (m < n || n == 0) return false;  // kInvalidInput
  sqrt_w_ = Eigen::Map<const Eigen::VectorXd>(weights, m).cwiseSqrt();
  rows_weighted_ = model.WeightJacobianRows(sqrt_w_.data());  // until Solve returns
  if (nominal) {
    J_ = nominal->G;
    ScaleRows(sqrt_w_, &J_);
    r_ = sqrt_w_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(mean_h, m) -
                              Eigen::Map<const Eigen::VectorXd>(nominal->h.data(), m));
    *cost = 0.5 * r_.squaredNorm();
  } else {
    *cost = Linearize(model, mean_h, *e, &r_, &J_);
  }
  result->initial_cost = result->final_cost = *cost;
  if (!std::isfinite(*cost)) {
    result->termination = Termination::kBeamMissed;
    return false;
  }
  if (!FirstNormalEquations(weights, nominal)) {
    result->termination = Termination::kRankDeficient;
    return false;
  }
  return true;
}

bool LevenbergMarquardt::FirstNormalEquations(const double* weights, const Nominal* nominal) {
  const int n = static_cast<int>(J_.cols());
  const bool equal_weights = (sqrt_w_.array() == sqrt_w_[0]).all();
  // With equal weights the first normal matrix, and its scaled factorisation, are the same for
  // every trial of a cell (computed once: Nominal::Factorize).
  const bool first_from_cache = nominal && equal_weights && nominal->GtG.rows() == n;
  if (first_from_cache) {
    A_ = weights[0] * nominal->GtG;
    g_.noalias() = J_.transpose() * r_;
  } else {
    FormNormalEquations();
  }
  first_factor_cached_ = first_from_cache && nominal->L0.rows() == n;
  // Column scaling (Marquardt): unit diagonal. A zero column is rank deficiency outright.
  scale_.resize(n);
  const double max_diag = A_.diagonal().maxCoeff();
  for (int k = 0; k < n; ++k) {
    if (!(A_(k, k) > 1e-20 * max_diag)) return false;
    scale_[k] = first_factor_cached_ ? nominal->D[k] / sqrt_w_[0] : 1.0 / std::sqrt(A_(k, k));
  }
  return true;
}

bool LevenbergMarquardt::LeastSquaresStep(int iteration, double lambda, const Nominal* nominal,
                                          Termination* termination) {
  // A pivot below 1e-13 of the scaled matrix: relative singular value below ~3e-7.
  constexpr double kMinScaledPivot = 1e-13;
  // Solve (S·A·S + λ·I)·y = S·g, step = S·y.
  rhs_ = scale_.cwiseProduct(g_);
  if (iteration == 1 && first_factor_cached_) {
    CholeskySubstitute(nominal->L0, rhs_, &step_);
  } else {
    ScaleSymmetric(scale_, A_, lambda, &As_);
    if (!CholeskySolve(As_, rhs_, &L_, &step_, lambda == 0 ? kMinScaledPivot : 0)) {
      *termination = lambda == 0 && iteration == 1 ? Termination::kRankDeficient
                                                   : Termination::kNumericalFailure;
      return false;
    }
  }
  step_ = scale_.cwiseProduct(step_);
  return true;
}

LevenbergMarquardt::Next LevenbergMarquardt::LeastSquaresIteration(MeasurementEvaluator& model,
                                                                   const double* mean_h,
                                                                   StepControl* control,
                                                                   Eigen::VectorXd* e, double* cost,
                                                                   Result* result) {
  e_trial_ = *e + step_;
  const double step_norm = step_.norm();
  const StepControl::Verdict verdict = control->Judge(step_norm, e->norm());
  const double predicted_decrease = 0.5 * step_.dot(g_);
  // A step is taken when it lowers the cost, or when it is predicted to gain less than the cost
  // can resolve (rounding noise is no reason to refuse it).
  const auto acceptable = [&](double trial_cost) {
    return std::isfinite(trial_cost) &&
           (trial_cost <= *cost || predicted_decrease <= StepControl::kCostResolution * *cost);
  };
  if (verdict.small_step || verdict.last_step) {
    // The final step: check it on residuals alone.
    const double trial_cost = Cost(model, mean_h, e_trial_);
    if (acceptable(trial_cost)) {
      e->swap(e_trial_);
      *cost = trial_cost;
      result->termination = Termination::kConverged;
      return Next::kStop;
    }
    if (verdict.small_step) {  // at the minimum to rounding: the step cannot lower the cost
      result->termination = Termination::kConverged;
      return Next::kStop;
    }
  }
  const double trial_cost = Linearize(model, mean_h, e_trial_, &r_trial_, &J_trial_);
  if (!acceptable(trial_cost)) {
    if (control->Reject()) return Next::kIterate;
    result->termination = Termination::kNumericalFailure;
    return Next::kStop;
  }
  const bool small_decrease = control->SmallDecrease(*cost, trial_cost);
  e->swap(e_trial_);
  J_.swap(J_trial_);
  r_.swap(r_trial_);
  *cost = trial_cost;
  control->Accept(step_norm);
  if (small_decrease) {  // done: no further step needs the normal equations
    result->termination = Termination::kConverged;
    return Next::kStop;
  }
  FormNormalEquations();
  return Next::kIterate;
}

// The Monte-Carlo hot path (27 µs per case-2 trial on the AVX-512 AMD EPYC, 48.5 µs on the
// AVX2 one: docs/PERFORMANCE.md): its bit-for-bit results are pinned by the golden tables and
// the Ceres agreement tests.
LevenbergMarquardt::Result LevenbergMarquardt::SolveLeastSquares(
    MeasurementEvaluator& model, const double* mean_h, const double* weights,
    const IdentificationOptions& options, Eigen::VectorXd* e, const Nominal* nominal) {
  Result result;
  double cost = 0;
  if (!StartLeastSquares(model, mean_h, weights, nominal, e, &cost, &result)) return result;
  StepControl control(options.parameter_tolerance, options.function_tolerance);
  for (int iter = 1; iter <= options.max_iterations; ++iter) {
    result.iterations = iter;
    // A failed factorisation keeps the cost at the start (the trial records it so).
    if (!LeastSquaresStep(iter, control.lambda(), nominal, &result.termination)) return result;
    if (LeastSquaresIteration(model, mean_h, &control, e, &cost, &result) == Next::kStop) {
      result.final_cost = cost;
      return result;
    }
  }
  result.termination = Termination::kMaxIterations;
  result.final_cost = cost;
  return result;
}

void LevenbergMarquardt::FormNormalEquations() {
  NormalMatrix(J_, &A_);
  g_.noalias() = J_.transpose() * r_;
}

LevenbergMarquardt::Result LevenbergMarquardt::Solve(const MeasurementModel& model,
                                                     const TargetedConfigurations& configs,
                                                     const double* mean_h, const double* weights,
                                                     const IdentificationOptions& options,
                                                     Eigen::VectorXd* e, const Nominal* nominal) {
  ranger_.Bind(model, configs);
  return Solve(ranger_, mean_h, weights, options, e, nominal);
}

LevenbergMarquardt::Result LevenbergMarquardt::Solve(MeasurementEvaluator& model,
                                                     const double* mean_h, const double* weights,
                                                     const IdentificationOptions& options,
                                                     Eigen::VectorXd* e, const Nominal* nominal) {
  // The evaluator goes back to the caller unweighted, also when a prediction throws.
  struct Unweight {
    MeasurementEvaluator& model;
    bool& weighted;
    ~Unweight() {
      if (weighted) model.WeightJacobianRows(nullptr);
      weighted = false;
    }
  } unweight{model, rows_weighted_};
  Result result = SolveLeastSquares(model, mean_h, weights, options, e, nominal);
  if (options.loss != RobustLoss::kNone && result.termination == Termination::kConverged)
    RefineRobust(model, mean_h, options, e, &result);
  return result;
}

double LevenbergMarquardt::RobustCost(const IdentificationOptions& options,
                                      const Eigen::VectorXd& r, RobustWeights* weights) {
  const double a = options.LossScale(), a2 = a * a;
  if (weights) {
    weights->rho1.resize(r.size());
    weights->curvature.resize(r.size());
  }
  double cost = 0;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    const double s = r[i] * r[i];
    double rho, rho1, rho2;
    if (options.loss == RobustLoss::kHuber) {  // ceres::HuberLoss
      const bool inlier = s <= a2;
      const double root = std::sqrt(s);
      rho = inlier ? s : 2 * a * root - a2;
      rho1 = inlier ? 1.0 : a / root;
      rho2 = inlier ? 0.0 : -0.5 * rho1 / s;
    } else {  // ceres::CauchyLoss
      const double sum = 1 + s / a2;
      rho = a2 * std::log(sum);
      rho1 = 1 / sum;
      rho2 = -rho1 * rho1 / a2;
    }
    cost += 0.5 * rho;
    if (weights) {
      weights->rho1[i] = rho1;
      // d²/dr² of ½ρ(r²) is ρ' + 2sρ''; negative (a falling tail) is clipped to 0.
      weights->curvature[i] = std::max(0.0, rho1 + 2 * s * rho2);
    }
  }
  return cost;
}

void LevenbergMarquardt::FormRobustModel() {
  const RobustWeights& w = robust_w_;
  g_.noalias() = J_.transpose() * w.rho1.cwiseProduct(r_);
  scale_ = (J_.array().square().colwise() * w.rho1.array()).colwise().sum().transpose();
  scale_ = scale_.cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  J_weighted_ = J_;
  J_weighted_.array().colwise() *= w.curvature.cwiseSqrt().array();
  NormalMatrix(J_weighted_, &A_);
  reweighted_formed_ = false;
}

const Eigen::MatrixXd& LevenbergMarquardt::ReweightedMatrix() {
  if (!reweighted_formed_) {
    J_weighted_ = J_;
    J_weighted_.array().colwise() *= robust_w_.rho1.cwiseSqrt().array();
    NormalMatrix(J_weighted_, &A_reweighted_);
    reweighted_formed_ = true;
  }
  return A_reweighted_;
}

void LevenbergMarquardt::RobustStep(double lambda, bool newton_failed, bool* used_newton) {
  rhs_ = scale_.cwiseProduct(g_);
  bool solved = false;
  // The Newton model first; the reweighted one (which always descends) when the Newton model is
  // singular (too few inliers) or its last step at this damping was rejected.
  for (int attempt = newton_failed ? 1 : 0; attempt < 2 && !solved; ++attempt) {
    *used_newton = attempt == 0;
    ScaleSymmetric(scale_, attempt == 0 ? A_ : ReweightedMatrix(), lambda, &As_);
    solved = CholeskySolve(As_, rhs_, &L_, &step_, 1e-13);
  }
  step_ = scale_.cwiseProduct(step_);
}

double LevenbergMarquardt::RobustCostAtTrial(MeasurementEvaluator& model, const double* mean_h,
                                             const IdentificationOptions& options) {
  const double cost = Cost(model, mean_h, e_trial_);
  if (!std::isfinite(cost)) return cost;
  r_trial_ = sqrt_w_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(mean_h, r_.size()) - h_);
  return RobustCost(options, r_trial_, nullptr);
}

LevenbergMarquardt::Next LevenbergMarquardt::RobustIteration(
    MeasurementEvaluator& model, const double* mean_h, const IdentificationOptions& options,
    bool used_newton, StepControl* control, bool* newton_failed, Eigen::VectorXd* e, double* cost,
    Result* result) {
  e_trial_ = *e + step_;
  const double step_norm = step_.norm();
  const StepControl::Verdict verdict = control->Judge(step_norm, e->norm());
  // Near the minimum the cost resolves only ~1e-12 relative: a step predicted to gain less than
  // that is at the minimum to rounding, whatever the evaluated cost says.
  const bool undamped = control->lambda() == 0;
  const bool at_resolution =
      undamped && 0.5 * step_.dot(g_) <= StepControl::kCostResolution * *cost;
  if ((verdict.small_step || verdict.last_step || at_resolution) && undamped) {
    // The final step: checked on residuals alone, without a Jacobian.
    const double final_cost = RobustCostAtTrial(model, mean_h, options);
    const bool accepted = std::isfinite(final_cost) && (final_cost <= *cost || at_resolution);
    if (accepted) {
      e->swap(e_trial_);
      *cost = final_cost;
    }
    if (accepted || verdict.small_step) {  // else a predicted last step that failed: go on
      result->termination = Termination::kConverged;
      return Next::kStop;
    }
  }
  double trial_cost = Linearize(model, mean_h, e_trial_, &r_trial_, &J_trial_);
  if (std::isfinite(trial_cost)) trial_cost = RobustCost(options, r_trial_, &robust_w_trial_);
  if (!(std::isfinite(trial_cost) && trial_cost <= *cost)) {
    // The same damping with the reweighted model next, or more damping.
    *newton_failed = used_newton;
    if (used_newton || control->Reject()) return Next::kIterate;
    result->termination = Termination::kNumericalFailure;
    return Next::kStop;
  }
  const bool small_decrease = control->SmallDecrease(*cost, trial_cost);
  e->swap(e_trial_);
  J_.swap(J_trial_);
  r_.swap(r_trial_);
  std::swap(robust_w_, robust_w_trial_);
  *newton_failed = false;
  *cost = trial_cost;
  FormRobustModel();
  control->Accept(step_norm);
  if (!(verdict.small_step || verdict.last_step || small_decrease || at_resolution))
    return Next::kIterate;
  result->termination = Termination::kConverged;
  return Next::kStop;
}

// Levenberg–Marquardt on F(e) = ½·Σρ(r_i²). The model's Hessian is Jᵀ·diag(ρ' + 2sρ'')·J with
// the curvature clipped at 0 (exact for Huber, whose cost is piecewise quadratic: convergence in
// a few steps once the inliers are settled, where reweighting alone crawls, L1-like, at small
// scales); the damping is scaled by the reweighted matrix Jᵀ·diag(ρ')·J, which stays regular
// when few residuals are inliers. The gradient is exact, so the minimum is Ceres' (which
// reweights). Stops on a small step or cost decrease like the least-squares loop (the same
// StepControl); a step that cannot lower the cost when undamped means the minimum is reached to
// rounding.
void LevenbergMarquardt::RefineRobust(MeasurementEvaluator& model, const double* mean_h,
                                      const IdentificationOptions& options, Eigen::VectorXd* e,
                                      Result* result) {
  double cost = Linearize(model, mean_h, *e, &r_, &J_);
  if (!std::isfinite(cost)) {
    result->termination = Termination::kBeamMissed;
    return;
  }
  cost = RobustCost(options, r_, &robust_w_);
  FormRobustModel();
  step_.resize(0);
  StepControl control(options.parameter_tolerance, options.function_tolerance);
  bool newton_failed = false, used_newton = false;
  result->termination = Termination::kMaxIterations;
  for (int iter = 1; iter <= options.max_robust_iterations; ++iter) {
    ++result->iterations;
    RobustStep(control.lambda(), newton_failed, &used_newton);
    if (RobustIteration(model, mean_h, options, used_newton, &control, &newton_failed, e, &cost,
                        result) == Next::kStop)
      break;
  }
  result->final_cost = cost;
}

}  // namespace lrcal
