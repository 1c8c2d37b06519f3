// Robot model: a serial chain of links with the paper's extended Denavit-Hartenberg convention.
//
// Link i transforms frame i-1 into frame i as
//   A_i = Rot(z, θ_i) · Trans(z, d_i) · Trans(x, a_i) · Rot(x, α_i) · Rot(y, β_i)
// with θ_i = θ0_i + q_i for a revolute joint, d_i = d0_i + q_i for a prismatic one (the paper's
// slide 'Kinematic Model'; β is Hayati's twist for (nearly) parallel consecutive axes). The last
// frame is the chain's last frame N. Around the chain sit two fixed transforms (identity unless
// the robot file or URDF gives them): the base transform (frame 0 in the robot's base frame B)
// and the tool transform (the tool frame T in frame N), so the tool pose is
//   X_BT = base · A_1 ··· A_N · tool.
// The tool frame is the ranger's: its origin is where the beam starts, its +Z axis the beam.
//
// Per link the five "link values" are stored in the fixed order θ0, α, a, d, β (rad, rad, m, m,
// rad): the robot file's order. The vector of all link values of an N-link robot has 5N entries,
// link after link. Each link value is either a geometric *parameter* (may be identified) or
// *fixed* (the paper's link 2 has β instead of d, so d2 is fixed at 0). Parameter names are
// `theta1 alpha1 a1 d1 theta2 alpha2 a2 beta2 ...`: the value's name and the 1-based link number.
//
// A RobotModel is read-only after construction and shared by all threads (Pinocchio's Model/Data
// split): per-evaluation scratch lives elsewhere.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "lrcal/kinematics/rigid_transform.h"

namespace lrcal {

enum class JointType { kRevolute, kPrismatic };

/// Index of a link value inside a link's five (robot file order).
enum LinkValue : int { kTheta = 0, kAlpha = 1, kA = 2, kD = 3, kBeta = 4 };
inline constexpr int kValuesPerLink = 5;
/// "theta", "alpha", "a", "d", "beta".
const char* LinkValueName(int value);
/// True for θ, α, β (rad); false for a, d (m).
inline bool IsAngle(int value) { return value == kTheta || value == kAlpha || value == kBeta; }

/// The name of link value `index` of a chain ("theta1", "beta2": the value's name and the
/// 1-based link number).
std::string LinkValueFullName(int index);
/// The index of a link value name among the 5·num_links values, or -1.
int LinkValueIndex(const std::string& name, int num_links);

struct Link {
  JointType joint = JointType::kRevolute;
  /// Nominal θ0 (rad), α (rad), a (m), d (m), β (rad).
  std::array<double, kValuesPerLink> nominal{};
  /// Which of the five values are geometric parameters (identifiable in principle).
  std::array<bool, kValuesPerLink> is_parameter{};
  /// Joint range used when sampling configurations (rad, or m for a prismatic joint).
  double q_min = -3.141592653589793;
  double q_max = 3.141592653589793;
  /// The joint's name in the robot's description (a URDF's joint name), "" if it has none. Data
  /// files may name the joint's column so instead of q<k> (robot_data.h ReadRobotCsv).
  std::string joint_name{};
};

class RobotModel {
 public:
  RobotModel() = default;
  /// Builds a model; throws InputError (where = `source`) if the description is inconsistent.
  /// `base` and `tool` are the fixed transforms around the chain (identity by default).
  RobotModel(std::string name, std::vector<Link> links, const std::string& source = "robot",
             RigidTransform base = {}, RigidTransform tool = {});

  const std::string& name() const { return name_; }
  int num_links() const { return static_cast<int>(links_.size()); }
  int num_values() const { return kValuesPerLink * num_links(); }
  const std::vector<Link>& links() const { return links_; }
  /// The chain's frame 0 in the robot's base frame B (the robot file's `base:`; estimated only
  /// when a parameter set asks for its terms, parameter_set.h FrameTerms).
  const RigidTransform& base() const { return base_; }
  /// The tool (ranger) frame T in the chain's last frame N (the robot file's `tool:`).
  const RigidTransform& tool() const { return tool_; }
  /// The same robot with other base and tool transforms (each must be a rotation and a
  /// translation: RigidTransform::Validate).
  RobotModel WithFrames(const RigidTransform& base, const RigidTransform& tool) const;

  /// All 5N nominal link values (SI).
  const Eigen::VectorXd& nominal_values() const { return nominal_values_; }

  /// Indices (into the 5N link values) of the geometric parameters, in robot file order.
  const std::vector<int>& parameter_indices() const { return parameter_indices_; }
  /// Name of link value `index` (0..5N-1), e.g. "beta2".
  std::string ValueName(int index) const;
  /// Index of a parameter name, or -1 if there is no link value of that name.
  int FindValue(const std::string& name) const;

  /// Where the model came from (a path or a name), for messages and manifests.
  std::string source;

 private:
  std::string name_;
  std::vector<Link> links_;
  RigidTransform base_, tool_;
  Eigen::VectorXd nominal_values_;
  std::vector<int> parameter_indices_;
};

}  // namespace lrcal
