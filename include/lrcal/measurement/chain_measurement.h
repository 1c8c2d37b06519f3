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
// MixedMeasurement (mixed_measurement.h) then joins the chains' parts into one kind, the terms
// of the same name estimated once: identification, identifiability, design and studies take the
// union.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "lrcal/measurement/measurement_kind.h"

namespace lrcal {

/// Where one chain sits in a tree robot.
struct ChainOfTree {
  std::string label{};      ///< the chain's name, on its tool frame's terms (its tool link)
  std::vector<int> joints;  ///< per link of the chain, its joint's index in the robot's vector
  /// Per link, the label its values carry ("" where every chain has the link: "theta1").
  std::vector<std::string> link_labels{};
  int robot_joints = 0;  ///< joints of the whole robot (the configurations' length)
};

class ChainMeasurement : public MeasurementKind {
 public:
  /// `kind` built on the chain's own robot model (its links in the order of `chain.joints`).
  /// Throws InputError (where = "tool-link") for an empty label, a joint index outside the robot,
  /// a repeated joint, or link labels not one per link.
  ChainMeasurement(std::shared_ptr<const MeasurementKind> kind, ChainOfTree chain);

  const ChainOfTree& chain() const { return chain_; }
  const MeasurementKind& kind() const { return *kind_; }

  /// The chain's configurations (its joints only) of the robot's `configs`, targets kept.
  TargetedConfigurations ChainConfigurations(const TargetedConfigurations& configs) const;
  /// The robot's configurations of the chain's `configs`: each of the chain's joints set, every
  /// other joint at `rest` (the robot's joint vector, robot_joints values) — how one chain's
  /// data file, which holds its own joints, joins the others'.
  TargetedConfigurations RobotConfigurations(const TargetedConfigurations& configs,
                                             const std::vector<double>& rest) const;

  const char* name() const override { return kind_->name(); }
  int rows_per_configuration() const override { return kind_->rows_per_configuration(); }
  bool RowIsAngle(int component) const override { return kind_->RowIsAngle(component); }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  Eigen::VectorXd NominalValues() const override { return kind_->NominalValues(); }
  /// Throws InputError for configurations that are not the robot's joint vectors.
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  /// The kind's linearisation configurations, the chain's joints moved in the robot's vectors.
  TargetedConfigurations LinearisationConfigurations(
      const TargetedConfigurations& configs) const override;
  /// Names as this chain has them (labelled or not). Throws InputError for a name it lacks.
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

 private:
  void CheckJoints(const TargetedConfigurations& configs) const;

  std::shared_ptr<const MeasurementKind> kind_;
  ChainOfTree chain_;
  std::vector<std::string> names_;
};

}  // namespace lrcal
