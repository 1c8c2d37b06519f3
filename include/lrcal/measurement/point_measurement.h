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
  static constexpr int kMaxTargets = 16;
  /// Throws InputError naming the library field (point.instrument, point.targets,
  /// point.targets[k]) unless the instrument's rotation is a rotation and its position finite,
  /// every offset is finite and there are 1 to kMaxTargets targets.
  void Validate() const;
};

class PointMeasurement : public MeasurementKind {
 public:
  /// Every link value the robot marks as a parameter, the instrument's six terms and each
  /// target's three, except the names in `fixed` (held at nominal). Throws InputError (where =
  /// `source`) for a name that is not a term of this kind. `robot` must outlive this kind.
  PointMeasurement(const RobotModel& robot, PointSetup setup,
                   const std::vector<std::string>& fixed = {}, const std::string& source = "fix");

  const RobotModel& robot() const { return *robot_; }
  const PointSetup& setup() const { return setup_; }
  const std::vector<std::string>& fixed() const { return fixed_; }
  /// The names of every term of this kind, estimated or not, in layout order.
  std::vector<std::string> AllTermNames() const;

  const char* name() const override { return "point"; }
  int rows_per_configuration() const override { return 3; }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  /// Link values, the instrument's nominal position (x, y, z) with 0 for its rotation terms, and
  /// each target's nominal offset.
  Eigen::VectorXd NominalValues() const override;
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

  /// The geometry at estimate e: link values (5N), the instrument's pose and the targets.
  struct State {
    Eigen::VectorXd link_values;
    Eigen::Matrix3d R_BI, Rz, Ry, Rx, R_BI0;
    Eigen::Vector3d p_BI;
    std::vector<Eigen::Vector3d> targets;
  };
  void StateAt(const double* e, State* state) const;
  /// Where the terms are in e (-1 when fixed): link value index → column, the instrument's six
  /// (x, y, z, roll, pitch, yaw) and each target's three.
  const std::vector<int>& robot_values() const { return robot_values_; }
  int instrument_column(int k) const { return instrument_columns_[k]; }
  int target_column(int target, int axis) const { return target_columns_[3 * target + axis]; }

 private:
  // Throws InputError (where = `source`) naming the first of `names` that is not a term.
  void CheckTermNames(const std::vector<std::string>& names, const std::string& source) const;

  const RobotModel* robot_;
  PointSetup setup_;
  std::vector<std::string> fixed_, names_;
  std::vector<int> robot_values_;
  int instrument_columns_[6] = {-1, -1, -1, -1, -1, -1};
  std::vector<int> target_columns_;
};

/// The name of target `k`'s term `axis` ("x", "y" or "z") among `num_targets`: "target_x" with
/// one target, "target2_x" (k = 1) with several.
std::string TargetTermName(int k, int num_targets, const std::string& axis);

}  // namespace lrcal
