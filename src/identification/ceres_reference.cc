#include "identification/ceres_reference.h"

#include <ceres/ceres.h>

#include <cmath>
#include <memory>
#include <utility>
#include <vector>

namespace lrcal {

namespace {

// Configuration i's residual √R·(h̄ − h) and (if `row`) its Jacobian row −√R·∂h/∂e; false if the
// beam runs parallel to the plane.
bool WeightedResidual(const MeasurementModel& model, const ModelPoint& point,
                      const MeasurementSet& data, int i, double* residual, double* row) {
  double h;
  const double nb = model.Evaluate(point, data.configs, i, &h, row);
  if (!(std::fabs(nb) > kParallelBeamThreshold)) return false;
  const double w = std::sqrt(data.Weight(i));
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

// Any kind's weighted residuals √w·(y − y(e)) at a set of configurations, from its evaluator's
// analytic Jacobian: all configurations in one block, or one configuration (`subset`).
class KindCost : public ceres::CostFunction {
 public:
  KindCost(const MeasurementKind& kind, TargetedConfigurations configs, const double* y,
           const double* weights)
      : configs_(std::move(configs)), y_(y), weights_(weights) {
    evaluator_ = kind.Bind(configs_);
    set_num_residuals(evaluator_->num_rows());
    mutable_parameter_block_sizes()->push_back(kind.num_parameters());
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int m = evaluator_->num_rows(), n = evaluator_->num_parameters();
    predicted_.resize(m);
    const bool jacobian = jacobians && jacobians[0];
    J_.resize(static_cast<std::size_t>(m) * n);
    if (!evaluator_->Predict(parameters[0], predicted_.data(), jacobian ? J_.data() : nullptr))
      return false;
    for (int i = 0; i < m; ++i) {
      const double w = std::sqrt(weights_[i]);
      residuals[i] = w * (y_[i] - predicted_[i]);
      if (jacobian)
        for (int k = 0; k < n; ++k)
          jacobians[0][i * n + k] = -w * J_[static_cast<std::size_t>(k) * m + i];
    }
    return true;
  }

 private:
  TargetedConfigurations configs_;
  std::unique_ptr<MeasurementEvaluator> evaluator_;
  const double* y_;
  const double* weights_;
  mutable std::vector<double> predicted_, J_;
};

// The priors' residuals √w_p·(0 − e_k), k = terms[p].
class PriorCost : public ceres::CostFunction {
 public:
  PriorCost(const CeresPriors& priors, int num_parameters) : priors_(priors), n_(num_parameters) {
    set_num_residuals(static_cast<int>(priors.terms.size()));
    mutable_parameter_block_sizes()->push_back(num_parameters);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (std::size_t p = 0; p < priors_.terms.size(); ++p) {
      const double w = std::sqrt(priors_.weights[p]);
      residuals[p] = -w * parameters[0][priors_.terms[p]];
      if (jacobians && jacobians[0])
        for (int k = 0; k < n_; ++k) jacobians[0][p * n_ + k] = k == priors_.terms[p] ? -w : 0.0;
    }
    return true;
  }

 private:
  CeresPriors priors_;
  int n_;
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

}  // namespace

namespace {

// Least squares from e = 0 with `all` as the one residual block, then, with a robust loss, the
// refinement from that estimate with one block `one(i)` per configuration, each with its own
// loss: Ceres applies a loss to the squared norm of a whole block. `priors` (if it has terms) is
// one more block in both problems, without a loss.
template <typename All, typename One>
Termination SolveLeastSquaresThenRobust(int num_parameters, int num_configurations, const All& all,
                                        const One& one, const CeresPriors& priors,
                                        const IdentificationOptions& options, Eigen::VectorXd* e,
                                        int* iterations, std::string* message) {
  e->setZero(num_parameters);
  const ceres::Solver::Options so = CeresOptions(options);
  // Least squares first: all configurations in one block, Ceres' per-block overhead paid once
  // (DESIGN.md).
  ceres::Problem least_squares;
  least_squares.AddResidualBlock(all(), nullptr, e->data());
  if (!priors.terms.empty())
    least_squares.AddResidualBlock(new PriorCost(priors, num_parameters), nullptr, e->data());
  ceres::Solver::Summary summary;
  ceres::Solve(so, &least_squares, &summary);
  *iterations = static_cast<int>(summary.iterations.size()) - 1;
  *message = summary.message;
  if (options.loss == RobustLoss::kNone || CeresTermination(summary) != Termination::kConverged)
    return CeresTermination(summary);
  // A robust loss then refines from the least-squares estimate (started at the nominal model,
  // every residual of a few mm would count as an outlier at a sub-mm scale, and the non-convex
  // Cauchy loss would hardly move).
  ceres::Solver::Options robust_options = so;
  robust_options.max_num_iterations = options.max_robust_iterations;
  ceres::Problem robust;
  for (int i = 0; i < num_configurations; ++i) {
    ceres::LossFunction* loss =
        options.loss == RobustLoss::kHuber
            ? static_cast<ceres::LossFunction*>(new ceres::HuberLoss(options.LossScale()))
            : new ceres::CauchyLoss(options.LossScale());
    robust.AddResidualBlock(one(i), loss, e->data());
  }
  if (!priors.terms.empty())
    robust.AddResidualBlock(new PriorCost(priors, num_parameters), nullptr, e->data());
  ceres::Solver::Summary robust_summary;
  ceres::Solve(robust_options, &robust, &robust_summary);
  *iterations += static_cast<int>(robust_summary.iterations.size()) - 1;
  *message = "least squares: " + summary.message + "; robust refinement: " + robust_summary.message;
  return CeresTermination(robust_summary);
}

}  // namespace

Termination SolveWithCeres(const MeasurementModel& model, const MeasurementSet& data,
                           const IdentificationOptions& options, Eigen::VectorXd* e,
                           int* iterations, std::string* message) {
  return SolveLeastSquaresThenRobust(
      model.num_parameters(), data.size(), [&] { return new LaserPlaneCost(model, data); },
      [&](int i) { return new OneConfigurationCost(model, data, i); }, CeresPriors{}, options, e,
      iterations, message);
}

Termination SolveWithCeres(const MeasurementKind& kind, const MeasuredValues& data,
                           const CeresPriors& priors, const IdentificationOptions& options,
                           Eigen::VectorXd* e, int* iterations, std::string* message) {
  const int k = kind.rows_per_configuration();
  const std::vector<double> weights = data.RowWeights(k);
  return SolveLeastSquaresThenRobust(
      kind.num_parameters(), data.size(),
      [&] { return new KindCost(kind, data.configs, data.y.data(), weights.data()); },
      [&](int i) {
        return new KindCost(kind, data.configs.Subset({i}), data.y.data() + i * k,
                            weights.data() + i * k);
      },
      priors, options, e, iterations, message);
}

}  // namespace lrcal
