#include "lrcal/identification/identifiability.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/measurement/environment_measurement.h"

namespace lrcal {

std::string Dependency::ToString() const {
  std::ostringstream out;
  out.precision(6);
  for (std::size_t k = 0; k < terms.size(); ++k) {
    double c = terms[k].second;
    if (k == 0) {
      out << terms[k].first;
    } else {
      out << (c < 0 ? " - " : " + ") << std::fabs(c) << "*" << terms[k].first;
    }
  }
  out << "  (readings unchanged along this direction)";
  return out.str();
}

std::string IdentifiabilityReport::ToString() const {
  std::ostringstream out;
  out << "parameters: " << num_params() << ", configurations: " << num_configurations
      << ", rank: " << rank << (full_rank() ? " (full)" : " (DEFICIENT)") << "\n";
  out << "condition number (column-scaled): " << condition_number << "\n";
  out << "singular values (column-scaled):";
  for (int i = 0; i < singular_values.size(); ++i) out << " " << singular_values[i];
  out << "\n";
  if (!unidentifiable.empty()) {
    out << "unidentifiable (no effect on any reading):";
    for (const auto& n : unidentifiable) out << " " << n;
    out << "\n";
  }
  for (const auto& d : dependencies) out << "dependence: " << d.ToString() << "\n";
  for (const auto& x : explanations) out << "lost: " << x << "\n";
  if (!suggested_fixed.empty()) {
    out << "suggested to fix:";
    for (const auto& n : suggested_fixed) out << " " << n;
    out << "\n";
  }
  return out.str();
}

Eigen::MatrixXd IdentificationJacobian(const MeasurementModel& model,
                                       const TargetedConfigurations& configs, const double* e) {
  const int n = model.num_parameters();
  std::vector<double> zero(n, 0.0);
  if (!e) e = zero.data();
  ModelPoint point;
  model.Prepare(e, &point);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> G(configs.size(), n);
  for (int i = 0; i < configs.size(); ++i) {
    double h;
    model.Evaluate(point, configs, i, &h, G.row(i).data());
  }
  return G;
}

const std::vector<SettingField<IdentifiabilityOptions>>& IdentifiabilityOptions::Settings() {
  using O = IdentifiabilityOptions;
  const auto tolerance = [](const char* field, const char* help) {
    SettingSpec spec{"identifiability", field, field, "", 1, "", 0, 1, false, false, "", "", help};
    spec.max_exclusive = true;
    return spec;
  };
  static const std::vector<SettingField<O>> fields = {
      {tolerance("rank_tolerance",
                 "relative singular value (of the unit-column Jacobian) below which a direction "
                 "is unobservable"),
       &O::rank_tolerance},
      {tolerance("zero_column_tolerance",
                 "relative column norm below which a parameter has no effect"),
       &O::zero_column_tolerance},
      {tolerance("coefficient_tolerance", "smallest coefficient of a dependence kept"),
       &O::coefficient_tolerance},
  };
  return fields;
}

void IdentifiabilityOptions::Validate() const { CheckSettings(*this, Settings()); }

namespace {

// Parameters with (numerically) no effect are set aside before scaling, so that rounding is never
// scaled into a fake dependence (`dead`); the rest (`live`) are scaled to unit columns.
Eigen::MatrixXd LiveScaledColumns(const Eigen::MatrixXd& G, const IdentifiabilityOptions& options,
                                  Eigen::VectorXd* norms, std::vector<int>* live,
                                  std::vector<int>* dead) {
  const int n = static_cast<int>(G.cols());
  *norms = G.colwise().norm().transpose();
  const double max_norm = n > 0 ? norms->maxCoeff() : 0.0;
  for (int j = 0; j < n; ++j)
    ((*norms)[j] <= options.zero_column_tolerance * max_norm ? dead : live)->push_back(j);
  const int nl = static_cast<int>(live->size());
  Eigen::MatrixXd Gs(G.rows(), nl);
  for (int k = 0; k < nl; ++k) Gs.col(k) = G.col((*live)[k]) / (*norms)[(*live)[k]];
  return Gs;
}

Eigen::MatrixXd ScaledLiveColumns(const Eigen::MatrixXd& G, const IdentifiabilityOptions& options,
                                  IdentifiabilityReport* report, std::vector<int>* live) {
  std::vector<int> dead;
  Eigen::MatrixXd Gs = LiveScaledColumns(G, options, &report->column_norms, live, &dead);
  for (int j : dead) report->unidentifiable.push_back(report->names[j]);
  return Gs;
}

// Rank and condition number from the singular values of the scaled live columns.
void RankFromSingularValues(const Eigen::MatrixXd& Gs, int n, const IdentifiabilityOptions& options,
                            IdentifiabilityReport* report) {
  if (Gs.cols() > 0 && Gs.rows() > 0) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(Gs);
    report->singular_values = svd.singularValues();
  } else {
    report->singular_values.resize(0);
  }
  const double smax = report->singular_values.size() ? report->singular_values[0] : 0.0;
  int rank = 0;
  for (int i = 0; i < report->singular_values.size(); ++i)
    if (report->singular_values[i] > options.rank_tolerance * smax) ++rank;
  report->rank = rank;
  report->condition_number = (rank == n && rank > 0) ? smax / report->singular_values[rank - 1]
                                                     : std::numeric_limits<double>::infinity();
}

// Dependent columns: QR with column pivoting keeps `rank` well-conditioned columns; each other
// column is written as a combination of the kept ones (none kept: a column depends on nothing).
void FindDependencies(const Eigen::MatrixXd& Gs, const std::vector<int>& live,
                      const IdentifiabilityOptions& options, IdentifiabilityReport* report) {
  const int rank = report->rank, nl = static_cast<int>(live.size());
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Gs);
  const auto& perm = qr.colsPermutation().indices();
  std::vector<int> kept(perm.data(), perm.data() + rank);
  std::sort(kept.begin(), kept.end());
  Eigen::MatrixXd Gk(Gs.rows(), rank);
  for (int k = 0; k < rank; ++k) Gk.col(k) = Gs.col(kept[k]);
  std::unique_ptr<Eigen::ColPivHouseholderQR<Eigen::MatrixXd>> qk;
  if (rank > 0) qk = std::make_unique<Eigen::ColPivHouseholderQR<Eigen::MatrixXd>>(Gk);
  std::vector<int> dependent(perm.data() + rank, perm.data() + nl);
  std::sort(dependent.begin(), dependent.end());
  for (int jd : dependent) {
    const int j = live[jd];
    Dependency dep;
    dep.terms.emplace_back(report->names[j], 1.0);
    const Eigen::VectorXd c = qk ? Eigen::VectorXd(qk->solve(Gs.col(jd))) : Eigen::VectorXd();
    for (int k = 0; k < c.size(); ++k) {
      if (std::fabs(c[k]) < options.coefficient_tolerance) continue;
      const int jk = live[kept[k]];
      // Scaled: g_j/|g_j| = Σ c_k g_k/|g_k|  ⇒  g_j = Σ c_k |g_j|/|g_k| g_k.
      dep.terms.emplace_back(report->names[jk],
                             -c[k] * report->column_norms[j] / report->column_norms[jk]);
    }
    report->dependencies.push_back(dep);
    report->suggested_fixed.push_back(report->names[j]);
  }
}

}  // namespace

Eigen::MatrixXd UnobservableDirections(const Eigen::MatrixXd& G,
                                       const IdentifiabilityOptions& options) {
  const int n = static_cast<int>(G.cols());
  Eigen::VectorXd norms;
  std::vector<int> live, dead;
  const Eigen::MatrixXd Gs = LiveScaledColumns(G, options, &norms, &live, &dead);
  std::vector<Eigen::VectorXd> out;
  for (int j : dead) out.push_back(Eigen::VectorXd::Unit(n, j));
  const int nl = static_cast<int>(live.size());
  if (nl > 0) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(Gs, Eigen::ComputeFullV);
    const Eigen::VectorXd& s = svd.singularValues();
    const double smax = s.size() ? s[0] : 0.0;
    for (int k = 0; k < nl; ++k) {
      if (k < s.size() && s[k] > options.rank_tolerance * smax) continue;
      Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
      for (int i = 0; i < nl; ++i) v[live[i]] = svd.matrixV()(i, k) / norms[live[i]];
      out.push_back(v);
    }
  }
  Eigen::MatrixXd N(n, static_cast<int>(out.size()));
  for (std::size_t k = 0; k < out.size(); ++k) N.col(static_cast<int>(k)) = out[k];
  return N;
}

IdentifiabilityReport AnalyzeJacobian(const Eigen::MatrixXd& G,
                                      const std::vector<std::string>& names, int num_configurations,
                                      const IdentifiabilityOptions& options) {
  options.Validate();
  IdentifiabilityReport report;
  report.names = names;
  report.num_configurations = num_configurations;
  std::vector<int> live;
  const Eigen::MatrixXd Gs = ScaledLiveColumns(G, options, &report, &live);
  RankFromSingularValues(Gs, static_cast<int>(G.cols()), options, &report);
  if (report.rank < static_cast<int>(live.size())) FindDependencies(Gs, live, options, &report);
  for (const auto& name : report.unidentifiable) report.suggested_fixed.push_back(name);
  // Keep suggested_fixed in parameter-set order.
  std::vector<std::string> ordered;
  for (const auto& name : report.names)
    if (std::find(report.suggested_fixed.begin(), report.suggested_fixed.end(), name) !=
        report.suggested_fixed.end())
      ordered.push_back(name);
  report.suggested_fixed = ordered;
  return report;
}

IdentifiabilityReport AnalyzeIdentifiability(const MeasurementModel& model,
                                             const TargetedConfigurations& configs, const double* e,
                                             const IdentifiabilityOptions& options) {
  options.Validate();
  return AnalyzeJacobian(IdentificationJacobian(model, configs, e), model.parameters().names,
                         configs.size(), options);
}

IdentifiabilityReport AnalyzeIdentifiability(const MeasurementKind& kind,
                                             const TargetedConfigurations& configs, const double* e,
                                             const IdentifiabilityOptions& options) {
  options.Validate();
  IdentifiabilityReport report =
      AnalyzeJacobian(MeasurementJacobian(kind, kind.LinearisationConfigurations(configs), e),
                      kind.parameter_names(), configs.size(), options);
  if (const auto* environment = dynamic_cast<const EnvironmentMeasurement*>(&kind)) {
    // Every non-geometric term the analysis could not estimate, explained in words.
    std::vector<std::string> lost = report.unidentifiable;
    for (const Dependency& d : report.dependencies)
      for (const auto& term : d.terms) lost.push_back(term.first);
    std::vector<std::string> unique;
    for (const std::string& name : lost)
      if ((ComplianceTermJoint(name) >= 0 || name == kThermalLinksTerm ||
           name == kThermalRangerTerm) &&
          std::find(unique.begin(), unique.end(), name) == unique.end())
        unique.push_back(name);
    report.explanations = environment->ExplainLostTerms(configs, unique);
  }
  return report;
}

}  // namespace lrcal
