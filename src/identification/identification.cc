#include "lrcal/identification/identification.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <boost/math/special_functions/gamma.hpp>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/cpu_dispatch.h"
#include "identification/levenberg_marquardt.h"
#include "lrcal/core/text_table.h"

namespace lrcal {

std::string IdentificationOptions::Validate() const {
  if (max_iterations < 1) return "max_iterations must be at least 1";
  if (max_robust_iterations < 1) return "max_robust_iterations must be at least 1";
  if (!(parameter_tolerance >= 0)) return "parameter_tolerance must be >= 0";
  if (!(function_tolerance >= 0)) return "function_tolerance must be >= 0";
  if (!(sigma >= 0) || !std::isfinite(sigma)) return "sigma must be a finite value >= 0 (m)";
  if (!(loss_scale > 0) || !std::isfinite(loss_scale))
    return "loss_scale must be a finite value > 0 (m)";
  return "";
}

bool CholeskySolve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                   Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>* L_out,
                   Eigen::VectorXd* x, double min_pivot) {
  const int n = static_cast<int>(A.rows());
  L_out->resize(n, n);
  double* L = L_out->data();  // row-major: L[i*n + k]
  double max_diag = 0;
  for (int i = 0; i < n; ++i) max_diag = std::max(max_diag, A(i, i));
  const double threshold = min_pivot * max_diag;
  for (int j = 0; j < n; ++j) {
    const double* lj = L + j * n;
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= lj[k] * lj[k];
    if (!(d > threshold) || !(d > 0)) return false;
    const double ljj = std::sqrt(d);
    L[j * n + j] = ljj;
    const double inv = 1.0 / ljj;
    for (int i = j + 1; i < n; ++i) {
      const double* li = L + i * n;
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= li[k] * lj[k];  // contiguous in both rows
      L[i * n + j] = s * inv;
    }
  }
  CholeskySubstitute(*L_out, b, x);
  return true;
}

void CholeskySubstitute(
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& L_in,
    const Eigen::VectorXd& b, Eigen::VectorXd* x) {
  const int n = static_cast<int>(L_in.rows());
  const double* L = L_in.data();
  x->resize(n);
  double* y = x->data();
  for (int i = 0; i < n; ++i) {  // L·y = b
    const double* li = L + i * n;
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= li[k] * y[k];
    y[i] = s / li[i];
  }
  for (int i = n - 1; i >= 0; --i) {  // Lᵀ·x = y
    double s = y[i];
    for (int k = i + 1; k < n; ++k) s -= L[k * n + i] * y[k];
    y[i] = s / L[i * n + i];
  }
}

void LevenbergMarquardt::Nominal::Factorize() {
  NormalMatrix(G, &GtG);
  const int n = static_cast<int>(GtG.rows());
  D = GtG.diagonal().cwiseSqrt().cwiseInverse();
  Eigen::MatrixXd scaled = D.asDiagonal() * GtG * D.asDiagonal();
  Eigen::VectorXd unused;
  if (!D.allFinite() || !CholeskySolve(scaled, Eigen::VectorXd::Zero(n), &L0, &unused, 1e-13))
    L0.resize(0, 0);
}

double LevenbergMarquardt::Linearize(const MeasurementModel& model, const double* mean_h,
                                     const Eigen::VectorXd& e, Eigen::VectorXd* r,
                                     Eigen::MatrixXd* J) {
  const int n = model.num_parameters(), m = batch_.size();
  model.Prepare(e.data(), &point_);
  J->resize(m, n);
  r->resize(m);
  h_.resize(m);
  if (!batch_.Evaluate(model, point_, h_.data(), J->data()))
    return std::numeric_limits<double>::quiet_NaN();
  J->array().colwise() *= sqrt_w_.array();
  *r = sqrt_w_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(mean_h, m) - h_);
  return 0.5 * r->squaredNorm();
}

double LevenbergMarquardt::Cost(const MeasurementModel& model, const double* mean_h,
                                const Eigen::VectorXd& e) {
  const int m = batch_.size();
  model.Prepare(e.data(), &point_);
  h_.resize(m);
  if (!batch_.Evaluate(model, point_, h_.data(), nullptr))
    return std::numeric_limits<double>::quiet_NaN();
  return 0.5 *
         sqrt_w_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(mean_h, m) - h_).squaredNorm();
}

namespace {

[[gnu::always_inline]] inline void NormalMatrixBody(const double* __restrict J, int m, int n,
                                                    double* __restrict A) {
  constexpr int kLanes = 8;
  const int full = m - m % kLanes;
  for (int a = 0; a < n; ++a) {
    const double* __restrict ca = J + static_cast<std::size_t>(a) * m;
    for (int b = 0; b <= a; ++b) {
      const double* __restrict cb = J + static_cast<std::size_t>(b) * m;
      double acc[kLanes] = {0, 0, 0, 0, 0, 0, 0, 0};
      for (int i = 0; i < full; i += kLanes)
        for (int l = 0; l < kLanes; ++l) acc[l] += ca[i + l] * cb[i + l];
      double tail = 0;
      for (int i = full; i < m; ++i) tail += ca[i] * cb[i];
      const double sum =
          ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])) + tail;
      A[a + static_cast<std::size_t>(b) * n] = sum;
      A[b + static_cast<std::size_t>(a) * n] = sum;
    }
  }
}

void NormalMatrixDefault(const double* J, int m, int n, double* A) { NormalMatrixBody(J, m, n, A); }
#if defined(__x86_64__)
__attribute__((target("avx2"))) void NormalMatrixAvx2(const double* J, int m, int n, double* A) {
  NormalMatrixBody(J, m, n, A);
}
__attribute__((target("avx512f"))) void NormalMatrixAvx512(const double* J, int m, int n,
                                                           double* A) {
  NormalMatrixBody(J, m, n, A);
}
#endif

}  // namespace

void NormalMatrix(const Eigen::MatrixXd& J, Eigen::MatrixXd* A, Isa isa) {
  const int m = static_cast<int>(J.rows()), n = static_cast<int>(J.cols());
  A->resize(n, n);
  switch (isa) {
#if defined(__x86_64__)
    case Isa::kAvx512:
      NormalMatrixAvx512(J.data(), m, n, A->data());
      return;
    case Isa::kAvx2:
      NormalMatrixAvx2(J.data(), m, n, A->data());
      return;
#endif
    default:
      NormalMatrixDefault(J.data(), m, n, A->data());
      return;
  }
}

void NormalMatrix(const Eigen::MatrixXd& J, Eigen::MatrixXd* A) { NormalMatrix(J, A, ActiveIsa()); }

void LevenbergMarquardt::FormNormalEquations() {
  NormalMatrix(J_, &A_);
  g_.noalias() = J_.transpose() * r_;
}

// The Monte-Carlo hot path (~45 µs per case-2 trial): one loop whose stopping rules, damping
// and predicted-convergence shortcut share their state. Kept whole on purpose: split into
// functions it needs that state passed around, and its bit-for-bit results are pinned by the
// golden tables and the Ceres agreement tests.
// NOLINTNEXTLINE(readability-function-size,readability-function-cognitive-complexity)
LevenbergMarquardt::Result LevenbergMarquardt::SolveLeastSquares(
    const MeasurementModel& model, const ConfigurationSet& configs, const double* mean_h,
    const double* weights, const IdentificationOptions& options, Eigen::VectorXd* e,
    const Nominal* nominal) {
  Result result;
  const int n = model.num_parameters(), m = configs.size();
  e->setZero(n);
  if (m < n || n == 0) return result;  // kInvalidInput
  batch_.SetConfigurations(configs);
  sqrt_w_ = Eigen::Map<const Eigen::VectorXd>(weights, m).cwiseSqrt();
  double cost;
  if (nominal) {
    J_ = nominal->G;
    J_.array().colwise() *= sqrt_w_.array();
    r_ = sqrt_w_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(mean_h, m) -
                              Eigen::Map<const Eigen::VectorXd>(nominal->h.data(), m));
    cost = 0.5 * r_.squaredNorm();
  } else {
    cost = Linearize(model, mean_h, *e, &r_, &J_);
  }
  result.initial_cost = result.final_cost = cost;
  if (!std::isfinite(cost)) {
    result.termination = Termination::kBeamMissed;
    return result;
  }
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
  const bool first_factor_cached = first_from_cache && nominal->L0.rows() == n;

  // Column scaling (Marquardt): unit diagonal. A zero column is rank deficiency outright.
  scale_.resize(n);
  const double max_diag = A_.diagonal().maxCoeff();
  for (int k = 0; k < n; ++k) {
    if (!(A_(k, k) > 1e-20 * max_diag)) {
      result.termination = Termination::kRankDeficient;
      return result;
    }
    scale_[k] = first_factor_cached ? nominal->D[k] / sqrt_w_[0] : 1.0 / std::sqrt(A_(k, k));
  }
  // A pivot below 1e-13 of the scaled matrix: relative singular value below ~3e-7.
  constexpr double kMinScaledPivot = 1e-13;
  // Near the minimum the cost is resolvable only to ~1e-12 relative (residuals of 0.1 mm on
  // readings of 1 m): a step whose predicted decrease is below that is taken on the model's
  // word, not rejected on rounding noise.
  constexpr double kCostResolution = 1e-10;
  double lambda = 0;
  double previous_step = std::numeric_limits<double>::infinity();
  for (int iter = 1; iter <= options.max_iterations; ++iter) {
    result.iterations = iter;
    // Solve (S·A·S + λ·I)·y = S·g, step = S·y.
    rhs_ = scale_.cwiseProduct(g_);
    if (iter == 1 && first_factor_cached) {
      CholeskySubstitute(nominal->L0, rhs_, &step_);
    } else {
      As_.noalias() = scale_.asDiagonal() * A_ * scale_.asDiagonal();
      As_.diagonal().array() += lambda;
      if (!CholeskySolve(As_, rhs_, &L_, &step_, lambda == 0 ? kMinScaledPivot : 0)) {
        result.termination =
            lambda == 0 && iter == 1 ? Termination::kRankDeficient : Termination::kNumericalFailure;
        return result;
      }
    }
    step_ = scale_.cwiseProduct(step_);
    e_trial_ = *e + step_;
    const double step_norm = step_.norm();
    const double tolerance =
        options.parameter_tolerance * (e->norm() + options.parameter_tolerance);
    const bool small_step = step_norm <= tolerance;
    // Predicted error left after this step: the step times the observed contraction.
    const double contraction = step_norm / previous_step;
    const bool last_step =
        std::isfinite(previous_step) && contraction < 0.5 && contraction * step_norm <= tolerance;
    const double predicted_decrease = 0.5 * step_.dot(g_);
    if (small_step || last_step) {
      // The final step: check it on residuals alone.
      const double trial_cost = Cost(model, mean_h, e_trial_);
      if (std::isfinite(trial_cost) &&
          (trial_cost <= cost || predicted_decrease <= kCostResolution * cost)) {
        e->swap(e_trial_);
        cost = trial_cost;
        result.termination = Termination::kConverged;
        result.final_cost = cost;
        return result;
      }
      if (small_step) {  // at the minimum to rounding: the step cannot lower the cost
        result.termination = Termination::kConverged;
        result.final_cost = cost;
        return result;
      }
    }
    const double trial_cost = Linearize(model, mean_h, e_trial_, &r_trial_, &J_trial_);
    if (std::isfinite(trial_cost) &&
        (trial_cost <= cost || predicted_decrease <= kCostResolution * cost)) {
      const bool small_decrease = cost - trial_cost <= options.function_tolerance * cost;
      e->swap(e_trial_);
      J_.swap(J_trial_);
      r_.swap(r_trial_);
      FormNormalEquations();
      cost = trial_cost;
      previous_step = step_norm;
      lambda = lambda < 1e-10 ? 0 : lambda / 10;
      if (small_decrease) {
        result.termination = Termination::kConverged;
        result.final_cost = cost;
        return result;
      }
    } else {
      lambda = lambda == 0 ? 1e-6 : lambda * 10;
      if (lambda > 1e12) {
        result.termination = Termination::kNumericalFailure;
        result.final_cost = cost;
        return result;
      }
    }
  }
  result.termination = Termination::kMaxIterations;
  result.final_cost = cost;
  return result;
}

LevenbergMarquardt::Result LevenbergMarquardt::Solve(const MeasurementModel& model,
                                                     const ConfigurationSet& configs,
                                                     const double* mean_h, const double* weights,
                                                     const IdentificationOptions& options,
                                                     Eigen::VectorXd* e, const Nominal* nominal) {
  Result result = SolveLeastSquares(model, configs, mean_h, weights, options, e, nominal);
  if (options.loss == RobustLoss::kNone || result.termination != Termination::kConverged)
    return result;
  RefineRobust(model, mean_h, options, e, &result);
  return result;
}

double LevenbergMarquardt::RobustCost(const IdentificationOptions& options,
                                      const Eigen::VectorXd& r, RobustWeights* weights) {
  const double a = options.loss_scale, a2 = a * a;
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

// Levenberg–Marquardt on F(e) = ½·Σρ(r_i²). The model's Hessian is Jᵀ·diag(ρ' + 2sρ'')·J with
// the curvature clipped at 0 (exact for Huber, whose cost is piecewise quadratic: convergence in
// a few steps once the inliers are settled, where reweighting alone crawls, L1-like, at small
// scales); the damping is scaled by the reweighted matrix Jᵀ·diag(ρ')·J, which stays regular
// when few residuals are inliers. The gradient is exact, so the minimum is Ceres' (which
// reweights). Stops on a small step or cost decrease like the least-squares loop; a step that
// cannot lower the cost when undamped means the minimum is reached to rounding. Kept whole like
// the least-squares loop: its two models, damping and stopping rules share their state.
// NOLINTNEXTLINE(readability-function-size,readability-function-cognitive-complexity)
void LevenbergMarquardt::RefineRobust(const MeasurementModel& model, const double* mean_h,
                                      const IdentificationOptions& options, Eigen::VectorXd* e,
                                      Result* result) {
  RobustWeights w, w_trial;
  Eigen::VectorXd step;
  Eigen::MatrixXd A_reweighted, J_weighted;
  bool newton_failed = false, used_newton = false;
  double cost = Linearize(model, mean_h, *e, &r_, &J_);
  if (!std::isfinite(cost)) {
    result->termination = Termination::kBeamMissed;
    return;
  }
  cost = RobustCost(options, r_, &w);
  bool reweighted_formed = false;
  const auto form = [&] {
    g_.noalias() = J_.transpose() * w.rho1.cwiseProduct(r_);
    scale_ = (J_.array().square().colwise() * w.rho1.array()).colwise().sum().transpose();
    scale_ = scale_.cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
    J_weighted = J_;
    J_weighted.array().colwise() *= w.curvature.cwiseSqrt().array();
    NormalMatrix(J_weighted, &A_);
    reweighted_formed = false;
  };
  const auto reweighted = [&]() -> const Eigen::MatrixXd& {  // formed when first needed
    if (!reweighted_formed) {
      J_weighted = J_;
      J_weighted.array().colwise() *= w.rho1.cwiseSqrt().array();
      NormalMatrix(J_weighted, &A_reweighted);
      reweighted_formed = true;
    }
    return A_reweighted;
  };
  form();
  constexpr double kCostResolution = 1e-10;
  double lambda = 0, previous_step = std::numeric_limits<double>::infinity();
  result->termination = Termination::kMaxIterations;
  for (int iter = 1; iter <= options.max_robust_iterations; ++iter) {
    ++result->iterations;
    rhs_ = scale_.cwiseProduct(g_);
    bool solved = false;
    // The Newton model first; the reweighted one (which always descends) when the Newton model
    // is singular (too few inliers) or its last step at this damping was rejected.
    for (int attempt = newton_failed ? 1 : 0; attempt < 2 && !solved; ++attempt) {
      used_newton = attempt == 0;
      As_.noalias() =
          scale_.asDiagonal() * (attempt == 0 ? A_ : reweighted()) * scale_.asDiagonal();
      As_.diagonal().array() += lambda;
      solved = CholeskySolve(As_, rhs_, &L_, &step, 1e-13);
    }
    step = scale_.cwiseProduct(step);
    e_trial_ = *e + step;
    const double tolerance =
        options.parameter_tolerance * (e->norm() + options.parameter_tolerance);
    const double step_norm = step.norm();
    const bool small_step = step_norm <= tolerance;
    // The error left after this step, from the observed contraction (as in least squares).
    const double contraction = step_norm / previous_step;
    const bool last_step =
        std::isfinite(previous_step) && contraction < 0.5 && contraction * step_norm <= tolerance;
    // Near the minimum the cost resolves only ~1e-12 relative: a step predicted to gain less
    // than that is at the minimum to rounding, whatever the evaluated cost says.
    const bool at_resolution = lambda == 0 && 0.5 * step.dot(g_) <= kCostResolution * cost;
    if ((small_step || last_step || at_resolution) && lambda == 0) {
      // The final step: checked on residuals alone, without a Jacobian.
      double final_cost = Cost(model, mean_h, e_trial_);
      if (std::isfinite(final_cost)) {
        r_trial_ = sqrt_w_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(mean_h, r_.size()) - h_);
        final_cost = RobustCost(options, r_trial_, nullptr);
      }
      const bool accepted = std::isfinite(final_cost) && (final_cost <= cost || at_resolution);
      if (accepted) {
        e->swap(e_trial_);
        cost = final_cost;
      }
      if (accepted || small_step) {  // else a predicted last step that failed: go on
        result->termination = Termination::kConverged;
        break;
      }
    }
    double trial_cost = Linearize(model, mean_h, e_trial_, &r_trial_, &J_trial_);
    if (std::isfinite(trial_cost)) trial_cost = RobustCost(options, r_trial_, &w_trial);
    if (std::isfinite(trial_cost) && trial_cost <= cost) {
      const bool small_decrease = cost - trial_cost <= options.function_tolerance * cost;
      e->swap(e_trial_);
      J_.swap(J_trial_);
      r_.swap(r_trial_);
      std::swap(w, w_trial);
      newton_failed = false;
      cost = trial_cost;
      form();
      previous_step = step_norm;
      lambda = lambda < 1e-10 ? 0 : lambda / 10;
      if (small_step || last_step || small_decrease || at_resolution) {
        result->termination = Termination::kConverged;
        break;
      }
    } else if (used_newton) {
      newton_failed = true;  // the same damping with the reweighted model next
    } else {
      newton_failed = false;
      lambda = lambda == 0 ? 1e-6 : lambda * 10;
      if (lambda > 1e12) {
        result->termination = Termination::kNumericalFailure;
        break;
      }
    }
  }
  result->final_cost = cost;
}

namespace {

// Configuration i's residual √R·(h̄ − h) and (if `row`) its Jacobian row −√R·∂h/∂e; false if the
// beam runs parallel to the plane.
bool WeightedResidual(const MeasurementModel& model, const ModelPoint& point,
                      const MeasurementSet& data, int i, double* residual, double* row) {
  double h;
  const double nb = model.Evaluate(point, data.configs, i, &h, row);
  if (!(std::fabs(nb) > kParallelBeamThreshold)) return false;
  const double w = std::sqrt(static_cast<double>(data.repetitions[i]));
  *residual = w * (data.mean_h[i] - h);
  if (row)
    for (int k = 0; k < model.num_parameters(); ++k) row[k] *= -w;
  return true;
}

// All configurations in one residual block: Ceres' per-block overhead and the link trig are
// paid once per evaluation (DESIGN.md).
class LaserPlaneCost : public ceres::CostFunction {
 public:
  LaserPlaneCost(const MeasurementModel& model, const MeasurementSet& data)
      : model_(model), data_(data) {
    set_num_residuals(data.size());
    mutable_parameter_block_sizes()->push_back(model.num_parameters());
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = model_.num_parameters();
    ModelPoint point;
    model_.Prepare(parameters[0], &point);
    for (int i = 0; i < data_.size(); ++i) {
      double* row = (jacobians && jacobians[0]) ? jacobians[0] + i * n : nullptr;
      if (!WeightedResidual(model_, point, data_, i, &residuals[i], row)) return false;
    }
    return true;
  }

 private:
  const MeasurementModel& model_;
  const MeasurementSet& data_;
};

// One configuration's residual: with a robust loss every configuration needs its own block,
// because Ceres applies a loss to the squared norm of a whole block.
class OneConfigurationCost : public ceres::CostFunction {
 public:
  OneConfigurationCost(const MeasurementModel& model, const MeasurementSet& data, int i)
      : model_(model), data_(data), i_(i) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(model.num_parameters());
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    ModelPoint point;
    model_.Prepare(parameters[0], &point);
    return WeightedResidual(model_, point, data_, i_, residuals,
                            (jacobians && jacobians[0]) ? jacobians[0] : nullptr);
  }

 private:
  const MeasurementModel& model_;
  const MeasurementSet& data_;
  int i_;
};

ceres::Solver::Options CeresOptions(const IdentificationOptions& options) {
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = options.function_tolerance;
  so.parameter_tolerance = options.parameter_tolerance;
  so.gradient_tolerance = 1e-20;
  // Near the minimum the cost is noisy at ~1e-12 relative; non-monotonic steps keep Ceres from
  // shrinking its trust region on that noise and stopping short (DESIGN.md).
  so.use_nonmonotonic_steps = true;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  return so;
}

Termination CeresTermination(const ceres::Solver::Summary& summary) {
  switch (summary.termination_type) {
    case ceres::CONVERGENCE:
      return Termination::kConverged;
    case ceres::NO_CONVERGENCE:
      return Termination::kMaxIterations;
    default:
      return Termination::kNumericalFailure;
  }
}

Termination SolveWithCeres(const MeasurementModel& model, const MeasurementSet& data,
                           const IdentificationOptions& options, Eigen::VectorXd* e,
                           int* iterations, std::string* message) {
  e->setZero(model.num_parameters());
  const ceres::Solver::Options so = CeresOptions(options);
  // Least squares first: all configurations in one block, Ceres' per-block overhead paid once
  // (DESIGN.md).
  ceres::Problem least_squares;
  least_squares.AddResidualBlock(new LaserPlaneCost(model, data), nullptr, e->data());
  ceres::Solver::Summary summary;
  ceres::Solve(so, &least_squares, &summary);
  *iterations = static_cast<int>(summary.iterations.size()) - 1;
  *message = summary.message;
  if (options.loss == RobustLoss::kNone || CeresTermination(summary) != Termination::kConverged)
    return CeresTermination(summary);
  // A robust loss then refines from the least-squares estimate (started at the nominal model,
  // every residual of a few mm would count as an outlier at a sub-mm scale, and the non-convex
  // Cauchy loss would hardly move). One block per configuration, each with its own loss on its
  // weighted residual √R·(h̄ − h): Ceres applies a loss to the squared norm of a whole block.
  ceres::Solver::Options robust_options = so;
  robust_options.max_num_iterations = options.max_robust_iterations;
  ceres::Problem robust;
  for (int i = 0; i < data.size(); ++i) {
    ceres::LossFunction* loss =
        options.loss == RobustLoss::kHuber
            ? static_cast<ceres::LossFunction*>(new ceres::HuberLoss(options.loss_scale))
            : new ceres::CauchyLoss(options.loss_scale);
    robust.AddResidualBlock(new OneConfigurationCost(model, data, i), loss, e->data());
  }
  ceres::Solver::Summary robust_summary;
  ceres::Solve(robust_options, &robust, &robust_summary);
  *iterations += static_cast<int>(robust_summary.iterations.size()) - 1;
  *message = "least squares: " + summary.message + "; robust refinement: " + robust_summary.message;
  return CeresTermination(robust_summary);
}

}  // namespace

namespace {

// Identifiability first: a rank-deficient set never gets a "converged" answer. Returns the model
// to identify (the given one, or `reduced` without the suggested parameters when the options
// say to fix them), or null when the set is rank-deficient (s says why).
const MeasurementModel* CheckIdentifiable(const MeasurementModel& model_in,
                                          const MeasurementSet& data,
                                          const IdentificationOptions& options,
                                          std::unique_ptr<MeasurementModel>* reduced,
                                          IdentificationSummary* summary) {
  IdentificationSummary& s = *summary;
  const MeasurementModel* model = &model_in;
  s.identifiability =
      AnalyzeIdentifiability(*model, data.configs, nullptr, options.identifiability);
  if (s.identifiability.full_rank()) return model;
  std::ostringstream msg;
  msg << "the parameter set is rank-deficient on these configurations (rank "
      << s.identifiability.rank << " of " << s.identifiability.num_params() << ")";
  if (!options.fix_dependent_parameters) {
    s.names = model->parameters().names;
    s.termination = Termination::kRankDeficient;
    msg << "; fix: ";
    for (const auto& f : s.identifiability.suggested_fixed) msg << f << " ";
    s.message = msg.str();
    return nullptr;
  }
  s.fixed = s.identifiability.suggested_fixed;
  *reduced = std::make_unique<MeasurementModel>(
      model_in.robot(), model_in.nominal_planes(),
      WithoutParameters(model_in.robot(), model_in.parameters(), s.fixed));
  model = reduced->get();
  s.identifiability =
      AnalyzeIdentifiability(*model, data.configs, nullptr, options.identifiability);
  if (s.identifiability.full_rank()) return model;
  s.names = model->parameters().names;
  s.termination = Termination::kRankDeficient;
  s.message = msg.str() + "; still rank-deficient after fixing the suggested parameters";
  return nullptr;
}

// The χ² test against the stated σ and the standardised residuals (FitCheck).
void CheckFit(const MeasurementModel& model, const MeasurementSet& data, const Eigen::VectorXd& e,
              const IdentificationOptions& options, IdentificationSummary* s) {
  FitCheck& fit = s->fit;
  const int m = data.size(), n = model.num_parameters();
  fit.dof = m - n;
  fit.sigma_given = options.sigma > 0;
  if (fit.sigma_given) {
    fit.chi2 = 2 * s->final_cost / (options.sigma * options.sigma);
    if (fit.dof > 0)
      fit.p_value = boost::math::gamma_q(0.5 * fit.dof, 0.5 * fit.chi2);  // χ² upper tail
    fit.consistent = !(fit.p_value < 1e-3);
  }
  const double scale = fit.sigma_given ? options.sigma : s->sigma_hat;
  if (!(scale > 0)) return;
  ModelPoint point;
  model.Prepare(e.data(), &point);
  for (int i = 0; i < m; ++i) {
    double h;
    model.Evaluate(point, data.configs, i, &h, nullptr);
    const double z =
        std::sqrt(static_cast<double>(data.repetitions[i])) * (data.mean_h[i] - h) / scale;
    fit.standardized.push_back(z);
    if (std::fabs(z) > 4) fit.suspects.push_back(i);
  }
}

// Costs, residuals and covariance at the estimate e (same formulas for both solvers).
void EstimateStatistics(const MeasurementModel& model_ref, const MeasurementSet& data,
                        const std::vector<double>& weights, const Eigen::VectorXd& e,
                        const IdentificationOptions& options, IdentificationSummary* summary) {
  IdentificationSummary& s = *summary;
  const MeasurementModel* model = &model_ref;
  const int n = model->num_parameters();
  const int m = data.size();
  ModelPoint point;
  std::vector<double> zero(n, 0.0);
  auto cost_at = [&](const double* x, double* rms) {
    model->Prepare(x, &point);
    double c = 0, ss = 0;
    for (int i = 0; i < m; ++i) {
      double h;
      model->Evaluate(point, data.configs, i, &h, nullptr);
      const double r = data.mean_h[i] - h;
      c += 0.5 * data.repetitions[i] * r * r;
      ss += r * r;
    }
    if (rms) *rms = std::sqrt(ss / m);
    return c;
  };
  s.initial_cost = cost_at(zero.data(), nullptr);
  s.final_cost = cost_at(e.data(), &s.residual_rms);
  s.delta = e;
  s.nominal.setZero(n);  // plane chart u and ranger terms are 0 at nominal
  const ParameterSet& ps = model->parameters();
  for (int k = 0; k < ps.num_robot(); ++k)
    s.nominal[k] = model->robot().nominal_values()[ps.robot_values[k]];
  for (int p = 0; p < ps.num_planes(); ++p)
    if (ps.plane_columns[p].f >= 0)
      s.nominal[ps.plane_columns[p].f] = model->nominal_planes()[p].offset;
  s.estimate = s.nominal + s.delta;

  Eigen::MatrixXd G = IdentificationJacobian(*model, data.configs, e.data());
  Eigen::MatrixXd A =
      G.transpose() *
      Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(weights.data(), m)).asDiagonal() * G;
  const Eigen::MatrixXd Ainv = ParameterCovariance(A, 1.0);
  s.sigma_hat = m > n ? std::sqrt(2 * s.final_cost / (m - n)) : std::nan("");
  CheckFit(*model, data, e, options, &s);
  s.covariance_residual = s.sigma_hat * s.sigma_hat * Ainv;
  s.std_residual = s.covariance_residual.diagonal().cwiseSqrt();
  if (options.sigma > 0) {
    s.covariance_given = options.sigma * options.sigma * Ainv;
    s.std_given = s.covariance_given.diagonal().cwiseSqrt();
  }
  Eigen::VectorXd d = Ainv.diagonal().cwiseSqrt().cwiseInverse();
  s.correlation = d.asDiagonal() * Ainv * d.asDiagonal();
}

}  // namespace

IdentificationSummary Identify(const MeasurementModel& model_in, const MeasurementSet& data,
                               const IdentificationOptions& options) {
  IdentificationSummary s;
  s.solver = options.solver == IdentificationOptions::Solver::kCeres ? "ceres" : "lrcal-lm";
  if (options.loss != RobustLoss::kNone) {
    std::ostringstream loss;
    loss << NameOf(kRobustLossNames, options.loss) << " loss, scale " << options.loss_scale * 1e3
         << " mm";
    s.loss = loss.str();
  }
  s.num_configurations = data.size();
  if (std::string problem = options.Validate(); !problem.empty()) {
    s.message = "invalid options: " + problem;
    return s;
  }
  if (static_cast<int>(data.mean_h.size()) != data.size() ||
      static_cast<int>(data.repetitions.size()) != data.size()) {
    s.message = "measurement set is inconsistent (configurations, readings, repetitions)";
    return s;
  }
  if (data.configs.num_planes_referenced() > model_in.num_planes()) {
    s.message = "a configuration is aimed at plane " +
                std::to_string(data.configs.num_planes_referenced()) + " but the model has " +
                std::to_string(model_in.num_planes()) + " plane(s)";
    return s;
  }

  // Too few configurations is its own diagnosis, before any talk of dependences (which every
  // parameter beyond the m-th would otherwise be listed as).
  if (data.size() < model_in.num_parameters()) {
    s.names = model_in.parameters().names;
    s.message = std::to_string(model_in.num_parameters()) +
                " parameters need at least as many configurations (distinct joint "
                "configurations with a reading); " +
                std::to_string(data.size()) + " given";
    return s;
  }
  std::unique_ptr<MeasurementModel> reduced;
  const MeasurementModel* model = CheckIdentifiable(model_in, data, options, &reduced, &s);
  if (!model) return s;

  s.names = model->parameters().names;
  std::vector<double> weights(data.repetitions.begin(), data.repetitions.end());
  Eigen::VectorXd e;
  LevenbergMarquardt lm;
  if (options.solver == IdentificationOptions::Solver::kCeres) {
    s.termination = SolveWithCeres(*model, data, options, &e, &s.iterations, &s.message);
  } else {
    LevenbergMarquardt::Result r =
        lm.Solve(*model, data.configs, data.mean_h.data(), weights.data(), options, &e);
    s.termination = r.termination;
    s.iterations = r.iterations;
    s.message = std::string("lrcal Levenberg-Marquardt: ") + TerminationName(r.termination);
  }

  EstimateStatistics(*model, data, weights, e, options, &s);
  return s;
}

Eigen::MatrixXd ParameterCovariance(const Eigen::MatrixXd& normal_matrix, double sigma) {
  const Eigen::Index n = normal_matrix.rows();
  return sigma * sigma * normal_matrix.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
}

std::string FitCheck::Explain() const {
  std::ostringstream out;
  if (sigma_given) {
    out << "fit: chi2 = " << chi2 << " on " << dof << " degrees of freedom";
    if (dof <= 0) {
      out << " (as many configurations as parameters: no test)";
    } else if (consistent) {
      out << ", p = " << p_value << ": consistent with the stated noise";
    } else {
      out << ", p = " << p_value << ": INCONSISTENT with the stated noise: the residuals are "
          << std::sqrt(chi2 / dof)
          << " times what sigma predicts. Likely causes: sigma too small for these readings; an "
             "error the model does not have (readings on a second plane, the ranger's offset or "
             "scale, noisy joint encoders, a fixed parameter that is not at its nominal value); "
             "wrong units (readings in mm, joint angles in degrees); outlying readings";
      if (!suspects.empty()) out << " (see the suspects below)";
    }
    out << "\n";
  }
  if (!suspects.empty()) {
    out << "suspect readings (|residual| > 4 " << (sigma_given ? "sigma" : "sigma_hat")
        << "), configuration (1-based) and standardised residual:";
    for (int i : suspects) out << " " << i + 1 << " (" << standardized[i] << ")";
    out << "\n";
  }
  return out.str();
}

std::string IdentificationSummary::BriefReport() const {
  std::ostringstream out;
  out << "lrcal identification (" << solver << ", " << loss << "): " << TerminationName(termination)
      << ", " << iterations << " iterations, " << names.size() << " parameters, "
      << num_configurations << " configurations, cost " << initial_cost << " -> " << final_cost
      << " m^2, residual RMS " << residual_rms * 1e3 << " mm";
  return out.str();
}

std::string IdentificationSummary::ParameterTable() const {
  if (!IsSolutionUsable()) return "";
  Table t({"parameter", "unit", "nominal (SI)", "delta", "std", "std (given sigma)"},
          "Identified parameters (delta and std in the unit shown: mrad, mm, ppm)");
  for (std::size_t k = 0; k < names.size(); ++k) {
    const DisplayUnit u = DisplayUnitOf(names[k]);
    t.AddRow({names[k], u.unit, Fixed(nominal[k], 6), Fixed(delta[k] * u.factor),
              std::isnan(std_residual[k]) ? "undefined" : Fixed(std_residual[k] * u.factor),
              std_given.size() ? Fixed(std_given[k] * u.factor) : "—"});
  }
  std::string text = t.ToText();
  if (std::isnan(sigma_hat))
    text +=
        "std: undefined (as many configurations as parameters: no residual to estimate the "
        "noise from; give --sigma-mm for the given-sigma column)\n";
  return text;
}

std::string IdentificationSummary::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n" << message << "\n";
  if (!fixed.empty()) {
    out << "fixed at nominal (rank deficiency):";
    for (const auto& f : fixed) out << " " << f;
    out << "\n";
  }
  if (IsSolutionUsable()) {
    out << "sigma_hat per reading: "
        << (std::isnan(sigma_hat) ? std::string("undefined") : Fixed(sigma_hat * 1e3, 4) + " mm")
        << "\n"
        << fit.Explain() << ParameterTable();
  } else if (!identifiability.full_rank()) {
    out << identifiability.ToString();
  }
  return out.str();
}

}  // namespace lrcal
