#include "lrcal/identification/prior.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/core/text_table.h"
#include "lrcal/measurement/parameter_set.h"

namespace lrcal {

namespace {

// Every class of term a measurement kind has (parameter_set.h, point_measurement.h).
constexpr const char* kClasses[] = {"theta",
                                    "alpha",
                                    "a",
                                    "d",
                                    "beta",
                                    "plane_u",
                                    "plane_f",
                                    "ranger_offset",
                                    "ranger_scale",
                                    "instrument_x",
                                    "instrument_y",
                                    "instrument_z",
                                    "instrument_roll",
                                    "instrument_pitch",
                                    "instrument_yaw",
                                    "target_x",
                                    "target_y",
                                    "target_z",
                                    "target_roll",
                                    "target_pitch",
                                    "target_yaw",
                                    "socket_x",
                                    "socket_y",
                                    "socket_z",
                                    "socket_u",
                                    "base_x",
                                    "base_y",
                                    "base_z",
                                    "base_roll",
                                    "base_pitch",
                                    "base_yaw",
                                    "tool_x",
                                    "tool_y",
                                    "tool_z",
                                    "tool_roll",
                                    "tool_pitch",
                                    "tool_yaw",
                                    "c",
                                    "thermal_links",
                                    "thermal_ranger"};

struct Unit {
  const char* name;
  double to_si;
  // 'a' angle, 'l' length, 's' scale, 'c' a joint's compliance, 't' a thermal coefficient
  char dimension;
};
constexpr Unit kUnits[] = {{"rad", 1, 'a'},          {"mrad", 1e-3, 'a'}, {"urad", 1e-6, 'a'},
                           {"deg", M_PI / 180, 'a'}, {"m", 1, 'l'},       {"mm", 1e-3, 'l'},
                           {"um", 1e-6, 'l'},        {"ppm", 1e-6, 's'},  {"rad/Nm", 1, 'c'},
                           {"urad/Nm", 1e-6, 'c'},   {"ppm/K", 1e-6, 't'}};

// The dimension of a class's terms.
char DimensionOf(const std::string& cls) {
  if (cls == "ranger_scale") return 's';
  if (cls == "c") return 'c';  // environment_measurement.h
  if (cls == "thermal_links" || cls == "thermal_ranger") return 't';
  // A class is angular when its first member is ("theta" → "theta1", "plane_u" → "plane_u1").
  const std::string member = cls == "plane_u" ? "plane_u1" : cls;
  return IsAngularName(member) ? 'a' : 'l';
}

const char* DimensionName(char dimension) {
  return dimension == 'a'   ? "an angle (rad, mrad, urad or deg)"
         : dimension == 'l' ? "a length (m, mm or um)"
         : dimension == 'c' ? "a joint's compliance (urad/Nm or rad/Nm)"
         : dimension == 't' ? "a thermal coefficient (ppm/K)"
                            : "a scale (ppm)";
}

}  // namespace

std::string TermClass(const std::string& name) {
  std::string cls;
  for (char c : name)
    if (!std::isdigit(static_cast<unsigned char>(c))) cls += c;
  return cls;
}

PriorSigmas PriorSigmas::Parse(const std::string& text, const std::string& source) {
  PriorSigmas priors;
  for (const std::string& item : SplitList(text)) {
    const std::size_t eq = item.find('=');
    const std::string where = "'" + item + "'";
    if (eq == std::string::npos)
      throw InputError(source, where + ": expected NAME=VALUE UNIT, e.g. theta=1mrad");
    const std::string key = item.substr(0, eq);
    const std::string cls = TermClass(key);
    if (std::find(std::begin(kClasses), std::end(kClasses), cls) == std::end(kClasses))
      throw InputError(source, where + ": '" + key +
                                   "' is neither a term nor a class of terms (theta, alpha, a, "
                                   "d, beta, plane_u, plane_f, ranger_offset, ranger_scale, "
                                   "instrument_*, target_*, socket_*, base_*, tool_*, c (a joint's "
                                   "compliance), thermal_links, thermal_ranger, or one of their "
                                   "names: d6)");
    for (const Entry& e : priors.entries)
      if (e.key == key) throw InputError(source, where + ": '" + key + "' is given twice");
    std::string value = item.substr(eq + 1);
    const Unit* unit = nullptr;
    for (const Unit& u : kUnits) {  // the longest unit that ends the value ("mm" before "m")
      const std::string name = u.name;
      if (value.size() > name.size() &&
          value.compare(value.size() - name.size(), name.size(), name) == 0 &&
          (!unit || name.size() > std::string(unit->name).size()))
        unit = &u;
    }
    const char dimension = DimensionOf(cls);
    if (!unit || unit->dimension != dimension)
      throw InputError(
          source, where + ": '" + key + "' is " + DimensionName(dimension) + ": give its unit");
    double number = 0;
    if (!ParseDecimal(value.substr(0, value.size() - std::string(unit->name).size()), &number) ||
        !(number > 0))
      throw InputError(source, where + ": expected a finite value > 0");
    priors.entries.push_back({key, number * unit->to_si});
  }
  return priors;
}

double PriorSigmas::SigmaOf(const std::string& name) const {
  const std::string cls = TermClass(name);
  double by_class = 0;
  for (const Entry& e : entries) {
    if (e.key == name) return e.sigma;
    if (e.key == cls) by_class = e.sigma;
  }
  return by_class;
}

Eigen::VectorXd PriorSigmas::SigmasOf(const std::vector<std::string>& names) const {
  Eigen::VectorXd sigmas(static_cast<Eigen::Index>(names.size()));
  for (std::size_t k = 0; k < names.size(); ++k)
    sigmas[static_cast<Eigen::Index>(k)] = SigmaOf(names[k]);
  return sigmas;
}

PriorSigmas PriorSigmas::OverriddenBy(const PriorSigmas& over) const {
  PriorSigmas merged;
  for (const Entry& e : entries) {
    const bool replaced = std::any_of(over.entries.begin(), over.entries.end(),
                                      [&](const Entry& o) { return o.key == e.key; });
    if (!replaced) merged.entries.push_back(e);
  }
  merged.entries.insert(merged.entries.end(), over.entries.begin(), over.entries.end());
  return merged;
}

std::string PriorSigmas::ToString() const {
  std::ostringstream out;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const std::string cls = TermClass(entries[k].key);
    const char dimension = DimensionOf(cls);
    const DisplayUnit unit = DisplayUnitOf(dimension == 'a'   ? "theta1"
                                           : dimension == 's' ? "ranger_scale"
                                           : dimension == 'c' ? "c1"
                                           : dimension == 't' ? "thermal_links"
                                                              : "a1");
    out << (k ? ", " : "") << entries[k].key << "=" << entries[k].sigma * unit.factor << " "
        << unit.unit;
  }
  return out.str();
}

PriorInformation InformationFromPriors(const Eigen::MatrixXd& G, const std::vector<double>& weights,
                                       double sigma, const PriorSigmas& priors,
                                       const std::vector<std::string>& names) {
  if (!(sigma > 0)) throw InputError("priors", "the noise of one reading must be > 0");
  PriorInformation info;
  info.names = names;
  info.sigma = sigma;
  info.prior_sigma = priors.SigmasOf(names);
  const Eigen::Index n = G.cols();
  const Eigen::VectorXd w = Eigen::Map<const Eigen::VectorXd>(weights.data(), G.rows());
  Eigen::MatrixXd A = G.transpose() * w.asDiagonal() * G / (sigma * sigma);
  for (Eigen::Index k = 0; k < n; ++k)
    if (info.prior_sigma[k] > 0) A(k, k) += 1 / (info.prior_sigma[k] * info.prior_sigma[k]);
  // Proper when the information matrix is positive definite, judged on its unit-diagonal form
  // with the identifiability analysis' default tolerance on singular values (1e-8, squared).
  const Eigen::VectorXd d = A.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(
                                     d.asDiagonal() * A * d.asDiagonal(), Eigen::EigenvaluesOnly)
                                     .eigenvalues();
  info.defined = n > 0 && lambda[0] > 1e-16 * lambda[n - 1];
  info.posterior_sigma = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  if (info.defined) {
    info.posterior_covariance = A.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
    info.posterior_sigma = info.posterior_covariance.diagonal().cwiseSqrt();
  }
  // Undefined, no ratio means anything: the unbounded direction is the message.
  info.posterior_to_prior.resize(n);
  for (Eigen::Index k = 0; k < n; ++k)
    info.posterior_to_prior[k] = info.defined && info.prior_sigma[k] > 0
                                     ? info.posterior_sigma[k] / info.prior_sigma[k]
                                     : std::numeric_limits<double>::quiet_NaN();
  return info;
}

PriorInformation InformationFromPriors(const MeasurementKind& kind,
                                       const TargetedConfigurations& configs,
                                       const NoiseModel& noise, const PriorSigmas& priors) {
  noise.Validate();
  if (!(noise.sigma > 0))
    throw SettingError(FindSetting(NoiseModel::Settings(), "sigma_mm")->spec,
                       "priors are weighed against the readings' noise: expected a value > 0");
  const Eigen::MatrixXd G = MeasurementJacobian(kind, configs);
  return InformationFromPriors(G, std::vector<double>(G.rows(), noise.repetitions), noise.sigma,
                               priors, kind.parameter_names());
}

std::vector<std::string> PriorInformation::SetByPrior() const {
  std::vector<std::string> set;
  for (Eigen::Index k = 0; k < posterior_to_prior.size(); ++k)
    if (posterior_to_prior[k] > kSetByPriorRatio) set.push_back(names[k]);
  return set;
}

std::string PriorInformation::ToString() const {
  std::ostringstream out;
  Table t({"parameter", "unit", "prior std", "posterior std", "posterior/prior"},
          "What the readings tell against the priors (sigma " + Fixed(sigma * 1e3, 4) +
              " mm per reading)");
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const DisplayUnit u = DisplayUnitOf(names[k]);
    const bool has = prior_sigma[i] > 0;
    t.AddRow(
        {names[k], u.unit, has ? Fixed(prior_sigma[i] * u.factor) : "—",
         std::isfinite(posterior_sigma[i]) ? Fixed(posterior_sigma[i] * u.factor) : "unbounded",
         std::isfinite(posterior_to_prior[i]) ? Fixed(posterior_to_prior[i], 3) : "—"});
  }
  out << t.ToText();
  if (!defined)
    out << "the readings and the priors together leave a direction unbounded: give a prior to "
           "every term the analysis above says to fix\n";
  const std::vector<std::string> set = SetByPrior();
  out << "set by the prior (posterior/prior std above " << Fixed(kSetByPriorRatio, 1) << "):";
  for (const std::string& name : set) out << " " << name;
  out << (set.empty() ? " none\n" : "\n");
  return out.str();
}

PriorRowsEvaluator::PriorRowsEvaluator(MeasurementEvaluator& data, std::vector<int> terms)
    : data_(data), terms_(std::move(terms)) {}

int PriorRowsEvaluator::num_rows() const {
  return data_.num_rows() + static_cast<int>(terms_.size());
}

bool PriorRowsEvaluator::Predict(const double* e, double* y, double* J) {
  const int m = data_.num_rows(), rows = num_rows(), n = num_parameters();
  scratch_.resize(J ? static_cast<std::size_t>(m) * n : 0);
  if (!data_.Predict(e, y, J ? scratch_.data() : nullptr)) return false;
  for (std::size_t p = 0; p < terms_.size(); ++p) y[m + p] = e[terms_[p]];
  if (!J) return true;
  for (int k = 0; k < n; ++k) {
    double* column = J + static_cast<std::size_t>(k) * rows;
    std::copy_n(scratch_.data() + static_cast<std::size_t>(k) * m, m, column);
    for (std::size_t p = 0; p < terms_.size(); ++p) column[m + p] = terms_[p] == k ? 1.0 : 0.0;
  }
  return true;
}

}  // namespace lrcal
