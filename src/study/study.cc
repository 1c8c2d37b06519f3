#include "lrcal/study/study.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/hash.h"
#include "lrcal/io/robot_file.h"
#include "io/yaml_util.h"

namespace lrcal {

std::string ResolveStudyPath(const std::string& name_or_path) {
  namespace fs = std::filesystem;
  if (fs::exists(name_or_path) || name_or_path.find('/') != std::string::npos) return name_or_path;
  for (const fs::path& base : {fs::path("."), fs::path(LRCAL_SOURCE_DIR)}) {
    fs::path p = base / "studies" / (name_or_path + ".yaml");
    if (fs::exists(p)) return p.string();
  }
  return name_or_path;  // LoadStudy reports "cannot open file"
}

namespace {

using LineMap = std::map<std::string, int>;

std::string Join(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

// YAML → JSON, recording the line of every key path.
Json ToJsonNode(const YAML::Node& node, const std::string& path, LineMap* lines) {
  if (lines && node.Mark().line >= 0) (*lines)[path] = node.Mark().line + 1;
  if (node.IsMap()) {
    Json j = Json::object();
    for (const auto& kv : node) {
      const std::string key = kv.first.as<std::string>();
      if (lines) (*lines)[Join(path, key)] = kv.first.Mark().line + 1;
      j[key] = ToJsonNode(kv.second, Join(path, key), lines);
      if (lines) (*lines)[Join(path, key)] = kv.first.Mark().line + 1;
    }
    return j;
  }
  if (node.IsSequence()) {
    Json j = Json::array();
    for (std::size_t i = 0; i < node.size(); ++i)
      j.push_back(ToJsonNode(node[i], path + "[" + std::to_string(i) + "]", lines));
    return j;
  }
  if (node.IsNull()) return Json();
  const std::string s = node.Scalar();
  if (node.Tag() == "!" ) return s;  // quoted: a string
  if (s == "true" || s == "yes") return true;
  if (s == "false" || s == "no") return false;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (!s.empty() && *end == '\0' && std::isfinite(v)) {
    if (s.find_first_of(".eE") == std::string::npos && std::fabs(v) < 9e15)
      return static_cast<long long>(v);
    return v;
  }
  return s;
}

const Json& Defaults() {
  static const Json d = Json::parse(R"({
    "robot": "paper",
    "plane": "robot",
    "truth": {"mode": "robot_file", "scale": 1.0, "angle_sigma_mrad": 1.0, "length_sigma_mm": 1.0},
    "noise": {"sigma_mm": 0.2, "repetitions": 10},
    "pool": {"size": 101, "redraw": false, "min_singular_value": 0.05},
    "selection": {"count": 50, "method": "backward", "criterion": "E", "samples": 1000,
                  "scaling": "si", "restarts": 4, "redraw": false},
    "validation": {"size": 20},
    "identification": {"estimate_plane": "none", "fix": [], "solver": "lm",
                       "max_iterations": 100, "on_rank_deficient": "fail"},
    "paper_case": 0
  })");
  return d;
}

// Where a key path was written: "file:line key 'path'".
struct KeyLocator {
  std::string file;
  const LineMap* lines;
  std::string context;  // e.g. "sweep value" description
  std::string operator()(const std::string& path) const {
    int line = 0;
    // The deepest recorded prefix of the path.
    for (std::string p = path; !p.empty(); p = p.substr(0, p.find_last_of(".[") == std::string::npos
                                                                ? 0
                                                                : p.find_last_of(".["))) {
      auto it = lines->find(p);
      if (it != lines->end()) {
        line = it->second;
        break;
      }
      if (p.find_last_of(".[") == std::string::npos) break;
    }
    std::string w = Location(file, line) + " key '" + path + "'";
    if (!context.empty()) w += " (" + context + ")";
    return w;
  }
};

void CheckUnknownKeys(const Json& given, const Json& defaults, const std::string& path,
                      const KeyLocator& where) {
  if (!given.is_object() || !defaults.is_object()) return;
  for (auto it = given.begin(); it != given.end(); ++it) {
    const std::string p = Join(path, it.key());
    if (path.empty() && (it.key() == "plane" || it.key() == "robot_file_fnv1a")) continue;  // plane: checked by the typed parser; the hash is ours
    if (!defaults.contains(it.key())) {
      std::string keys;
      for (auto d = defaults.begin(); d != defaults.end(); ++d) keys += (keys.empty() ? "" : ", ") + d.key();
      throw InputError(where(p), "unknown key; expected one of: " + keys);
    }
    CheckUnknownKeys(it.value(), defaults[it.key()], p, where);
  }
}

double Num(const Json& s, const std::string& path, const KeyLocator& where) {
  const Json* j = &s;
  std::string rest = path;
  while (!rest.empty()) {
    const auto dot = rest.find('.');
    const std::string key = rest.substr(0, dot);
    j = &(*j)[key];
    rest = dot == std::string::npos ? "" : rest.substr(dot + 1);
  }
  if (!j->is_number())
    throw InputError(where(path), "expected a number, got " + (j->is_null() ? "nothing" : j->dump()));
  return j->get<double>();
}

int Int(const Json& s, const std::string& path, const KeyLocator& where, int min) {
  const double v = Num(s, path, where);
  if (v != std::floor(v) || v < min || v > 1e9)
    throw InputError(where(path), "expected a whole number >= " + std::to_string(min) +
                                      ", got " + Json(v).dump());
  return static_cast<int>(v);
}

double NonNegative(const Json& s, const std::string& path, const KeyLocator& where) {
  const double v = Num(s, path, where);
  if (!(v >= 0)) throw InputError(where(path), "expected a value >= 0, got " + Json(v).dump());
  return v;
}

std::string Str(const Json& j, const std::string& path, const KeyLocator& where) {
  if (!j.is_string()) throw InputError(where(path), "expected a string, got " + j.dump());
  return j.get<std::string>();
}

bool Bool(const Json& j, const std::string& path, const KeyLocator& where) {
  if (!j.is_boolean()) throw InputError(where(path), "expected true or false, got " + j.dump());
  return j.get<bool>();
}

CellSettings ParseCell(const Json& s, const KeyLocator& where) {
  CellSettings c;
  c.robot = Str(s["robot"], "robot", where);
  const Json& plane = s["plane"];
  if (plane.is_string()) {
    if (plane != "robot")
      throw InputError(where("plane"), "expected 'robot', {normal: [nx, ny, nz], offset: f} or "
                                       "{tilt_deg: t, azimuth_deg: a, through: [x, y, z]}");
  } else if (plane.is_object()) {
    c.plane_from_robot = false;
    if (plane.contains("normal")) {
      for (auto it = plane.begin(); it != plane.end(); ++it)
        if (it.key() != "normal" && it.key() != "offset")
          throw InputError(where("plane." + it.key()), "unknown key; expected normal, offset");
      const Json& n = plane["normal"];
      if (!n.is_array() || n.size() != 3 || !n[0].is_number() || !n[1].is_number() ||
          !n[2].is_number())
        throw InputError(where("plane.normal"), "expected three numbers [nx, ny, nz]");
      c.plane = Plane::FromCoefficients(n[0], n[1], n[2], Num(s, "plane.offset", where),
                                        where("plane"));
    } else {
      for (auto it = plane.begin(); it != plane.end(); ++it)
        if (it.key() != "tilt_deg" && it.key() != "azimuth_deg" && it.key() != "through")
          throw InputError(where("plane." + it.key()),
                           "unknown key; expected normal/offset or tilt_deg/azimuth_deg/through");
      const double tilt = Num(s, "plane.tilt_deg", where) * M_PI / 180;
      const double az = plane.contains("azimuth_deg") ? Num(s, "plane.azimuth_deg", where) * M_PI / 180 : 0.0;
      if (tilt < 0 || tilt > M_PI)
        throw InputError(where("plane.tilt_deg"), "expected an angle in [0, 180] degrees");
      Eigen::Vector3d through(0, 0, 0);
      if (plane.contains("through")) {
        const Json& t = plane["through"];
        if (!t.is_array() || t.size() != 3)
          throw InputError(where("plane.through"), "expected a point [x, y, z] in m");
        for (int k = 0; k < 3; ++k) {
          if (!t[k].is_number()) throw InputError(where("plane.through"), "expected numbers");
          through[k] = t[k];
        }
      }
      const Eigen::Vector3d n(std::sin(tilt) * std::cos(az), std::sin(tilt) * std::sin(az),
                              std::cos(tilt));
      c.plane = Plane::FromCoefficients(n.x(), n.y(), n.z(), -n.dot(through), where("plane"));
    }
  } else {
    throw InputError(where("plane"), "expected 'robot' or a mapping");
  }

  const std::string mode = Str(s["truth"]["mode"], "truth.mode", where);
  if (mode != "robot_file" && mode != "random")
    throw InputError(where("truth.mode"), "expected robot_file or random, got '" + mode + "'");
  c.truth_random = mode == "random";
  c.truth_scale = NonNegative(s, "truth.scale", where);
  c.truth_angle_sigma = NonNegative(s, "truth.angle_sigma_mrad", where) * 1e-3;
  c.truth_length_sigma = NonNegative(s, "truth.length_sigma_mm", where) * 1e-3;

  c.sigma = NonNegative(s, "noise.sigma_mm", where) * 1e-3;
  c.repetitions = Int(s, "noise.repetitions", where, 1);

  c.pool_size = Int(s, "pool.size", where, 1);
  c.pool_redraw = Bool(s["pool"]["redraw"], "pool.redraw", where);
  c.min_singular_value = NonNegative(s, "pool.min_singular_value", where);

  c.select_count = Int(s, "selection.count", where, 1);
  if (c.select_count > c.pool_size)
    throw InputError(where("selection.count"),
                     "cannot select " + std::to_string(c.select_count) + " configurations from a pool of " +
                         std::to_string(c.pool_size) + " (pool.size)");
  c.selection.method = ParseSelectionMethod(Str(s["selection"]["method"], "selection.method", where),
                                            where("selection.method"));
  c.selection.criterion = ParseDesignCriterion(
      Str(s["selection"]["criterion"], "selection.criterion", where), where("selection.criterion"));
  c.selection.samples = Int(s, "selection.samples", where, 1);
  c.selection.restarts = Int(s, "selection.restarts", where, 1);
  c.selection_redraw = Bool(s["selection"]["redraw"], "selection.redraw", where);
  c.scaling = ParseDesignScaling(Str(s["selection"]["scaling"], "selection.scaling", where),
                                 where("selection.scaling"));

  c.validation_size = Int(s, "validation.size", where, 1);

  const Json& id = s["identification"];
  c.plane_terms = PlaneTerms::Parse(Str(id["estimate_plane"], "identification.estimate_plane", where),
                                    where("identification.estimate_plane"));
  if (!id["fix"].is_array())
    throw InputError(where("identification.fix"), "expected a list of parameter names");
  for (const auto& f : id["fix"]) c.fixed.push_back(Str(f, "identification.fix", where));
  const std::string solver = Str(id["solver"], "identification.solver", where);
  if (solver == "ceres") c.identification.solver = IdentificationOptions::Solver::kCeres;
  else if (solver != "lm")
    throw InputError(where("identification.solver"), "expected lm or ceres, got '" + solver + "'");
  c.identification.max_iterations = Int(s, "identification.max_iterations", where, 1);
  const std::string rank = Str(id["on_rank_deficient"], "identification.on_rank_deficient", where);
  if (rank != "fail" && rank != "fix")
    throw InputError(where("identification.on_rank_deficient"), "expected fail or fix, got '" + rank + "'");
  c.fix_dependent = rank == "fix";
  c.paper_case = Int(s, "paper_case", where, 0);
  if (c.paper_case > 2) throw InputError(where("paper_case"), "expected 0 (none), 1 or 2");
  return c;
}

// Applies an axis value at `key` ("." = the whole settings): maps are merged, others replace.
void Apply(Json* settings, const std::string& key, const Json& value) {
  if (key == ".") {
    settings->merge_patch(value);
    return;
  }
  Json* target = settings;
  std::string rest = key;
  while (true) {
    const auto dot = rest.find('.');
    const std::string k = rest.substr(0, dot);
    target = &(*target)[k];
    if (dot == std::string::npos) break;
    rest = rest.substr(dot + 1);
  }
  if (value.is_object() && target->is_object()) target->merge_patch(value);
  else *target = value;
}

bool KeyExists(const Json& defaults, const std::string& key) {
  if (key == "." || key == "plane" || key.rfind("plane.", 0) == 0) return true;
  const Json* j = &defaults;
  std::string rest = key;
  while (!rest.empty()) {
    const auto dot = rest.find('.');
    const std::string k = rest.substr(0, dot);
    if (!j->is_object() || !j->contains(k)) return false;
    j = &(*j)[k];
    rest = dot == std::string::npos ? "" : rest.substr(dot + 1);
  }
  return true;
}

std::string ValueLabel(const Json& v) {
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

}  // namespace

Json Study::ToJson() const {
  Json j;
  j["name"] = name;
  j["description"] = description;
  j["seed"] = seed;
  j["trials"] = trials;
  j["base"] = base;
  j["sweep"] = sweep;
  Json cs = Json::array();
  for (const auto& c : cells) cs.push_back({{"id", c.id}, {"label", c.label}});
  j["cells"] = cs;
  return j;
}

Study LoadStudy(const std::string& path) {
  YAML::Node root = yaml::LoadFile(path);
  yaml::RequireMap(root, path, "");
  LineMap lines;
  Json given = ToJsonNode(root, "", &lines);
  KeyLocator where{path, &lines, ""};

  Study study;
  study.path = path;
  for (const char* required : {"name", "seed", "trials"})
    if (!given.contains(required))
      throw InputError(Location(path, 1) + " key '" + required + "'", "missing (required)");
  study.name = Str(given["name"], "name", where);
  if (study.name.empty() || study.name.find_first_of("/\\ ") != std::string::npos)
    throw InputError(where("name"), "expected a non-empty name without spaces or slashes");
  if (given.contains("description"))
    study.description = Str(given["description"], "description", where);
  const double seed = Num(given, "seed", where);
  if (seed < 0 || seed != std::floor(seed) || seed > 9e15)
    throw InputError(where("seed"), "expected a whole number >= 0");
  study.seed = static_cast<std::uint64_t>(seed);
  study.trials = Int(given, "trials", where, 1);

  Json settings = given;
  for (const char* k : {"name", "description", "seed", "trials", "sweep"}) settings.erase(k);
  CheckUnknownKeys(settings, Defaults(), "", where);
  Json base = Defaults();
  base.merge_patch(settings);
  // The robot file's content is part of every cell's settings: a changed robot is a new cell.
  const std::string robot_path = ResolveRobotPath(base["robot"].get<std::string>());
  {
    std::ifstream in(robot_path);
    if (!in) throw InputError(where("robot"), "cannot open robot file '" + robot_path + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    base["robot_file_fnv1a"] = HashHex(ss.str());
  }
  ParseCell(base, where);  // the base itself must be valid
  study.base = base;

  // Sweep axes.
  struct Axis {
    std::string key;
    std::vector<Json> values;
    std::vector<std::string> labels;
    std::vector<std::string> value_paths;  // for line lookup
  };
  std::vector<Axis> axes;
  std::string combine = "product";
  if (given.contains("sweep")) {
    const Json& sw = given["sweep"];
    study.sweep = sw;
    if (!sw.is_object()) throw InputError(where("sweep"), "expected a mapping with 'axes'");
    for (auto it = sw.begin(); it != sw.end(); ++it)
      if (it.key() != "combine" && it.key() != "axes")
        throw InputError(where("sweep." + it.key()), "unknown key; expected combine, axes");
    if (sw.contains("combine")) {
      combine = Str(sw["combine"], "sweep.combine", where);
      if (combine != "product" && combine != "zip")
        throw InputError(where("sweep.combine"), "expected product or zip, got '" + combine + "'");
    }
    if (!sw.contains("axes") || !sw["axes"].is_array() || sw["axes"].empty())
      throw InputError(where("sweep.axes"), "expected a non-empty list of axes");
    for (std::size_t a = 0; a < sw["axes"].size(); ++a) {
      const Json& ax = sw["axes"][a];
      const std::string ap = "sweep.axes[" + std::to_string(a) + "]";
      if (!ax.is_object()) throw InputError(where(ap), "expected {key: ..., values: [...]}");
      for (auto it = ax.begin(); it != ax.end(); ++it)
        if (it.key() != "key" && it.key() != "values" && it.key() != "labels")
          throw InputError(where(ap + "." + it.key()), "unknown key; expected key, values, labels");
      Axis axis;
      if (!ax.contains("key")) throw InputError(where(ap), "missing 'key'");
      axis.key = Str(ax["key"], ap + ".key", where);
      if (!KeyExists(Defaults(), axis.key))
        throw InputError(where(ap + ".key"), "'" + axis.key + "' is not a study setting (e.g. "
                                             "noise.sigma_mm, selection.count, plane, '.')");
      if (!ax.contains("values") || !ax["values"].is_array() || ax["values"].empty())
        throw InputError(where(ap + ".values"), "expected a non-empty list of values");
      for (std::size_t v = 0; v < ax["values"].size(); ++v) {
        axis.values.push_back(ax["values"][v]);
        axis.value_paths.push_back(ap + ".values[" + std::to_string(v) + "]");
      }
      if (ax.contains("labels")) {
        if (!ax["labels"].is_array() || ax["labels"].size() != axis.values.size())
          throw InputError(where(ap + ".labels"), "expected one label per value");
        for (const auto& l : ax["labels"]) axis.labels.push_back(ValueLabel(l));
      } else {
        for (const auto& v : axis.values) axis.labels.push_back(axis.key + "=" + ValueLabel(v));
      }
      study.axis_keys.push_back(axis.key);
      axes.push_back(axis);
    }
    if (combine == "zip")
      for (const auto& a : axes)
        if (a.values.size() != axes[0].values.size())
          throw InputError(where("sweep.axes"), "zip needs axes of equal length");
  }

  // Expand the cells in canonical order (first axis slowest).
  std::vector<std::vector<int>> combos;
  if (axes.empty()) {
    combos.push_back({});
  } else if (combine == "zip") {
    for (std::size_t v = 0; v < axes[0].values.size(); ++v)
      combos.push_back(std::vector<int>(axes.size(), static_cast<int>(v)));
  } else {
    std::vector<int> idx(axes.size(), 0);
    while (true) {
      combos.push_back(idx);
      int a = static_cast<int>(axes.size()) - 1;
      while (a >= 0 && ++idx[a] == static_cast<int>(axes[a].values.size())) idx[a--] = 0;
      if (a < 0) break;
    }
  }
  std::map<std::string, std::string> seen;
  for (const auto& combo : combos) {
    Cell cell;
    cell.settings = base;
    std::string context;
    for (std::size_t a = 0; a < axes.size(); ++a) {
      Apply(&cell.settings, axes[a].key, axes[a].values[combo[a]]);
      cell.label += (a ? ", " : "") + axes[a].labels[combo[a]];
      cell.axis_values[axes[a].key] = axes[a].labels[combo[a]];
      context += (a ? "; " : "") + std::string("sweep value at ") +
                 Location(path, lines.count(axes[a].value_paths[combo[a]])
                                    ? lines[axes[a].value_paths[combo[a]]]
                                    : 0);
    }
    if (cell.label.empty()) cell.label = "base";
    CheckUnknownKeys(cell.settings, Defaults(), "", KeyLocator{path, &lines, context});
    cell.typed = ParseCell(cell.settings, KeyLocator{path, &lines, context});
    cell.id = HashHex(cell.settings.dump());
    if (seen.count(cell.id))
      throw InputError(path, "sweep cells '" + seen[cell.id] + "' and '" + cell.label +
                                 "' have identical settings");
    seen[cell.id] = cell.label;
    cell.order = static_cast<int>(study.cells.size());
    study.cells.push_back(std::move(cell));
  }
  return study;
}

}  // namespace lrcal
