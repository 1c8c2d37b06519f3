// A tracker's measurement of a point on the tool — a laser tracker's reflector, a motion-capture
// marker — as a MeasurementKind (measurement_kind.h): the 3-D position of a target rigidly
// attached to the tool, in the measuring instrument's frame I.
//
//   y = R_BIᵀ·(p_BT(q) + R_BT(q)·t_k − p_BI)        (m, three rows per configuration: x, y, z)
//
// (R_BT, p_BT) is the tool pose in the base frame B (the chain with its base and tool transforms,
// chain.h), t_k the offset of target k in the tool frame T, (R_BI, p_BI) the instrument's pose in
// B. Which target a configuration sees is its tag (TargetedConfigurations::target(i), the index
// the ranger uses for its plane). Estimated terms, in this order:
//  - the robot's link values, as the ranger's (names "theta1", ...);
//  - the instrument's pose: "instrument_x", "instrument_y", "instrument_z" (m, a shift of p_BI in
//    B) and "instrument_roll", "instrument_pitch", "instrument_yaw" (rad: R_BI = R_BI0·Rz(yaw)·
//    Ry(pitch)·Rx(roll), a rotation of the nominal orientation about the instrument's own axes,
//    URDF's order);
//  - each target's offset in T: "target_x", "target_y", "target_z" (m) with one target,
//    "target1_x", ... with several.
// Any of them can be fixed by name. The Jacobian is analytic (the point's differential motion per
// link value, as measurement_model.h derives for the ranger's hit point; the rotation's through
// the product rule), checked against autodiff and central differences in the tests. A tracker
// always sees its target here: line of sight is not modelled (MissReasons says "ok").
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "lrcal/kinematics/rigid_transform.h"
#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_kind.h"

namespace lrcal {

/// The nominal geometry of a point measurement.
struct PointSetup {
  /// T_BI: the instrument's frame in the robot's base frame B.
  RigidTransform instrument;
  /// Each target's offset in the tool frame T (m); at least one, at most kMaxTargets.
  std::vector<Eigen::Vector3d> targets{Eigen::Vector3d::Zero()};
  /// The pose kind only (pose_measurement.h): each target's orientation R_TM in the tool frame
  /// (a 6-D probe's or a marker's axes); empty: the tool's axes for every target.
  std::vector<Eigen::Matrix3d> target_orientations{};
  static constexpr int kMaxTargets = 16;
  /// Throws InputError naming the library field (point.instrument, point.targets,
  /// point.targets[k], point.target_orientations[k]) unless the instrument's rotation is a
  /// rotation and its position finite, every offset is finite, there are 1 to kMaxTargets
  /// targets and target_orientations is empty or holds one rotation per target.
  void Validate() const;
  /// Target k's orientation in T: target_orientations[k], or the identity when empty.
  Eigen::Matrix3d TargetOrientation(int k) const;
};

class PointMeasurement : public MeasurementKind {
 public:
  /// Every link value the robot marks as a parameter, the instrument's six terms and each
  /// target's three, except the names in `fixed` (held at nominal). Throws InputError (where =
  /// `source`) for a name that is not a term of this kind. `robot` must outlive this kind.
  PointMeasurement(const RobotModel& robot, PointSetup setup,
                   const std::vector<std::string>& fixed = {}, const std::string& source = "fix")
      : PointMeasurement(robot, std::move(setup), fixed, source, false) {}

  const RobotModel& robot() const { return *robot_; }
  const PointSetup& setup() const { return setup_; }
  const std::vector<std::string>& fixed() const { return fixed_; }
  /// The names of every term of this kind, estimated or not, in layout order.
  std::vector<std::string> AllTermNames() const;

  /// True for the pose kind: three orientation rows follow each configuration's position.
  bool measures_orientation() const { return orientation_; }

  const char* name() const override { return orientation_ ? "pose" : "point"; }
  int rows_per_configuration() const override { return orientation_ ? 6 : 3; }
  bool RowIsAngle(int component) const override { return orientation_ && component >= 3; }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  /// Link values, the instrument's nominal position (x, y, z) with 0 for its rotation terms, and
  /// each target's nominal offset.
  Eigen::VectorXd NominalValues() const override;
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  /// The pose kind's orientation rows centred on the charts of `chart_configs` (InputError
  /// unless as many as `configs`).
  std::unique_ptr<MeasurementEvaluator> BindInChartsOf(
      const TargetedConfigurations& configs,
      const TargetedConfigurations& chart_configs) const override;
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

  /// The geometry at estimate e: link values (5N), the instrument's pose and the targets (with
  /// the pose kind, each target's orientation R_TM = R_TM0·Rz(yaw)·Ry(pitch)·Rx(roll), its
  /// elementary rotations kept for the Jacobian).
  struct State {
    Eigen::VectorXd link_values;
    Eigen::Matrix3d R_BI, Rz, Ry, Rx, R_BI0;
    Eigen::Vector3d p_BI;
    std::vector<Eigen::Vector3d> targets;
    std::vector<Eigen::Matrix3d> R_TM, target_Ry, target_Rx;
  };
  void StateAt(const double* e, State* state) const;
  /// Where the terms are in e: the link value index (into the robot's 5N) of each of the first
  /// robot_values().size() columns; the instrument's six columns (x, y, z, roll, pitch, yaw) and
  /// each target's three (-1 when fixed).
  const std::vector<int>& robot_values() const { return robot_values_; }
  /// The robot's link values at estimate e (5N, SI): nominal, plus e on the estimated ones.
  Eigen::VectorXd LinkValuesAt(const double* e) const;
  int instrument_column(int k) const { return instrument_columns_[k]; }
  int target_column(int target, int axis) const { return target_columns_[3 * target + axis]; }
  /// The pose kind's target orientation terms (roll, pitch, yaw: k = 0, 1, 2); -1 when fixed or
  /// for the point kind.
  int target_rotation_column(int target, int k) const {
    return orientation_ ? rotation_columns_[3 * target + k] : -1;
  }

 protected:
  PointMeasurement(const RobotModel& robot, PointSetup setup, const std::vector<std::string>& fixed,
                   const std::string& source, bool orientation);
  /// Throws InputError unless `configs` have the robot's joints and name only set-up targets.
  void CheckConfigurations(const TargetedConfigurations& configs) const;
  /// Per configuration, the rotation the orientation rows are measured from (the pose kind's
  /// chart centres, pose_measurement.h); none for the point kind.
  virtual std::vector<Eigen::Matrix3d> ChartCentres(const TargetedConfigurations& configs) const {
    (void)configs;
    return {};
  }

 private:
  // Throws InputError (where = `source`) naming the first of `names` that is not a term.
  void CheckTermNames(const std::vector<std::string>& names, const std::string& source) const;

  const RobotModel* robot_;
  PointSetup setup_;
  std::vector<std::string> fixed_, names_;
  std::vector<int> robot_values_;
  int instrument_columns_[6] = {-1, -1, -1, -1, -1, -1};
  std::vector<int> target_columns_, rotation_columns_;
  bool orientation_ = false;
};

/// The instrument's six terms, in layout order: "instrument_x" … "instrument_yaw".
const std::vector<std::string>& InstrumentTermNames();

/// The point kind of a tool point given in the base frame itself: the instrument at B with its
/// six terms held, `tool_point` (m, tool frame) its one target. What the constraint kinds
/// (socket_measurement.h, contact_measurement.h) build their arm part on. Of `fixed`, only the
/// robot's link values and target_x … target_z are taken (the rest are the other kind's).
PointMeasurement ToolPointKind(const RobotModel& robot, const Eigen::Vector3d& tool_point,
                               const std::vector<std::string>& fixed, const std::string& source);

/// The name of target `k`'s term `axis` ("x", "y" or "z") among `num_targets`: "target_x" with
/// one target, "target2_x" (k = 1) with several.
std::string TargetTermName(int k, int num_targets, const std::string& axis);

}  // namespace lrcal
