#include "lrcal/measurement/targeted_configurations.h"

#include <algorithm>

namespace lrcal {

TargetedConfigurations::TargetedConfigurations(const ConfigurationSet& configs, int target)
    : ConfigurationSet(configs),
      target_(static_cast<std::size_t>(configs.size()), target),
      environment_(static_cast<std::size_t>(configs.size())) {}

void TargetedConfigurations::Add(const double* q, int target) {
  ConfigurationSet::Add(q);
  target_.push_back(target);
  environment_.emplace_back();
}

void TargetedConfigurations::AddFrom(const TargetedConfigurations& other, int i) {
  ConfigurationSet::AddFrom(other, i);
  target_.push_back(other.target(i));
  environment_.push_back(other.environment(i));
}

void TargetedConfigurations::AddFrom(const ConfigurationSet& other, int i, int target) {
  ConfigurationSet::AddFrom(other, i);
  target_.push_back(target);
  environment_.emplace_back();
}

void TargetedConfigurations::Reserve(int n) {
  ConfigurationSet::Reserve(n);
  target_.reserve(static_cast<std::size_t>(std::max(n, 0)));
  environment_.reserve(static_cast<std::size_t>(std::max(n, 0)));
}

bool TargetedConfigurations::HasEnvironments() const {
  for (const Environment& e : environment_)
    if (e.gravity.allFinite() || e.temperature_c == e.temperature_c) return true;
  return false;
}

int TargetedConfigurations::num_targets_referenced() const {
  int n = 0;
  for (int t : target_) n = std::max(n, t + 1);
  return n;
}

TargetedConfigurations TargetedConfigurations::Subset(const std::vector<int>& indices) const {
  TargetedConfigurations out(num_joints());
  out.Reserve(static_cast<int>(indices.size()));
  for (int i : indices) out.AddFrom(*this, i);
  return out;
}

}  // namespace lrcal
