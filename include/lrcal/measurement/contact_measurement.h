// A tool point touching a plane — a probe tip on a table, a flange pressed flat on a face — as a
// MeasurementKind (measurement_kind.h). Nothing is read: the constraint is that the point lies on
// its plane,
//
//   y0 = n_k(u)·(p_BT(q) + R_BT(q)·t) + f_k = 0            (m, the signed distance)
//
// and, for a *flush* contact (the tool's z axis along the plane's normal, a flat tool face on the
// plane), two more rows,
//
//   y1 = (z·t1_k)/(z·n0_k) − u1_k,   y2 = (z·t2_k)/(z·n0_k) − u2_k     (≈ rad)
//
// z = R_BT(q)·[0 0 1]ᵀ, n0_k the plane's nominal normal with its tangent basis t1_k, t2_k and its
// chart coordinates u_k (plane.h NormalChart): z has the gnomonic coordinates of n_k(u), so it is
// parallel (or antiparallel) to the estimated normal. Plane k is the configuration's tag. The
// estimated terms: the arm's link values, the tool point's offset t in the tool frame
// ("target_x", "target_y", "target_z"), and each plane's "plane_u1", "plane_u2" and "plane_f"
// (plane.h's names: "plane2_u1", ... with several) as the ParameterSet's plane terms say. A
// measured value is the point's offset from its plane (its scatter: the contact's play,
// NoiseModel::sigma) and, flush, the tool's tilt against the normal (NoiseModel::sigma_angle).
// The Jacobian is analytic (the point kind's motions projected on n, the plane's chart), checked
// against autodiff and central differences in the tests.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/estimated_planes.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/measurement/plane.h"
#include "lrcal/measurement/point_measurement.h"

namespace lrcal {

/// The nominal geometry of a contact measurement.
struct ContactSetup {
  PlaneSet planes;
  /// Which of each plane's terms are estimated (one per plane; empty: none).
  std::vector<PlaneTerms> plane_terms{};
  /// The tool point's nominal offset in the tool frame (m).
  Eigen::Vector3d tool_point = Eigen::Vector3d::Zero();
  /// Every contact is flush: three rows per configuration instead of one.
  bool flush = false;
  /// Throws InputError naming the field (contact.planes, contact.plane_terms, contact.tool_point)
  /// unless plane_terms is empty or one per plane and the tool point is finite.
  void Validate() const;
};

class ContactMeasurement : public MeasurementKind {
 public:
  /// Every link value the robot marks as a parameter, the tool point's three terms and the
  /// planes' estimated terms, except the names in `fixed`. Throws InputError (where = `source`)
  /// for a name that is not a term of this kind or an invalid set-up. `robot` must outlive it.
  ContactMeasurement(const RobotModel& robot, ContactSetup setup,
                     const std::vector<std::string>& fixed = {}, const std::string& source = "fix");

  const RobotModel& robot() const { return arm_.robot(); }
  const ContactSetup& setup() const { return setup_; }
  const std::vector<std::string>& fixed() const { return fixed_; }
  const PointMeasurement& arm() const { return arm_; }
  std::vector<std::string> AllTermNames() const;

  const char* name() const override { return "contact"; }
  int rows_per_configuration() const override { return setup_.flush ? 3 : 1; }
  bool RowIsAngle(int component) const override { return component > 0; }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  Eigen::VectorXd NominalValues() const override;
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;
  /// Each configuration moved (SeatOnPlane) until the nominal model satisfies its constraints.
  TargetedConfigurations LinearisationConfigurations(
      const TargetedConfigurations& configs) const override;

  /// Plane k at estimate e: its normal n(u), ∂n/∂u, its offset, and e's columns of u1, u2, f
  /// (-1 where held).
  using PlaneState = EstimatedPlanes::State;
  PlaneState PlaneAt(const double* e, int k) const { return planes_.At(e, k); }
  /// The chart of plane k's normal (its nominal normal and tangent basis).
  const NormalChart& chart(int k) const { return planes_.chart(k); }

 private:
  PointMeasurement arm_;
  ContactSetup setup_;
  std::vector<std::string> fixed_, names_;
  EstimatedPlanes planes_;
};

/// Moves the joints q (rad or m) until `robot`'s nominal tool point `tool_point` lies at signed
/// distance `distance` (m) from `plane` and, with `flush`, the tool's z axis has the gnomonic
/// coordinates `tilt` (≈ rad) in the plane's normal chart (0: along the normal): Gauss–Newton
/// steps of minimum norm from the start. Returns false (q at the last iterate) unless within 1e-12
/// after 100 steps.
bool SeatOnPlane(const RobotModel& robot, const Eigen::Vector3d& tool_point, const Plane& plane,
                 bool flush, double distance, const Eigen::Vector2d& tilt, double* q);

/// Contact data as a campaign on `truth` (the kind on the true arm, tool point and planes)
/// records it: each start is seated on its plane with a play δ ~ N(0, σ²/R) along the normal
/// and, flush, a tilt of N(0, σ_angle²/R) per chart coordinate (σ = noise.sigma, σ_angle =
/// noise.sigma_angle, R = noise.repetitions; the standard normals at indices k·i … k·i + k − 1 of
/// `stream`, k the rows per configuration); the recorded values are 0 (a flush contact's
/// orientation rows weighed (σ/σ_angle)² per seating, as SimulateMeasurements does). Starts that
/// cannot be seated, or only outside the joint ranges, are left out with their reason. Returns
/// the number left out.
int SimulateContactMeasurements(const ContactMeasurement& truth,
                                const TargetedConfigurations& starts, const NoiseModel& noise,
                                const RandomStream& stream, MeasuredValues* data,
                                std::vector<std::string>* misses = nullptr);

}  // namespace lrcal
