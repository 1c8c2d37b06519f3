// A tool point held in fixed sockets — a ball on the flange seated in one of K cups (MUKCa's
// two sockets 50 mm apart), a probe tip in a cone — as a MeasurementKind (measurement_kind.h).
// Nothing is read: the constraint is that the tool point coincides with its socket,
//
//   y = p_BT(q) + R_BT(q)·t − s_k = 0        (m, three rows per configuration: x, y, z in B)
//
// (R_BT, p_BT) the tool pose in the base frame B, t the tool point's offset in the tool frame
// ("target_x", "target_y", "target_z", as the point kind's single target), s_k the position in B
// of the socket the configuration is in (its tag, TargetedConfigurations::target(i), an index
// into SocketSetup::ids). A measured value is the ball's offset from the socket centre: 0 with a
// perfect fit, its scatter the play of the ball in the socket (NoiseModel::sigma per axis).
//
// The sockets' positions are unknown and estimated: "socket<id>_x", "_y", "_z" (m), <id> the
// socket's id as the data write it (socket 0, 1, ...). A *known distance* D between sockets a
// and b (a length reference, the only thing in socket data that fixes the arm's scale) is built
// into the model exactly rather than weighed: socket b sits at s_b = s_a + D·u_b, u_b a unit
// direction with two chart coordinates "socket<b>_u1", "socket<b>_u2" (≈ rad, as a plane's
// normal, plane.h): u_b = v/|v|, v = u0 + u1·t1 + u2·t2, u0 the nominal direction, t1 the base
// axis least aligned with u0 made orthogonal to it and normalised, t2 = u0 × t1. So b has two
// terms instead of three. Known distances must form a forest (no
// cycle: three sockets with three known distances are over-determined and refused) and each
// socket is placed by at most one of them; they are applied root first.
//
// The nominal socket positions are given (SocketPositionsFromData: the nominal model's mean
// ball centre per socket); a socket placed by a known distance takes its nominal direction from
// them and its nominal position from the distance. Any term can be held at nominal by name.
// The Jacobian is analytic (the point kind's for the arm, −∂s_k/∂e for the sockets), checked
// against autodiff and central differences in the tests.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/point_measurement.h"

namespace lrcal {

/// A known distance between two sockets (their ids), m.
struct SocketDistance {
  int a = 0, b = 0;
  double metres = 0;
  /// Parses "0,1=0.05" (socket ids, metres). Throws InputError (where = `source`) naming the
  /// text unless it is two distinct non-negative integer ids and a finite distance > 0.
  static SocketDistance Parse(const std::string& text, const std::string& source);
};

/// The nominal geometry of a socket measurement.
struct SocketSetup {
  /// The sockets' ids as the data name them, distinct and ≥ 0; a configuration's tag is an index
  /// into this list.
  std::vector<int> ids{0};
  /// Each socket's nominal position in the base frame (m), one per id.
  std::vector<Eigen::Vector3d> positions{Eigen::Vector3d::Zero()};
  /// The tool point's nominal offset in the tool frame (m).
  Eigen::Vector3d tool_point = Eigen::Vector3d::Zero();
  /// Known distances between sockets (a forest, each socket placed by at most one).
  std::vector<SocketDistance> distances{};
  static constexpr int kMaxSockets = 64;
  /// Throws InputError naming the field (socket.ids, socket.positions[k], socket.tool_point,
  /// socket.distances[k]) unless ids are 1 to kMaxSockets distinct non-negative integers with one
  /// finite position each, the tool point is finite, and every distance names two of the ids, is
  /// finite and > 0, and the distances form a forest in which each socket is placed once.
  void Validate() const;
  /// The index of socket `id` in ids, or -1.
  int IndexOf(int id) const;
  /// Sockets numbered 0, 1, … in the order of `positions` (not validated).
  static SocketSetup Numbered(std::vector<Eigen::Vector3d> positions,
                              const Eigen::Vector3d& tool_point,
                              std::vector<SocketDistance> distances);
};

class SocketMeasurement : public MeasurementKind {
 public:
  /// Every link value the robot marks as a parameter, the tool point's three terms and the
  /// sockets' terms, except the names in `fixed` (held at nominal). Throws InputError (where =
  /// `source`) for a name that is not a term of this kind, or for an invalid set-up. `robot`
  /// must outlive this kind.
  SocketMeasurement(const RobotModel& robot, SocketSetup setup,
                    const std::vector<std::string>& fixed = {}, const std::string& source = "fix");

  const RobotModel& robot() const { return arm_.robot(); }
  const SocketSetup& setup() const { return setup_; }
  const std::vector<std::string>& fixed() const { return fixed_; }
  /// The names of every term of this kind, estimated or not, in layout order.
  std::vector<std::string> AllTermNames() const;

  const char* name() const override { return "socket"; }
  int rows_per_configuration() const override { return 3; }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  Eigen::VectorXd NominalValues() const override;
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;
  /// Each configuration seated (SeatToolPoint) on the nominal model at its socket's nominal
  /// position; one that cannot be seated is kept as it is.
  TargetedConfigurations LinearisationConfigurations(
      const TargetedConfigurations& configs) const override;

  /// The sockets' positions in B at estimate e (one per id, m) and, if `derivative` is not null,
  /// each one's derivative with respect to e's socket columns (3 × num_socket_terms() per socket,
  /// column c for e's column first_socket_column() + c).
  void SocketsAt(const double* e, std::vector<Eigen::Vector3d>* positions,
                 std::vector<Eigen::MatrixXd>* derivative = nullptr) const;
  /// The arm's part of the layout: link values and the tool point's terms come first, as the
  /// point kind `arm()` (instrument at the base frame, held) lays them out.
  const PointMeasurement& arm() const { return arm_; }
  int first_socket_column() const { return arm_.num_parameters(); }
  int num_socket_terms() const { return num_parameters() - first_socket_column(); }
  /// The nominal sockets (a socket placed by a known distance at its distance from its parent).
  const std::vector<Eigen::Vector3d>& nominal_positions() const { return nominal_; }

 private:
  // A socket's terms: three position columns, or (placed by a distance) two chart columns and
  // its parent's index; -1 where held.
  struct Placement {
    int parent = -1;  // index into ids, -1 for a free socket
    double distance = 0;
    int column[3] = {-1, -1, -1};  // x, y, z, or u1, u2 (relative to first_socket_column)
    Eigen::Vector3d direction, tangent1, tangent2;  // the nominal unit direction and its chart
  };

  std::vector<std::string> SocketTermNames() const;
  // Each socket's parent and distance, and order_ (parents first).
  void OrderSockets();
  // Socket k's nominal direction, chart and position from its parent's nominal position.
  void PlaceByDistance(int k);
  // A socket placed by a distance at estimate s (the socket columns): its position from its
  // parent's and, with `derivative`, its derivative from the parent's.
  void PlacedSocketAt(const Placement& p, const double* s, const Eigen::Vector3d& parent,
                      const Eigen::MatrixXd* parent_derivative, Eigen::Vector3d* position,
                      Eigen::MatrixXd* derivative) const;

  PointMeasurement arm_;
  SocketSetup setup_;
  std::vector<std::string> fixed_, names_;
  std::vector<Placement> placement_;
  std::vector<int> order_;  // socket indices, parents before children
  std::vector<Eigen::Vector3d> nominal_;
};

/// Each socket's nominal position: the mean over its configurations of the ball centre
/// p_BT(q) + R_BT(q)·tool_point that `robot`'s nominal model predicts. Throws InputError when a
/// socket of `num_sockets` has no configuration.
std::vector<Eigen::Vector3d> SocketPositionsFromData(const RobotModel& robot,
                                                     const Eigen::Vector3d& tool_point,
                                                     const TargetedConfigurations& configs,
                                                     int num_sockets);

/// The socket kind's nominal set-up for socket data (the sockets' `ids`, `configs` tagged by
/// index into them): the nominal model's mean tool point per socket as the sockets' positions
/// (SocketPositionsFromData), the tool point and the known distances. Throws InputError (where =
/// `distances_source`, with the item) for a distance naming a socket the data do not have,
/// closing a cycle or placing a socket twice.
SocketSetup SocketSetupFromData(const RobotModel& robot, const std::vector<int>& ids,
                                const TargetedConfigurations& configs,
                                const Eigen::Vector3d& tool_point,
                                const std::vector<SocketDistance>& distances,
                                const std::string& distances_source);

/// Moves the joints q (rad or m, `robot`'s N) so that the tool point `tool_point` (m, tool frame)
/// of `robot`'s nominal model sits at `target` (m, base frame): Gauss–Newton steps of minimum
/// norm on the point's 3 × N Jacobian, so the arm's remaining freedom keeps the starting posture
/// as far as it can. Returns false (q at the last iterate) when the point is not within 1e-12 m
/// after 100 steps: out of reach, or at a singularity.
bool SeatToolPoint(const RobotModel& robot, const Eigen::Vector3d& tool_point,
                   const Eigen::Vector3d& target, double* q);

/// Socket data as a campaign on `truth` (the kind on the true arm, tool point and sockets)
/// records it: configuration i of `starts` is moved (SeatToolPoint) until the true tool point
/// sits at its socket's true position plus the seating's play, δ_i ~ N(0, σ²/R·I) (σ =
/// noise.sigma, R = noise.repetitions; δ's components are the standard normals at indices 3i …
/// 3i + 2 of `stream`, times σ/√R); the recorded value is 0 (three rows) with weight R. A start
/// that cannot be seated is left out, its reason "out of reach" in `misses`; one seated outside
/// the arm's joint ranges (after whole turns of its revolute joints) likewise, "outside the joint
/// ranges". Only sigma and
/// repetitions apply: NoiseModel's ranger disturbances and averaging are refused. Returns the
/// number left out.
int SimulateSocketMeasurements(const SocketMeasurement& truth, const TargetedConfigurations& starts,
                               const NoiseModel& noise, const RandomStream& stream,
                               MeasuredValues* data, std::vector<std::string>* misses = nullptr);

/// The name of socket `id`'s term `term` ("x", "y", "z", "u1", "u2"): "socket0_x".
std::string SocketTermName(int id, const std::string& term);

}  // namespace lrcal
