// One chain of a robot that is a tree — an arm on a shared torso, a humanoid's leg and arm — as a
// part of the whole robot's calibration.
//
// A tree's chains (io/urdf.h LoadUrdfChains: from one base link to each tool link) share their
// first joints. In lrcal's D-H + β model, the links between two shared joints are the same links
// in every chain (each D-H frame is placed by its own joint's axis and the next one's), and so is
// the base frame; the link from the last shared joint to the chain's own next joint, and every
// link after it, are the chain's own (its θ and d take in both the shared joint's zero and where
// this chain's arm sits on the link the joint turns). A ChainMeasurement is any measurement kind
// built on one chain's robot model, seen from the whole robot:
//  - configurations are the whole robot's joint vectors (a value for every joint of the tree);
//    the chain reads its own joints from them (`joints`);
//  - its terms keep their names where every chain has them — the values of the links all chains
//    share, the base frame, the planes, and what is fixed in the world: a tracker's frame (one
//    instrument sees every tool), sockets — and carry a label where they are not: a link's values
//    carry the label of the first chain that has the link (two chains of three that share an arm
//    share its links' labelled names); what the chain's tool carries (its frame, a target, a tip,
//    a scanner, a ranger) the chain's own ("left_tool.theta4", "left_tool.target_x").
//  - a coupled link (JointCoupling) takes multiplier · q[joint] + offset; its offset's error is
//    the link's θ0 (d0), and its multiplier's error is one more term, "coupling<k>_gain"
//    (dimensionless, labelled as the link), estimated when the kind has the link's θ0 (d0): y
//    depends on θ0_k + (m + δm)·q_j, so ∂y/∂δm = ∂y/∂θ0_k · q_j exactly. Holding θ0_k (a
//    dependence of a last link's offset on a target's) keeps its column for the gain, hidden.
// MixedMeasurement (mixed_measurement.h) then joins the chains' parts into one kind, the terms
// of the same name estimated once: identification, identifiability, design and studies take the
// union.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "lrcal/measurement/measurement_kind.h"

namespace lrcal {

/// A link of a chain whose joint follows another joint of the robot (a URDF mimic joint, a
/// coupled torso joint): its value is multiplier · q[joint] + offset, never a joint of its own.
struct JointCoupling {
  int link = 0;             ///< the coupled link of the chain (0-based)
  int joint = 0;            ///< the robot joint it follows (its index in the robot's vector)
  double multiplier = 1.0;  ///< nominal; its error is the term "coupling<k>_gain" (k = link + 1)
  double offset = 0.0;      ///< rad (m); its error is the link's own θ0 (d0)
  bool prismatic = false;   ///< the coupled link slides (its d), else it turns (its θ)
};

/// Where one chain sits in a tree robot.
struct ChainOfTree {
  std::string label{};  ///< the chain's name, on its tool frame's terms (its tool link)
  /// Per link of the chain, its joint's index in the robot's vector (a coupled link: the joint
  /// it follows).
  std::vector<int> joints;
  /// Per link, the label its values carry ("" where every chain has the link: "theta1").
  std::vector<std::string> link_labels{};
  int robot_joints = 0;  ///< joints of the whole robot (the configurations' length)
  std::vector<JointCoupling> couplings{};  ///< the chain's coupled links, if any
};

class ChainMeasurement : public MeasurementKind {
 public:
  /// `kind` built on the chain's own robot model (its links in the order of `chain.joints`),
  /// estimating the gain of every coupling whose link's θ0 (d0) `kind` estimates. Throws
  /// InputError (where = "tool-link") for an empty label, a joint index outside the robot, a
  /// joint repeated other than by a coupling, a coupling of no link or not naming its link's
  /// joint, or link labels not one per link.
  ChainMeasurement(std::shared_ptr<const MeasurementKind> kind, ChainOfTree chain)
      : ChainMeasurement(std::move(kind), std::move(chain), {}, {}) {}

  const ChainOfTree& chain() const { return chain_; }
  const MeasurementKind& kind() const { return *kind_; }

  /// The chain's configurations (its joints only) of the robot's `configs`, targets kept; a
  /// coupled link at its multiplier plus `gains` (one per coupling; empty: none).
  TargetedConfigurations ChainConfigurations(const TargetedConfigurations& configs,
                                             const std::vector<double>& gains = {}) const;
  /// The robot's configurations of the chain's `configs`: each of the chain's joints set, every
  /// other joint at `rest` (the robot's joint vector, robot_joints values; empty: 0) — how one
  /// chain's data file, which holds its own joints, joins the others'. A coupled link's value is
  /// not read: it follows its joint.
  TargetedConfigurations RobotConfigurations(const TargetedConfigurations& configs,
                                             const std::vector<double>& rest = {}) const;

  const char* name() const override { return kind_->name(); }
  int rows_per_configuration() const override { return kind_->rows_per_configuration(); }
  bool RowIsAngle(int component) const override { return kind_->RowIsAngle(component); }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  /// The kind's, then 0 for each gain (the multiplier's nominal is the coupling's).
  Eigen::VectorXd NominalValues() const override;
  /// Throws InputError for configurations that are not the robot's joint vectors.
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  /// The kind's linearisation configurations, the chain's joints moved in the robot's vectors.
  TargetedConfigurations LinearisationConfigurations(
      const TargetedConfigurations& configs) const override;
  /// Names as this chain has them (labelled or not). Throws InputError for a name it lacks.
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

  /// What an evaluator needs of the layout: per term of this chain before the gains, the kind's
  /// column; per gain, its coupling and its link's θ0 (d0) column of the kind.
  struct Layout {
    std::vector<int> inner_column, gain_coupling, gain_column;
  };
  const Layout& layout() const { return layout_; }

 private:
  ChainMeasurement(std::shared_ptr<const MeasurementKind> kind, ChainOfTree chain,
                   const std::vector<int>& held_gains, const std::vector<int>& hidden);
  void CheckChain() const;
  void CheckJoints(const TargetedConfigurations& configs) const;
  std::vector<bool> CoupledLinks() const;  // per link: whether a coupling drives it
  std::vector<double> Gains(const double* e) const;

  std::shared_ptr<const MeasurementKind> kind_;
  ChainOfTree chain_;
  std::vector<std::string> names_;       // the kind's shown terms as named here, then the gains
  std::vector<std::string> gain_names_;  // per coupling: its gain term, or empty
  std::vector<int> hidden_;              // the kind's columns held here but kept for a gain
  Layout layout_;
};

}  // namespace lrcal
