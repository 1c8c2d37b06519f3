#include "lrcal/measurement/parameter_set.h"

#include <algorithm>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"

namespace lrcal {

PlaneTerms PlaneTerms::Parse(const std::string& text, const std::string& source) {
  PlaneTerms t;
  if (text == "none" || text.empty()) return t;
  if (text == "both") return PlaneTerms{true, true};
  for (const std::string& s : SplitList(text)) {
    if (s == "normal")
      t.normal = true;
    else if (s == "offset")
      t.offset = true;
    else
      throw InputError(
          source, "unknown plane term '" + s + "'; expected none, normal, offset or normal,offset");
  }
  return t;
}

std::string PlaneTerms::ToString() const {
  if (normal && offset) return "normal,offset";
  if (normal) return "normal";
  if (offset) return "offset";
  return "none";
}

RangerTerms RangerTerms::Parse(const std::string& text, const std::string& source) {
  RangerTerms t;
  if (text == "none" || text.empty()) return t;
  for (const std::string& s : SplitList(text)) {
    if (s == "offset")
      t.offset = true;
    else if (s == "scale")
      t.scale = true;
    else
      throw InputError(
          source, "unknown ranger term '" + s + "'; expected none, offset, scale or offset,scale");
  }
  return t;
}

std::string RangerTerms::ToString() const {
  if (offset && scale) return "offset,scale";
  if (offset) return "offset";
  if (scale) return "scale";
  return "none";
}

DisplayUnit DisplayUnitOf(const std::string& name) {
  if (name == "ranger_scale") return {"ppm", 1e6};
  return IsAngularName(name) ? DisplayUnit{"mrad", 1e3} : DisplayUnit{"mm", 1e3};
}

ParameterSet WithoutParameters(const RobotModel& robot, const ParameterSet& in,
                               const std::vector<std::string>& names) {
  // Everything `in` already leaves out stays out.
  std::vector<std::string> fixed = names;
  for (int k : robot.parameter_indices())
    if (std::find(in.robot_values.begin(), in.robot_values.end(), k) == in.robot_values.end())
      fixed.push_back(robot.ValueName(k));
  if (in.plane.normal && in.u_index[0] < 0) fixed.push_back("plane_u1");
  if (in.plane.normal && in.u_index[1] < 0) fixed.push_back("plane_u2");
  if (in.plane.offset && in.f_index < 0) fixed.push_back("plane_f");
  if (in.ranger.offset && in.ranger_offset_index < 0) fixed.push_back("ranger_offset");
  if (in.ranger.scale && in.ranger_scale_index < 0) fixed.push_back("ranger_scale");
  return MakeParameterSet(robot, in.plane, fixed, "--fix", in.ranger);
}

bool IsAngularName(const std::string& name) {
  for (const char* prefix : {"theta", "alpha", "beta", "plane_u"})
    if (name.rfind(prefix, 0) == 0) return true;
  return false;
}

bool ParameterSet::IsAngular(int k) const { return IsAngularName(names[k]); }

int ParameterSet::Find(const std::string& name) const {
  auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

namespace {

// What `fixed` names: robot link values (indices) and plane terms.
struct FixedNames {
  std::vector<int> values;
  bool u[2] = {false, false};
  bool offset = false;
  bool ranger_offset = false, ranger_scale = false;
};

FixedNames ParseFixed(const RobotModel& robot, const std::vector<std::string>& fixed,
                      const std::string& source) {
  FixedNames out;
  for (const std::string& name : fixed) {
    if (name.empty()) continue;
    if (name == "plane_u1" || name == "plane_u2") {
      out.u[name == "plane_u2"] = true;
      continue;
    }
    if (name == "plane_f") {
      out.offset = true;
      continue;
    }
    if (name == "ranger_offset" || name == "ranger_scale") {
      (name == "ranger_offset" ? out.ranger_offset : out.ranger_scale) = true;
      continue;
    }
    const int k = robot.FindValue(name);
    if (k < 0)
      throw InputError(source, "unknown parameter '" + name +
                                   "'; expected a name like theta1, alpha2, a3, d4, beta6");
    const auto& ids = robot.parameter_indices();
    if (std::find(ids.begin(), ids.end(), k) == ids.end())
      throw InputError(source, "'" + name + "' is fixed on this robot already (not a parameter)");
    out.values.push_back(k);
  }
  return out;
}

}  // namespace

ParameterSet MakeParameterSet(const RobotModel& robot, PlaneTerms plane,
                              const std::vector<std::string>& fixed, const std::string& source,
                              RangerTerms ranger) {
  const FixedNames f = ParseFixed(robot, fixed, source);
  ParameterSet set;
  set.plane = plane;
  for (int k : robot.parameter_indices()) {
    if (std::find(f.values.begin(), f.values.end(), k) != f.values.end()) continue;
    set.robot_values.push_back(k);
    set.names.push_back(robot.ValueName(k));
  }
  for (int c = 0; c < 2; ++c) {
    if (plane.normal && !f.u[c]) {
      set.u_index[c] = set.size();
      set.names.push_back(c == 0 ? "plane_u1" : "plane_u2");
    }
  }
  if (plane.offset && !f.offset) {
    set.f_index = set.size();
    set.names.push_back("plane_f");
  }
  set.ranger = ranger;
  if (ranger.offset && !f.ranger_offset) {
    set.ranger_offset_index = set.size();
    set.names.push_back("ranger_offset");
  }
  if (ranger.scale && !f.ranger_scale) {
    set.ranger_scale_index = set.size();
    set.names.push_back("ranger_scale");
  }
  if (set.size() == 0)
    throw InputError(source,
                     "nothing left to estimate: the robot file marks no link value as a "
                     "parameter, or every parameter is fixed; list parameters in the "
                     "robot file's links or fix fewer");
  return set;
}

}  // namespace lrcal
