#include "lrcal/identification/identification.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <boost/math/special_functions/gamma.hpp>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "identification/ceres_reference.h"
#include "identification/levenberg_marquardt.h"
#include "lrcal/core/descriptive_statistics.h"
#include "lrcal/core/text_table.h"
#include "lrcal/measurement/ranger_measurement.h"

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
// Rows from `data_rows` on are not readings (the priors' rows): they count in χ² and its degrees
// of freedom, not among the standardised residuals.
void CheckFit(const std::vector<double>& residuals, const std::vector<double>& weights,
              int num_parameters, int rows_per_configuration, int data_rows,
              const IdentificationOptions& options, IdentificationSummary* s) {
  FitCheck& fit = s->fit;
  const int m = static_cast<int>(residuals.size());
  fit.rows_per_configuration = rows_per_configuration;
  fit.dof = m - num_parameters;
  fit.sigma_given = options.sigma > 0;
  fit.num_priors = m - data_rows;
  if (fit.sigma_given) {
    fit.chi2 = 2 * s->final_cost / (options.sigma * options.sigma);
    if (fit.num_priors > 0) {
      fit.chi2_priors = 0;
      for (int i = data_rows; i < m; ++i)
        fit.chi2_priors +=
            weights[i] * residuals[i] * residuals[i] / (options.sigma * options.sigma);
    }
    if (fit.dof > 0)
      fit.p_value = boost::math::gamma_q(0.5 * fit.dof, 0.5 * fit.chi2);  // χ² upper tail
    fit.consistent = !(fit.p_value < 1e-3);
  }
  const double scale = fit.sigma_given ? options.sigma : s->sigma_hat;
  if (!(scale > 0)) return;
  for (int i = 0; i < data_rows; ++i) {
    const double z = std::sqrt(weights[i]) * residuals[i] / scale;
    fit.standardized.push_back(z);
    if (std::fabs(z) > 4) fit.suspects.push_back(i);
  }
}

// 1.4826·median|z| over z's entries (the normal distribution's σ from its median absolute value).
double RobustScale(std::vector<double> z) {
  for (double& v : z) v = std::fabs(v);
  return 1.4826 * Quantile(&z, 50);
}

// The robust fit check (FitCheck::robust_*): the robust scale of the readings' standardised
// residuals against its distribution under the linearised null, z* = (I − Q·Qᵀ)·ε with ε standard
// normal and Q an orthonormal basis of W^½·G's columns (the fit's projection), drawn in blocks.
void CheckRobustFit(const Eigen::MatrixXd& G, const std::vector<double>& weights, int data_rows,
                    FitCheck* fit) {
  const int m = static_cast<int>(G.rows()), n = static_cast<int>(G.cols());
  fit->robust = true;
  fit->robust_scale = RobustScale(fit->standardized);
  if (fit->dof <= 0) return;
  Eigen::MatrixXd Gw = G;
  for (int i = 0; i < m; ++i) Gw.row(i) *= std::sqrt(weights[static_cast<std::size_t>(i)]);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Gw);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(m, n);
  const RandomStream stream(0, 0, 0, RandomPurpose::kFitCheck);
  constexpr int kBlock = 64;
  int at_least = 0;
  std::vector<double> z(static_cast<std::size_t>(data_rows));
  for (int first = 0; first < FitCheck::kRobustCheckDraws; first += kBlock) {
    const int count = std::min(kBlock, FitCheck::kRobustCheckDraws - first);
    Eigen::MatrixXd E(m, count);
    for (int b = 0; b < count; ++b)
      stream.Normals(static_cast<std::uint64_t>(first + b) * static_cast<std::uint64_t>(m), m,
                     E.col(b).data());
    E -= Q * (Q.transpose() * E);
    for (int b = 0; b < count; ++b) {
      for (int i = 0; i < data_rows; ++i) z[static_cast<std::size_t>(i)] = E(i, b);
      at_least += RobustScale(z) >= fit->robust_scale;
    }
  }
  fit->robust_p_value = (1.0 + at_least) / (1.0 + FitCheck::kRobustCheckDraws);
  fit->consistent = fit->robust_p_value > 1e-3;
}

// σ̂, the fit check and the covariances at the estimate, from the Jacobian G at e (rows: measured
// values), the weights and the unweighted residuals; s->final_cost is set.
void SummarizeFit(const Eigen::MatrixXd& G, const std::vector<double>& weights,
                  const std::vector<double>& residuals, int rows_per_configuration, int data_rows,
                  const IdentificationOptions& options, IdentificationSummary* summary) {
  IdentificationSummary& s = *summary;
  const int m = static_cast<int>(G.rows()), n = static_cast<int>(G.cols());
  Eigen::MatrixXd A =
      G.transpose() *
      Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(weights.data(), m)).asDiagonal() * G;
  const Eigen::MatrixXd Ainv = ParameterCovariance(A, 1.0);
  s.sigma_hat = m > n ? std::sqrt(2 * s.final_cost / (m - n)) : std::nan("");
  CheckFit(residuals, weights, n, rows_per_configuration, data_rows, options, &s);
  if (options.loss != RobustLoss::kNone && s.fit.sigma_given && options.robust_fit_check)
    CheckRobustFit(G, weights, data_rows, &s.fit);
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
      c += 0.5 * data.Weight(i) * r * r;
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
  SummarizeFit(IdentificationJacobian(*model, data.configs, e.data()), weights, residuals, 1, m,
               options, &s);
}

// The solver and loss in words (IdentificationSummary::solver, loss).
void DescribeSolver(const IdentificationOptions& options, IdentificationSummary* s) {
  s->solver = options.solver == IdentificationOptions::Solver::kCeres ? "ceres" : "lrcal-lm";
  if (options.loss != RobustLoss::kNone) {
    std::ostringstream loss;
    loss << NameOf(kRobustLossNames, options.loss) << " loss, scale " << options.LossScale() * 1e3
         << " mm";
    if (options.loss_scale_sigma > 0) loss << " (" << options.loss_scale_sigma << " σ)";
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

std::vector<double> ErrorsInVariablesWeights(const MeasurementKind& kind,
                                             const MeasuredValues& data, double sigma,
                                             double joint_sigma) {
  const int k = kind.rows_per_configuration(), m = data.size(), nj = data.configs.num_joints();
  const std::vector<double> e(static_cast<std::size_t>(kind.num_parameters()), 0.0);
  std::vector<double> gradient2(static_cast<std::size_t>(k) * m, 0.0), plus(k * m), minus(k * m);
  constexpr double kStep = 1e-6;  // rad or m: truncation O(step²), rounding O(1e-16/step)
  for (int j = 0; j < nj; ++j) {
    TargetedConfigurations up(nj), down(nj);
    std::vector<double> q(nj);
    for (int i = 0; i < m; ++i) {
      std::copy(data.configs.q(i), data.configs.q(i) + nj, q.begin());
      q[j] += kStep;
      up.Add(q.data(), data.configs.target(i));
      q[j] -= 2 * kStep;
      down.Add(q.data(), data.configs.target(i));
    }
    kind.Bind(up)->Predict(e.data(), plus.data(), nullptr);
    kind.Bind(down)->Predict(e.data(), minus.data(), nullptr);
    for (int r = 0; r < k * m; ++r) {
      const double g = (plus[r] - minus[r]) / (2 * kStep);
      if (std::isfinite(g)) gradient2[r] += g * g;
    }
  }
  std::vector<double> weights(static_cast<std::size_t>(k) * m);
  const std::vector<double> readings = data.RowWeights(k);  // R, or R/c for a median
  for (int i = 0; i < m; ++i)
    for (int c = 0; c < k; ++c) {
      const double variance =
          sigma * sigma / readings[i * k + c] + joint_sigma * joint_sigma * gradient2[i * k + c];
      weights[i * k + c] = sigma * sigma / variance;
    }
  return weights;
}

namespace {

// The second-order check of the fit's covariance when asked for (linearisation_check.h).
void CheckLinearisationIfAsked(MeasurementEvaluator& evaluator, const std::vector<double>& weights,
                               const Eigen::VectorXd& e, const IdentificationOptions& options,
                               IdentificationSummary* s) {
  if (!options.check_linearisation || !s->IsSolutionUsable()) return;
  s->linearisation = CheckLinearisation(evaluator, weights, e, FitCovariance(*s, options),
                                        options.sigma > 0 ? options.sigma : s->sigma_hat);
}

IdentificationSummary IdentifyReadings(const MeasurementModel& model_in, const MeasurementSet& data,
                                       const IdentificationOptions& options) {
  // The maximum a-posteriori estimate and errors in variables are the kind-neutral path's
  // (prior.h, ErrorsInVariablesWeights).
  if (!options.priors.empty() || options.encoder_sigma > 0)
    return Identify(RangerMeasurement(model_in), ToMeasuredValues(data), options);
  IdentificationSummary s;
  DescribeSolver(options, &s);
  s.num_configurations = data.size();
  if (!ValidOptions(options, &s)) return s;
  if (static_cast<int>(data.mean_h.size()) != data.size() ||
      static_cast<int>(data.repetitions.size()) != data.size()) {
    s.message = "measurement set is inconsistent (configurations, readings, repetitions)";
    return s;
  }
  if (data.configs.num_targets_referenced() > model_in.num_planes()) {
    s.message = "a configuration is aimed at plane " +
                std::to_string(data.configs.num_targets_referenced()) + " but the model has " +
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
  std::vector<double> weights = data.Weights();
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
  if (options.check_linearisation) {
    const RangerMeasurement kind(*model);
    CheckLinearisationIfAsked(*kind.Bind(data.configs), weights, e, options, &s);
  }
  return s;
}

}  // namespace

IdentificationSummary Identify(const MeasurementModel& model, const MeasurementSet& data,
                               const IdentificationOptions& options) {
  IdentificationSummary s = IdentifyReadings(model, data, options);
  if (data.labels.size() == static_cast<std::size_t>(data.size()))
    s.fit.configuration_labels = data.labels;
  return s;
}

namespace {

// The rows an identification of a kind solves: every measured value (weighted by its
// configuration's repetitions), then, with priors, one row per term that has a prior (measured 0,
// weight (σ/σ_k)²: prior.h).
struct Rows {
  std::vector<double> measured, weights;
  int data_rows = 0;
  Eigen::VectorXd prior_sigma;   // per term, 0 where it has none (empty without priors)
  std::vector<int> prior_terms;  // the columns with a prior, ascending
};

Rows MakeRows(const MeasurementKind& kind, const MeasuredValues& data,
              const IdentificationOptions& options) {
  Rows rows;
  const int k = kind.rows_per_configuration();
  rows.measured = data.y;
  rows.weights = data.RowWeights(k);
  rows.data_rows = static_cast<int>(rows.measured.size());
  if (options.priors.empty()) return rows;
  rows.prior_sigma = options.priors.SigmasOf(kind.parameter_names());
  for (int t = 0; t < kind.num_parameters(); ++t) {
    if (!(rows.prior_sigma[t] > 0)) continue;
    rows.prior_terms.push_back(t);
    rows.measured.push_back(0);
    const double ratio = options.sigma / rows.prior_sigma[t];
    rows.weights.push_back(ratio * ratio);
  }
  return rows;
}

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
  // A prior is one more value (prior.h): with priors, fewer readings than terms can do.
  const int values = k * data.size();
  const int priors = static_cast<int>(MakeRows(kind, data, options).prior_terms.size());
  if (values + priors < kind.num_parameters()) {
    s->names = kind.parameter_names();
    s->message = std::to_string(kind.num_parameters()) +
                 " parameters need at least as many measured values" +
                 (priors ? " and priors" : "") + "; " + std::to_string(values) + " given (" +
                 std::to_string(data.size()) + " configurations)";
    return false;
  }
  return true;
}

// The identifiability of a kind's rows: with priors, the Jacobian gains the priors' rows (scaled
// like weighted readings), so a direction the readings cannot see but a prior sets is no
// deficiency.
IdentifiabilityReport AnalyzeRows(const MeasurementKind& kind, const MeasuredValues& data,
                                  const IdentificationOptions& options) {
  if (options.priors.empty())
    return AnalyzeIdentifiability(kind, data.configs, nullptr, options.identifiability);
  const Rows rows = MakeRows(kind, data, options);
  const Eigen::MatrixXd G =
      MeasurementJacobian(kind, kind.LinearisationConfigurations(data.configs));
  const int m = static_cast<int>(G.rows()), p = static_cast<int>(rows.prior_terms.size());
  Eigen::MatrixXd augmented = Eigen::MatrixXd::Zero(m + p, G.cols());
  augmented.topRows(m) = G;
  for (int r = 0; r < p; ++r)
    augmented(m + r, rows.prior_terms[r]) = std::sqrt(rows.weights[rows.data_rows + r]);
  return AnalyzeJacobian(augmented, kind.parameter_names(), data.size(), options.identifiability);
}

// Costs, residuals and covariance at e for any kind's rows (the ranger's own path:
// EstimateStatistics). The residual RMS is over the readings alone.
void EstimateKindStatistics(MeasurementEvaluator& evaluator, const Rows& rows,
                            const Eigen::VectorXd& nominal, const Eigen::VectorXd& e,
                            int rows_per_configuration, const IdentificationOptions& options,
                            IdentificationSummary* summary) {
  IdentificationSummary& s = *summary;
  const int m = evaluator.num_rows(), n = evaluator.num_parameters();
  std::vector<double> y(m), residuals(m);
  Eigen::MatrixXd G(m, n);
  auto cost_at = [&](const Eigen::VectorXd& x, double* rms, double* J) {
    evaluator.Predict(x.data(), y.data(), J);
    double c = 0, ss = 0;
    for (int i = 0; i < m; ++i) {
      residuals[i] = rows.measured[i] - y[i];
      c += 0.5 * rows.weights[i] * residuals[i] * residuals[i];
      if (i < rows.data_rows) ss += residuals[i] * residuals[i];
    }
    if (rms) *rms = std::sqrt(ss / rows.data_rows);
    return c;
  };
  s.initial_cost = cost_at(Eigen::VectorXd::Zero(n), nullptr, nullptr);
  s.final_cost = cost_at(e, &s.residual_rms, G.data());
  s.delta = e;
  s.nominal = nominal;
  s.estimate = s.nominal + s.delta;
  SummarizeFit(G, rows.weights, residuals, rows_per_configuration, rows.data_rows, options, &s);
  if (rows.prior_sigma.size() == 0) return;
  s.prior_sigma = rows.prior_sigma;
  s.posterior_to_prior.resize(n);
  for (int k = 0; k < n; ++k)
    s.posterior_to_prior[k] =
        rows.prior_sigma[k] > 0 ? s.std_given[k] / rows.prior_sigma[k] : std::nan("");
}

}  // namespace

namespace {

// Identify() once the options and values are checked and the weights are final (errors in
// variables applied): `s` has its description already.
IdentificationSummary IdentifyWeighted(const MeasurementKind& kind_in, const MeasuredValues& data,
                                       const IdentificationOptions& options,
                                       IdentificationSummary s) {
  std::unique_ptr<MeasurementKind> reduced;
  const MeasurementKind* kind = CheckIdentifiable(
      kind_in, kind_in.parameter_names(), options,
      [&](const MeasurementKind& k) { return AnalyzeRows(k, data, options); },
      [](const MeasurementKind& k, const std::vector<std::string>& names) {
        return k.Without(names);
      },
      &reduced, &s);
  if (!kind) return s;

  s.names = kind->parameter_names();
  const Rows rows = MakeRows(*kind, data, options);
  std::unique_ptr<MeasurementEvaluator> readings = kind->Bind(data.configs);
  PriorRowsEvaluator evaluator(*readings, rows.prior_terms);
  Eigen::VectorXd e;
  if (options.solver == IdentificationOptions::Solver::kCeres) {
    s.termination = SolveWithCeres(
        *kind, data,
        {rows.prior_terms,
         std::vector<double>(rows.weights.begin() + rows.data_rows, rows.weights.end())},
        options, &e, &s.iterations, &s.message);
  } else {
    LevenbergMarquardt lm;
    LevenbergMarquardt::Result r =
        lm.Solve(evaluator, rows.measured.data(), rows.weights.data(), options, &e);
    s.termination = r.termination;
    s.iterations = r.iterations;
    s.message = std::string("lrcal Levenberg-Marquardt: ") + TerminationName(r.termination);
  }
  EstimateKindStatistics(evaluator, rows, kind->NominalValues(), e, kind->rows_per_configuration(),
                         options, &s);
  CheckLinearisationIfAsked(evaluator, rows.weights, e, options, &s);
  return s;
}

}  // namespace

IdentificationSummary Identify(const MeasurementKind& kind_in, const MeasuredValues& data,
                               const IdentificationOptions& options) {
  IdentificationSummary s;
  DescribeSolver(options, &s);
  if (!options.priors.empty()) s.loss += " with priors";
  if (options.encoder_sigma > 0)
    s.loss +=
        ", errors in variables (joint sigma " + Fixed(options.encoder_sigma * 1e3, 4) + " mrad)";
  s.num_configurations = data.size();
  if (!ValidOptions(options, &s) || !CheckMeasuredValues(kind_in, data, options, &s)) return s;
  if (options.encoder_sigma == 0) return IdentifyWeighted(kind_in, data, options, std::move(s));
  // Errors in variables on top of the values' own weights (repetitions, or a median's R/c):
  // valid options have sigma > 0.
  MeasuredValues weighted = data;
  weighted.weights = ErrorsInVariablesWeights(kind_in, data, options.sigma, options.encoder_sigma);
  return IdentifyWeighted(kind_in, weighted, options, std::move(s));
}

std::vector<std::string> IdentificationSummary::SetByPrior() const {
  std::vector<std::string> set;
  for (Eigen::Index k = 0; k < posterior_to_prior.size(); ++k)
    if (posterior_to_prior[k] > kSetByPrior) set.push_back(names[k]);
  return set;
}

Eigen::MatrixXd ParameterCovariance(const Eigen::MatrixXd& normal_matrix, double sigma) {
  const Eigen::Index n = normal_matrix.rows();
  return sigma * sigma * normal_matrix.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
}

std::string FitCheck::LabelOf(int configuration) const {
  const auto i = static_cast<std::size_t>(configuration);
  return i < configuration_labels.size() ? configuration_labels[i] : std::string();
}

std::vector<std::string> FitCheck::SuspectLabels() const {
  std::vector<std::string> out;
  if (configuration_labels.empty()) return out;
  for (int i : suspects) out.push_back(LabelOf(i / rows_per_configuration));
  return out;
}

const char* FitCheck::TestName() const {
  return !sigma_given ? "none" : robust ? "robust_scale" : "chi2";
}

namespace {

// The robust fit check's verdict (FitCheck::robust).
void ExplainRobustCheck(const FitCheck& f, std::ostream& out) {
  out << "fit (robust loss): robust scale of the residuals " << f.robust_scale
      << " of the stated sigma (1.4826 x median |standardised residual|)";
  if (f.dof <= 0) {
    out << " (as many configurations as parameters: no test)";
  } else if (f.consistent) {
    out << ", p = " << f.robust_p_value << ": consistent with the stated noise";
  } else {
    out << ", p = " << f.robust_p_value
        << ": INCONSISTENT with the stated noise: the bulk of the residuals is " << f.robust_scale
        << " times what sigma predicts, outliers aside. Likely causes: sigma too small for "
           "these readings; an error the model does not have (a second plane, the ranger's "
           "offset or scale, a fixed parameter that is not at its nominal value); wrong units "
           "(readings in mm, joint angles in degrees)";
  }
  out << "; chi2 = " << f.chi2 << " on " << f.dof
      << " degrees of freedom is not the test with a robust loss (outliers inflate it)\n";
}

// The χ² test's verdict.
void ExplainChiSquared(const FitCheck& f, std::ostream& out) {
  out << "fit: chi2 = " << f.chi2 << " on " << f.dof << " degrees of freedom";
  if (f.num_priors > 0)
    out << " (readings " << f.chi2 - f.chi2_priors << ", the " << f.num_priors << " priors "
        << f.chi2_priors << ")";
  if (f.dof <= 0) {
    out << " (as many configurations as parameters: no test)";
  } else if (f.consistent) {
    out << ", p = " << f.p_value << ": consistent with the stated noise";
  } else {
    out << ", p = " << f.p_value << ": INCONSISTENT with the stated noise: the residuals are "
        << std::sqrt(f.chi2 / f.dof)
        << " times what sigma predicts. Likely causes: sigma too small for these readings; an "
           "error the model does not have (readings on a second plane, the ranger's offset or "
           "scale, noisy joint encoders, a fixed parameter that is not at its nominal value); "
           "wrong units (readings in mm, joint angles in degrees); outlying readings";
    if (f.num_priors > 0)
      out << "; priors tighter than the terms' true deviations (a large priors' part of chi2)";
    if (!f.suspects.empty()) out << " (see the suspects below)";
  }
  out << "\n";
}

// The suspects, by number (and value, for several per configuration) and label.
void ExplainSuspects(const FitCheck& f, std::ostream& out) {
  const int k = f.rows_per_configuration;
  out << "suspect readings (|residual| > 4 " << (f.sigma_given ? "sigma" : "sigma_hat")
      << "), configuration (1-based" << (f.configuration_labels.empty() ? "" : ", with its label")
      << (k > 1 ? ", then the value: .1 .. ." + std::to_string(k) : std::string())
      << ") and standardised residual:";
  for (int i : f.suspects) {
    out << " " << i / k + 1;
    if (k > 1) out << "." << i % k + 1;
    const std::string label = f.LabelOf(i / k);
    if (!label.empty()) out << " '" << label << "'";
    out << " (" << f.standardized[static_cast<std::size_t>(i)] << ")";
  }
  out << "\n";
}

}  // namespace

std::string FitCheck::Explain() const {
  std::ostringstream out;
  if (sigma_given && robust)
    ExplainRobustCheck(*this, out);
  else if (sigma_given)
    ExplainChiSquared(*this, out);
  if (!suspects.empty()) ExplainSuspects(*this, out);
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
  const bool priors = prior_sigma.size() > 0;
  std::vector<std::string> header = {"parameter", "unit", "nominal (SI)",
                                     "delta",     "std",  "std (given sigma)"};
  if (priors) header.insert(header.end(), {"prior std", "posterior/prior"});
  Table t(header, "Identified parameters (delta and std in the unit shown: mrad, mm, ppm)");
  for (std::size_t k = 0; k < names.size(); ++k) {
    const DisplayUnit u = DisplayUnitOf(names[k]);
    std::vector<std::string> row = {
        names[k],
        u.unit,
        Fixed(nominal[k], 6),
        Fixed(delta[k] * u.factor),
        std::isnan(std_residual[k]) ? "undefined" : Fixed(std_residual[k] * u.factor),
        std_given.size() ? Fixed(std_given[k] * u.factor) : "—"};
    if (priors) {
      const bool has = prior_sigma[static_cast<Eigen::Index>(k)] > 0;
      row.push_back(has ? Fixed(prior_sigma[static_cast<Eigen::Index>(k)] * u.factor) : "—");
      row.push_back(has ? Fixed(posterior_to_prior[static_cast<Eigen::Index>(k)], 3) : "—");
    }
    t.AddRow(row);
  }
  std::string text = t.ToText();
  if (std::isnan(sigma_hat))
    text +=
        "std: undefined (as many configurations as parameters: no residual to estimate the "
        "noise from; give --sigma-mm for the given-sigma column)\n";
  if (priors) {
    const std::vector<std::string> set = SetByPrior();
    text += "set by the prior (posterior/prior std above " + Fixed(kSetByPrior, 1) + "):";
    for (const std::string& name : set) text += " " + name;
    text += set.empty() ? " none\n" : "\n";
  }
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
      << fit.Explain() << linearisation.Explain(names) << ParameterTable();
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
