#include "lrcal/measurement/contact_measurement.h"

#include <algorithm>
#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/joint_constraints.h"
#include "lrcal/measurement/constraint_kinds.h"

namespace lrcal {

namespace {

// The gnomonic coordinates of direction z in `chart` (z·t/z·n0) and, if `d` is given, their
// derivatives with respect to z (2 × 3).
Eigen::Vector2d Gnomonic(const NormalChart& chart, const Eigen::Vector3d& z,
                         Eigen::Matrix<double, 2, 3>* d) {
  const double zn = z.dot(chart.n0);
  const Eigen::Vector2d c(z.dot(chart.t1) / zn, z.dot(chart.t2) / zn);
  if (d) {
    d->row(0) = (chart.t1.transpose() - c[0] * chart.n0.transpose()) / zn;
    d->row(1) = (chart.t2.transpose() - c[1] * chart.n0.transpose()) / zn;
  }
  return c;
}

class ContactEvaluator : public MeasurementEvaluator {
 public:
  ContactEvaluator(const ContactMeasurement& kind, const TargetedConfigurations& configs)
      : kind_(kind),
        configs_(configs),
        k_(kind.rows_per_configuration()),
        retagged_(configs.num_joints()) {
    retagged_.Reserve(configs.size());
    for (int i = 0; i < configs.size(); ++i) retagged_.AddFrom(configs, i, 0);
    arm_ = kind.arm().Bind(retagged_);
    point_.resize(static_cast<std::size_t>(3 * configs.size()));
  }
  int num_rows() const override { return k_ * configs_.size(); }
  int num_parameters() const override { return kind_.num_parameters(); }
  bool Predict(const double* e, double* y, double* J) override {
    const int m = num_rows(), n = num_parameters(), arm_terms = kind_.arm().num_parameters();
    // The tool point in B and its Jacobian from the arm's kind (rows of three, config-major).
    arm_J_.resize(J ? static_cast<std::size_t>(point_.size()) * arm_terms : 0);
    if (!arm_->Predict(e, point_.data(), J ? arm_J_.data() : nullptr)) return false;
    if (J) std::fill(J, J + static_cast<std::size_t>(m) * n, 0.0);
    if (k_ == 3) PrepareChainPoint(kind_.robot(), kind_.arm().LinkValuesAt(e).data(), &chain_);
    for (int i = 0; i < configs_.size(); ++i) {
      const int k = configs_.target(i);
      const ContactMeasurement::PlaneState plane = kind_.PlaneAt(e, k);
      const Eigen::Vector3d P(&point_[static_cast<std::size_t>(3 * i)]);
      y[k_ * i] = plane.normal.dot(P) + plane.offset;
      if (J) DistanceRow(plane, P, i, m, arm_terms, J);
      if (k_ == 3) FlushRows(plane, k, i, m, y, J);
    }
    return true;
  }

 private:
  // Row k·i: n·∂P/∂e for the arm's terms, Pᵀ·∂n/∂u and 1 for the plane's.
  void DistanceRow(const ContactMeasurement::PlaneState& plane, const Eigen::Vector3d& P, int i,
                   int m, int arm_terms, double* J) const {
    const int row = k_ * i, point_rows = 3 * configs_.size();
    for (int c = 0; c < arm_terms; ++c) {
      const double* dP = &arm_J_[static_cast<std::size_t>(c) * point_rows + 3 * i];
      J[static_cast<std::size_t>(c) * m + row] =
          plane.normal.x() * dP[0] + plane.normal.y() * dP[1] + plane.normal.z() * dP[2];
    }
    for (int a = 0; a < 2; ++a)
      if (plane.column[a] >= 0)
        J[static_cast<std::size_t>(plane.column[a]) * m + row] = plane.dn_du.col(a).dot(P);
    if (plane.column[2] >= 0) J[static_cast<std::size_t>(plane.column[2]) * m + row] = 1.0;
  }
  // Rows k·i + 1, k·i + 2: the tool z axis's gnomonic coordinates minus u; ∂z/∂v = ω × z for
  // each link value (the joint axis for θ, the common normal for α, the twist axis for β).
  void FlushRows(const ContactMeasurement::PlaneState& plane, int k, int i, int m, double* y,
                 double* J) {
    const Pose<double> pose = ToolPose(chain_, configs_, i, J ? &frames_ : nullptr);
    const Eigen::Vector3d z = pose.R_BT.col(2);
    Eigen::Matrix<double, 2, 3> dc;
    const Eigen::Vector2d c = Gnomonic(kind_.chart(k), z, &dc);
    const int row = k_ * i + 1;
    y[row] = c[0] - plane.u[0];
    y[row + 1] = c[1] - plane.u[1];
    if (!J) return;
    const std::vector<int>& robot_values = kind_.arm().robot_values();
    for (std::size_t col = 0; col < robot_values.size(); ++col) {
      const Eigen::Vector2d d = dc * LinkValueRotation(frames_, robot_values[col]).cross(z);
      J[col * m + row] = d[0];
      J[col * m + row + 1] = d[1];
    }
    if (plane.column[0] >= 0) J[static_cast<std::size_t>(plane.column[0]) * m + row] = -1.0;
    if (plane.column[1] >= 0) J[static_cast<std::size_t>(plane.column[1]) * m + row + 1] = -1.0;
  }

  const ContactMeasurement& kind_;
  const TargetedConfigurations& configs_;
  const int k_;
  TargetedConfigurations retagged_;
  std::unique_ptr<MeasurementEvaluator> arm_;
  std::vector<double> point_, arm_J_;
  ChainPoint chain_;
  ChainFrames frames_;
};

}  // namespace

void ContactSetup::Validate() const {
  if (planes.size() < 1) throw InputError("contact.planes", "expected at least one plane");
  if (!plane_terms.empty() && static_cast<int>(plane_terms.size()) != planes.size())
    throw InputError("contact.plane_terms", "expected none or one per plane (" +
                                                std::to_string(planes.size()) + "), got " +
                                                std::to_string(plane_terms.size()));
  if (!tool_point.allFinite())
    throw InputError("contact.tool_point", "expected a finite offset in the tool frame (m)");
}

ContactMeasurement::ContactMeasurement(const RobotModel& robot, ContactSetup setup,
                                       const std::vector<std::string>& fixed,
                                       const std::string& source)
    : arm_(ToolPointKind(robot, setup.tool_point, fixed, source)),
      setup_(std::move(setup)),
      fixed_(fixed) {
  setup_.Validate();
  names_ = arm_.parameter_names();
  planes_ = EstimatedPlanes(setup_.planes, setup_.plane_terms, fixed, &names_);
  const std::vector<std::string> plane_terms = planes_.TermNames();
  for (const std::string& name : fixed)
    if (name.rfind("plane", 0) == 0 &&
        std::find(plane_terms.begin(), plane_terms.end(), name) == plane_terms.end())
      throw InputError(source, "'" + name +
                                   "' is not a term of the contact measurement: expected a robot "
                                   "parameter, target_x … target_z, or an estimated plane term");
}

std::vector<std::string> ContactMeasurement::AllTermNames() const {
  std::vector<std::string> names;
  for (const std::string& name : arm_.AllTermNames())
    if (std::find(InstrumentTermNames().begin(), InstrumentTermNames().end(), name) ==
        InstrumentTermNames().end())
      names.push_back(name);
  for (const std::string& name : planes_.TermNames()) names.push_back(name);
  return names;
}

Eigen::VectorXd ContactMeasurement::NominalValues() const {
  Eigen::VectorXd nominal = Eigen::VectorXd::Zero(num_parameters());
  nominal.head(arm_.num_parameters()) = arm_.NominalValues();
  planes_.SetNominal(&nominal);
  return nominal;
}

std::unique_ptr<MeasurementEvaluator> ContactMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  planes_.CheckConfigurations(configs, robot().num_links(), "touches");
  return std::make_unique<ContactEvaluator>(*this, configs);
}

std::vector<std::string> ContactMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                         const double*) const {
  return std::vector<std::string>(configs.size(), "ok");
}

std::unique_ptr<MeasurementKind> ContactMeasurement::Without(
    const std::vector<std::string>& names) const {
  return std::make_unique<ContactMeasurement>(robot(), setup_,
                                              HeldTerms(fixed_, names, AllTermNames(), name()));
}

TargetedConfigurations ContactMeasurement::LinearisationConfigurations(
    const TargetedConfigurations& configs) const {
  return SeatEach(configs, [&](double* q, int k) {
    return k < setup_.planes.size() && configs.num_joints() == robot().num_links() &&
           SeatOnPlane(robot(), setup_.tool_point, setup_.planes[k], setup_.flush, 0,
                       Eigen::Vector2d::Zero(), q);
  });
}

bool SeatOnPlane(const RobotModel& robot, const Eigen::Vector3d& tool_point, const Plane& plane,
                 bool flush, double distance, const Eigen::Vector2d& tilt, double* q) {
  const NormalChart chart(plane.normal);
  return SolveJointConstraints(
      robot, flush ? 3 : 1,
      [&](const Pose<double>& pose, const Eigen::Matrix<double, 6, Eigen::Dynamic>& G,
          Eigen::VectorXd* r, Eigen::MatrixXd* J) {
        const Eigen::Vector3d offset = pose.R_BT * tool_point;
        (*r)[0] = plane.SignedDistance(pose.p_BT + offset) - distance;
        for (int j = 0; j < static_cast<int>(G.cols()); ++j)
          (*J)(0, j) = plane.normal.dot(G.col(j).head<3>() + G.col(j).tail<3>().cross(offset));
        if (!flush) return;
        const Eigen::Vector3d z = pose.R_BT.col(2);
        Eigen::Matrix<double, 2, 3> dc;
        r->tail<2>() = Gnomonic(chart, z, &dc) - tilt;
        for (int j = 0; j < static_cast<int>(G.cols()); ++j)
          J->block<2, 1>(1, j) = dc * G.col(j).tail<3>().cross(z);
      },
      q);
}

int SimulateContactMeasurements(const ContactMeasurement& truth,
                                const TargetedConfigurations& starts, const NoiseModel& noise,
                                const RandomStream& stream, MeasuredValues* data,
                                std::vector<std::string>* misses) {
  noise.Validate();
  if (noise.encoder_sigma > 0 || noise.form_sigma > 0 || noise.outlier_fraction > 0 ||
      noise.ranger_offset != 0 || noise.ranger_scale != 0 || !noise.average.IsMean())
    throw InputError("noise",
                     "the contact measurement takes sigma (the contact's play, m), sigma_angle "
                     "(a flush contact's tilt, rad) and repetitions; the ranger's disturbances "
                     "and averaging do not apply");
  truth.Bind(starts);  // checks the tags and joints
  const int R = noise.repetitions, nj = starts.num_joints(), k = truth.rows_per_configuration();
  const bool flush = truth.setup().flush;
  const double root = std::sqrt(static_cast<double>(R));
  *data = MeasuredValues{TargetedConfigurations(nj), {}, {}};
  if (misses) misses->assign(static_cast<std::size_t>(starts.size()), "ok");
  const double angle_weight =
      noise.sigma > 0 && noise.sigma_angle > 0 ? std::pow(noise.sigma / noise.sigma_angle, 2) : 1;
  int missed = 0;
  std::vector<double> q(static_cast<std::size_t>(nj)), z(static_cast<std::size_t>(k));
  for (int i = 0; i < starts.size(); ++i) {
    stream.Normals(static_cast<std::uint64_t>(k) * i, k, z.data());
    const Eigen::Vector2d tilt =
        flush ? Eigen::Vector2d(Eigen::Vector2d(z[1], z[2]) * (noise.sigma_angle / root))
              : Eigen::Vector2d::Zero();
    std::copy(starts.q(i), starts.q(i) + nj, q.begin());
    const Plane& plane = truth.setup().planes[starts.target(i)];
    const char* reason = nullptr;
    if (!SeatOnPlane(truth.robot(), truth.setup().tool_point, plane, flush,
                     z[0] * noise.sigma / root, tilt, q.data()))
      reason = "out of reach";
    else if (!WrapIntoJointRanges(truth.robot(), q.data()))
      reason = "outside the joint ranges";
    if (reason) {
      ++missed;
      if (misses) (*misses)[static_cast<std::size_t>(i)] = reason;
      continue;
    }
    data->configs.Add(q.data(), starts.target(i));
    data->y.insert(data->y.end(), static_cast<std::size_t>(k), 0.0);
    data->repetitions.push_back(R);
    if (!flush) continue;
    data->weights.push_back(R);
    data->weights.insert(data->weights.end(), 2, R * angle_weight);
  }
  return missed;
}

}  // namespace lrcal
