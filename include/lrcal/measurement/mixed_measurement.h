// Several measurement kinds in one calibration: a tracker's points and a probe's plane contacts,
// a ranger's readings and a scanner's fans, all of one arm, identified together.
//
// A MixedMeasurement is itself a MeasurementKind (measurement_kind.h), so the identification, its
// solvers (lrcal's LM and Ceres), priors, errors in variables, the fit check and the rank
// analysis take it unchanged. Its parts keep their own formulas, Jacobians and evaluators; the
// mixed kind only lays their rows side by side and maps its estimate onto each part's.
//
// Rows. The parts give different numbers of values per configuration (a distance, a point, a
// pose), so a mixed set is laid out one *measured value* per entry: rows_per_configuration() is
// 1, and a part's configuration of k values is k consecutive entries with the same joint values,
// tagged Tag(part, target, component) for component 0 … k − 1. Combine builds that layout from
// each part's MeasuredValues (their repetitions and angle weights kept as per-value weights), so
// users never write it by hand; Bind refuses any other layout, naming the entry.
//
// Terms. The estimate is the union of the parts' terms. The arm's link values ("theta1", "a2",
// …), the base and tool frame terms ("base_x", "tool_yaw", …) and the plane terms ("plane_f",
// "plane2_u1", …) are shared by name: they are one arm and one set of planes, so the parts must
// be built on the same robot and the same planes (a shared term whose nominal value differs
// between parts is refused). Every other term is the part's own (a tracker's frame, a target, a
// socket, the ranger's offset); where two parts have an own term of the same name (a tracker's
// reflector and a probe's tip are both "target_x"), each is prefixed with its part's label
// ("point.target_x", "contact.target_x").
#pragma once

#include <Eigen/Core>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "lrcal/measurement/measurement_kind.h"

namespace lrcal {

/// One kind in a mixed calibration, with the label its own terms and messages carry (the kind's
/// name by default; labels must differ when a kind appears twice).
struct MixedPart {
  std::shared_ptr<const MeasurementKind> kind;
  std::string label{};
  /// A tree's chain (chain_measurement.h): its own terms are already labelled where they are
  /// its own, so a name it has in common with another such part (a tracker's frame) is one term.
  bool names_are_shared = false;
};

/// `kinds` as parts labelled by their names, numbered where a kind appears more than once
/// ("point1", "point2"): how the command line and Python label the files or dicts they are given.
std::vector<MixedPart> PartsLabelledByKind(
    const std::vector<std::shared_ptr<const MeasurementKind>>& kinds);

class MixedMeasurement : public MeasurementKind {
 public:
  /// Throws InputError (where = "sensor") for no parts, an empty kind, repeated labels, or a
  /// shared term whose nominal value differs between parts.
  explicit MixedMeasurement(std::vector<MixedPart> parts);

  int num_parts() const { return static_cast<int>(parts_.size()); }
  const MixedPart& part(int p) const { return parts_[static_cast<std::size_t>(p)]; }
  /// Part p's terms as columns of the mixed estimate (one per term of the part, in its order).
  const std::vector<int>& columns(int p) const { return columns_[static_cast<std::size_t>(p)]; }
  /// True for a term shared between parts by name (link values, base/tool frame, planes; a tree
  /// chain's labelled link and tool values, "left_tool.theta4", between the chains that have it).
  static bool IsSharedTerm(const std::string& name);

  /// The tag of component `component` of a configuration of part `part` measured on its target
  /// `target` (every index 0-based).
  int Tag(int part, int target, int component) const;
  struct Entry {
    int part = 0, target = 0, component = 0;
  };
  /// The inverse of Tag.
  Entry Decode(int tag) const;

  /// The mixed layout of the parts' measured values (one MeasuredValues per part, in part order;
  /// an empty one for a part without data): each value an entry, its weight the part's row weight
  /// (MeasuredValues::RowWeights: repetitions, or given weights such as a pose's angle rows), its
  /// repetitions the configuration's. Throws InputError (where = the part's label) when a part's
  /// values do not match its kind or the joint counts differ.
  MeasuredValues Combine(const std::vector<MeasuredValues>& values) const;
  /// How many configurations (not values) of each part `values` (the mixed layout) holds.
  std::vector<int> ConfigurationsPerPart(const TargetedConfigurations& configs) const;

  const char* name() const override { return "mixed"; }
  int rows_per_configuration() const override { return 1; }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  Eigen::VectorXd NominalValues() const override { return nominal_; }
  /// Throws InputError naming the entry when the layout is not Combine's.
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  /// Each part's reason for its configuration, on each of its entries.
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  /// Each part's linearisation configurations, on each of its entries.
  TargetedConfigurations LinearisationConfigurations(
      const TargetedConfigurations& configs) const override;
  /// Each part without the names it has (a prefixed name: the part's own term). Throws InputError
  /// for a name no part has.
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

 private:
  MixedMeasurement(std::vector<MixedPart> parts, std::set<std::string> prefixed);
  // Part p's configurations of the mixed layout and, per value of them, its entry.
  struct Grouped {
    std::vector<TargetedConfigurations> configs;
    std::vector<std::vector<int>> entries;
  };
  Grouped Group(const TargetedConfigurations& configs) const;

  std::vector<MixedPart> parts_;
  std::vector<std::vector<int>> columns_;
  std::vector<std::vector<std::string>>
      own_names_;                   // per part: its names as the mixed set has them
  std::set<std::string> prefixed_;  // "label.term" of every own term named with its prefix
  std::vector<std::string> names_;
  Eigen::VectorXd nominal_;
  int max_rows_ = 1;
};

}  // namespace lrcal
