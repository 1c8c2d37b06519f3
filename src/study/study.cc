#include "lrcal/study/study.h"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>

#include "io/yaml_util.h"
#include "lrcal/core/data_dir.h"
#include "lrcal/core/error.h"
#include "lrcal/core/hash.h"
#include "lrcal/core/strings.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/urdf.h"
#include "lrcal/kinematics/validation_metric.h"
#include "lrcal/measurement/scanner_measurement.h"
#include "lrcal/study/sensitivity.h"

namespace lrcal {

std::string ResolveStudyPath(const std::string& name_or_path) {
  namespace fs = std::filesystem;
  // A folder of that name (e.g. a run directory made by --out quick) is never a study file: a
  // short name then still means the shipped study.
  const bool file_here = PathExists(name_or_path) && !IsDirectory(name_or_path);
  if (file_here || name_or_path.find('/') != std::string::npos) return name_or_path;
  const fs::path local = fs::path("studies") / (name_or_path + ".yaml");
  if (PathExists(local)) return local.string();
  if (std::string shipped = FindDataFile(local.string()); !shipped.empty()) return shipped;
  return name_or_path;  // LoadStudy reports "cannot open file"
}

// The defaults of an option struct's settings (settings.h) as a study section: each setting's
// study name with the struct's initial value in the setting's unit.
// `names`: only these settings (empty: every one).
template <class Options>
Json SettingDefaults(const std::vector<SettingField<Options>>& fields,
                     std::initializer_list<const char*> names = {}) {
  Json section = Json::object();
  for (const SettingField<Options>& f : fields) {
    if (names.size() > 0 && std::find_if(names.begin(), names.end(), [&](const char* n) {
                              return f.spec.name == std::string(n);
                            }) == names.end())
      continue;
    section[f.spec.name] =
        f.spec.integer ? Json(static_cast<long long>(f.Default())) : Json(f.Default());
  }
  return section;
}

// The one place the study settings' defaults are written, with those of the library's option
// structs taken from their settings schema (docs/STUDIES.md shows them; a test checks that it
// shows these).
const Json& StudyDefaults() {
  static const Json d = [] {
    Json j = Json::parse(R"({
    "robot": "paper",
    "plane": "robot",
    "truth": {"mode": "robot_file", "ranger_offset_mm": "robot_file",
              "ranger_scale_ppm": "robot_file"},
    "pool": {"size": 101, "redraw": false},
    "selection": {"count": 50, "method": "backward", "criterion": "E", "scaling": "si",
                  "redraw": false},
    "validation": {"size": 20, "coverage": false},
    "identification": {"estimate_plane": "none", "fix": [], "solver": "lm",
                       "on_rank_deficient": "fail",
                       "loss": "none", "loss_scale_sigma": 1.345, "estimate_ranger": "none",
                       "prior_sigma": "none", "errors_in_variables": false},
    "sensor": {"kind": "ranger", "instrument": null, "target": [0, 0, 0], "flush": false,
               "sigma_mrad": 0.2, "cost_per_reading": 1, "budget": null, "beams": 1,
               "fan_deg": 0, "sockets": [], "socket_distances": []},
    "paper_case": 0
  })");
    j["noise"] = SettingDefaults(NoiseModel::Settings());
    j["truth"].merge_patch(SettingDefaults(TruthOptions::Settings()));
    j["pool"].merge_patch(SettingDefaults(SamplingOptions::Settings(), {"min_singular_value"}));
    j["selection"].merge_patch(
        SettingDefaults(SelectionOptions::Settings(), {"samples", "restarts"}));
    j["noise"]["average"] = Averaging{}.Name();
    j["identification"].merge_patch(
        SettingDefaults(IdentificationOptions::Settings(), {"max_iterations"}));
    return j;
  }();
  return d;
}

namespace {

using LineMap = std::map<std::string, int>;

// The robust loss scale, given one way per cell: in mm, or in multiples of the reading's σ (the
// default, 1.345). "identification.loss_scale" is the earlier spelling of the second.
constexpr const char* kLossScaleMm = "identification.loss_scale_mm";
constexpr const char* kLossScaleSigma = "identification.loss_scale_sigma";

std::string Join(const std::string& prefix, const std::string& key) {
  if (key.empty()) return prefix;
  return prefix.empty() ? key : prefix + "." + key;
}

// YAML → JSON, recording the line of every key path. `budget` bounds the values converted, so
// that nested aliases (a "billion laughs" file) are refused instead of expanded for minutes.
constexpr long kMaxStudyValues = 100000;
constexpr int kMaxCells = 100000;

Json ToJsonScalar(const YAML::Node& node, const std::string& path, const std::string& file) {
  const std::string s = node.Scalar();
  if (!IsValidUtf8(s))
    throw InputError(Location(file, node.Mark().line + 1) + " key '" + path + "'",
                     "the value is not valid UTF-8 text");
  if (node.Tag() == "!") return s;  // quoted: a string
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

Json ToJsonNode(const YAML::Node& node, const std::string& path, const std::string& file,
                LineMap* lines, long* budget) {
  if (--*budget < 0)
    throw InputError(file, "the file expands to more than " + std::to_string(kMaxStudyValues) +
                               " values (nested YAML aliases?): refused");
  if (node.Mark().line >= 0) (*lines)[path] = node.Mark().line + 1;
  if (node.IsMap()) {
    Json j = Json::object();
    for (const auto& kv : node) {
      const std::string key = yaml::Key(kv.first, file, path);
      if (!IsValidUtf8(key))
        throw InputError(Location(file, kv.first.Mark().line + 1), "a key is not valid UTF-8 text");
      const std::string sub = Join(path, key);
      if (j.contains(key))
        throw InputError(Location(file, kv.first.Mark().line + 1) + " key '" + sub + "'",
                         "repeated key (first at line " + std::to_string((*lines)[sub]) + ")");
      (*lines)[sub] = kv.first.Mark().line + 1;
      j[key] = ToJsonNode(kv.second, sub, file, lines, budget);
      (*lines)[sub] = kv.first.Mark().line + 1;
    }
    return j;
  }
  if (node.IsSequence()) {
    Json j = Json::array();
    for (std::size_t i = 0; i < node.size(); ++i)
      j.push_back(ToJsonNode(node[i], path + "[" + std::to_string(i) + "]", file, lines, budget));
    return j;
  }
  if (node.IsNull()) return Json();
  return ToJsonScalar(node, path, file);
}

// identification.loss_scale, the earlier spelling of identification.loss_scale_sigma, renamed
// wherever a study may write it (the identification mapping of the base or a sweep value, an axis
// or a sensitivity input key); a mapping that gives the scale twice is refused.
void RenameEarlierKeys(Json* j, const std::string& path, const std::string& file, LineMap* lines,
                       bool identification = false) {
  if (j->is_array()) {
    for (std::size_t i = 0; i < j->size(); ++i)
      RenameEarlierKeys(&(*j)[i], path + "[" + std::to_string(i) + "]", file, lines,
                        identification);
    return;
  }
  if (!j->is_object()) return;
  if (identification) {
    const auto twice = [&](const char* a, const char* b) {
      if (!j->contains(a) || !j->contains(b)) return;
      throw InputError(Location(file, (*lines)[Join(path, b)]) + " key '" + Join(path, b) + "'",
                       std::string("the loss scale is given twice (also as ") + a +
                           "): give loss_scale_mm (mm) or loss_scale_sigma (multiples of "
                           "noise.sigma_mm), not both");
    };
    twice("loss_scale", "loss_scale_sigma");
    twice("loss_scale_sigma", "loss_scale_mm");
    twice("loss_scale", "loss_scale_mm");
    if (j->contains("loss_scale")) {
      (*j)["loss_scale_sigma"] = (*j)["loss_scale"];
      j->erase("loss_scale");
      (*lines)[Join(path, "loss_scale_sigma")] = (*lines)[Join(path, "loss_scale")];
    }
  }
  const auto key = j->find("key");
  const bool axis_of_identification = key != j->end() && *key == "identification";
  if (key != j->end() && *key == "identification.loss_scale") *key = std::string(kLossScaleSigma);
  for (auto it = j->begin(); it != j->end(); ++it)
    RenameEarlierKeys(
        &it.value(), Join(path, it.key()), file, lines,
        it.key() == "identification" || (axis_of_identification && it.key() == "values"));
}

// Where a key path was written: "file:line key 'path'".
struct KeyLocator {
  std::string file;
  const LineMap* lines;
  std::string context;  // e.g. "sweep value" description
  std::string prefix;   // key path of the mapping the given paths are relative to
  std::string operator()(const std::string& relative) const {
    const std::string path = Join(prefix, relative);
    int line = 0;
    // The deepest recorded prefix of the path.
    for (std::string p = path; !p.empty();
         p = p.substr(0, p.find_last_of(".[") == std::string::npos ? 0 : p.find_last_of(".["))) {
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

std::string KeyList(const Json& map) {
  std::string keys;
  for (auto d = map.begin(); d != map.end(); ++d) keys += (keys.empty() ? "" : ", ") + d.key();
  return keys;
}

// Keys that are settings without a default. plane: checked by the typed parser; the robot
// file's hash is lrcal's own. pool.file and validation.file (with lrcal's hash of them) are
// optional. tool_link and base_link (URDF robots), and validation.tool_link (tree cells), are
// optional, so that earlier studies' settings and tables stay as they were.
// identification.loss_scale_mm: the loss scale in mm, in place of loss_scale_sigma.
bool IsOptionalKey(const std::string& section, const std::string& key) {
  if (section.empty())
    return key == "plane" || key == "robot_file_fnv1a" || key == "tool_link" ||
           key == "base_link" || key == "environment";
  if (section == "pool" || section == "validation")
    return key == "file" || key == "file_fnv1a" || (section == "validation" && key == "tool_link");
  // environment: and identification.estimate (issue 28): optional, so that the cells of studies
  // without them keep their names.
  return section == "identification" && (key == "loss_scale_mm" || key == "estimate");
}

// Every key of `given` must be a setting; a section (a mapping in the defaults) must be given as
// a mapping: `noise:` with nothing after it, or `noise: 5`, is an error, not a silent deletion.
void CheckUnknownKeys(const Json& given, const Json& defaults, const std::string& path,
                      const KeyLocator& where) {
  if (!given.is_object() || !defaults.is_object()) return;
  for (auto it = given.begin(); it != given.end(); ++it) {
    const std::string p = Join(path, it.key());
    if (IsOptionalKey(path, it.key())) continue;
    if (!defaults.contains(it.key()))
      throw InputError(where(p), "unknown key; expected one of: " + KeyList(defaults));
    const Json& d = defaults[it.key()];
    if (d.is_object() && !it.value().is_object())
      throw InputError(where(p), "expected a mapping with keys " + KeyList(d) + ", got " +
                                     (it.value().is_null() ? "nothing" : it.value().dump()));
    CheckUnknownKeys(it.value(), d, p, where);
  }
}

// The value at a dotted key path, or null if a part is missing (never inserts).
const Json& At(const Json& s, const std::string& path) {
  static const Json kNull;
  const Json* j = &s;
  std::string rest = path;
  while (!rest.empty()) {
    const auto dot = rest.find('.');
    const std::string key = rest.substr(0, dot);
    if (!j->is_object()) return kNull;
    const auto it = j->find(key);
    if (it == j->end()) return kNull;
    j = &*it;
    rest = dot == std::string::npos ? "" : rest.substr(dot + 1);
  }
  return *j;
}

double Num(const Json& s, const std::string& path, const KeyLocator& where) {
  const Json& j = At(s, path);
  if (!j.is_number())
    throw InputError(where(path), "expected a number, got " + (j.is_null() ? "nothing" : j.dump()));
  return j.get<double>();
}

// A whole number in [min, max]: the upper limits keep a typo (1e9 configurations) from
// running out of memory or time without a word.
int Int(const Json& s, const std::string& path, const KeyLocator& where, int min,
        int max = 1000000000) {
  const double v = Num(s, path, where);
  if (v != std::floor(v) || v < min || v > max)
    throw InputError(where(path), "expected a whole number from " + std::to_string(min) + " to " +
                                      std::to_string(max) + ", got " + Json(v).dump());
  return static_cast<int>(v);
}

std::string Str(const Json& s, const std::string& path, const KeyLocator& where) {
  const Json& j = At(s, path);
  if (!j.is_string()) throw InputError(where(path), "expected a string, got " + j.dump());
  return j.get<std::string>();
}

bool Bool(const Json& s, const std::string& path, const KeyLocator& where) {
  const Json& j = At(s, path);
  if (!j.is_boolean()) throw InputError(where(path), "expected true or false, got " + j.dump());
  return j.get<bool>();
}

// The settings of one option struct (settings.h) from their study keys (section.name, in the
// settings' units), each checked by its spec; an error names the file, line and key.
template <class Options>
void ReadSetting(const Json& s, const KeyLocator& where, const SettingField<Options>& f,
                 Options* options) {
  const std::string key = f.spec.Spelling(Frontend::kStudyFile);
  const double si = Num(s, key, where) * f.spec.to_si;
  if (!f.spec.Allows(si))
    throw SettingError(f.spec, si).Respelled(Frontend::kStudyFile, where(key));
  f.Set(options, si);
}

template <class Options>
void ReadSettings(const Json& s, const KeyLocator& where,
                  const std::vector<SettingField<Options>>& fields, Options* options) {
  for (const SettingField<Options>& f : fields) ReadSetting(s, where, f, options);
}

// Only `allowed` keys in the mapping at `path`.
void OnlyKeys(const Json& map, const std::string& path, std::initializer_list<const char*> allowed,
              const std::string& expected, const KeyLocator& where) {
  for (auto it = map.begin(); it != map.end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok |= it.key() == a;
    if (!ok) throw InputError(where(Join(path, it.key())), "unknown key; expected " + expected);
  }
}

Eigen::Vector3d Vector3(const Json& s, const std::string& path, const std::string& expected,
                        const KeyLocator& where) {
  const Json& v = At(s, path);
  if (!v.is_array() || v.size() != 3) throw InputError(where(path), "expected " + expected);
  Eigen::Vector3d out;
  for (int k = 0; k < 3; ++k) {
    if (!v[k].is_number()) throw InputError(where(path), "expected " + expected);
    out[k] = v[k];
  }
  return out;
}

// One plane: {normal, offset} or {tilt_deg, azimuth_deg, through}, the mapping `m` at the key
// path where.prefix ("plane", or "plane[k]" in a list, which may also give name, share and
// estimate).
Plane ParsePlaneMapping(const Json& m, const KeyLocator& where, bool in_list) {
  const char* const extra = in_list ? ", name, share, estimate" : "";
  if (m.contains("normal")) {
    if (in_list)
      OnlyKeys(m, "", {"normal", "offset", "name", "share", "estimate"},
               std::string("normal, offset") + extra, where);
    else
      OnlyKeys(m, "", {"normal", "offset"}, "normal, offset", where);
    const Eigen::Vector3d n = Vector3(m, "normal", "three numbers [nx, ny, nz]", where);
    return Plane::FromCoefficients(n.x(), n.y(), n.z(), Num(m, "offset", where), where(""));
  }
  const std::string expected = std::string("normal/offset or tilt_deg/azimuth_deg/through") + extra;
  if (in_list)
    OnlyKeys(m, "", {"tilt_deg", "azimuth_deg", "through", "name", "share", "estimate"}, expected,
             where);
  else
    OnlyKeys(m, "", {"tilt_deg", "azimuth_deg", "through"}, expected, where);
  const double tilt = Num(m, "tilt_deg", where) * M_PI / 180;
  const double az = m.contains("azimuth_deg") ? Num(m, "azimuth_deg", where) * M_PI / 180 : 0.0;
  if (tilt < 0 || tilt > M_PI)
    throw InputError(where("tilt_deg"), "expected an angle in [0, 180] degrees");
  const Eigen::Vector3d through = m.contains("through")
                                      ? Vector3(m, "through", "a point [x, y, z] in m", where)
                                      : Eigen::Vector3d::Zero();
  const Eigen::Vector3d n(std::sin(tilt) * std::cos(az), std::sin(tilt) * std::sin(az),
                          std::cos(tilt));
  return Plane::FromCoefficients(n.x(), n.y(), n.z(), -n.dot(through), where(""));
}

// plane: 'robot', one plane mapping, or a list of them (several planes: each may add name,
// share — its part of the pool and validation draws, default equal — and estimate — its plane
// terms, default identification.estimate_plane).
void ParsePlane(const Json& s, const KeyLocator& where, CellSettings* c) {
  const Json& plane = At(s, "plane");  // null when given as nothing (a merge deletes it)
  if (plane.is_string()) {
    if (plane != "robot")
      throw InputError(where("plane"),
                       "expected 'robot', {normal: [nx, ny, nz], offset: f}, "
                       "{tilt_deg: t, azimuth_deg: a, through: [x, y, z]} or a list of these");
    return;
  }
  c->plane_from_robot = false;
  KeyLocator at = where;
  if (plane.is_object()) {
    at.prefix = Join(where.prefix, "plane");
    c->planes = PlaneSet(ParsePlaneMapping(plane, at, false));
    return;
  }
  if (!plane.is_array() || plane.empty())
    throw InputError(where("plane"), "expected 'robot', a plane mapping or a list of them");
  std::vector<Plane> planes;
  std::vector<std::string> names;
  for (std::size_t k = 0; k < plane.size(); ++k) {
    at.prefix = Join(where.prefix, "plane") + "[" + std::to_string(k) + "]";
    const Json& m = plane[k];
    if (!m.is_object()) throw InputError(at(""), "expected a plane mapping");
    planes.push_back(ParsePlaneMapping(m, at, true));
    names.push_back(m.contains("name") ? Str(m, "name", at) : "");
    const double share = m.contains("share") ? Num(m, "share", at) : 1.0;
    if (!(share > 0 && std::isfinite(share)))
      throw InputError(at("share"), "expected a positive share of the configurations");
    c->plane_shares.push_back(share);
    c->plane_estimate.push_back(m.contains("estimate") ? Str(m, "estimate", at) : "");
    if (m.contains("estimate")) PlaneTerms::Parse(c->plane_estimate.back(), at("estimate"));
  }
  c->planes = PlaneSet(std::move(planes), std::move(names), where("plane"));
}

void ParseTruthAndNoise(const Json& s, const KeyLocator& where, CellSettings* c) {
  const std::string mode = Str(s, "truth.mode", where);
  if (mode != "robot_file" && mode != "random")
    throw InputError(where("truth.mode"), "expected robot_file or random, got '" + mode + "'");
  c->truth.random = mode == "random";
  ReadSettings(s, where, TruthOptions::Settings(), &c->truth);
  for (const char* key : {"truth.ranger_offset_mm", "truth.ranger_scale_ppm"}) {
    const Json& v = At(s, key);
    if (v == "robot_file") continue;
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      throw InputError(where(key), "expected a number, or robot_file (the robot file's value)");
    const bool offset = std::string(key) == "truth.ranger_offset_mm";
    (offset ? c->truth.ranger_offset : c->truth.ranger_scale) =
        v.get<double>() * (offset ? 1e-3 : 1e-6);
  }
  try {
    c->truth.Validate();
  } catch (const SettingError& e) {
    throw e.Respelled(Frontend::kStudyFile, where("truth.ranger_scale_ppm"));
  }
  ReadSettings(s, where, NoiseModel::Settings(), &c->noise);
  try {
    if (!At(s, "noise.average").is_null())
      c->noise.average = Averaging::Parse(Str(s, "noise.average", where));
    c->noise.average.CheckCount(c->noise.repetitions);
  } catch (const SettingError& e) {
    throw e.Respelled(Frontend::kStudyFile, where("noise.average"));
  }
}

void ParsePoolAndSelection(const Json& s, const KeyLocator& where, CellSettings* c) {
  c->pool_size = Int(s, "pool.size", where, 1, 100000);
  c->pool_redraw = Bool(s, "pool.redraw", where);
  SamplingOptions sampling;
  ReadSetting(s, where, *FindSetting(SamplingOptions::Settings(), "min_singular_value"), &sampling);
  c->min_singular_value = sampling.min_jacobian_singular_value;
  if (!At(s, "pool.file").is_null()) {
    c->pool_file = Str(s, "pool.file", where);
    if (c->pool_redraw)
      throw InputError(where("pool.redraw"),
                       "a pool read from a file (pool.file) cannot be redrawn per trial; drop "
                       "pool.redraw or pool.file");
  }
  if (!At(s, "validation.file").is_null()) c->validation_file = Str(s, "validation.file", where);
  if (!At(s, "validation.tool_link").is_null())
    c->validation_tool_link = Str(s, "validation.tool_link", where);
  c->select_count = Int(s, "selection.count", where, 1);
  // A pool from a file is checked against the count when it is read (PrepareCell).
  if (c->pool_file.empty() && c->select_count > c->pool_size)
    throw InputError(where("selection.count"), "cannot select " + std::to_string(c->select_count) +
                                                   " configurations from a pool of " +
                                                   std::to_string(c->pool_size) + " (pool.size)");
  c->selection.method =
      ParseSelectionMethod(Str(s, "selection.method", where), where("selection.method"));
  const std::string criterion = Str(s, "selection.criterion", where);
  c->task_criterion = criterion == "I";
  c->selection.criterion = c->task_criterion
                               ? DesignCriterion::kA
                               : ParseDesignCriterion(criterion, where("selection.criterion"));
  for (const char* name : {"samples", "restarts"})
    ReadSetting(s, where, *FindSetting(SelectionOptions::Settings(), name), &c->selection);
  c->selection_redraw = Bool(s, "selection.redraw", where);
  c->scaling = ParseDesignScaling(Str(s, "selection.scaling", where), where("selection.scaling"));
  c->validation_size = Int(s, "validation.size", where, 1, 100000);
  c->coverage = Bool(s, "validation.coverage", where);
  if (c->coverage && (c->pool_redraw || c->selection_redraw))
    throw InputError(where("validation.coverage"),
                     "coverage is of the radius a cell's one design states: it needs the pool and "
                     "the selection kept for every trial (drop pool.redraw and selection.redraw)");
}

void ParseIdentification(const Json& s, const KeyLocator& where, CellSettings* c) {
  c->plane_terms = PlaneTerms::Parse(Str(s, "identification.estimate_plane", where),
                                     where("identification.estimate_plane"));
  const Json& fix = At(s, "identification.fix");
  if (!fix.is_array())
    throw InputError(where("identification.fix"), "expected a list of parameter names");
  for (std::size_t i = 0; i < fix.size(); ++i) {
    if (!fix[i].is_string())
      throw InputError(where("identification.fix[" + std::to_string(i) + "]"),
                       "expected a parameter name, got " + fix[i].dump());
    c->fixed.push_back(fix[i].get<std::string>());
  }
  c->identification.solver = ParseName(kSolverNames, Str(s, "identification.solver", where),
                                       where("identification.solver"), "solver");
  ReadSetting(s, where, *FindSetting(IdentificationOptions::Settings(), "max_iterations"),
              &c->identification);
  const std::string rank = Str(s, "identification.on_rank_deficient", where);
  if (rank != "fail" && rank != "fix")
    throw InputError(where("identification.on_rank_deficient"),
                     "expected fail or fix, got '" + rank + "'");
  c->fix_dependent = rank == "fix";
  c->ranger_terms = RangerTerms::Parse(Str(s, "identification.estimate_ranger", where),
                                       where("identification.estimate_ranger"));
  c->identification.loss = ParseName(kRobustLossNames, Str(s, "identification.loss", where),
                                     where("identification.loss"), "loss");
  // The scale applies to each configuration's weighted residual √R·(h̄ − h), whose standard
  // deviation is that of one reading: in mm (loss_scale_mm) or in multiples of that σ.
  if (At(s, kLossScaleMm).is_null()) {
    const double scale = Num(s, kLossScaleSigma, where);
    if (!(scale > 0) || !std::isfinite(scale))
      throw InputError(where(kLossScaleSigma),
                       "expected a scale > 0 in units of the reading's standard deviation "
                       "(Huber 1.345, Cauchy 2.385 for 95 % efficiency), or the scale in mm "
                       "as identification.loss_scale_mm");
    if (c->identification.loss != RobustLoss::kNone && !(c->noise.sigma > 0))
      throw InputError(where("identification.loss"),
                       "a robust loss needs noise.sigma_mm > 0 for a scale in units of σ "
                       "(identification.loss_scale_sigma); or give identification.loss_scale_mm");
    c->identification.loss_scale = c->noise.sigma > 0 ? scale * c->noise.sigma : 1e-3;
    return;
  }
  const auto& mm = *FindSetting(IdentificationOptions::Settings(), "loss_scale_mm");
  const double scale = Num(s, kLossScaleMm, where) * mm.spec.to_si;
  if (!mm.spec.Allows(scale))
    throw SettingError(mm.spec, scale).Respelled(Frontend::kStudyFile, where(kLossScaleMm));
  c->identification.loss_scale = scale;
}

// identification.prior_sigma: "none", "truth" (the truth's error magnitudes by class:
// truth.angle_sigma_mrad for θ, α, β and truth.length_sigma_mm for a, d), priors as the command
// line's --prior-sigma gives them ("theta=1mrad,d6=0.2mm"), or "truth" followed by such items,
// which take the place of the truth's for their keys.
PriorSigmas StudyPriors(const std::string& text, const CellSettings& c, const std::string& where) {
  std::string rest = text;
  PriorSigmas priors;
  const std::string truth = "truth";
  if (rest.compare(0, truth.size(), truth) == 0 &&
      (rest.size() == truth.size() || rest[truth.size()] == ',')) {
    if (!(c.truth.angle_sigma > 0) || !(c.truth.length_sigma > 0))
      throw InputError(where,
                       "priors from the truth need truth.angle_sigma_mrad and "
                       "truth.length_sigma_mm > 0");
    for (const char* angle : {"theta", "alpha", "beta"})
      priors.entries.push_back({angle, c.truth.angle_sigma});
    for (const char* length : {"a", "d"}) priors.entries.push_back({length, c.truth.length_sigma});
    rest = rest.size() == truth.size() ? "" : rest.substr(truth.size() + 1);
  }
  if (rest.empty()) return priors;
  return priors.OverriddenBy(PriorSigmas::Parse(rest, where));
}

// What the identification is told of the uncertainty it does not estimate: priors on the terms
// (maximum a-posteriori) and the recorded joint values' noise (errors in variables). Either
// weighs against the reading noise, so needs noise.sigma_mm > 0. A study's encoder noise is per
// reading (noise.encoder_sigma_mrad), so a configuration's averaged value carries the joint
// error of R_eff readings: errors in variables are given σ_q/√R_eff (R_eff = R for a mean).
void ParsePriorsAndErrorsInVariables(const Json& s, const KeyLocator& where, CellSettings* c) {
  const std::string prior = Str(s, "identification.prior_sigma", where);
  if (prior != "none")
    c->identification.priors = StudyPriors(prior, *c, where("identification.prior_sigma"));
  const bool eiv = Bool(s, "identification.errors_in_variables", where);
  if (c->identification.priors.empty() && !eiv) return;
  if (!(c->noise.sigma > 0))
    throw InputError(
        where(eiv ? "identification.errors_in_variables" : "identification.prior_sigma"),
        std::string(eiv ? "errors in variables" : "priors") +
            " are weighed against the reading noise: needs noise.sigma_mm > 0");
  c->identification.sigma = c->noise.sigma;
  if (eiv)
    c->identification.encoder_sigma =
        c->noise.encoder_sigma / std::sqrt(c->noise.EffectiveReadings());
}

// sensor.instrument / sensor.target: a list of 3 (x, y, z in m) or 6 numbers (and roll, pitch,
// yaw in rad) as a transform.
RigidTransform SensorFrame(const Json& s, const std::string& key, const KeyLocator& where,
                           bool allow_three) {
  const Json& v = At(s, key);
  const char* expected = allow_three ? "[x, y, z] (m) or [x, y, z, roll, pitch, yaw] (m, rad)"
                                     : "[x, y, z, roll, pitch, yaw] (m, rad)";
  bool ok = v.is_array() && (v.size() == 6 || (allow_three && v.size() == 3));
  for (std::size_t k = 0; ok && k < v.size(); ++k)
    ok = v[k].is_number() && std::isfinite(v[k].get<double>());
  if (!ok)
    throw InputError(where(key), std::string("expected ") + expected + ", got " +
                                     (v.is_null() ? "nothing" : v.dump()));
  double x[6] = {0, 0, 0, 0, 0, 0};
  for (std::size_t k = 0; k < v.size(); ++k) x[k] = v[k].get<double>();
  return RigidTransform::FromXyzRpy(Eigen::Vector3d(x[0], x[1], x[2]),
                                    Eigen::Vector3d(x[3], x[4], x[5]));
}

// A tracker or contact cell: the ranger's settings it cannot take are refused by key, not
// ignored.
void RefuseRangerSettings(const Json& s, const KeyLocator& where, const CellSettings& c) {
  const std::string kind = c.sensor.kind;
  const auto refuse = [&](const std::string& key, const std::string& why) {
    throw InputError(where(key), "sensor.kind " + kind + ": " + why);
  };
  if (kind != "contact" && kind != "scanner" &&
      Str(s, "identification.estimate_plane", where) != "none")
    refuse("identification.estimate_plane", "it measures no plane; expected none");
  if (c.ranger_terms.offset || c.ranger_terms.scale)
    refuse("identification.estimate_ranger", "it has no ranger; expected none");
  if (c.noise.DisturbsGeometry() || c.noise.outlier_fraction > 0)
    refuse(c.noise.encoder_sigma > 0 ? "noise.encoder_sigma_mrad"
           : c.noise.form_sigma > 0  ? "noise.form_sigma_mm"
                                     : "noise.outlier_fraction",
           "the rig's disturbances are modelled for the ranger only; expected 0");
  if (c.task_criterion)
    refuse("selection.criterion", "the task criterion (I) is the ranger's; expected E, D, A or O*");
  if (c.pool_redraw || c.selection_redraw)
    refuse(c.pool_redraw ? "pool.redraw" : "selection.redraw",
           "its cell keeps one pool and one design; expected false");
  if (c.coverage) refuse("validation.coverage", "coverage is the ranger's so far; expected false");
  if (!c.identification.priors.empty() || c.identification.encoder_sigma > 0)
    refuse(c.identification.priors.empty() ? "identification.errors_in_variables"
                                           : "identification.prior_sigma",
           "priors and errors in variables are the ranger's in studies; expected none/false");
  if (c.identification.loss != RobustLoss::kNone)
    refuse("identification.loss", "a robust loss takes one value per configuration; expected none");
  if (c.paper_case != 0) refuse("paper_case", "the paper's cases are the ranger's; expected 0");
}

// The sensor section without the keys of the scanner and socket cells at their defaults.
Json WithoutLateSensorDefaults(Json sensor) {
  const Json& defaults = StudyDefaults()["sensor"];
  for (const char* key : {"beams", "fan_deg", "sockets", "socket_distances"})
    if (sensor.contains(key) && sensor[key] == defaults[key]) sensor.erase(key);
  return sensor;
}

// The sensor section with every default key (a sweep value may give only some).
Json FullSensorSection(const Json& settings) {
  Json full = StudyDefaults()["sensor"];
  const auto given = settings.find("sensor");
  if (given == settings.end() || !given->is_object()) return full;
  for (auto it = given->begin(); it != given->end(); ++it) full[it.key()] = it.value();
  return full;
}

// sensor came after studies were run: at its defaults (the ranger) it is left out of the resolved
// settings, so that earlier studies' tables and run directories stay as they were; otherwise it
// is written in full, except the keys that came with the scanner and socket cells, which are
// left out at their defaults so that earlier tracker and contact cells keep their names.
void NormaliseSensor(Json* settings) {
  if (!settings->contains("sensor") || !(*settings)["sensor"].is_object()) return;
  const Json full = WithoutLateSensorDefaults(FullSensorSection(*settings));
  if (full == WithoutLateSensorDefaults(StudyDefaults()["sensor"]))
    settings->erase("sensor");
  else
    (*settings)["sensor"] = full;
}

// sensor.budget: the configurations it buys (selection.count), a configuration costing
// cost_per_reading × noise.repetitions per tool it reads.
void ParseBudget(const Json& s, const KeyLocator& where, CellSettings* c) {
  StudySensor& sensor = c->sensor;
  const double budget = Num(s, "sensor.budget", where);
  // A tree cell reads every tool at each configuration: one reading per chain.
  const double per_configuration =
      sensor.cost_per_reading * c->noise.repetitions *
      static_cast<double>(std::max<std::size_t>(1, c->ToolLinks().size()));
  const double count = std::floor(budget / per_configuration);
  if (!(count >= 1) || !std::isfinite(budget))
    throw InputError(where("sensor.budget"),
                     "expected a budget of at least one configuration's cost (cost_per_reading "
                     "× noise.repetitions" +
                         std::string(c->IsTree() ? " × tool links" : "") + " = " +
                         Json(per_configuration).dump() + ")");
  if (count > c->pool_size && c->pool_file.empty())
    throw InputError(where("sensor.budget"),
                     "buys " + Json(count).dump() +
                         " configurations: more than pool.size = " + std::to_string(c->pool_size));
  sensor.budget = budget;
  c->select_count = static_cast<int>(count);
}

// sensor.beams over ±sensor.fan_deg: the scanner's beam angles (rad).
std::vector<double> ParseFan(const Json& s, const KeyLocator& where) {
  const Json& beams = At(s, "sensor.beams");
  if (!beams.is_number_integer())
    throw InputError(where("sensor.beams"), "expected a whole number of beams (1 to " +
                                                std::to_string(ScannerSetup::kMaxBeams) +
                                                "), got " + beams.dump());
  return ScannerSetup::FanOf(beams.get<long long>(), Num(s, "sensor.fan_deg", where),
                             where("sensor.beams"), where("sensor.fan_deg"));
}

// sensor.sockets (positions in B, ids 0, 1, … in order) and sensor.socket_distances ("A,B=M",
// socket ids and metres), each distance the one the positions give.
void ParseSockets(const Json& s, const KeyLocator& where, StudySensor* sensor) {
  const Json& list = At(s, "sensor.sockets");
  if (!list.is_array() || list.empty() ||
      list.size() > static_cast<std::size_t>(SocketSetup::kMaxSockets))
    throw InputError(where("sensor.sockets"),
                     "sensor.kind socket needs the sockets' positions in the base frame: a list "
                     "of 1 to " +
                         std::to_string(SocketSetup::kMaxSockets) + " [x, y, z] (m)");
  sensor->sockets.clear();
  for (std::size_t k = 0; k < list.size(); ++k) {
    const Json& p = list[k];
    bool ok = p.is_array() && p.size() == 3;
    for (std::size_t i = 0; ok && i < 3; ++i)
      ok = p[i].is_number() && std::isfinite(p[i].get<double>());
    if (!ok)
      throw InputError(where("sensor.sockets"),
                       "socket " + std::to_string(k) + ": expected [x, y, z] (m), got " + p.dump());
    sensor->sockets.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  }
  const Json& texts = At(s, "sensor.socket_distances");
  if (!texts.is_array())
    throw InputError(where("sensor.socket_distances"),
                     "expected a list of \"A,B=METRES\" (socket ids, m)");
  sensor->socket_distances.clear();
  for (const Json& t : texts) {
    if (!t.is_string())
      throw InputError(where("sensor.socket_distances"),
                       "expected \"A,B=METRES\" (socket ids, m), got " + t.dump());
    sensor->socket_distances.push_back(
        SocketDistance::Parse(t.get<std::string>(), where("sensor.socket_distances")));
  }
  const SocketSetup setup = SocketSetup::Numbered(sensor->sockets, sensor->tracker.targets.at(0),
                                                  sensor->socket_distances);
  try {
    setup.Validate();
  } catch (const InputError& e) {
    throw InputError(where("sensor.socket_distances"), e.what());
  }
  // A known distance is the truth's: the positions must agree with it (to 1 µm).
  for (const SocketDistance& d : sensor->socket_distances) {
    const double given = (sensor->sockets[static_cast<std::size_t>(d.b)] -
                          sensor->sockets[static_cast<std::size_t>(d.a)])
                             .norm();
    if (std::abs(given - d.metres) > 1e-6)
      throw InputError(where("sensor.socket_distances"),
                       "sockets " + std::to_string(d.a) + " and " + std::to_string(d.b) + " are " +
                           Json(given).dump() + " m apart in sensor.sockets, not " +
                           Json(d.metres).dump() + " m");
  }
}

// sensor: the kind, a tracker's frames and orientation noise, the cost of a reading and the
// campaign's budget (which sets selection.count).
void ParseSensor(const Json& settings, const KeyLocator& where, CellSettings* c) {
  const Json s = {{"sensor", FullSensorSection(settings)}};
  StudySensor& sensor = c->sensor;
  sensor.kind = Str(s, "sensor.kind", where);
  if (!IsMeasurementKindName(sensor.kind))
    throw InputError(where("sensor.kind"),
                     "expected " + MeasurementKindNameList() + ", got '" + sensor.kind + "'");
  sensor.cost_per_reading = Num(s, "sensor.cost_per_reading", where);
  if (!(sensor.cost_per_reading > 0) || !std::isfinite(sensor.cost_per_reading))
    throw InputError(where("sensor.cost_per_reading"),
                     "expected a cost > 0 per reading (in the study's own unit)");
  if (!At(s, "sensor.budget").is_null()) ParseBudget(s, where, c);
  const double sigma_mrad = Num(s, "sensor.sigma_mrad", where);
  if (!(sigma_mrad >= 0) || !std::isfinite(sigma_mrad))
    throw InputError(where("sensor.sigma_mrad"), "expected a standard deviation ≥ 0 mrad");
  sensor.sigma_angle = sigma_mrad * 1e-3;
  if (!At(s, "sensor.flush").is_boolean())
    throw InputError(where("sensor.flush"), "expected true or false");
  sensor.flush = At(s, "sensor.flush").get<bool>();
  if (sensor.flush && sensor.kind != "contact")
    throw InputError(where("sensor.flush"),
                     "is the contact sensor's; sensor.kind is " + sensor.kind);
  // A kind's geometry is read by that kind only: a study may set the instrument, the sockets
  // or the fan once and sweep the kind.
  if (sensor.IsRanger()) return;
  if (sensor.kind == "scanner") {
    sensor.scanner_frame = SensorFrame(s, "sensor.target", where, true);
    sensor.beam_angles = ParseFan(s, where);
    RefuseRangerSettings(settings, where, *c);
    return;
  }
  if (sensor.kind == "contact" || sensor.kind == "socket") {  // a tool point, nothing read
    const RigidTransform point = SensorFrame(s, "sensor.target", where, true);
    if (!point.rotation.isIdentity(0))
      throw InputError(
          where("sensor.target"),
          "sensor.kind " + sensor.kind + " seats a point: give [x, y, z] (m, tool frame)");
    sensor.tracker.targets = {point.translation};
    if (sensor.kind == "socket") ParseSockets(s, where, &sensor);
    RefuseRangerSettings(settings, where, *c);
    return;
  }
  if (At(s, "sensor.instrument").is_null())
    throw InputError(where("sensor.instrument"),
                     "sensor.kind " + sensor.kind +
                         " needs the instrument's frame in the base frame: [x, y, z, roll, "
                         "pitch, yaw] (m, rad)");
  sensor.tracker.instrument = SensorFrame(s, "sensor.instrument", where, false);
  const RigidTransform target = SensorFrame(s, "sensor.target", where, true);
  sensor.tracker.targets = {target.translation};
  if (sensor.kind == "pose") {
    sensor.tracker.target_orientations = {target.rotation};
  } else if (!target.rotation.isIdentity(0)) {
    throw InputError(where("sensor.target"),
                     "sensor.kind point reads positions only: give [x, y, z], or use pose");
  }
  RefuseRangerSettings(settings, where, *c);
}

// tool_link's links (several: a tree cell, measured by a tracker) and validation.tool_link,
// one of them.
void CheckToolLinks(const KeyLocator& where, const CellSettings& c) {
  const std::vector<std::string> links = c.ToolLinks();
  for (std::size_t i = 0; i < links.size(); ++i) {
    if (links[i].empty() && links.size() > 1)
      throw InputError(where("tool_link"), "an empty link name in '" + c.tool_link +
                                               "'; expected links separated by commas");
    if (std::find(links.begin(), links.begin() + static_cast<long>(i), links[i]) !=
        links.begin() + static_cast<long>(i))
      throw InputError(where("tool_link"), "'" + links[i] + "' is given twice");
  }
  if (c.IsTree()) {
    if (c.sensor.kind != "point" && c.sensor.kind != "pose")
      throw InputError(where("sensor.kind"),
                       "a tree cell (several tool links) is measured by a tracker that sees "
                       "every tool: expected point or pose, got " +
                           c.sensor.kind);
    if (!c.truth.random)
      throw InputError(where("truth.mode"),
                       "a tree cell draws its true errors (a URDF has none to read); expected "
                       "random");
  }
  if (c.validation_tool_link.empty()) return;
  if (std::find(links.begin(), links.end(), c.validation_tool_link) == links.end())
    throw InputError(where("validation.tool_link"),
                     "'" + c.validation_tool_link + "' is not one of tool_link (" +
                         (c.tool_link.empty() ? std::string("none given") : c.tool_link) + ")");
}

// environment.calibration / environment.validation: {gravity: [x, y, z], temperature_c: T or
// [T1, T2, ...]}.
CellSettings::EnvironmentPhase ParseEnvironmentPhase(const Json& s, const std::string& key,
                                                     const KeyLocator& where) {
  CellSettings::EnvironmentPhase phase;
  const Json& j = At(s, key);
  if (j.is_null()) return phase;
  if (!j.is_object())
    throw InputError(where(key), "expected a mapping with keys gravity, temperature_c");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.key() != "gravity" && it.key() != "temperature_c")
      throw InputError(where(key + "." + it.key()),
                       "unknown key; expected one of: gravity, temperature_c");
  if (j.contains("gravity")) {
    const Json& g = j["gravity"];
    if (!g.is_array() || g.size() != 3 || !g[0].is_number() || !g[1].is_number() ||
        !g[2].is_number())
      throw InputError(where(key + ".gravity"),
                       "expected [x, y, z] in m/s² in the base frame ([0, 0, -9.81] upright on "
                       "the ground, [0, 0, 0] on orbit)");
    phase.gravity = Eigen::Vector3d(g[0].get<double>(), g[1].get<double>(), g[2].get<double>());
    if (!phase.gravity.allFinite() || phase.gravity.norm() > 100)
      throw InputError(where(key + ".gravity"), "expected finite m/s² (|g| at most 100)");
  }
  if (j.contains("temperature_c")) {
    const Json& t = j["temperature_c"];
    const Json list = t.is_array() ? t : Json::array({t});
    if (list.empty())
      throw InputError(where(key + ".temperature_c"), "expected a temperature or a list (°C)");
    for (const Json& v : list) {
      if (!v.is_number() || !(v.get<double>() >= -273.15) || !std::isfinite(v.get<double>()))
        throw InputError(where(key + ".temperature_c"),
                         "expected temperatures in °C (above absolute zero), got " + t.dump());
      phase.temperatures_c.push_back(v.get<double>());
    }
  }
  return phase;
}

// environment: {calibration: ..., validation: ...}.
void ParseEnvironment(const Json& s, const KeyLocator& where, CellSettings* c) {
  const Json& e = At(s, "environment");
  if (e.is_null()) return;
  if (!e.is_object())
    throw InputError(where("environment"), "expected a mapping with keys calibration, validation");
  for (auto it = e.begin(); it != e.end(); ++it)
    if (it.key() != "calibration" && it.key() != "validation")
      throw InputError(where("environment." + it.key()),
                       "unknown key; expected one of: calibration, validation");
  c->calibration_environment = ParseEnvironmentPhase(s, "environment.calibration", where);
  c->validation_environment = ParseEnvironmentPhase(s, "environment.validation", where);
}

void SetEstimate(const std::vector<std::string>& items, const KeyLocator& where, CellSettings* c);

// identification.estimate: geometric, compliance, thermal, as a list or "geometric,thermal".
void ParseEstimate(const Json& s, const KeyLocator& where, CellSettings* c) {
  const Json& j = At(s, "identification.estimate");
  c->in_environment = !j.is_null() || !At(s, "environment").is_null();
  ParseEnvironment(s, where, c);
  if (j.is_null()) return;
  std::vector<std::string> items;
  if (j.is_string()) {
    items = SplitList(j.get<std::string>());
  } else if (j.is_array()) {
    for (const Json& v : j) {
      if (!v.is_string())
        throw InputError(where("identification.estimate"),
                         "expected a list of geometric, compliance, thermal");
      items.push_back(v.get<std::string>());
    }
  } else {
    throw InputError(where("identification.estimate"),
                     "expected a list of geometric, compliance, thermal (or one string of them "
                     "separated by commas), got " +
                         j.dump());
  }
  SetEstimate(items, where, c);
}

// identification.estimate's items into the cell's flags.
void SetEstimate(const std::vector<std::string>& items, const KeyLocator& where, CellSettings* c) {
  c->estimate_geometric = c->estimate_compliance = c->estimate_thermal = false;
  for (const std::string& item : items) {
    if (item == "geometric") {
      c->estimate_geometric = true;
    } else if (item == "compliance") {
      c->estimate_compliance = true;
    } else if (item == "thermal") {
      c->estimate_thermal = true;
    } else {
      throw InputError(where("identification.estimate"),
                       "'" + item + "': expected geometric, compliance or thermal");
    }
  }
  if (items.empty())
    throw InputError(where("identification.estimate"),
                     "expected at least one of geometric, compliance, thermal");
}

CellSettings ParseCell(const Json& s, const KeyLocator& where) {
  CellSettings c;
  c.robot = Str(s, "robot", where);
  if (s.contains("tool_link")) c.tool_link = Str(s, "tool_link", where);
  if (s.contains("base_link")) c.base_link = Str(s, "base_link", where);
  const std::pair<const char*, const std::string*> links[] = {{"tool_link", &c.tool_link},
                                                              {"base_link", &c.base_link}};
  for (const auto& [key, value] : links)
    if (!value->empty() && !IsUrdfPath(c.robot))
      throw InputError(where(key), "applies to a URDF robot (robot: arm.urdf); '" + c.robot +
                                       "' is a robot YAML file or a shipped name");
  ParsePlane(s, where, &c);
  ParseTruthAndNoise(s, where, &c);
  ParsePoolAndSelection(s, where, &c);
  ParseIdentification(s, where, &c);
  ParsePriorsAndErrorsInVariables(s, where, &c);
  c.paper_case = Int(s, "paper_case", where, 0);
  if (c.paper_case > 2) throw InputError(where("paper_case"), "expected 0 (none), 1 or 2");
  ParseSensor(s, where, &c);
  ParseEstimate(s, where, &c);
  if (c.in_environment && (!c.sensor.IsRanger() || c.IsTree()))
    throw InputError(
        where(At(s, "environment").is_null() ? "identification.estimate" : "environment"),
        "compliance, thermal growth and environments are modelled in studies of the "
        "ranger on one arm (sensor.kind: ranger)");
  CheckToolLinks(where, c);
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
  if (value.is_object() && target->is_object())
    target->merge_patch(value);
  else
    *target = value;
}

bool KeyExists(const Json& defaults, const std::string& key) {
  if (key == "." || key == "plane" || key == kLossScaleMm) return true;
  for (const char* k : {"normal", "offset", "tilt_deg", "azimuth_deg", "through"})
    if (key == std::string("plane.") + k) return true;
  if (key.rfind("plane.", 0) == 0) return false;
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

std::string Study::folder() const { return std::filesystem::path(path).parent_path().string(); }

std::string ResolveStudyFile(const std::string& file, const std::string& folder) {
  const std::filesystem::path p(file);
  if (p.is_absolute() || folder.empty()) return file;
  return (std::filesystem::path(folder) / p).string();
}

Json Study::ToJson() const {
  Json j;
  j["name"] = name;
  j["description"] = description;
  j["seed"] = seed;
  j["trials"] = trials;
  if (stop_when.enabled()) j["stop_when"] = stop_when.ToJson();
  j["base"] = base;
  j["sweep"] = sweep;
  if (!sensitivity.is_null()) j["sensitivity"] = sensitivity;
  Json cs = Json::array();
  for (const auto& c : cells) cs.push_back({{"id", c.id}, {"label", c.label}});
  j["cells"] = cs;
  return j;
}

namespace {

struct Axis {
  std::string key;
  std::vector<Json> values;
  std::vector<std::string> labels;
  std::vector<std::string> value_paths;  // for line lookup
};

// stop_when: {block, relative_se, p95_relative_halfwidth, trials}. `trials` there is another
// place for the study's maximum (the top-level `trials`); given twice, the two must agree.
void ParseStopWhen(const Json& given, const KeyLocator& where, Study* study) {
  if (!given.contains("stop_when")) return;
  Json rule = given["stop_when"];
  if (!rule.is_object())
    throw InputError(where("stop_when"),
                     "expected a mapping {block, relative_se, p95_relative_halfwidth, trials}, "
                     "got " +
                         (rule.is_null() ? std::string("nothing") : rule.dump()));
  OnlyKeys(rule, "stop_when", {"block", "relative_se", "p95_relative_halfwidth", "trials"},
           "block, relative_se, p95_relative_halfwidth, trials", where);
  if (rule.contains("trials")) {
    const int max = Int(given, "stop_when.trials", where, 1);
    if (given.contains("trials") && max != Int(given, "trials", where, 1))
      throw InputError(where("stop_when.trials"), "differs from the study's trials (" +
                                                      given["trials"].dump() +
                                                      "); give the maximum once");
    study->trials = max;
    rule.erase("trials");
  }
  try {
    study->stop_when = StopWhen::FromJson(rule, "stop_when");
  } catch (const InputError& e) {
    // Name the file and line of the key at fault.
    const std::string what = e.what();
    throw InputError(where(e.where()), what.substr(e.where().size() + 2));
  }
  if (study->stop_when.block > study->trials)
    throw InputError(where("stop_when.block"), "expected at most the study's trials (" +
                                                   std::to_string(study->trials) + "), got " +
                                                   std::to_string(study->stop_when.block));
}

// name, description, seed, trials, stop_when.
void ParseHeader(const Json& given, const std::string& path, const KeyLocator& where,
                 Study* study) {
  const bool trials_in_rule = given.contains("stop_when") && given["stop_when"].is_object() &&
                              given["stop_when"].contains("trials");
  for (const char* required : {"name", "seed", "trials"})
    if (!given.contains(required) && !(trials_in_rule && std::string(required) == "trials"))
      throw InputError(Location(path, 1) + " key '" + required + "'", "missing (required)");
  study->name = Str(given, "name", where);
  // The name becomes a folder (output/<name>): only plain names.
  const bool plain = !study->name.empty() && study->name[0] != '.' &&
                     study->name.find_first_not_of(
                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                         "0123456789._-") == std::string::npos;
  if (!plain)
    throw InputError(where("name"),
                     "expected a plain name (letters, digits, '.', '_', '-'; not "
                     "starting with '.'), got '" +
                         study->name + "'");
  if (given.contains("description")) study->description = Str(given, "description", where);
  const double seed = Num(given, "seed", where);
  if (seed < 0 || seed != std::floor(seed) || seed > 9e15)
    throw InputError(where("seed"), "expected a whole number >= 0");
  study->seed = static_cast<std::uint64_t>(seed);
  if (given.contains("trials")) study->trials = Int(given, "trials", where, 1);
  ParseStopWhen(given, where, study);
}

// The robot file's content hash, per cell (a sweep may name another robot file).
void HashRobotFile(Json* settings, const KeyLocator& where, const std::string& folder) {
  std::string robot_path;
  try {
    robot_path = ResolveRobotPath(Str(*settings, "robot", where), folder);
  } catch (const InputError& e) {
    throw InputError(where("robot"), e.what());
  }
  std::ifstream in(robot_path);
  if (!in || std::filesystem::is_directory(robot_path))
    throw InputError(where("robot"), "cannot open robot file '" + robot_path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  (*settings)["robot_file_fnv1a"] = HashHex(ss.str());
}

// The defaults with the file's settings merged in, and the robot file's content hash: a changed
// robot is a new cell.
Json ResolveBase(const Json& given, const KeyLocator& where, const std::string& folder) {
  Json settings = given;
  for (const char* k :
       {"name", "description", "seed", "trials", "stop_when", "sweep", "sensitivity"})
    settings.erase(k);
  CheckUnknownKeys(settings, StudyDefaults(), "", where);
  Json base = StudyDefaults();
  base.merge_patch(settings);
  if (!At(settings, kLossScaleMm).is_null()) base["identification"].erase("loss_scale_sigma");
  // noise.average came after studies were run: at its default (the mean) it is left out of the
  // settings, so that earlier studies' tables stay as they were.
  if (base["noise"].is_object() && base["noise"].value("average", Json()) == Averaging{}.Name())
    base["noise"].erase("average");
  NormaliseSensor(&base);
  HashRobotFile(&base, where, folder);
  ParseCell(base, where);  // the base itself must be valid
  return base;
}

Axis ParseAxis(const Json& ax, const std::string& ap, const KeyLocator& where) {
  if (!ax.is_object()) throw InputError(where(ap), "expected {key: ..., values: [...]}");
  OnlyKeys(ax, ap, {"key", "values", "labels"}, "key, values, labels", where);
  Axis axis;
  if (!ax.contains("key")) throw InputError(where(ap), "missing 'key'");
  axis.key = Str(ax, "key", KeyLocator{where.file, where.lines, where.context, ap});
  // The URDF links are settings without a default (CheckUnknownKeys): sweepable all the same.
  const bool link_key =
      axis.key == "tool_link" || axis.key == "base_link" || axis.key == "validation.tool_link" ||
      axis.key == "identification.estimate" || axis.key == "environment" ||
      axis.key == "environment.calibration" || axis.key == "environment.validation";
  if (!link_key && !KeyExists(StudyDefaults(), axis.key))
    throw InputError(where(ap + ".key"), "'" + axis.key +
                                             "' is not a study setting (e.g. "
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
  return axis;
}

// The sweep section: axes and how they combine.
std::vector<Axis> ParseSweep(const Json& given, const KeyLocator& where, Study* study,
                             std::string* combine) {
  std::vector<Axis> axes;
  *combine = "product";
  if (!given.contains("sweep")) return axes;
  const Json& sw = given["sweep"];
  study->sweep = sw;
  if (!sw.is_object()) throw InputError(where("sweep"), "expected a mapping with 'axes'");
  OnlyKeys(sw, "sweep", {"combine", "axes"}, "combine, axes", where);
  if (sw.contains("combine")) {
    *combine = Str(sw, "combine", KeyLocator{where.file, where.lines, where.context, "sweep"});
    if (*combine != "product" && *combine != "zip")
      throw InputError(where("sweep.combine"), "expected product or zip, got '" + *combine + "'");
  }
  if (!sw.contains("axes") || !sw["axes"].is_array() || sw["axes"].empty())
    throw InputError(where("sweep.axes"), "expected a non-empty list of axes");
  for (std::size_t a = 0; a < sw["axes"].size(); ++a) {
    axes.push_back(ParseAxis(sw["axes"][a], "sweep.axes[" + std::to_string(a) + "]", where));
    study->axis_keys.push_back(axes.back().key);
  }
  if (*combine == "zip")
    for (const auto& a : axes)
      if (a.values.size() != axes[0].values.size())
        throw InputError(where("sweep.axes"), "zip needs axes of equal length");
  double cells = 1;
  for (const auto& a : axes) cells *= *combine == "zip" ? 1 : static_cast<double>(a.values.size());
  if (cells > kMaxCells)
    throw InputError(where("sweep.axes"), "the axes give " + Json(cells).dump() +
                                              " cells; at most " + std::to_string(kMaxCells) +
                                              " are allowed in one study (split the sweep)");
  return axes;
}

// An uncertain input's law: uniform on [min, max], or normal (mean, std) through its quantile
// function (Sobol plans only: Morris' grid reaches 0 and 1).
struct InputDistribution {
  bool normal = false;
  double a = 0, b = 1;  // min, max or mean, std
  double At(double u) const {
    if (!normal) return a + u * (b - a);
    const double p = std::min(u, 1 - std::numeric_limits<double>::epsilon() / 2);
    return a + b * boost::math::quantile(boost::math::normal(), p);
  }
};

InputDistribution ParseInputDistribution(const Json& input, const std::string& ip,
                                         const std::string& method, const KeyLocator& where) {
  const KeyLocator at{where.file, where.lines, where.context, ip};
  InputDistribution d;
  d.normal = input.contains("mean") || input.contains("std");
  if (d.normal && (input.contains("min") || input.contains("max")))
    throw InputError(where(ip), "give min and max (uniform) or mean and std (normal), not both");
  if (d.normal && method != "sobol")
    throw InputError(where(ip), "a normal input needs method sobol (Morris' grid reaches 0 and 1)");
  d.a = Num(input, d.normal ? "mean" : "min", at);
  d.b = Num(input, d.normal ? "std" : "max", at);
  if (d.normal ? !(d.b > 0) : !(d.a < d.b))
    throw InputError(where(ip), d.normal ? "expected std > 0" : "expected min < max");
  return d;
}

// An uncertain input must be a numeric setting (the ranger errors' default is the robot file's
// value, also numeric), or a number of the study's one plane: plane.tilt_deg and
// plane.azimuth_deg when it is given by {tilt_deg, azimuth_deg, through}, plane.offset when by
// {normal, offset}.
void CheckSensitivityKey(const std::string& key, const Json& base, const std::string& where) {
  if (key.rfind("plane.", 0) == 0) {
    const bool known =
        key == "plane.tilt_deg" || key == "plane.azimuth_deg" || key == "plane.offset";
    if (!known)
      throw InputError(where, "'" + key +
                                  "' is not a numeric plane setting (plane.tilt_deg, "
                                  "plane.azimuth_deg or plane.offset)");
    if (!At(base, key).is_number())
      throw InputError(where, "'" + key + "' needs the study's plane given as one mapping " +
                                  (key == "plane.offset" ? "{normal, offset}"
                                                         : "{tilt_deg, azimuth_deg, through}") +
                                  " (not the robot file's plane or a list of planes)");
    return;
  }
  if (key == kLossScaleMm) return;
  if (!KeyExists(StudyDefaults(), key) ||
      !(At(StudyDefaults(), key).is_number() || At(StudyDefaults(), key) == "robot_file"))
    throw InputError(where, "'" + key +
                                "' is not a numeric study setting (e.g. noise.sigma_mm, "
                                "truth.scale, plane.tilt_deg)");
}

// The sensitivity inputs: each {key, min, max} or {key, mean, std}, each key a numeric study
// setting listed once; their keys become the study's axis keys.
void ParseSensitivityInputs(const Json& inputs, const std::string& method, const KeyLocator& where,
                            Study* study, std::vector<Axis>* axes_out,
                            std::vector<InputDistribution>* dist_out) {
  std::vector<Axis>& axes = *axes_out;
  std::vector<InputDistribution>& dist = *dist_out;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const std::string ip = "sensitivity.inputs[" + std::to_string(i) + "]";
    const KeyLocator in_at{where.file, where.lines, where.context, ip};
    if (!inputs[i].is_object())
      throw InputError(where(ip), "expected {key, min, max} or {key, mean, std}");
    OnlyKeys(inputs[i], ip, {"key", "min", "max", "mean", "std"}, "key, and min, max or mean, std",
             where);
    axes[i].key = Str(inputs[i], "key", in_at);
    CheckSensitivityKey(axes[i].key, study->base, where(ip + ".key"));
    // The same input twice would be two columns of one plan varied together: every index of
    // both would be meaningless (exactly zero), not an error anyone could see.
    for (std::size_t j = 0; j < i; ++j)
      if (axes[j].key == axes[i].key)
        throw InputError(where(ip + ".key"), "'" + axes[i].key +
                                                 "' is already sensitivity.inputs[" +
                                                 std::to_string(j) + "]; list each input once");
    dist[i] = ParseInputDistribution(inputs[i], ip, method, where);
    study->axis_keys.push_back(axes[i].key);
  }
}

// The sensitivity section (sensitivity.h; docs/STUDIES.md): uncertain inputs, each uniform on
// [min, max] or normal, sampled by Saltelli's or Morris' plan from the study's seed; the plan's
// points become the cells of a zipped sweep, one axis per input.
std::vector<Axis> ParseSensitivity(const Json& given, const KeyLocator& where, Study* study) {
  const Json& sn = given["sensitivity"];
  if (given.contains("sweep"))
    throw InputError(where("sensitivity"),
                     "a study has either a sweep or a sensitivity analysis, not both");
  if (!sn.is_object()) throw InputError(where("sensitivity"), "expected a mapping with 'inputs'");
  OnlyKeys(sn, "sensitivity",
           {"method", "samples", "levels", "bootstrap", "metric", "quantity", "inputs"},
           "method, samples, levels, bootstrap, metric, quantity, inputs", where);
  Json spec = {{"method", "sobol"},
               {"samples", 32},
               {"levels", 4},
               {"bootstrap", 1000},
               {"metric", NameOf(kValidationMetricNames, ValidationMetric::kRmsPosition)}};
  spec.merge_patch(sn);
  const KeyLocator at{where.file, where.lines, where.context, "sensitivity"};
  const std::string method = Str(spec, "method", at);
  if (method != "sobol" && method != "morris")
    throw InputError(where("sensitivity.method"), "expected sobol or morris, got '" + method + "'");
  const int samples = Int(spec, "samples", at, 2, 100000);
  const int levels = Int(spec, "levels", at, 2, 100);
  if (levels % 2 != 0)
    throw InputError(where("sensitivity.levels"), "expected an even number of grid levels");
  Int(spec, "bootstrap", at, 0, 100000);
  const std::string metric = Str(spec, "metric", at);
  ValidationMetric parsed{};
  if (!TryParseName(kValidationMetricNames, metric, &parsed))
    throw InputError(where("sensitivity.metric"),
                     "expected " + NameList(kValidationMetricNames) + ", got '" + metric + "'");
  // quantity (optional, not added when absent so that earlier runs' manifests stay the same):
  // cell_mean (default) or trial, a single calibration's metric with the noise as an input.
  if (spec.contains("quantity")) {
    const std::string quantity = Str(spec, "quantity", at);
    if (quantity != "cell_mean" && quantity != "trial")
      throw InputError(where("sensitivity.quantity"),
                       "expected cell_mean or trial, got '" + quantity + "'");
    if (quantity == "trial" && method != "sobol")
      throw InputError(where("sensitivity.quantity"),
                       "quantity trial needs method sobol (the noise's share is a variance)");
  }
  const Json& inputs = spec["inputs"];
  if (!inputs.is_array() || inputs.empty() || inputs.size() > 20)
    throw InputError(where("sensitivity.inputs"),
                     "expected a list of 1 to 20 inputs, each {key, min, max}");
  std::vector<Axis> axes(inputs.size());
  std::vector<InputDistribution> dist(inputs.size());
  ParseSensitivityInputs(inputs, method, where, study, &axes, &dist);
  const int d = static_cast<int>(inputs.size());
  const double cells = static_cast<double>(samples) * (method == "sobol" ? d + 2 : d + 1);
  if (cells > kMaxCells)
    throw InputError(where("sensitivity.samples"),
                     "the plan has " + Json(cells).dump() + " points; at most " +
                         std::to_string(kMaxCells) + " cells are allowed in one study");
  const Eigen::MatrixXd points = method == "sobol"
                                     ? MakeSaltelliPlan(samples, d, study->seed).points
                                     : MakeMorrisPlan(samples, d, levels, study->seed).points;
  for (int i = 0; i < d; ++i)
    for (Eigen::Index r = 0; r < points.rows(); ++r) {
      const double value = dist[i].At(points(r, i));
      axes[i].values.push_back(value);
      axes[i].labels.push_back(axes[i].key + "=" + ValueLabel(Json(value)));
      axes[i].value_paths.push_back("sensitivity.inputs[" + std::to_string(i) + "]");
    }
  study->sensitivity = spec;
  return axes;
}

// Value indices of every cell in canonical order (first axis slowest).
std::vector<std::vector<int>> Combinations(const std::vector<Axis>& axes,
                                           const std::string& combine) {
  std::vector<std::vector<int>> combos;
  if (axes.empty()) return {{}};
  if (combine == "zip") {
    for (std::size_t v = 0; v < axes[0].values.size(); ++v)
      combos.push_back(std::vector<int>(axes.size(), static_cast<int>(v)));
    return combos;
  }
  std::vector<int> idx(axes.size(), 0);
  while (true) {
    combos.push_back(idx);
    int a = static_cast<int>(axes.size()) - 1;
    while (a >= 0 && ++idx[a] == static_cast<int>(axes[a].values.size())) idx[a--] = 0;
    if (a < 0) return combos;
  }
}

// pool.file and validation.file: their content's hash goes into the settings (a changed file
// is a new cell), next to the path as written.
void HashConfigurationFiles(Json* settings, const KeyLocator& where, const std::string& folder) {
  for (const char* section : {"pool", "validation"}) {
    if (!settings->contains(section) || !(*settings)[section].is_object()) continue;
    Json& sec = (*settings)[section];
    sec.erase("file_fnv1a");  // lrcal's own key, never the user's
    if (!sec.contains("file")) continue;
    const std::string key = std::string(section) + ".file";
    if (!sec["file"].is_string() || sec["file"].get<std::string>().empty())
      throw InputError(where(key), "expected the path of a CSV file of configurations (q1..qN)");
    const std::string file = ResolveStudyFile(sec["file"].get<std::string>(), folder);
    std::ifstream in(file, std::ios::binary);
    if (!in || std::filesystem::is_directory(file))
      throw InputError(where(key), "cannot open the configuration file '" + file + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    sec["file_fnv1a"] = HashHex(ss.str());
  }
}

// True if an axis value at `key` sets the key path `path`.
bool Sets(const std::string& key, const Json& value, const std::string& path) {
  if (key == path) return true;
  if (key == ".") return !At(value, path).is_null();
  return path.rfind(key + ".", 0) == 0 && !At(value, path.substr(key.size() + 1)).is_null();
}

// A cell has its loss scale one way: a sweep value in one spelling replaces the base's in the
// other (the base's default, 1.345 σ, included).
// Two axes of one cell giving the scale in both spellings are refused, naming both values.
void KeepOneLossScale(const std::vector<Axis>& axes, const std::vector<int>& combo,
                      const std::string& path, const LineMap& lines, Json* settings) {
  int mm_axis = -1, sigma_axis = -1;
  for (std::size_t a = 0; a < axes.size(); ++a) {
    if (mm_axis < 0 && Sets(axes[a].key, axes[a].values[combo[a]], kLossScaleMm))
      mm_axis = static_cast<int>(a);
    if (sigma_axis < 0 && Sets(axes[a].key, axes[a].values[combo[a]], kLossScaleSigma))
      sigma_axis = static_cast<int>(a);
  }
  const bool mm = mm_axis >= 0, sigma = sigma_axis >= 0;
  if (mm && sigma && mm_axis != sigma_axis) {
    const auto line_of = [&](int a) {
      const auto it = lines.find(axes[a].value_paths[combo[a]]);
      return std::to_string(it == lines.end() ? 0 : it->second);
    };
    const int later = std::max(mm_axis, sigma_axis);
    throw InputError(KeyLocator{path, &lines, "", ""}(axes[later].value_paths[combo[later]]),
                     "this cell is given the robust loss scale twice: in mm by the sweep value "
                     "at line " +
                         line_of(mm_axis) + " (" + kLossScaleMm +
                         ") and in multiples of sigma by the one at line " + line_of(sigma_axis) +
                         " (" + kLossScaleSigma + "); give it one way");
  }
  // A sweep value may have replaced the settings by a non-mapping: the checks after this say so.
  if (!settings->is_object()) return;
  const auto id = settings->find("identification");
  if (id == settings->end() || !id->is_object() || !id->contains("loss_scale_mm") ||
      !id->contains("loss_scale_sigma"))
    return;
  id->erase(sigma && !mm ? "loss_scale_mm" : "loss_scale_sigma");
}

Cell MakeCell(const Json& base, const std::vector<Axis>& axes, const std::vector<int>& combo,
              const std::string& path, const LineMap& lines) {
  Cell cell;
  cell.settings = base;
  std::string context;
  for (std::size_t a = 0; a < axes.size(); ++a) {
    try {
      Apply(&cell.settings, axes[a].key, axes[a].values[combo[a]]);
    } catch (const Json::exception&) {  // e.g. plane.normal on a plane given as 'robot'
      throw InputError(KeyLocator{path, &lines, "", ""}(axes[a].value_paths[combo[a]]),
                       "cannot set '" + axes[a].key +
                           "' here: the setting above it is not a "
                           "mapping in this cell");
    }
    cell.label += (a ? ", " : "") + axes[a].labels[combo[a]];
    cell.axis_values[axes[a].key] = axes[a].labels[combo[a]];
    const auto line = lines.find(axes[a].value_paths[combo[a]]);
    context += (a ? "; " : "") + std::string("sweep value at ") +
               Location(path, line == lines.end() ? 0 : line->second);
  }
  if (cell.label.empty()) cell.label = "base";
  KeepOneLossScale(axes, combo, path, lines, &cell.settings);
  NormaliseSensor(&cell.settings);
  const std::string folder = std::filesystem::path(path).parent_path().string();
  HashRobotFile(&cell.settings, KeyLocator{path, &lines, context, ""}, folder);
  HashConfigurationFiles(&cell.settings, KeyLocator{path, &lines, context, ""}, folder);
  CheckUnknownKeys(cell.settings, StudyDefaults(), "", KeyLocator{path, &lines, context, ""});
  cell.typed = ParseCell(cell.settings, KeyLocator{path, &lines, context, ""});
  // sensor.budget sets the count: the resolved settings (and the tables) show the count bought.
  if (cell.typed.sensor.budget) cell.settings["selection"]["count"] = cell.typed.select_count;
  cell.id = HashHex(CellIdentity(cell.settings).dump());
  return cell;
}

}  // namespace

namespace {

// Keys added after studies were run: left out of a cell's identity at their neutral value
// (with the companion key that matters only when they are not), so that the cells and run
// directories of earlier studies keep their names.
struct NeutralKey {
  const char* section;
  const char* key;
  Json neutral;
  const char* companion;
};

void DropNeutralKeys(Json* id) {
  static const NeutralKey kNeutral[] = {{"truth", "ranger_offset_mm", "robot_file", nullptr},
                                        {"truth", "ranger_scale_ppm", "robot_file", nullptr},
                                        {"noise", "encoder_sigma_mrad", 0, nullptr},
                                        {"noise", "form_sigma_mm", 0, nullptr},
                                        {"noise", "average", "mean", nullptr},
                                        {"noise", "outlier_fraction", 0, "outlier_sigma_mm"},
                                        {"identification", "estimate_ranger", "none", nullptr},
                                        {"identification", "loss", "none", "loss_scale"},
                                        {"identification", "prior_sigma", "none", nullptr},
                                        {"validation", "coverage", false, nullptr},
                                        {"identification", "errors_in_variables", false, nullptr}};
  for (const NeutralKey& k : kNeutral) {
    const auto section = id->find(k.section);
    if (section == id->end() || !section->is_object()) continue;
    const auto value = section->find(k.key);
    if (value == section->end() || *value != k.neutral) continue;
    section->erase(k.key);
    if (k.companion) section->erase(k.companion);
  }
}

bool IsRobotFilePath(const std::string& robot) {
  return robot.find('/') != std::string::npos ||
         (robot.size() > 5 && robot.substr(robot.size() - 5) == ".yaml") || IsUrdfPath(robot);
}

}  // namespace

Json CellIdentity(const Json& settings) {
  Json id = settings;
  // loss_scale_sigma was loss_scale when the first robust studies were run: named so in the
  // identity, and neither spelling counts without a robust loss.
  if (id.contains("identification") && id["identification"].is_object()) {
    Json& ident = id["identification"];
    if (ident.contains("loss_scale_sigma")) {
      ident["loss_scale"] = ident["loss_scale_sigma"];
      ident.erase("loss_scale_sigma");
    }
    if (ident.value("loss", Json()) == "none") ident.erase("loss_scale_mm");
  }
  DropNeutralKeys(&id);
  // sensor came with the tracker kinds: the ranger's default section is left out.
  if (id.contains("sensor") && id["sensor"].is_object() &&
      WithoutLateSensorDefaults(id["sensor"]) ==
          WithoutLateSensorDefaults(StudyDefaults()["sensor"]))
    id.erase("sensor");
  // tool_link and base_link came with URDF robots: left out when empty (as if not given).
  for (const char* key : {"tool_link", "base_link"})
    if (id.contains(key) && id[key] == "") id.erase(key);
  if (id.contains("validation") && id["validation"].is_object() &&
      id["validation"].value("tool_link", Json()) == "")
    id["validation"].erase("tool_link");
  for (const char* section : {"pool", "validation"})
    if (id.contains(section) && id[section].is_object()) id[section].erase("file");
  if (id.contains("robot") && id["robot"].is_string() &&
      IsRobotFilePath(id["robot"].get<std::string>()))
    id["robot"] = "file";
  return id;
}

std::vector<std::string> CellSettings::ToolLinks() const { return SplitList(tool_link); }

Study LoadStudy(const std::string& path) {
  YAML::Node root = yaml::LoadFile(path);
  yaml::RequireMap(root, path, "");
  LineMap lines;
  long budget = kMaxStudyValues;
  Json given = ToJsonNode(root, "", path, &lines, &budget);
  RenameEarlierKeys(&given, "", path, &lines);
  const KeyLocator where{path, &lines, "", ""};
  Study study;
  study.path = path;
  ParseHeader(given, path, where, &study);
  study.base = ResolveBase(given, where, study.folder());
  std::string combine = "zip";
  const bool sensitivity = given.contains("sensitivity");
  const std::vector<Axis> axes = sensitivity ? ParseSensitivity(given, where, &study)
                                             : ParseSweep(given, where, &study, &combine);
  std::map<std::string, std::string> seen;
  Json plan_cells = Json::array();  // sensitivity: each plan point's cell (points may repeat)
  for (const auto& combo : Combinations(axes, combine)) {
    Cell cell = MakeCell(study.base, axes, combo, path, lines);
    if (sensitivity) plan_cells.push_back(cell.id);
    if (sensitivity && seen.count(cell.id)) continue;
    if (seen.count(cell.id))
      throw InputError(path, "sweep cells '" + seen[cell.id] + "' and '" + cell.label +
                                 "' have identical settings");
    seen[cell.id] = cell.label;
    cell.order = static_cast<int>(study.cells.size());
    study.cells.push_back(std::move(cell));
  }
  if (sensitivity) study.sensitivity["plan_cells"] = plan_cells;
  return study;
}

}  // namespace lrcal
