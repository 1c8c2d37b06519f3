#include "identification/ceres_reference.h"

#include <ceres/ceres.h>

#include <cmath>

namespace lrcal {

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

}  // namespace

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

}  // namespace lrcal
