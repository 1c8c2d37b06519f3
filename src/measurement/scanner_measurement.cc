#include "lrcal/measurement/scanner_measurement.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/measurement/constraint_kinds.h"

namespace lrcal {

namespace {

constexpr double kParallel = 1e-9;  // |n·D| below this: the beam runs along its plane

Eigen::Matrix3d Hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

Eigen::Vector3d BeamDirection(double angle) {
  return Eigen::Vector3d(std::sin(angle), 0.0, std::cos(angle));
}

class ScannerEvaluator : public MeasurementEvaluator {
 public:
  ScannerEvaluator(const ScannerMeasurement& kind, const TargetedConfigurations& configs)
      : kind_(kind), configs_(configs), beams_(kind.num_beams()), retagged_(configs.num_joints()) {
    retagged_.Reserve(configs.size());
    for (int i = 0; i < configs.size(); ++i) retagged_.AddFrom(configs, i, 0);
    arm_ = kind.arm().Bind(retagged_);
    origin_.resize(static_cast<std::size_t>(3 * configs.size()));
    incidence_cosine_.resize(static_cast<std::size_t>(beams_ * configs.size()));
  }
  /// |cos| of each row's angle between its beam and its plane's normal at the last Predict.
  const std::vector<double>& incidence_cosines() const { return incidence_cosine_; }
  int num_rows() const override { return beams_ * configs_.size(); }
  int num_parameters() const override { return kind_.num_parameters(); }
  bool Predict(const double* e, double* y, double* J) override {
    const int m = num_rows(), n = num_parameters();
    arm_J_.resize(J ? origin_.size() * static_cast<std::size_t>(kind_.arm().num_parameters()) : 0);
    if (!arm_->Predict(e, origin_.data(), J ? arm_J_.data() : nullptr)) return false;
    if (J) std::fill(J, J + static_cast<std::size_t>(m) * n, 0.0);
    PrepareChainPoint(kind_.robot(), kind_.arm().LinkValuesAt(e).data(), &chain_);
    Eigen::Matrix3d dR_TS[3];
    const Eigen::Matrix3d R_TS = kind_.OrientationAt(e, dR_TS);
    bool defined = true;
    for (int i = 0; i < configs_.size(); ++i) {
      const EstimatedPlanes::State plane = kind_.PlaneAt(e, configs_.target(i));
      const Pose<double> pose = ToolPose(chain_, configs_, i, J ? &frames_ : nullptr);
      const Eigen::Vector3d O(&origin_[static_cast<std::size_t>(3 * i)]);
      for (int b = 0; b < beams_; ++b) {
        const Eigen::Vector3d d_T = R_TS * BeamDirection(kind_.setup().beam_angles[b]);
        const Eigen::Vector3d D = pose.R_BT * d_T;
        const double nD = plane.normal.dot(D);
        const int row = beams_ * i + b;
        incidence_cosine_[static_cast<std::size_t>(row)] = std::fabs(nD);
        if (!(std::fabs(nD) > kParallel)) {
          y[row] = std::nan("");
          defined = false;
          continue;
        }
        const double h = -(plane.normal.dot(O) + plane.offset) / nD;
        y[row] = h;
        if (J) BeamRow(plane, pose, O, D, b, h, nD, i, row, m, dR_TS, J);
      }
    }
    return defined;
  }

 private:
  // ∂h = −(n·∂O + h·n·∂D + ∂n·(O + h·D) + ∂f)/(n·D): ∂O from the arm's kind (link values and the
  // origin's terms), ∂D = ω × D per link value, R_BT·∂R_TS·d_b per scanner angle.
  void BeamRow(const EstimatedPlanes::State& plane, const Pose<double>& pose,
               const Eigen::Vector3d& O, const Eigen::Vector3d& D, int b, double h, double nD,
               int i, int row, int m, const Eigen::Matrix3d dR_TS[3], double* J) const {
    const int arm_terms = kind_.arm().num_parameters(), point_rows = 3 * configs_.size();
    const std::vector<int>& robot_values = kind_.arm().robot_values();
    for (int c = 0; c < arm_terms; ++c) {
      const Eigen::Vector3d dO(&arm_J_[static_cast<std::size_t>(c) * point_rows + 3 * i]);
      double dn = plane.normal.dot(dO);
      if (c < static_cast<int>(robot_values.size()))
        dn +=
            h * plane.normal.dot(
                    LinkValueRotation(frames_, robot_values[static_cast<std::size_t>(c)]).cross(D));
      J[static_cast<std::size_t>(c) * m + row] = -dn / nD;
    }
    const Eigen::Vector3d d_S = BeamDirection(kind_.setup().beam_angles[b]);
    for (int a = 0; a < 3; ++a)
      if (kind_.angle_column(a) >= 0)
        J[static_cast<std::size_t>(kind_.angle_column(a)) * m + row] =
            -h * plane.normal.dot(pose.R_BT * dR_TS[a] * d_S) / nD;
    const Eigen::Vector3d hit = O + h * D;
    for (int a = 0; a < 2; ++a)
      if (plane.column[a] >= 0)
        J[static_cast<std::size_t>(plane.column[a]) * m + row] = -plane.dn_du.col(a).dot(hit) / nD;
    if (plane.column[2] >= 0) J[static_cast<std::size_t>(plane.column[2]) * m + row] = -1.0 / nD;
  }

  const ScannerMeasurement& kind_;
  const TargetedConfigurations& configs_;
  const int beams_;
  TargetedConfigurations retagged_;
  std::unique_ptr<MeasurementEvaluator> arm_;
  std::vector<double> origin_, arm_J_, incidence_cosine_;
  ChainPoint chain_;
  ChainFrames frames_;
};

}  // namespace

const std::vector<std::string>& ScannerAngleNames() {
  static const std::vector<std::string> names = {"scanner_roll", "scanner_pitch", "scanner_yaw"};
  return names;
}

std::vector<double> ScannerSetup::Fan(int count, double half_angle) {
  std::vector<double> angles;
  for (int b = 0; b < count; ++b)
    angles.push_back(count == 1 ? 0.0 : -half_angle + 2 * half_angle * b / (count - 1));
  return angles;
}

std::vector<double> ScannerSetup::FanOf(long long count, double half_angle_deg,
                                        const std::string& count_source,
                                        const std::string& angle_source) {
  if (count < 1 || count > kMaxBeams)
    throw InputError(count_source, "expected 1 to " + std::to_string(kMaxBeams) + " beams, got " +
                                       std::to_string(count));
  if (!(half_angle_deg >= 0 && half_angle_deg < 90)) {
    std::ostringstream got;
    got << half_angle_deg;
    throw InputError(angle_source,
                     "expected a half angle from 0 to below 90 deg, got " + got.str());
  }
  return Fan(static_cast<int>(count), half_angle_deg * M_PI / 180);
}

void ScannerSetup::Validate() const {
  if (planes.size() < 1) throw InputError("scanner.planes", "expected at least one plane");
  if (!plane_terms.empty() && static_cast<int>(plane_terms.size()) != planes.size())
    throw InputError("scanner.plane_terms", "expected none or one per plane (" +
                                                std::to_string(planes.size()) + "), got " +
                                                std::to_string(plane_terms.size()));
  if (!origin.allFinite())
    throw InputError("scanner.origin", "expected a finite point in the tool frame (m)");
  if (!orientation.allFinite() || !(orientation.transpose() * orientation).isIdentity(1e-9) ||
      !(orientation.determinant() > 0))
    throw InputError("scanner.orientation", "expected a rotation matrix");
  if (beam_angles.empty() || static_cast<int>(beam_angles.size()) > kMaxBeams)
    throw InputError("scanner.beam_angles", "expected 1 to " + std::to_string(kMaxBeams) +
                                                " beams, got " +
                                                std::to_string(beam_angles.size()));
  range.Validate();
  for (std::size_t b = 0; b < beam_angles.size(); ++b)
    if (!(std::fabs(beam_angles[b]) < M_PI / 2))
      throw InputError("scanner.beam_angles[" + std::to_string(b) + "]",
                       "expected a finite angle within (-pi/2, pi/2) rad of the scanner's z axis");
}

ScannerMeasurement::ScannerMeasurement(const RobotModel& robot, ScannerSetup setup,
                                       const std::vector<std::string>& fixed,
                                       const std::string& source)
    : arm_(ToolPointKind(robot, setup.origin, fixed, source)),
      setup_(std::move(setup)),
      fixed_(fixed) {
  setup_.Validate();
  names_ = arm_.parameter_names();
  for (int a = 0; a < 3; ++a) {
    const std::string& name = ScannerAngleNames()[static_cast<std::size_t>(a)];
    if (std::find(fixed.begin(), fixed.end(), name) != fixed.end()) continue;
    angle_columns_[a] = static_cast<int>(names_.size());
    names_.push_back(name);
  }
  planes_ = EstimatedPlanes(setup_.planes, setup_.plane_terms, fixed, &names_);
  const std::vector<std::string> all = AllTermNames();
  for (const std::string& name : fixed)
    if ((name.rfind("plane", 0) == 0 || name.rfind("scanner", 0) == 0) &&
        std::find(all.begin(), all.end(), name) == all.end())
      throw InputError(source, "'" + name +
                                   "' is not a term of the scanner measurement: expected a robot "
                                   "parameter, target_x … target_z, scanner_roll, scanner_pitch, "
                                   "scanner_yaw, or an estimated plane term");
}

std::vector<std::string> ScannerMeasurement::AllTermNames() const {
  std::vector<std::string> names;
  for (const std::string& name : arm_.AllTermNames())
    if (std::find(InstrumentTermNames().begin(), InstrumentTermNames().end(), name) ==
        InstrumentTermNames().end())
      names.push_back(name);
  for (const std::string& name : ScannerAngleNames()) names.push_back(name);
  for (const std::string& name : planes_.TermNames()) names.push_back(name);
  return names;
}

Eigen::VectorXd ScannerMeasurement::NominalValues() const {
  Eigen::VectorXd nominal = Eigen::VectorXd::Zero(num_parameters());
  nominal.head(arm_.num_parameters()) = arm_.NominalValues();
  planes_.SetNominal(&nominal);  // the angles: 0 at the nominal orientation
  return nominal;
}

Eigen::Matrix3d ScannerMeasurement::OrientationAt(const double* e, Eigen::Matrix3d d[3]) const {
  double angle[3];
  for (int a = 0; a < 3; ++a) angle[a] = angle_columns_[a] >= 0 ? e[angle_columns_[a]] : 0.0;
  const Eigen::Matrix3d Rx = Eigen::AngleAxisd(angle[0], Eigen::Vector3d::UnitX()).matrix();
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(angle[1], Eigen::Vector3d::UnitY()).matrix();
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(angle[2], Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Matrix3d& R0 = setup_.orientation;
  if (d) {
    d[0] = angle_columns_[0] >= 0
               ? Eigen::Matrix3d(R0 * Rz * Ry * Rx * Hat(Eigen::Vector3d::UnitX()))
               : Eigen::Matrix3d::Zero();
    d[1] = angle_columns_[1] >= 0
               ? Eigen::Matrix3d(R0 * Rz * Ry * Hat(Eigen::Vector3d::UnitY()) * Rx)
               : Eigen::Matrix3d::Zero();
    d[2] = angle_columns_[2] >= 0
               ? Eigen::Matrix3d(R0 * Rz * Hat(Eigen::Vector3d::UnitZ()) * Ry * Rx)
               : Eigen::Matrix3d::Zero();
  }
  return R0 * Rz * Ry * Rx;
}

std::unique_ptr<MeasurementEvaluator> ScannerMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  planes_.CheckConfigurations(configs, robot().num_links(), "is aimed at");
  return std::make_unique<ScannerEvaluator>(*this, configs);
}

std::vector<std::string> ScannerMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                         const double* e) const {
  std::vector<std::string> reasons(static_cast<std::size_t>(configs.size()), "ok");
  planes_.CheckConfigurations(configs, robot().num_links(), "is aimed at");
  ScannerEvaluator evaluator(*this, configs);
  std::vector<double> h(static_cast<std::size_t>(evaluator.num_rows()));
  evaluator.Predict(e, h.data(), nullptr);
  const RangerSpec& range = setup_.range;
  const double min_cosine = std::cos(range.max_incidence);
  const int B = num_beams();
  for (int i = 0; i < configs.size(); ++i)
    for (int b = 0; b < B; ++b) {
      const auto row = static_cast<std::size_t>(B * i + b);
      const double v = h[row];
      const std::string beam = "beam " + std::to_string(b + 1),
                        plane = "plane " + std::to_string(configs.target(i) + 1);
      std::string reason;
      if (!std::isfinite(v))
        reason = beam + " parallel to " + plane;
      else if (v <= 0)
        reason = plane + " behind " + beam;
      else if (v < range.min_range || v > range.max_range)
        reason = beam + " out of range (" + std::to_string(v) + " m)";
      else if (evaluator.incidence_cosines()[row] < min_cosine)
        reason = beam + " grazing " + plane;
      if (reason.empty()) continue;
      reasons[static_cast<std::size_t>(i)] = reason;
      break;
    }
  return reasons;
}

std::unique_ptr<MeasurementKind> ScannerMeasurement::Without(
    const std::vector<std::string>& names) const {
  return std::make_unique<ScannerMeasurement>(robot(), setup_,
                                              HeldTerms(fixed_, names, AllTermNames(), name()));
}

}  // namespace lrcal
