// Joint configurations with their sines and cosines precomputed once.
#pragma once

#include <vector>

namespace lrcal {

/// A set of joint configurations with cos/sin precomputed. Row-major: configuration i's joints
/// are q(i)[0..N-1] (rad, or m for prismatic joints).
///
/// With several target planes (measurement/plane.h, PlaneSet) a measurement is a pair
/// (configuration, plane): each configuration carries plane(i), the 0-based index of the plane
/// its beam is aimed at (0 with one plane). Subsets and copies keep it.
class ConfigurationSet {
 public:
  ConfigurationSet() = default;
  explicit ConfigurationSet(int num_joints) : num_joints_(num_joints) {}
  int num_joints() const { return num_joints_; }
  int size() const { return num_joints_ == 0 ? 0 : static_cast<int>(q_.size()) / num_joints_; }
  void Add(const double* q, int plane = 0);
  void Add(const std::vector<double>& q, int plane = 0) { Add(q.data(), plane); }
  /// Appends configuration i of `other` with its precomputed cos/sin (no trig).
  void AddFrom(const ConfigurationSet& other, int i);
  void Clear() {
    q_.clear();
    cos_q_.clear();
    sin_q_.clear();
    plane_.clear();
  }
  void Reserve(int n);
  const double* q(int i) const { return q_.data() + i * num_joints_; }
  const double* cos_q(int i) const { return cos_q_.data() + i * num_joints_; }
  const double* sin_q(int i) const { return sin_q_.data() + i * num_joints_; }
  /// Index of the plane configuration i's beam is aimed at (0-based).
  int plane(int i) const { return plane_[i]; }
  /// 1 + the largest plane index (0 for an empty set): the planes the set refers to.
  int num_planes_referenced() const;
  /// A new set with configurations `indices` (in that order).
  ConfigurationSet Subset(const std::vector<int>& indices) const;

 private:
  int num_joints_ = 0;
  std::vector<double> q_, cos_q_, sin_q_;
  std::vector<int> plane_;
};

}  // namespace lrcal
