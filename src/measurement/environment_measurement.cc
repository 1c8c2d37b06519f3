#include "lrcal/measurement/environment_measurement.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"

namespace lrcal {

bool Environment::operator==(const Environment& o) const {
  const auto same = [](double a, double b) { return a == b || (a != a && b != b); };
  for (int k = 0; k < 3; ++k)
    if (!same(gravity[k], o.gravity[k])) return false;
  return same(temperature_c, o.temperature_c);
}

std::string Environment::ToString() const {
  std::ostringstream out;
  out << "gravity (" << FormatExact(gravity[0]) << ", " << FormatExact(gravity[1]) << ", "
      << FormatExact(gravity[2]) << ") m/s², " << FormatExact(temperature_c) << " °C";
  return out.str();
}

bool NonGeometricModel::IsGeometric() const {
  const bool stiff = masses.empty() || compliance.size() == 0 || compliance.isZero(0.0);
  return stiff && thermal.LinksStill() && thermal.ranger == 0;
}

std::string ComplianceTermName(int joint) { return "c" + std::to_string(joint + 1); }

int ComplianceTermJoint(const std::string& name) {
  if (name.size() < 2 || name[0] != 'c') return -1;
  for (std::size_t i = 1; i < name.size(); ++i)
    if (name[i] < '0' || name[i] > '9') return -1;
  if (name[1] == '0') return -1;
  return std::stoi(name.substr(1)) - 1;
}

std::vector<int> NonGeometricTerms::ParseCompliance(const std::string& text, int num_joints,
                                                    const std::string& source) {
  std::vector<int> joints;
  if (text == "none" || text.empty()) return joints;
  if (text == "all") {
    for (int j = 0; j < num_joints; ++j) joints.push_back(j);
    return joints;
  }
  for (std::string item : SplitList(text)) {
    if (!item.empty() && (item[0] == 'j' || item[0] == 'c')) item = item.substr(1);
    int j = -1;
    if (!item.empty() && item.find_first_not_of("0123456789") == std::string::npos &&
        item.size() < 4)
      j = std::stoi(item) - 1;
    if (j < 0 || j >= num_joints)
      throw InputError(source, "'" + text + "': expected none, all, or joints j1 to j" +
                                   std::to_string(num_joints) + " separated by commas (j1,j3)");
    if (std::find(joints.begin(), joints.end(), j) == joints.end()) joints.push_back(j);
  }
  std::sort(joints.begin(), joints.end());
  return joints;
}

void NonGeometricTerms::ParseThermal(const std::string& text, const std::string& source) {
  thermal_links = thermal_ranger = false;
  if (text == "none" || text.empty()) return;
  for (const std::string& item : SplitList(text)) {
    if (item == "links") {
      thermal_links = true;
    } else if (item == "ranger") {
      thermal_ranger = true;
    } else if (item == "all") {
      thermal_links = thermal_ranger = true;
    } else {
      throw InputError(source, "'" + text + "': expected none, links, ranger or all");
    }
  }
}

namespace {

int FindName(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

bool Contains(const std::vector<std::string>& names, const std::string& name) {
  return FindName(names, name) >= 0;
}

}  // namespace

EnvironmentMeasurement::EnvironmentMeasurement(std::shared_ptr<const MeasurementKind> inner,
                                               const RobotModel& robot, NonGeometricModel model,
                                               NonGeometricTerms estimate,
                                               std::vector<std::string> held,
                                               const std::string& source)
    : inner_(std::move(inner)),
      robot_(&robot),
      model_(std::move(model)),
      estimate_(std::move(estimate)),
      held_(std::move(held)),
      source_(source) {
  const int n = robot.num_links();
  if (model_.compliance.size() != 0 && model_.compliance.size() != n)
    throw InputError(source + ".compliance", "expected one compliance per joint (" +
                                                 std::to_string(n) + "), got " +
                                                 std::to_string(model_.compliance.size()));
  if (model_.thermal.per_link.size() != 0 && model_.thermal.per_link.size() != n)
    throw InputError(source + ".thermal", "expected one coefficient per link (" +
                                              std::to_string(n) + "), got " +
                                              std::to_string(model_.thermal.per_link.size()));
  for (const std::string& h : held_)
    if (!Contains(inner_->parameter_names(), h))
      throw InputError(source,
                       "cannot hold '" + h + "': the " + inner_->name() + " kind has no such term");
  LayOutInnerTerms();
  LayOutNonGeometricTerms();
  if (!model_.masses.empty()) model_.masses.Validate(n, source + ".masses");
}

void EnvironmentMeasurement::LayOutInnerTerms() {
  const std::vector<std::string>& inner_names = inner_->parameter_names();
  // The lengths' own nominal values: a truth's inner kind sits on the true arm.
  const Eigen::VectorXd inner_nominal = inner_->NominalValues();
  for (int k = 0; k < static_cast<int>(inner_names.size()); ++k) {
    const int v = robot_->FindValue(inner_names[static_cast<std::size_t>(k)]);
    const bool length = v >= 0 && !IsAngle(v % kValuesPerLink);
    const double base = length ? model_.thermal.Link(v / kValuesPerLink) - model_.thermal.links : 0;
    if (length) {
      layout_.length_columns.push_back(k);
      layout_.length_nominal.push_back(inner_nominal[k]);
      layout_.length_base.push_back(base);
    }
    if (Contains(held_, inner_names[static_cast<std::size_t>(k)])) continue;
    layout_.exposed.push_back(k);
    layout_.exposed_length.push_back(length ? v : -1);
    layout_.exposed_base.push_back(base);
    names_.push_back(inner_names[static_cast<std::size_t>(k)]);
  }
  if (estimate_.thermal_links || !model_.thermal.LinksStill())
    for (int v : robot_->parameter_indices())
      if (!IsAngle(v % kValuesPerLink) && !Contains(inner_names, robot_->ValueName(v)))
        throw InputError(source_, "thermal growth moves " + robot_->ValueName(v) + ", which the " +
                                      inner_->name() + " kind does not have among its terms");
}

void EnvironmentMeasurement::LayOutNonGeometricTerms() {
  const std::vector<std::string>& inner_names = inner_->parameter_names();
  for (int j : estimate_.compliance_joints) {
    if (j < 0 || j >= robot_->num_links())
      throw InputError(source_, "no joint " + std::to_string(j + 1));
    const bool revolute =
        robot_->links()[static_cast<std::size_t>(j)].joint == JointType::kRevolute;
    const std::string joint_term = LinkValueFullName(j * kValuesPerLink + (revolute ? kTheta : kD));
    const int column = FindName(inner_names, joint_term);
    if (column < 0)
      throw InputError(source_, "the compliance of joint " + std::to_string(j + 1) + " needs " +
                                    joint_term + " among the " + inner_->name() +
                                    " kind's terms (a geometric parameter of the robot)");
    layout_.joint_columns.push_back(column);
    names_.push_back(ComplianceTermName(j));
  }
  layout_.ranger_scale_column = FindName(inner_names, "ranger_scale");
  if ((estimate_.thermal_ranger || model_.thermal.ranger != 0) && layout_.ranger_scale_column < 0)
    throw InputError(source_, std::string("the ranger's thermal coefficient needs a ranger kind "
                                          "with ranger_scale among its terms; the ") +
                                  inner_->name() + " kind has none");
  if (estimate_.thermal_links) names_.push_back(kThermalLinksTerm);
  if (estimate_.thermal_ranger) names_.push_back(kThermalRangerTerm);
}

Eigen::VectorXd EnvironmentMeasurement::NominalValues() const {
  const Eigen::VectorXd inner = inner_->NominalValues();
  Eigen::VectorXd v(num_parameters());
  int o = 0;
  for (int k : layout_.exposed) v[o++] = inner[k];
  for (int j : estimate_.compliance_joints) v[o++] = model_.Compliance(j);
  if (estimate_.thermal_links) v[o++] = model_.thermal.links;
  if (estimate_.thermal_ranger) v[o++] = model_.thermal.ranger;
  return v;
}

namespace {

// The configurations of one temperature: their rows in the whole set and their own evaluator.
struct TemperatureGroup {
  double delta_t = 0;                // K from the reference
  std::vector<int> members;          // configuration indices, ascending
  TargetedConfigurations commanded;  // the members as commanded
  TargetedConfigurations deflected;  // the members' joints as compliance turns them
  std::unique_ptr<MeasurementEvaluator> evaluator;
  std::vector<double> y, J, e;
};

class EnvironmentEvaluator : public MeasurementEvaluator {
 public:
  EnvironmentEvaluator(const EnvironmentMeasurement& kind, const RobotModel& robot,
                       const TargetedConfigurations& configs)
      : kind_(kind), robot_(robot), rows_per_(kind.rows_per_configuration()) {
    const int m = configs.size(), n = robot.num_links();
    torque_.resize(n, m);
    for (int i = 0; i < m; ++i) {
      const Environment env = kind.EnvironmentOf(configs, i);
      torque_.col(i) = GravityTorques(robot, robot.nominal_values().data(), kind.model().masses,
                                      configs.q(i), env.gravity);
      const double dt = env.temperature_c - kind.model().thermal.reference_c;
      auto it = std::find_if(groups_.begin(), groups_.end(),
                             [&](const TemperatureGroup& g) { return g.delta_t == dt; });
      if (it == groups_.end()) {
        groups_.emplace_back();
        groups_.back().delta_t = dt;
        groups_.back().commanded = TargetedConfigurations(configs.num_joints());
        it = std::prev(groups_.end());
      }
      it->members.push_back(i);
      it->commanded.AddFrom(configs, i);
    }
    num_rows_ = m * rows_per_;
    const int inner_n = kind.inner().num_parameters();
    for (TemperatureGroup& g : groups_) {
      g.e.resize(static_cast<std::size_t>(inner_n));
      g.y.resize(static_cast<std::size_t>(g.members.size()) * rows_per_);
      g.J.resize(g.y.size() * static_cast<std::size_t>(inner_n));
    }
    compliance_estimated_ = !kind.estimate().compliance_joints.empty();
    if (!compliance_estimated_) Deflect(nullptr);
  }

  int num_rows() const override { return num_rows_; }
  int num_parameters() const override { return kind_.num_parameters(); }

  bool Predict(const double* e, double* y, double* J) override {
    if (compliance_estimated_) Deflect(e);
    bool ok = true;
    for (TemperatureGroup& g : groups_) {
      InnerEstimate(e, g.delta_t, g.e.data());
      ok = g.evaluator->Predict(g.e.data(), g.y.data(), J ? g.J.data() : nullptr) && ok;
      Scatter(g, e, y, J);
    }
    return ok;
  }

  // The inner kind's misses at each configuration as compliance and temperature leave it.
  std::vector<std::string> Misses(const double* e) {
    Deflect(e);
    std::vector<std::string> reasons(static_cast<std::size_t>(num_rows_ / rows_per_), "ok");
    for (TemperatureGroup& g : groups_) {
      InnerEstimate(e, g.delta_t, g.e.data());
      const std::vector<std::string> own = kind_.inner().MissReasons(g.deflected, g.e.data());
      for (std::size_t r = 0; r < own.size(); ++r)
        reasons[static_cast<std::size_t>(g.members[r])] = own[r];
    }
    return reasons;
  }

  // The joint values compliance turns each configuration to, at estimate e (nullptr: nominal),
  // each group's evaluator bound to them.
  void Deflect(const double* e) {
    const EnvironmentMeasurement::Layout& L = kind_.layout();
    const int n = robot_.num_links();
    Eigen::VectorXd c(n);
    for (int j = 0; j < n; ++j) c[j] = kind_.model().Compliance(j);
    if (e) {
      const int base = static_cast<int>(L.exposed.size());
      const std::vector<int>& joints = kind_.estimate().compliance_joints;
      for (std::size_t k = 0; k < joints.size(); ++k) c[joints[k]] += e[base + static_cast<int>(k)];
    }
    std::vector<double> q(static_cast<std::size_t>(n));
    for (TemperatureGroup& g : groups_) {
      g.deflected = TargetedConfigurations(g.commanded.num_joints());
      g.deflected.Reserve(g.commanded.size());
      for (int k = 0; k < g.commanded.size(); ++k) {
        const int i = g.members[static_cast<std::size_t>(k)];
        for (int j = 0; j < n; ++j)
          q[static_cast<std::size_t>(j)] = g.commanded.q(k)[j] + c[j] * torque_(j, i);
        g.deflected.Add(q, g.commanded.target(k));
        g.deflected.SetEnvironment(k, g.commanded.environment(k));
      }
      g.evaluator = kind_.inner().BindInChartsOf(g.deflected, g.commanded);
    }
  }

 private:
  double ThermalLinks(const double* e) const {
    double alpha = kind_.model().thermal.links;
    if (kind_.estimate().thermal_links) alpha += e[ThermalIndex()];
    return alpha;
  }
  double ThermalRanger(const double* e) const {
    double alpha = kind_.model().thermal.ranger;
    if (kind_.estimate().thermal_ranger)
      alpha += e[ThermalIndex() + (kind_.estimate().thermal_links ? 1 : 0)];
    return alpha;
  }
  int ThermalIndex() const {
    return static_cast<int>(kind_.layout().exposed.size() +
                            kind_.estimate().compliance_joints.size());
  }

  // The inner kind's estimate at temperature offset dt: the exposed terms from e, the lengths
  // grown, the ranger's scale grown.
  void InnerEstimate(const double* e, double dt, double* inner) const {
    const EnvironmentMeasurement::Layout& L = kind_.layout();
    std::fill(inner, inner + kind_.inner().num_parameters(), 0.0);
    for (std::size_t o = 0; o < L.exposed.size(); ++o) inner[L.exposed[o]] = e[o];
    const double common = ThermalLinks(e);
    if (dt != 0)
      for (std::size_t k = 0; k < L.length_columns.size(); ++k) {
        const double growth = (common + L.length_base[k]) * dt;
        double& v = inner[L.length_columns[k]];
        v = (L.length_nominal[k] + v) * (1 + growth) - L.length_nominal[k];
      }
    if (L.ranger_scale_column >= 0) inner[L.ranger_scale_column] += ThermalRanger(e) * dt;
  }

  // Group g's values into y and its Jacobian, chained to the outer terms, into J.
  void Scatter(const TemperatureGroup& g, const double* e, double* y, double* J) const {
    const int k = rows_per_;
    const auto gm = static_cast<int>(g.members.size());
    for (int r = 0; r < gm; ++r)
      for (int c = 0; c < k; ++c) y[g.members[r] * k + c] = g.y[r * k + c];
    if (!J) return;
    int o = ChainInnerTerms(g, e, J);
    if (kind_.estimate().thermal_links) ChainThermalLinks(g, e, o++, J);
    if (kind_.estimate().thermal_ranger) {
      const int column = kind_.layout().ranger_scale_column;
      ForEachRow(g, o, J, [&](int row) { return Inner(g, column, row) * g.delta_t; });
    }
  }

  // Inner Jacobian entry (column, group row).
  double Inner(const TemperatureGroup& g, int column, int row) const {
    return g.J[static_cast<std::size_t>(column) * g.y.size() + static_cast<std::size_t>(row)];
  }

  // Column `o` of J over group g's rows: value(group row).
  template <typename Value>
  void ForEachRow(const TemperatureGroup& g, int o, double* J, const Value& value) const {
    const int k = rows_per_;
    for (std::size_t r = 0; r < g.members.size(); ++r)
      for (int c = 0; c < k; ++c)
        J[static_cast<std::ptrdiff_t>(o) * num_rows_ + g.members[r] * k + c] =
            value(static_cast<int>(r) * k + c);
  }

  // The exposed inner terms (a length's column times its growth 1 + α ΔT) and each compliance's
  // (its joint's column times the joint's gravity torque); returns the next column.
  int ChainInnerTerms(const TemperatureGroup& g, const double* e, double* J) const {
    const EnvironmentMeasurement::Layout& L = kind_.layout();
    const double common = ThermalLinks(e);
    int o = 0;
    for (std::size_t x = 0; x < L.exposed.size(); ++x, ++o) {
      const double chain =
          L.exposed_length[x] >= 0 ? 1 + (common + L.exposed_base[x]) * g.delta_t : 1.0;
      ForEachRow(g, o, J, [&](int row) { return Inner(g, L.exposed[x], row) * chain; });
    }
    for (std::size_t x = 0; x < L.joint_columns.size(); ++x, ++o) {
      const int j = kind_.estimate().compliance_joints[x];
      ForEachRow(g, o, J, [&](int row) {
        return Inner(g, L.joint_columns[x], row) * torque_(j, g.members[row / rows_per_]);
      });
    }
    return o;
  }

  // ∂y/∂α = Σ over the lengths ℓ of ∂y/∂ℓ'·(ℓ0 + e_ℓ)·ΔT.
  void ChainThermalLinks(const TemperatureGroup& g, const double* e, int o, double* J) const {
    const EnvironmentMeasurement::Layout& L = kind_.layout();
    ForEachRow(g, o, J, [&](int row) {
      double sum = 0;
      for (std::size_t x = 0; x < L.length_columns.size(); ++x) {
        const int col = L.length_columns[x];
        sum += Inner(g, col, row) * (L.length_nominal[x] + ExposedValue(col, e)) * g.delta_t;
      }
      return sum;
    });
  }

  // The estimate of inner column `col` in e (0 when it is held).
  double ExposedValue(int col, const double* e) const {
    const std::vector<int>& exposed = kind_.layout().exposed;
    const auto it = std::find(exposed.begin(), exposed.end(), col);
    return it == exposed.end() ? 0.0 : e[it - exposed.begin()];
  }

  const EnvironmentMeasurement& kind_;
  const RobotModel& robot_;
  const int rows_per_;
  int num_rows_ = 0;
  bool compliance_estimated_ = false;
  Eigen::MatrixXd torque_;  // N × m: τ_j at each configuration
  std::vector<TemperatureGroup> groups_;
};

}  // namespace

std::unique_ptr<MeasurementEvaluator> EnvironmentMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  return std::make_unique<EnvironmentEvaluator>(*this, *robot_, configs);
}

std::vector<std::string> EnvironmentMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                             const double* e) const {
  const std::vector<double> zero(static_cast<std::size_t>(num_parameters()), 0.0);
  EnvironmentEvaluator evaluator(*this, *robot_, configs);
  return evaluator.Misses(e ? e : zero.data());
}

std::unique_ptr<MeasurementKind> EnvironmentMeasurement::Without(
    const std::vector<std::string>& names) const {
  std::vector<std::string> held = held_;
  NonGeometricTerms estimate = estimate_;
  for (const std::string& name : names) {
    const int joint = ComplianceTermJoint(name);
    auto& joints = estimate.compliance_joints;
    if (joint >= 0 && std::find(joints.begin(), joints.end(), joint) != joints.end()) {
      joints.erase(std::find(joints.begin(), joints.end(), joint));
    } else if (name == kThermalLinksTerm && estimate.thermal_links) {
      estimate.thermal_links = false;
    } else if (name == kThermalRangerTerm && estimate.thermal_ranger) {
      estimate.thermal_ranger = false;
    } else if (Contains(names_, name)) {
      held.push_back(name);
    } else {
      throw InputError(source_, "cannot fix '" + name + "': not an estimated term of this " +
                                    inner_->name() + " model");
    }
  }
  return std::make_unique<EnvironmentMeasurement>(inner_, *robot_, model_, estimate, held, source_);
}

std::vector<std::string> EnvironmentMeasurement::ExplainLostTerms(
    const TargetedConfigurations& configs, const std::vector<std::string>& lost) const {
  std::vector<std::string> out;
  const int n = robot_->num_links();
  Eigen::VectorXd largest = Eigen::VectorXd::Zero(n);
  double t_min = INFINITY, t_max = -INFINITY;
  for (int i = 0; i < configs.size(); ++i) {
    const Environment env = EnvironmentOf(configs, i);
    largest = largest.cwiseMax(GravityTorques(*robot_, robot_->nominal_values().data(),
                                              model_.masses, configs.q(i), env.gravity)
                                   .cwiseAbs());
    t_min = std::min(t_min, env.temperature_c);
    t_max = std::max(t_max, env.temperature_c);
  }
  const double scale = std::max(largest.maxCoeff(), 1e-300);
  for (const std::string& name : lost) {
    const int j = ComplianceTermJoint(name);
    if (j >= 0 && j < n && largest[j] <= 1e-9 * scale) {
      out.push_back(name + ": joint " + std::to_string(j + 1) +
                    " carries no gravity torque in these measurements (gravity along its axis, "
                    "no gravity, or no mass beyond it), so its compliance cannot be seen");
    } else if (j >= 0 && j < n) {
      out.push_back(name + ": the deflection of joint " + std::to_string(j + 1) +
                    " under gravity reads like a change of the geometry at these "
                    "configurations (vary the gravity's direction relative to the arm)");
    } else if ((name == kThermalLinksTerm || name == kThermalRangerTerm) && t_min == t_max) {
      out.push_back(name + ": every measurement at " + FormatExact(t_min) +
                    " °C, so thermal growth cannot be told from " +
                    (name == kThermalLinksTerm ? "the link lengths" : "the ranger's scale") +
                    " (measure at two temperatures or more)");
    } else if (name == kThermalLinksTerm || name == kThermalRangerTerm) {
      out.push_back(name +
                    ": a uniform growth of the arm reads, on these planes, as the "
                    "ranger's gain and a shift of the planes (measure on planes of "
                    "other orientations, or hold one of them)");
    }
  }
  return out;
}

std::vector<Pose<double>> EnvironmentToolPoses(const RobotModel& robot,
                                               const Eigen::VectorXd& link_values,
                                               const NonGeometricModel& model,
                                               const TargetedConfigurations& configs) {
  std::vector<Pose<double>> poses;
  poses.reserve(static_cast<std::size_t>(configs.size()));
  const int n = robot.num_links();
  std::vector<double> q(static_cast<std::size_t>(n));
  Eigen::VectorXd grown = link_values;
  for (int i = 0; i < configs.size(); ++i) {
    const Environment env = configs.environment(i).Or(model.defaults);
    const double dt = env.temperature_c - model.thermal.reference_c;
    grown = link_values;
    for (int v : robot.parameter_indices())
      if (!IsAngle(v % kValuesPerLink)) grown[v] *= 1 + model.thermal.Link(v / kValuesPerLink) * dt;
    const Eigen::VectorXd tau = GravityTorques(robot, robot.nominal_values().data(), model.masses,
                                               configs.q(i), env.gravity);
    for (int j = 0; j < n; ++j)
      q[static_cast<std::size_t>(j)] = configs.q(i)[j] + model.Compliance(j) * tau[j];
    poses.push_back(ForwardKinematics<double>(robot, grown.data(), q.data()));
  }
  return poses;
}

}  // namespace lrcal
