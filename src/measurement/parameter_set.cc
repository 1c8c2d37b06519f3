#include "lrcal/measurement/parameter_set.h"

#include <algorithm>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/measurement/plane.h"

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

FrameTerms FrameTerms::Parse(const std::string& text, const std::string& source) {
  FrameTerms t;
  if (text == "none" || text.empty()) return t;
  for (const std::string& s : SplitList(text)) {
    if (s == "all" || s == "xyz" || s == "rpy") {
      for (int k = 0; k < 6; ++k)
        if (s == "all" || (s == "xyz") == (k < 3)) t.estimated[k] = true;
      continue;
    }
    const auto* it = std::find_if(std::begin(kFrameTermNames), std::end(kFrameTermNames),
                                  [&](const char* name) { return s == name; });
    if (it == std::end(kFrameTermNames))
      throw InputError(source, "unknown frame term '" + s +
                                   "'; expected none, all, xyz, rpy or a list of x, y, z, roll, "
                                   "pitch, yaw");
    t.estimated[it - std::begin(kFrameTermNames)] = true;
  }
  return t;
}

std::string FrameTerms::ToString() const {
  const bool shifts = estimated[0] && estimated[1] && estimated[2];
  const bool turns = estimated[3] && estimated[4] && estimated[5];
  if (shifts && turns) return "all";
  std::string out;
  const auto add = [&](const std::string& item) { out += (out.empty() ? "" : ",") + item; };
  for (int k = 0; k < 6; ++k) {
    if (k == 0 && shifts) add("xyz");
    if (k == 3 && turns) add("rpy");
    if (estimated[k] && !(k < 3 ? shifts : turns)) add(kFrameTermNames[k]);
  }
  return out.empty() ? "none" : out;
}

std::string FrameTermName(int frame, int k) {
  return std::string(kFrameNames[frame]) + "_" + kFrameTermNames[k];
}

namespace {

// "base_roll" → (0, 3); "tool_x" → (1, 0); else false.
bool ParseFrameTermName(const std::string& name, int* frame, int* term) {
  for (int f = 0; f < 2; ++f)
    for (int k = 0; k < 6; ++k)
      if (name == FrameTermName(f, k)) {
        *frame = f;
        *term = k;
        return true;
      }
  return false;
}

}  // namespace

bool IsFrameTermName(const std::string& name) {
  int frame, term;
  return ParseFrameTermName(name, &frame, &term);
}

bool ParameterSet::EstimatesFrames() const {
  for (const auto& columns : frame_columns)
    for (int c : columns)
      if (c >= 0) return true;
  return false;
}

std::string UnlabelledName(const std::string& name) { return name.substr(name.rfind('.') + 1); }

DisplayUnit DisplayUnitOf(const std::string& name) {
  const std::string term = UnlabelledName(name);
  // The ranger's scale and a coupling's gain (chain_measurement.h) are dimensionless.
  if (term == "ranger_scale" || (term.size() > 5 && term.compare(term.size() - 5, 5, "_gain") == 0))
    return {"ppm", 1e6};
  // A joint's compliance (environment_measurement.h: c3, rad/(N·m)) and the thermal coefficients
  // (1/K).
  if (term.size() > 1 && term[0] == 'c' && term[1] >= '1' && term[1] <= '9' &&
      term.find_first_not_of("0123456789", 1) == std::string::npos)
    return {"urad/(N m)", 1e6};
  if (term == "thermal_links" || term == "thermal_ranger") return {"ppm/K", 1e6};
  return IsAngularName(name) ? DisplayUnit{"mrad", 1e3} : DisplayUnit{"mm", 1e3};
}

std::string PlaneTermName(int p, int num_planes, const std::string& term) {
  return num_planes == 1 ? "plane_" + term : "plane" + std::to_string(p + 1) + "_" + term;
}

bool ParameterSet::EstimatesPlanes() const {
  for (const PlaneColumns& c : plane_columns)
    if (c.EstimatesNormal() || c.f >= 0) return true;
  return false;
}

ParameterSet WithoutParameters(const RobotModel& robot, const ParameterSet& in,
                               const std::vector<std::string>& names) {
  // Everything `in` already leaves out stays out.
  std::vector<std::string> fixed = names;
  for (int k : robot.parameter_indices())
    if (std::find(in.robot_values.begin(), in.robot_values.end(), k) == in.robot_values.end())
      fixed.push_back(robot.ValueName(k));
  const int np = in.num_planes();
  for (int p = 0; p < np; ++p) {
    const PlaneTerms& t = in.plane_terms[p];
    const PlaneColumns& c = in.plane_columns[p];
    if (t.normal && c.u[0] < 0) fixed.push_back(PlaneTermName(p, np, "u1"));
    if (t.normal && c.u[1] < 0) fixed.push_back(PlaneTermName(p, np, "u2"));
    if (t.offset && c.f < 0) fixed.push_back(PlaneTermName(p, np, "f"));
  }
  if (in.ranger.offset && in.ranger_offset_index < 0) fixed.push_back("ranger_offset");
  if (in.ranger.scale && in.ranger_scale_index < 0) fixed.push_back("ranger_scale");
  for (int f = 0; f < 2; ++f)
    for (int k = 0; k < 6; ++k)
      if (in.frames[f].estimated[k] && in.frame_columns[f][k] < 0)
        fixed.push_back(FrameTermName(f, k));
  return MakeParameterSet(robot, in.plane_terms, fixed, "fix", in.ranger, in.frames[0],
                          in.frames[1]);
}

namespace {

// "plane_u1" → (0, "u1") with one plane; "plane2_f" → (1, "f"); else false.
bool ParsePlaneTermName(const std::string& name, int* plane, std::string* term) {
  if (name.rfind("plane", 0) != 0) return false;
  std::size_t k = 5;
  int number = 0;
  while (k < name.size() && name[k] >= '0' && name[k] <= '9' && number <= kMaxPlanes)
    number = 10 * number + (name[k++] - '0');
  if (k >= name.size() || name[k] != '_') return false;
  *term = name.substr(k + 1);
  if (*term != "u1" && *term != "u2" && *term != "f") return false;
  *plane = k == 5 ? -1 : number - 1;  // -1: the unnumbered single-plane form
  return k == 5 || number >= 1;
}

}  // namespace

bool IsAngularName(const std::string& full_name) {
  // A part's or a chain's own term carries its label ("left_tool.theta4", "point.target_x"): the
  // unit is the term's.
  const std::string name = UnlabelledName(full_name);
  for (const char* prefix : {"theta", "alpha", "beta"})
    if (name.rfind(prefix, 0) == 0) return true;
  // A frame's rotation terms (a tracker's instrument_roll, ...).
  for (const std::string suffix : {"_roll", "_pitch", "_yaw"})
    if (name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      return true;
  // A socket's direction from its parent (socket_measurement.h): "socket1_u1", "socket1_u2",
  // and their class "socket_u".
  const auto ends_with = [&](const std::string& suffix) {
    return name.size() > suffix.size() &&
           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (name.rfind("socket", 0) == 0 && (ends_with("_u1") || ends_with("_u2") || ends_with("_u")))
    return true;
  int plane;
  std::string term;
  return ParsePlaneTermName(name, &plane, &term) && term != "f";
}

bool ParameterSet::IsAngular(int k) const { return IsAngularName(names[k]); }

int ParameterSet::Find(const std::string& name) const {
  auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

namespace {

// What `fixed` names: robot link values (indices) and plane terms.
struct FixedNames {
  struct PlaneFixed {
    bool u[2] = {false, false};
    bool offset = false;
  };
  std::vector<int> values;
  std::vector<PlaneFixed> planes;
  bool ranger_offset = false, ranger_scale = false;
  bool frames[2][6] = {};
};

FixedNames ParseFixed(const RobotModel& robot, const std::vector<std::string>& fixed,
                      int num_planes, const std::string& source) {
  FixedNames out;
  out.planes.resize(num_planes);
  for (const std::string& name : fixed) {
    if (name.empty()) continue;
    int p;
    std::string term;
    if (ParsePlaneTermName(name, &p, &term)) {
      if ((p < 0) != (num_planes == 1) || p >= num_planes)
        throw InputError(source, "unknown plane term '" + name + "': with " +
                                     std::to_string(num_planes) + " plane(s) the names are " +
                                     PlaneTermName(0, num_planes, "u1") + " ... " +
                                     PlaneTermName(num_planes - 1, num_planes, "f"));
      FixedNames::PlaneFixed& f = out.planes[std::max(p, 0)];
      (term == "f" ? f.offset : f.u[term == "u2"]) = true;
      continue;
    }
    if (name == "ranger_offset" || name == "ranger_scale") {
      (name == "ranger_offset" ? out.ranger_offset : out.ranger_scale) = true;
      continue;
    }
    int frame, frame_term;
    if (ParseFrameTermName(name, &frame, &frame_term)) {
      out.frames[frame][frame_term] = true;
      continue;
    }
    const int k = robot.FindValue(name);
    if (k < 0)
      throw InputError(
          source, "unknown parameter '" + name +
                      "'; expected a name like theta1, alpha2, a3, d4, beta6, a plane or ranger "
                      "term, or base_x ... base_yaw, tool_x ... tool_yaw");
    const auto& ids = robot.parameter_indices();
    if (std::find(ids.begin(), ids.end(), k) == ids.end())
      throw InputError(source, "'" + name + "' is fixed on this robot already (not a parameter)");
    out.values.push_back(k);
  }
  return out;
}

// The ranger's and the frames' terms asked for and not fixed, at the end of `set`.
void AppendRangerAndFrameTerms(const FixedNames& f, RangerTerms ranger, FrameTerms base,
                               FrameTerms tool, ParameterSet* set) {
  set->ranger = ranger;
  if (ranger.offset && !f.ranger_offset) {
    set->ranger_offset_index = set->size();
    set->names.push_back("ranger_offset");
  }
  if (ranger.scale && !f.ranger_scale) {
    set->ranger_scale_index = set->size();
    set->names.push_back("ranger_scale");
  }
  set->frames[0] = base;
  set->frames[1] = tool;
  for (int fr = 0; fr < 2; ++fr)
    for (int k = 0; k < 6; ++k) {
      if (!set->frames[fr].estimated[k] || f.frames[fr][k]) continue;
      set->frame_columns[fr][k] = set->size();
      set->names.push_back(FrameTermName(fr, k));
    }
}

}  // namespace

ParameterSet MakeParameterSet(const RobotModel& robot, PlaneTerms plane,
                              const std::vector<std::string>& fixed, const std::string& source,
                              RangerTerms ranger, FrameTerms base, FrameTerms tool) {
  return MakeParameterSet(robot, std::vector<PlaneTerms>{plane}, fixed, source, ranger, base, tool);
}

ParameterSet MakeParameterSet(const RobotModel& robot, const std::vector<PlaneTerms>& planes,
                              const std::vector<std::string>& fixed, const std::string& source,
                              RangerTerms ranger, FrameTerms base, FrameTerms tool) {
  const int np = static_cast<int>(planes.size());
  if (np < 1 || np > kMaxPlanes)
    throw InputError(source, "expected 1 to " + std::to_string(kMaxPlanes) + " planes, got " +
                                 std::to_string(np));
  const FixedNames f = ParseFixed(robot, fixed, np, source);
  ParameterSet set;
  set.plane_terms = planes;
  set.plane_columns.assign(np, PlaneColumns{});
  for (int k : robot.parameter_indices()) {
    if (std::find(f.values.begin(), f.values.end(), k) != f.values.end()) continue;
    set.robot_values.push_back(k);
    set.names.push_back(robot.ValueName(k));
  }
  for (int p = 0; p < np; ++p) {
    PlaneColumns& columns = set.plane_columns[p];
    for (int c = 0; c < 2; ++c) {
      if (planes[p].normal && !f.planes[p].u[c]) {
        columns.u[c] = set.size();
        set.names.push_back(PlaneTermName(p, np, c == 0 ? "u1" : "u2"));
      }
    }
    if (planes[p].offset && !f.planes[p].offset) {
      columns.f = set.size();
      set.names.push_back(PlaneTermName(p, np, "f"));
    }
  }
  AppendRangerAndFrameTerms(f, ranger, base, tool, &set);
  if (set.size() == 0)
    throw InputError(source,
                     "nothing left to estimate: the robot file marks no link value as a "
                     "parameter, or every parameter is fixed; list parameters in the "
                     "robot file's links or fix fewer");
  return set;
}

}  // namespace lrcal
