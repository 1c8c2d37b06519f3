#include "lrcal/kinematics/robot_model.h"

#include <cmath>

#include "lrcal/core/error.h"

namespace lrcal {

const char* LinkValueName(int value) {
  static const char* kNames[] = {"theta", "alpha", "a", "d", "beta"};
  return kNames[value];
}

RobotModel::RobotModel(std::string name, std::vector<Link> links, const std::string& where,
                       RigidTransform base, RigidTransform tool)
    : name_(std::move(name)), links_(std::move(links)), base_(base), tool_(tool) {
  base_.Validate(where + ": base");
  tool_.Validate(where + ": tool");
  if (links_.empty()) throw InputError(where, "a robot needs at least one link");
  if (links_.size() > 16) throw InputError(where, "at most 16 links are supported");
  nominal_values_.resize(num_values());
  for (int i = 0; i < num_links(); ++i) {
    const Link& link = links_[i];
    if (!(link.q_min < link.q_max))
      throw InputError(where, "link " + std::to_string(i + 1) + ": q_min must be below q_max");
    for (int v = 0; v < kValuesPerLink; ++v) {
      nominal_values_[kValuesPerLink * i + v] = link.nominal[v];
      if (link.is_parameter[v]) parameter_indices_.push_back(kValuesPerLink * i + v);
    }
  }
}

RobotModel RobotModel::WithFrames(const RigidTransform& base, const RigidTransform& tool) const {
  base.Validate(source + ": base");
  tool.Validate(source + ": tool");
  RobotModel out = *this;
  out.base_ = base;
  out.tool_ = tool;
  return out;
}

std::string LinkValueFullName(int index) {
  return std::string(LinkValueName(index % kValuesPerLink)) +
         std::to_string(index / kValuesPerLink + 1);
}

int LinkValueIndex(const std::string& name, int num_links) {
  for (int k = 0; k < kValuesPerLink * num_links; ++k)
    if (LinkValueFullName(k) == name) return k;
  return -1;
}

std::string RobotModel::ValueName(int index) const { return LinkValueFullName(index); }

int RobotModel::FindValue(const std::string& name) const {
  return LinkValueIndex(name, num_links());
}

}  // namespace lrcal
