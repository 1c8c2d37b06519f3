// A tracker's 6-D probe or a camera's tool marker: the position *and orientation* of a target
// frame M on the tool, in the instrument's frame I, as a MeasurementKind (measurement_kind.h).
// It is the point measurement (point_measurement.h) with three orientation rows after the three
// position rows of each configuration:
//
//   rows 0–2:  R_BIᵀ·(p_BT(q) + R_BT(q)·t_k − p_BI)             (m)
//   rows 3–5:  φ = log(C(q)ᵀ·R_IM(q)),  R_IM = R_BIᵀ·R_BT(q)·R_TM,k   (rad, a rotation vector)
//
// R_TM,k = R_TM0,k·Rz(yaw)·Ry(pitch)·Rx(roll) is target k's orientation in the tool frame
// (PointSetup::target_orientations), its three terms "target_roll", "target_pitch",
// "target_yaw" ("target2_roll", ... with several targets) estimated with the point's terms.
// C(q) is the *chart centre*: the orientation the nominal model predicts at that configuration
// (the reference kind's, see UseChartOf). An orientation is a point on a curved space; writing it
// as the rotation vector from a nearby fixed orientation makes it three ordinary numbers whose
// differences are angles (mrad at the interfaces), with no wrap-around unless the arm is 180°
// away from its nominal model. A measured orientation R_meas becomes log(C(q)ᵀ·R_meas) by
// `OrientationValue`. The Jacobian of the rows is J_r⁻¹(φ)·ω, ω the body-frame rotation per term
// (analytic, checked against Ceres' autodiff through ceres::RotationMatrixToAngleAxis and
// against central differences in the tests).
//
// Everett's count for a full-pose measurement, 4R + 2P + 6 (30 for six revolute joints, with the
// instrument's frame and the tool's estimated), is what lrcal's rank analysis gives for this kind
// on the paper's arm (README, "What each sensor can identify").
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/measurement/point_measurement.h"

namespace lrcal {

class PoseMeasurement : public PointMeasurement {
 public:
  /// The point's terms (point_measurement.h) and each target's three orientation terms, except
  /// the names in `fixed`. Throws InputError (where = `source`) for a name that is not a term.
  /// The chart centres are this kind's own nominal predictions until UseChartOf.
  PoseMeasurement(const RobotModel& robot, PointSetup setup,
                  const std::vector<std::string>& fixed = {}, const std::string& source = "fix");

  /// Centre the orientation rows on `nominal`'s predictions at e = 0 instead of this kind's own:
  /// a simulation's truth kind (built on the true geometry) must write its orientations in the
  /// chart the calibration's nominal kind reads them in. `nominal`'s robot must outlive this kind;
  /// both must have the same joints and targets (InputError otherwise).
  void UseChartOf(const PoseMeasurement& nominal);
  /// The chart centre C(q) of configuration `q` seeing `target` (rotation, I → M).
  Eigen::Matrix3d ChartCentre(const double* q, int target) const;
  /// A measured orientation R_IM (the target's axes in the instrument's frame) as this kind's
  /// three orientation rows at `q`: log(C(q)ᵀ·R_IM) (rad).
  Eigen::Vector3d OrientationValue(const double* q, int target, const Eigen::Matrix3d& R_IM) const;
  /// The inverse: the orientation R_IM = C(q)·exp([φ]×) whose rows are φ (what a file or an
  /// array of quaternions holds).
  Eigen::Matrix3d OrientationOf(const double* q, int target, const Eigen::Vector3d& phi) const;

  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

 protected:
  std::vector<Eigen::Matrix3d> ChartCentres(const TargetedConfigurations& configs) const override;

 private:
  const RobotModel* chart_robot_;
  PointSetup chart_setup_;
};

/// The same kind (point or pose), set-up and estimated terms on another arm: a simulation's truth
/// on the true arm (`robot` must outlive it), a pose written in `like`'s chart (UseChartOf).
std::unique_ptr<PointMeasurement> TrackerKindOn(const RobotModel& robot,
                                                const PointMeasurement& like);

/// Weighs `data`'s angle rows (kind.RowIsAngle) against its lengths: each value's weight becomes
/// its configuration's repetitions times (sigma/sigma_angle)² for an angle, as SimulateMeasurements
/// weighs them (measured values of a pose read from a file carry only their repetitions). No
/// change for a kind without angle rows. Throws InputError unless both σ are finite and > 0.
void WeighAngleRows(const MeasurementKind& kind, double sigma, double sigma_angle,
                    MeasuredValues* data);

/// The rotation vector φ (rad, |φ| ≤ π) of a rotation R: R = exp([φ]×).
Eigen::Vector3d RotationLog(const Eigen::Matrix3d& R);

/// J_r⁻¹(φ): how the rotation vector φ of R moves when R turns by a small body-frame angle ω,
/// log(R·exp([ω]×)) ≈ φ + J_r⁻¹(φ)·ω. The identity at φ = 0; singular at |φ| = 2π only.
Eigen::Matrix3d InverseRightJacobian(const Eigen::Vector3d& phi);

}  // namespace lrcal
