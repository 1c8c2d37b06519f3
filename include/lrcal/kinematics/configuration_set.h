// Joint configurations with their sines and cosines precomputed once.
#pragma once

#include <vector>

namespace lrcal {

/// A set of joint configurations with cos/sin precomputed. Row-major: configuration i's joints
/// are q(i)[0..N-1] (rad, or m for prismatic joints).
///
/// Only joint values: which plane or target a measurement at a configuration is of belongs to
/// the measurement layer (measurement/targeted_configurations.h).
class ConfigurationSet {
 public:
  ConfigurationSet() = default;
  explicit ConfigurationSet(int num_joints) : num_joints_(num_joints) {}
  int num_joints() const { return num_joints_; }
  int size() const { return num_joints_ == 0 ? 0 : static_cast<int>(q_.size()) / num_joints_; }
  void Add(const double* q);
  void Add(const std::vector<double>& q) { Add(q.data()); }
  /// Appends configuration i of `other` with its precomputed cos/sin (no trig).
  void AddFrom(const ConfigurationSet& other, int i);
  void Clear() {
    q_.clear();
    cos_q_.clear();
    sin_q_.clear();
  }
  void Reserve(int n);
  const double* q(int i) const { return q_.data() + i * num_joints_; }
  const double* cos_q(int i) const { return cos_q_.data() + i * num_joints_; }
  const double* sin_q(int i) const { return sin_q_.data() + i * num_joints_; }
  /// A new set with configurations `indices` (in that order).
  ConfigurationSet Subset(const std::vector<int>& indices) const;

 private:
  int num_joints_ = 0;
  std::vector<double> q_, cos_q_, sin_q_;
};

}  // namespace lrcal
