#include "lrcal/measurement/point_measurement.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/measurement/pose_measurement.h"
#include "measurement/batch_point.h"

namespace lrcal {

namespace {

constexpr const char* kInstrumentTerms[6] = {"instrument_x",     "instrument_y",
                                             "instrument_z",     "instrument_roll",
                                             "instrument_pitch", "instrument_yaw"};
constexpr const char* kAxes[3] = {"x", "y", "z"};
constexpr const char* kRotations[3] = {"roll", "pitch", "yaw"};

class PointEvaluator : public MeasurementEvaluator {
 public:
  PointEvaluator(const PointMeasurement& kind, const TargetedConfigurations& configs,
                 std::vector<Eigen::Matrix3d> chart_centres)
      : kind_(kind),
        k_(kind.rows_per_configuration()),
        m_(configs.size()),
        chart_centres_(std::move(chart_centres)) {
    batch_.SetConfigurations(configs);
  }
  int num_rows() const override { return k_ * m_; }
  int num_parameters() const override { return kind_.num_parameters(); }
  // Every configuration at once (batch_point.h).
  bool Predict(const double* e, double* y, double* J) override {
    kind_.StateAt(e, &state_);
    PrepareChainPoint(kind_.robot(), state_.link_values.data(), &chain_);
    batch_.Evaluate(kind_, state_, chain_, k_ == 6 ? chart_centres_.data() : nullptr, y, J);
    return true;
  }

 private:
  const PointMeasurement& kind_;
  const int k_, m_;
  const std::vector<Eigen::Matrix3d> chart_centres_;
  PointMeasurement::State state_;
  ChainPoint chain_;
  BatchPointEvaluator batch_;
};

}  // namespace

const std::vector<std::string>& InstrumentTermNames() {
  static const std::vector<std::string> names(std::begin(kInstrumentTerms),
                                              std::end(kInstrumentTerms));
  return names;
}

PointMeasurement ToolPointKind(const RobotModel& robot, const Eigen::Vector3d& tool_point,
                               const std::vector<std::string>& fixed, const std::string& source) {
  PointSetup setup;
  setup.targets = {tool_point};
  std::vector<std::string> held = InstrumentTermNames();
  for (const std::string& name : fixed)
    if (robot.FindValue(name) >= 0 || name.rfind("target_", 0) == 0) held.push_back(name);
  return PointMeasurement(robot, setup, held, source);
}

std::string TargetTermName(int k, int num_targets, const std::string& axis) {
  return num_targets == 1 ? "target_" + axis : "target" + std::to_string(k + 1) + "_" + axis;
}

void PointSetup::Validate() const {
  instrument.Validate("point.instrument");
  if (!instrument.translation.allFinite())
    throw InputError("point.instrument", "expected a finite position (m)");
  if (targets.empty() || static_cast<int>(targets.size()) > kMaxTargets)
    throw InputError("point.targets", "expected 1 to " + std::to_string(kMaxTargets) +
                                          " targets, got " + std::to_string(targets.size()));
  for (std::size_t k = 0; k < targets.size(); ++k)
    if (!targets[k].allFinite())
      throw InputError("point.targets[" + std::to_string(k) + "]",
                       "expected a finite offset in the tool frame (m)");
  if (!target_orientations.empty() && target_orientations.size() != targets.size())
    throw InputError("point.target_orientations", "expected none or one per target (" +
                                                      std::to_string(targets.size()) + "), got " +
                                                      std::to_string(target_orientations.size()));
  for (std::size_t k = 0; k < target_orientations.size(); ++k)
    RigidTransform{target_orientations[k], Eigen::Vector3d::Zero()}.Validate(
        "point.target_orientations[" + std::to_string(k) + "]");
}

Eigen::Matrix3d PointSetup::TargetOrientation(int k) const {
  return target_orientations.empty() ? Eigen::Matrix3d::Identity()
                                     : target_orientations[static_cast<std::size_t>(k)];
}

PointMeasurement::PointMeasurement(const RobotModel& robot, PointSetup setup,
                                   const std::vector<std::string>& fixed, const std::string& source,
                                   bool orientation)
    : robot_(&robot), setup_(std::move(setup)), fixed_(fixed), orientation_(orientation) {
  setup_.Validate();
  CheckTermNames(fixed, source);
  const auto is_fixed = [&](const std::string& name) {
    return std::find(fixed.begin(), fixed.end(), name) != fixed.end();
  };
  for (int index = 0; index < robot.num_values(); ++index) {
    const std::string name = LinkValueFullName(index);
    if (!robot.links()[index / kValuesPerLink].is_parameter[index % kValuesPerLink] ||
        is_fixed(name))
      continue;
    robot_values_.push_back(index);
    names_.push_back(name);
  }
  for (int k = 0; k < 6; ++k) {
    if (is_fixed(kInstrumentTerms[k])) continue;
    instrument_columns_[k] = static_cast<int>(names_.size());
    names_.emplace_back(kInstrumentTerms[k]);
  }
  const int targets = static_cast<int>(setup_.targets.size());
  target_columns_.assign(3 * targets, -1);
  rotation_columns_.assign(3 * targets, -1);
  for (int t = 0; t < targets; ++t) {
    for (int c = 0; c < 3; ++c) {
      const std::string name = TargetTermName(t, targets, kAxes[c]);
      if (is_fixed(name)) continue;
      target_columns_[3 * t + c] = static_cast<int>(names_.size());
      names_.push_back(name);
    }
    for (int c = 0; c < 3 && orientation_; ++c) {
      const std::string name = TargetTermName(t, targets, kRotations[c]);
      if (is_fixed(name)) continue;
      rotation_columns_[3 * t + c] = static_cast<int>(names_.size());
      names_.push_back(name);
    }
  }
}

std::vector<std::string> PointMeasurement::AllTermNames() const {
  std::vector<std::string> names;
  for (int index = 0; index < robot_->num_values(); ++index)
    if (robot_->links()[index / kValuesPerLink].is_parameter[index % kValuesPerLink])
      names.push_back(LinkValueFullName(index));
  for (const char* term : kInstrumentTerms) names.emplace_back(term);
  const int targets = static_cast<int>(setup_.targets.size());
  for (int t = 0; t < targets; ++t) {
    for (const char* axis : kAxes) names.push_back(TargetTermName(t, targets, axis));
    if (orientation_)
      for (const char* axis : kRotations) names.push_back(TargetTermName(t, targets, axis));
  }
  return names;
}

void PointMeasurement::CheckTermNames(const std::vector<std::string>& names,
                                      const std::string& source) const {
  const std::vector<std::string> all = AllTermNames();
  for (const std::string& name : names)
    if (std::find(all.begin(), all.end(), name) == all.end())
      throw InputError(source, "'" + name + "' is not a term of the " + this->name() +
                                   " measurement: expected a robot parameter, instrument_x … "
                                   "instrument_yaw, or " +
                                   TargetTermName(0, static_cast<int>(setup_.targets.size()), "x") +
                                   " … " + all.back());
}

Eigen::VectorXd PointMeasurement::NominalValues() const {
  Eigen::VectorXd nominal = Eigen::VectorXd::Zero(num_parameters());
  for (std::size_t k = 0; k < robot_values_.size(); ++k)
    nominal[static_cast<Eigen::Index>(k)] = robot_->nominal_values()[robot_values_[k]];
  for (int c = 0; c < 3; ++c)
    if (instrument_columns_[c] >= 0)
      nominal[instrument_columns_[c]] = setup_.instrument.translation[c];
  for (int t = 0; t < static_cast<int>(setup_.targets.size()); ++t)
    for (int c = 0; c < 3; ++c)
      if (target_column(t, c) >= 0) nominal[target_column(t, c)] = setup_.targets[t][c];
  return nominal;
}

Eigen::VectorXd PointMeasurement::LinkValuesAt(const double* e) const {
  Eigen::VectorXd values = robot_->nominal_values();
  for (std::size_t k = 0; k < robot_values_.size(); ++k) values[robot_values_[k]] += e[k];
  return values;
}

void PointMeasurement::StateAt(const double* e, State* s) const {
  s->link_values = LinkValuesAt(e);
  double d[6];
  for (int k = 0; k < 6; ++k) d[k] = instrument_columns_[k] >= 0 ? e[instrument_columns_[k]] : 0.0;
  s->R_BI0 = setup_.instrument.rotation;
  s->Rx = Eigen::AngleAxisd(d[3], Eigen::Vector3d::UnitX()).toRotationMatrix();
  s->Ry = Eigen::AngleAxisd(d[4], Eigen::Vector3d::UnitY()).toRotationMatrix();
  s->Rz = Eigen::AngleAxisd(d[5], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s->R_BI = s->R_BI0 * s->Rz * s->Ry * s->Rx;
  s->p_BI = setup_.instrument.translation + Eigen::Vector3d(d[0], d[1], d[2]);
  s->targets = setup_.targets;
  const int targets = static_cast<int>(s->targets.size());
  for (int t = 0; t < targets; ++t)
    for (int c = 0; c < 3; ++c) {
      const int column = target_column(t, c);
      if (column >= 0) s->targets[static_cast<std::size_t>(t)][c] += e[column];
    }
  if (!orientation_) return;
  s->R_TM.resize(s->targets.size());
  s->target_Rx.resize(s->targets.size());
  s->target_Ry.resize(s->targets.size());
  for (int t = 0; t < targets; ++t) {
    double r[3];
    for (int k = 0; k < 3; ++k) {
      const int column = target_rotation_column(t, k);
      r[k] = column >= 0 ? e[column] : 0.0;
    }
    const auto u = static_cast<std::size_t>(t);
    s->target_Rx[u] = Eigen::AngleAxisd(r[0], Eigen::Vector3d::UnitX()).toRotationMatrix();
    s->target_Ry[u] = Eigen::AngleAxisd(r[1], Eigen::Vector3d::UnitY()).toRotationMatrix();
    s->R_TM[u] = setup_.TargetOrientation(t) *
                 Eigen::AngleAxisd(r[2], Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                 s->target_Ry[u] * s->target_Rx[u];
  }
}

std::unique_ptr<MeasurementEvaluator> PointMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  CheckConfigurations(configs);
  return std::make_unique<PointEvaluator>(*this, configs, ChartCentres(configs));
}

std::unique_ptr<MeasurementEvaluator> PointMeasurement::BindInChartsOf(
    const TargetedConfigurations& configs, const TargetedConfigurations& chart_configs) const {
  CheckConfigurations(configs);
  CheckConfigurations(chart_configs);
  if (chart_configs.size() != configs.size())
    throw InputError("configurations", std::to_string(configs.size()) +
                                           " configurations but charts of " +
                                           std::to_string(chart_configs.size()));
  return std::make_unique<PointEvaluator>(*this, configs, ChartCentres(chart_configs));
}

void PointMeasurement::CheckConfigurations(const TargetedConfigurations& configs) const {
  if (configs.num_joints() != robot_->num_links())
    throw InputError("configurations", "the robot has " + std::to_string(robot_->num_links()) +
                                           " joints, the configurations " +
                                           std::to_string(configs.num_joints()));
  if (configs.num_targets_referenced() > static_cast<int>(setup_.targets.size()))
    throw InputError("configurations", "a configuration names target " +
                                           std::to_string(configs.num_targets_referenced()) +
                                           " but the set-up has " +
                                           std::to_string(setup_.targets.size()) + " target(s)");
}

std::vector<std::string> PointMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                       const double*) const {
  return std::vector<std::string>(configs.size(), "ok");
}

std::unique_ptr<MeasurementKind> PointMeasurement::Without(
    const std::vector<std::string>& names) const {
  CheckTermNames(names, "fix");
  std::vector<std::string> fixed = fixed_;
  for (const std::string& name : names)
    if (std::find(fixed.begin(), fixed.end(), name) == fixed.end()) fixed.push_back(name);
  return std::make_unique<PointMeasurement>(*robot_, setup_, fixed);
}

}  // namespace lrcal

namespace lrcal {

Eigen::Vector3d RotationLog(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d InverseRightJacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  Eigen::Matrix3d hat;
  hat << 0, -phi.z(), phi.y(), phi.z(), 0, -phi.x(), -phi.y(), phi.x(), 0;
  // The coefficient of [φ]×², 1/θ² − (1 + cos θ)/(2θ sin θ), tends to 1/12 (+ θ²/720).
  const double c =
      theta < 1e-4 ? 1.0 / 12.0 + theta * theta / 720.0
                   : 1.0 / (theta * theta) - (1 + std::cos(theta)) / (2 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() + 0.5 * hat + c * hat * hat;
}

PoseMeasurement::PoseMeasurement(const RobotModel& robot, PointSetup setup,
                                 const std::vector<std::string>& fixed, const std::string& source)
    : PointMeasurement(robot, std::move(setup), fixed, source, true),
      chart_robot_(&robot),
      chart_setup_(this->setup()) {}

void PoseMeasurement::UseChartOf(const PoseMeasurement& nominal) {
  if (nominal.robot().num_links() != robot().num_links() ||
      nominal.setup().targets.size() != setup().targets.size())
    throw InputError("pose chart",
                     "the nominal kind has " + std::to_string(nominal.robot().num_links()) +
                         " joints and " + std::to_string(nominal.setup().targets.size()) +
                         " target(s), this one " + std::to_string(robot().num_links()) + " and " +
                         std::to_string(setup().targets.size()));
  chart_robot_ = nominal.chart_robot_;
  chart_setup_ = nominal.chart_setup_;
}

Eigen::Matrix3d PoseMeasurement::ChartCentre(const double* q, int target) const {
  const Pose<double> pose =
      ForwardKinematics<double>(*chart_robot_, chart_robot_->nominal_values().data(), q);
  return chart_setup_.instrument.rotation.transpose() * pose.R_BT *
         chart_setup_.TargetOrientation(target);
}

Eigen::Vector3d PoseMeasurement::OrientationValue(const double* q, int target,
                                                  const Eigen::Matrix3d& R_IM) const {
  return RotationLog(ChartCentre(q, target).transpose() * R_IM);
}

Eigen::Matrix3d PoseMeasurement::OrientationOf(const double* q, int target,
                                               const Eigen::Vector3d& phi) const {
  const double angle = phi.norm();
  const Eigen::Matrix3d turn = angle > 0 ? Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix()
                                         : Eigen::Matrix3d::Identity();
  return ChartCentre(q, target) * turn;
}

std::vector<Eigen::Matrix3d> PoseMeasurement::ChartCentres(
    const TargetedConfigurations& configs) const {
  std::vector<Eigen::Matrix3d> centres(static_cast<std::size_t>(configs.size()));
  for (int i = 0; i < configs.size(); ++i)
    centres[static_cast<std::size_t>(i)] = ChartCentre(configs.q(i), configs.target(i));
  return centres;
}

std::unique_ptr<MeasurementKind> PoseMeasurement::Without(
    const std::vector<std::string>& names) const {
  std::vector<std::string> fixed_terms = fixed();
  for (const std::string& name : names)
    if (std::find(fixed_terms.begin(), fixed_terms.end(), name) == fixed_terms.end())
      fixed_terms.push_back(name);
  auto kind = std::make_unique<PoseMeasurement>(robot(), setup(), fixed_terms);
  kind->chart_robot_ = chart_robot_;
  kind->chart_setup_ = chart_setup_;
  return kind;
}

std::unique_ptr<PointMeasurement> TrackerKindOn(const RobotModel& robot,
                                                const PointMeasurement& like) {
  if (const auto* pose = dynamic_cast<const PoseMeasurement*>(&like)) {
    auto kind = std::make_unique<PoseMeasurement>(robot, like.setup(), like.fixed());
    kind->UseChartOf(*pose);
    return kind;
  }
  return std::make_unique<PointMeasurement>(robot, like.setup(), like.fixed());
}

void WeighAngleRows(const MeasurementKind& kind, double sigma, double sigma_angle,
                    MeasuredValues* data) {
  if (!(sigma > 0) || !std::isfinite(sigma) || !(sigma_angle > 0) || !std::isfinite(sigma_angle))
    throw InputError("noise",
                     "orientations are weighed against positions by sigma/sigma_angle: "
                     "expected both finite and > 0");
  const int k = kind.rows_per_configuration();
  bool angles = false;
  for (int c = 0; c < k; ++c) angles = angles || kind.RowIsAngle(c);
  if (!angles) return;
  std::vector<double> weights = data->RowWeights(k);
  const double ratio = sigma / sigma_angle;
  for (std::size_t r = 0; r < weights.size(); ++r)
    if (kind.RowIsAngle(static_cast<int>(r % static_cast<std::size_t>(k))))
      weights[r] *= ratio * ratio;
  data->weights = std::move(weights);
}

}  // namespace lrcal
