#include "lrcal/kinematics/configuration_set.h"

#include <algorithm>
#include <cmath>

namespace lrcal {

void ConfigurationSet::Add(const double* q) {
  for (int j = 0; j < num_joints_; ++j) {
    q_.push_back(q[j]);
    cos_q_.push_back(std::cos(q[j]));
    sin_q_.push_back(std::sin(q[j]));
  }
}

void ConfigurationSet::AddFrom(const ConfigurationSet& other, int i) {
  q_.insert(q_.end(), other.q(i), other.q(i) + num_joints_);
  cos_q_.insert(cos_q_.end(), other.cos_q(i), other.cos_q(i) + num_joints_);
  sin_q_.insert(sin_q_.end(), other.sin_q(i), other.sin_q(i) + num_joints_);
}

void ConfigurationSet::Reserve(int n) {
  const std::size_t values = static_cast<std::size_t>(std::max(n, 0)) * num_joints_;
  q_.reserve(values);
  cos_q_.reserve(values);
  sin_q_.reserve(values);
}

ConfigurationSet ConfigurationSet::Subset(const std::vector<int>& indices) const {
  ConfigurationSet out(num_joints_);
  out.Reserve(static_cast<int>(indices.size()));
  for (int i : indices) out.AddFrom(*this, i);
  return out;
}

}  // namespace lrcal
