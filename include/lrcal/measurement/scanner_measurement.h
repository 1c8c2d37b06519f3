// A 2-D line scanner (a fan of laser beams) on the tool, each beam reading the distance to the
// plane the configuration is aimed at, as a MeasurementKind (measurement_kind.h). The ranger's
// reading (ranger_measurement.h) with several beams, each with its own direction:
//
//   h_b = −(n·O + f) / (n·D_b)                     (m, one row per beam b = 0 … B − 1)
//   O = p_BT(q) + R_BT(q)·o,   D_b = R_BT(q)·R_TS·d_b,   d_b = (sin φ_b, 0, cos φ_b)
//
// (R_BT, p_BT) the tool pose in the base frame B, o the scanner's origin in the tool frame T (the
// beams' common origin), R_TS the scanner frame S in T, φ_b the beam's angle in S's x–z plane
// from S's z axis (the fan), n·x + f = 0 the plane (unit normal n, base frame). A configuration's
// tag is its plane; every beam of a configuration sees that plane. Estimated terms, in order:
//  - the robot's link values, as the ranger's ("theta1", ...);
//  - the scanner's origin in T: "target_x", "target_y", "target_z" (m; the tool point's names,
//    as the contact and socket kinds call the point they carry);
//  - the scanner's orientation: "scanner_roll", "scanner_pitch", "scanner_yaw" (rad: R_TS =
//    R_TS0·Rz(yaw)·Ry(pitch)·Rx(roll), as the tracker's instrument);
//  - each plane's estimated terms (estimated_planes.h).
// Any of them can be held at nominal by name. A beam misses when it is parallel to its plane, the
// plane is behind it (h ≤ 0), its reading is outside the scanner's range or it meets the plane
// beyond the largest angle of incidence (ScannerSetup::range, the ranger's limits); a
// configuration with a missing beam has no measurement (MissReasons names the beam). The Jacobian
// is analytic (the point kind's motion of O, ω × D for the beam's direction, the roll-pitch-yaw
// derivatives for R_TS, the plane's chart), checked against autodiff and central differences in the
// tests.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/estimated_planes.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/point_measurement.h"

namespace lrcal {

/// The nominal geometry of a scanner measurement.
struct ScannerSetup {
  PlaneSet planes;
  /// Which of each plane's terms are estimated (one per plane; empty: none).
  std::vector<PlaneTerms> plane_terms{};
  /// The beams' common origin in the tool frame (m).
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  /// R_TS: the scanner frame in the tool frame (the fan lies in its x–z plane).
  Eigen::Matrix3d orientation = Eigen::Matrix3d::Identity();
  /// Each beam's angle φ_b from S's z axis towards its x axis (rad); 1 to kMaxBeams of them.
  std::vector<double> beam_angles{0.0};
  static constexpr int kMaxBeams = 256;
  /// Each beam's range and largest angle of incidence (the ranger's: a robot file's `ranger:`).
  RangerSpec range{};
  /// A fan of `count` beams spread evenly over [−half_angle, half_angle] (rad; one beam: 0).
  static std::vector<double> Fan(int count, double half_angle);
  /// The same for a user's request: `count` beams (1 to kMaxBeams) over ±`half_angle_deg`
  /// (degrees, 0 to below 90). Throws InputError naming `count_source` or `angle_source` (the
  /// option or argument the user wrote: "--beams", "fan_deg") with the value given.
  static std::vector<double> FanOf(long long count, double half_angle_deg,
                                   const std::string& count_source,
                                   const std::string& angle_source);
  /// Throws InputError naming the field (scanner.planes, scanner.plane_terms, scanner.origin,
  /// scanner.orientation, scanner.beam_angles[b]; the range's SettingError) unless there is a
  /// plane, plane_terms is empty or one per plane, the origin is finite, the orientation a
  /// rotation, the range valid, and there are 1 to kMaxBeams finite beam angles in (−π/2, π/2).
  void Validate() const;
};

class ScannerMeasurement : public MeasurementKind {
 public:
  /// Every link value the robot marks as a parameter, the scanner's origin (3) and orientation
  /// (3) and the planes' estimated terms, except the names in `fixed`. Throws InputError (where
  /// = `source`) for a name that is not a term of this kind or an invalid set-up. `robot` must
  /// outlive it.
  ScannerMeasurement(const RobotModel& robot, ScannerSetup setup,
                     const std::vector<std::string>& fixed = {}, const std::string& source = "fix");

  const RobotModel& robot() const { return arm_.robot(); }
  const ScannerSetup& setup() const { return setup_; }
  const std::vector<std::string>& fixed() const { return fixed_; }
  /// The kind of the beams' origin (the tool point o), whose terms come first.
  const PointMeasurement& arm() const { return arm_; }
  std::vector<std::string> AllTermNames() const;
  int num_beams() const { return static_cast<int>(setup_.beam_angles.size()); }

  const char* name() const override { return "scanner"; }
  int rows_per_configuration() const override { return num_beams(); }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  Eigen::VectorXd NominalValues() const override;
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  /// "ok", or why the first missing beam misses: "beam B parallel to plane P", "plane P behind
  /// beam B", "beam B out of range (H m)", "beam B grazing plane P" (1-based numbers).
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

  /// R_TS at estimate e and, if `d` is given, its derivatives by roll, pitch, yaw (zero where
  /// held: see angle_column).
  Eigen::Matrix3d OrientationAt(const double* e, Eigen::Matrix3d d[3]) const;
  /// e's column of scanner_roll, _pitch, _yaw (a = 0, 1, 2), or -1 where held.
  int angle_column(int a) const { return angle_columns_[a]; }
  EstimatedPlanes::State PlaneAt(const double* e, int k) const { return planes_.At(e, k); }

 private:
  PointMeasurement arm_;
  ScannerSetup setup_;
  std::vector<std::string> fixed_, names_;
  int angle_columns_[3] = {-1, -1, -1};
  EstimatedPlanes planes_;
};

/// The names of the scanner's orientation terms: scanner_roll, scanner_pitch, scanner_yaw.
const std::vector<std::string>& ScannerAngleNames();

}  // namespace lrcal
