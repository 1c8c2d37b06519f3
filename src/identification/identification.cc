#include "lrcal/identification/identification.h"

#include <Eigen/Cholesky>
#include <boost/math/special_functions/gamma.hpp>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "identification/ceres_reference.h"
#include "identification/levenberg_marquardt.h"
#include "lrcal/core/text_table.h"

namespace lrcal {

namespace {

// Identifiability first: a rank-deficient set never gets a "converged" answer. Returns the model
// to identify (the given one, or `reduced` without the suggested parameters when the options
// say to fix them), or null when the set is rank-deficient (s says why). `analyze(model)` gives
// a model's report, `reduce(model, names)` the model without `names`: the ranger's own path and
// any measurement kind share this.
template <typename Model, typename Analyze, typename Reduce>
const Model* CheckIdentifiable(const Model& model_in, const std::vector<std::string>& names_in,
                               const IdentificationOptions& options, const Analyze& analyze,
                               const Reduce& reduce, std::unique_ptr<Model>* reduced,
                               IdentificationSummary* summary) {
  IdentificationSummary& s = *summary;
  s.identifiability = analyze(model_in);
  if (s.identifiability.full_rank()) return &model_in;
  std::ostringstream msg;
  msg << "the parameter set is rank-deficient on these configurations (rank "
      << s.identifiability.rank << " of " << s.identifiability.num_params() << ")";
  if (!options.fix_dependent_parameters) {
    s.names = names_in;
    s.termination = Termination::kRankDeficient;
    msg << "; fix: ";
    for (const auto& f : s.identifiability.suggested_fixed) msg << f << " ";
    s.message = msg.str();
    return nullptr;
  }
  s.fixed = s.identifiability.suggested_fixed;
  *reduced = reduce(model_in, s.fixed);
  s.identifiability = analyze(**reduced);
  if (s.identifiability.full_rank()) return reduced->get();
  s.names = s.identifiability.names;
  s.termination = Termination::kRankDeficient;
  s.message = msg.str() + "; still rank-deficient after fixing the suggested parameters";
  return nullptr;
}

// The χ² test against the stated σ and the standardised residuals (FitCheck) from the
// unweighted residuals y − y(e) of every measured value and their weights (repetitions).
void CheckFit(const std::vector<double>& residuals, const std::vector<double>& weights,
              int num_parameters, int rows_per_configuration, const IdentificationOptions& options,
              IdentificationSummary* s) {
  FitCheck& fit = s->fit;
  const int m = static_cast<int>(residuals.size());
  fit.rows_per_configuration = rows_per_configuration;
  fit.dof = m - num_parameters;
  fit.sigma_given = options.sigma > 0;
  if (fit.sigma_given) {
    fit.chi2 = 2 * s->final_cost / (options.sigma * options.sigma);
    if (fit.dof > 0)
      fit.p_value = boost::math::gamma_q(0.5 * fit.dof, 0.5 * fit.chi2);  // χ² upper tail
    fit.consistent = !(fit.p_value < 1e-3);
  }
  const double scale = fit.sigma_given ? options.sigma : s->sigma_hat;
  if (!(scale > 0)) return;
  for (int i = 0; i < m; ++i) {
    const double z = std::sqrt(weights[i]) * residuals[i] / scale;
    fit.standardized.push_back(z);
    if (std::fabs(z) > 4) fit.suspects.push_back(i);
  }
}

// σ̂, the fit check and the covariances at the estimate, from the Jacobian G at e (rows: measured
// values), the weights and the unweighted residuals; s->final_cost is set.
void SummarizeFit(const Eigen::MatrixXd& G, const std::vector<double>& weights,
                  const std::vector<double>& residuals, int rows_per_configuration,
                  const IdentificationOptions& options, IdentificationSummary* summary) {
  IdentificationSummary& s = *summary;
  const int m = static_cast<int>(G.rows()), n = static_cast<int>(G.cols());
  Eigen::MatrixXd A =
      G.transpose() *
      Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(weights.data(), m)).asDiagonal() * G;
  const Eigen::MatrixXd Ainv = ParameterCovariance(A, 1.0);
  s.sigma_hat = m > n ? std::sqrt(2 * s.final_cost / (m - n)) : std::nan("");
  CheckFit(residuals, weights, n, rows_per_configuration, options, &s);
  s.covariance_residual = s.sigma_hat * s.sigma_hat * Ainv;
  s.std_residual = s.covariance_residual.diagonal().cwiseSqrt();
  if (options.sigma > 0) {
    s.covariance_given = options.sigma * options.sigma * Ainv;
    s.std_given = s.covariance_given.diagonal().cwiseSqrt();
  }
  Eigen::VectorXd d = Ainv.diagonal().cwiseSqrt().cwiseInverse();
  s.correlation = d.asDiagonal() * Ainv * d.asDiagonal();
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
  std::vector<double> zero(n, 0.0), residuals(m);
  auto cost_at = [&](const double* x, double* rms) {
    model->Prepare(x, &point);
    double c = 0, ss = 0;
    for (int i = 0; i < m; ++i) {
      double h;
      model->Evaluate(point, data.configs, i, &h, nullptr);
      const double r = data.mean_h[i] - h;
      residuals[i] = r;
      c += 0.5 * data.repetitions[i] * r * r;
      ss += r * r;
    }
    if (rms) *rms = std::sqrt(ss / m);
    return c;
  };
  s.initial_cost = cost_at(zero.data(), nullptr);
  s.final_cost = cost_at(e.data(), &s.residual_rms);
  s.delta = e;
  s.nominal = RangerMeasurement(model_ref).NominalValues();
  s.estimate = s.nominal + s.delta;
  SummarizeFit(IdentificationJacobian(*model, data.configs, e.data()), weights, residuals, 1,
               options, &s);
}

// The solver and loss in words (IdentificationSummary::solver, loss).
void DescribeSolver(const IdentificationOptions& options, IdentificationSummary* s) {
  s->solver = options.solver == IdentificationOptions::Solver::kCeres ? "ceres" : "lrcal-lm";
  if (options.loss != RobustLoss::kNone) {
    std::ostringstream loss;
    loss << NameOf(kRobustLossNames, options.loss) << " loss, scale " << options.loss_scale * 1e3
         << " mm";
    s->loss = loss.str();
  }
}

// False (s->message says why) when the options are out of range.
bool ValidOptions(const IdentificationOptions& options, IdentificationSummary* s) {
  try {
    options.Validate();
  } catch (const SettingError& e) {
    s->message = std::string("invalid options: ") + e.what();
    return false;
  }
  return true;
}

}  // namespace

IdentificationSummary Identify(const MeasurementModel& model_in, const MeasurementSet& data,
                               const IdentificationOptions& options) {
  IdentificationSummary s;
  DescribeSolver(options, &s);
  s.num_configurations = data.size();
  if (!ValidOptions(options, &s)) return s;
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
  const MeasurementModel* model = CheckIdentifiable(
      model_in, model_in.parameters().names, options,
      [&](const MeasurementModel& m) {
        return AnalyzeIdentifiability(m, data.configs, nullptr, options.identifiability);
      },
      [](const MeasurementModel& m, const std::vector<std::string>& names) {
        return std::make_unique<MeasurementModel>(
            m.robot(), m.nominal_planes(), WithoutParameters(m.robot(), m.parameters(), names));
      },
      &reduced, &s);
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

namespace {

// The measured values' consistency and the kind's limits; false (s->message says why).
bool CheckMeasuredValues(const MeasurementKind& kind, const MeasuredValues& data,
                         const IdentificationOptions& options, IdentificationSummary* s) {
  const int k = kind.rows_per_configuration();
  if (static_cast<int>(data.y.size()) != k * data.size() ||
      static_cast<int>(data.repetitions.size()) != data.size()) {
    s->message = "measured values are inconsistent (configurations, values, repetitions)";
    return false;
  }
  if (k > 1 && options.loss != RobustLoss::kNone) {
    s->message = std::string("a robust loss acts on single readings; the ") + kind.name() +
                 " measurement gives " + std::to_string(k) +
                 " values per configuration: use least squares";
    return false;
  }
  const int values = k * data.size();
  if (values < kind.num_parameters()) {
    s->names = kind.parameter_names();
    s->message = std::to_string(kind.num_parameters()) +
                 " parameters need at least as many measured values; " + std::to_string(values) +
                 " given (" + std::to_string(data.size()) + " configurations)";
    return false;
  }
  return true;
}

// Costs, residuals and covariance at e for any kind (the ranger's own path: EstimateStatistics).
void EstimateKindStatistics(const MeasurementKind& kind, const MeasuredValues& data,
                            const std::vector<double>& weights, const Eigen::VectorXd& e,
                            const IdentificationOptions& options, IdentificationSummary* summary) {
  IdentificationSummary& s = *summary;
  std::unique_ptr<MeasurementEvaluator> evaluator = kind.Bind(data.configs);
  const int m = evaluator->num_rows(), n = kind.num_parameters();
  std::vector<double> y(m), residuals(m);
  Eigen::MatrixXd G(m, n);
  auto cost_at = [&](const Eigen::VectorXd& x, double* rms, double* J) {
    evaluator->Predict(x.data(), y.data(), J);
    double c = 0, ss = 0;
    for (int i = 0; i < m; ++i) {
      residuals[i] = data.y[i] - y[i];
      c += 0.5 * weights[i] * residuals[i] * residuals[i];
      ss += residuals[i] * residuals[i];
    }
    if (rms) *rms = std::sqrt(ss / m);
    return c;
  };
  s.initial_cost = cost_at(Eigen::VectorXd::Zero(n), nullptr, nullptr);
  s.final_cost = cost_at(e, &s.residual_rms, G.data());
  s.delta = e;
  s.nominal = kind.NominalValues();
  s.estimate = s.nominal + s.delta;
  SummarizeFit(G, weights, residuals, kind.rows_per_configuration(), options, &s);
}

}  // namespace

IdentificationSummary Identify(const MeasurementKind& kind_in, const MeasuredValues& data,
                               const IdentificationOptions& options) {
  IdentificationSummary s;
  DescribeSolver(options, &s);
  s.num_configurations = data.size();
  if (!ValidOptions(options, &s) || !CheckMeasuredValues(kind_in, data, options, &s)) return s;
  std::unique_ptr<MeasurementKind> reduced;
  const MeasurementKind* kind = CheckIdentifiable(
      kind_in, kind_in.parameter_names(), options,
      [&](const MeasurementKind& k) {
        return AnalyzeIdentifiability(k, data.configs, nullptr, options.identifiability);
      },
      [](const MeasurementKind& k, const std::vector<std::string>& names) {
        return k.Without(names);
      },
      &reduced, &s);
  if (!kind) return s;

  s.names = kind->parameter_names();
  const int k = kind->rows_per_configuration();
  std::vector<double> weights;
  for (int i = 0; i < data.size(); ++i) weights.insert(weights.end(), k, data.repetitions[i]);
  Eigen::VectorXd e;
  if (options.solver == IdentificationOptions::Solver::kCeres) {
    s.termination = SolveWithCeres(*kind, data, options, &e, &s.iterations, &s.message);
  } else {
    std::unique_ptr<MeasurementEvaluator> evaluator = kind->Bind(data.configs);
    LevenbergMarquardt lm;
    LevenbergMarquardt::Result r = lm.Solve(*evaluator, data.y.data(), weights.data(), options, &e);
    s.termination = r.termination;
    s.iterations = r.iterations;
    s.message = std::string("lrcal Levenberg-Marquardt: ") + TerminationName(r.termination);
  }
  EstimateKindStatistics(*kind, data, weights, e, options, &s);
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
        << "), configuration (1-based"
        << (rows_per_configuration > 1 ? ", then the value: .1 .. ." : "")
        << (rows_per_configuration > 1 ? std::to_string(rows_per_configuration) : "")
        << ") and standardised residual:";
    for (int i : suspects) {
      out << " " << i / rows_per_configuration + 1;
      if (rows_per_configuration > 1) out << "." << i % rows_per_configuration + 1;
      out << " (" << standardized[i] << ")";
    }
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
  out << BriefReport() << "\n";
  if (!IsSolutionUsable()) {
    out << message << "\n";
    if (!identifiability.full_rank()) out << identifiability.ToString();
    return out.str();
  }
  out << "sigma_hat per reading: "
      << (std::isnan(sigma_hat) ? std::string("undefined") : Fixed(sigma_hat * 1e3, 4) + " mm")
      << "\n"
      << fit.Explain() << ParameterTable();
  if (!fixed.empty()) {
    out << "fixed at nominal because of rank deficiency:";
    for (const auto& f : fixed) out << " " << f;
    out << "\n";
  }
  return out.str();
}

MeasurementModel SolvedModel(const MeasurementModel& model, const IdentificationSummary& s) {
  return MeasurementModel(model.robot(), model.nominal_planes(),
                          WithoutParameters(model.robot(), model.parameters(), s.fixed));
}

const Eigen::MatrixXd& FitCovariance(const IdentificationSummary& s,
                                     const IdentificationOptions& options) {
  return options.sigma > 0 ? s.covariance_given : s.covariance_residual;
}

}  // namespace lrcal
