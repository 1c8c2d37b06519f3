// Joint configurations, each tagged with the target its measurement is of.
#pragma once

#include <vector>

#include "lrcal/kinematics/configuration_set.h"
#include "lrcal/measurement/environment.h"

namespace lrcal {

/// Joint configurations (ConfigurationSet: joint values with their cos/sin), each tagged with
/// the 0-based index of the target its measurement is of: the plane a ranger's beam is aimed
/// at (plane.h, PlaneSet), the reflector a tracker sees (point_measurement.h). The tag is 0
/// with one target. A measurement is the pair (configuration, target): subsets and copies keep
/// the tag (and the environment it was measured in, when given), and a kind refuses a tag it has no
/// target for (MeasurementKind::Bind).
///
/// Kinematics uses it as a ConfigurationSet (joint values only). Invariant: one tag per
/// configuration. It holds as long as the set is changed through this class; adding to it
/// through a ConfigurationSet reference would break it, and nothing in lrcal does.
class TargetedConfigurations : public ConfigurationSet {
 public:
  TargetedConfigurations() = default;
  explicit TargetedConfigurations(int num_joints) : ConfigurationSet(num_joints) {}
  /// Every configuration of `configs`, each of target `target`. Explicit, so that joint
  /// values never silently lose or gain their tags.
  explicit TargetedConfigurations(const ConfigurationSet& configs, int target = 0);

  /// Appends joint values q (num_joints values, rad or m) measured on target `target`.
  void Add(const double* q, int target = 0);
  void Add(const std::vector<double>& q, int target = 0) { Add(q.data(), target); }
  /// Appends configuration i of `other` with its tag and its precomputed cos/sin (no trig).
  void AddFrom(const TargetedConfigurations& other, int i);
  /// Appends configuration i of the untagged `other`, of target `target`.
  void AddFrom(const ConfigurationSet& other, int i, int target);
  void Clear() {
    ConfigurationSet::Clear();
    target_.clear();
    environment_.clear();
  }
  void Reserve(int n);

  /// The target configuration i's measurement is of (0-based).
  int target(int i) const { return target_[static_cast<std::size_t>(i)]; }
  /// Every configuration's target, in order.
  const std::vector<int>& targets() const { return target_; }
  /// 1 + the largest tag (0 for an empty set): the targets the set refers to.
  int num_targets_referenced() const;
  /// A new set with configurations `indices` (in that order), tags and environments kept.
  TargetedConfigurations Subset(const std::vector<int>& indices) const;

  /// The environment configuration i was measured in (environment.h): fields not given are NaN
  /// (a file without environment columns), so that a kind takes its robot's defaults.
  const Environment& environment(int i) const { return environment_[static_cast<std::size_t>(i)]; }
  /// Sets configuration i's environment.
  void SetEnvironment(int i, const Environment& e) {
    environment_[static_cast<std::size_t>(i)] = e;
  }
  /// True when some configuration has a field of its environment given.
  bool HasEnvironments() const;

 private:
  std::vector<int> target_;
  std::vector<Environment> environment_;  // one per configuration
};

}  // namespace lrcal
