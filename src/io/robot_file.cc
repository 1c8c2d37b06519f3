#include "lrcal/io/robot_file.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>

#include "io/yaml_util.h"
#include "lrcal/core/data_dir.h"
#include "lrcal/core/error.h"
#include "lrcal/core/json.h"
#include "lrcal/core/settings.h"
#include "lrcal/core/strings.h"
#include "lrcal/io/urdf.h"
#include "lrcal/measurement/parameter_set.h"

namespace lrcal {

std::string ResolveRobotPath(const std::string& name_or_path, const std::string& relative_to) {
  namespace fs = std::filesystem;
  const bool looks_like_file =
      (name_or_path.size() > 5 && name_or_path.substr(name_or_path.size() - 5) == ".yaml") ||
      IsUrdfPath(name_or_path);
  const fs::path given(name_or_path);
  if (!relative_to.empty() && given.is_relative() &&
      (looks_like_file || name_or_path.find('/') != std::string::npos))
    return (fs::path(relative_to) / given).string();
  const bool file_here = PathExists(name_or_path) && !IsDirectory(name_or_path);
  if (name_or_path.find('/') != std::string::npos || file_here || looks_like_file)
    return name_or_path;
  // A short name: studies/robots/NAME.yaml in the working directory, then in lrcal's data.
  const fs::path local = fs::path("studies") / "robots" / (name_or_path + ".yaml");
  if (PathExists(local)) return local.string();
  if (std::string shipped = FindDataFile(local.string()); !shipped.empty()) return shipped;
  throw SettingError(SettingSpec::Named("setup", "robot", "robot", "robot file or shipped name"),
                     "'" + name_or_path +
                         "' is neither a robot file nor a shipped robot name "
                         "(shipped: studies/robots/*.yaml, e.g. 'paper')");
}

namespace {

double AngleScale(const std::string& unit, const std::string& where) {
  if (unit == "rad") return 1.0;
  if (unit == "mrad") return 1e-3;
  if (unit == "deg") return M_PI / 180.0;
  throw InputError(where, "expected rad, mrad or deg; got '" + unit + "'");
}

double LengthScale(const std::string& unit, const std::string& where) {
  if (unit == "m") return 1.0;
  if (unit == "mm") return 1e-3;
  throw InputError(where, "expected m or mm; got '" + unit + "'");
}

}  // namespace

namespace {

JointType ParseJoint(const YAML::Node& node, const std::string& path, const std::string& key) {
  const std::string j = yaml::String(node, path, key);
  if (j == "revolute") return JointType::kRevolute;
  if (j == "prismatic") return JointType::kPrismatic;
  throw InputError(yaml::Where(path, node, key), "expected revolute or prismatic; got '" + j + "'");
}

// links[i]: joint, the five nominal values (β defaults to 0), which are parameters, joint range.
Link ParseLink(const YAML::Node& ln, const std::string& path, const std::string& ctx) {
  using namespace yaml;
  CheckKeys(ln,
            {"joint", "theta", "alpha", "a", "d", "beta", "parameters", "q_min", "q_max", "couple"},
            path, ctx);
  Link link;
  if (ln["joint"]) link.joint = ParseJoint(ln["joint"], path, ctx + ".joint");
  for (int v = 0; v < kValuesPerLink; ++v) {
    const char* vn = LinkValueName(v);
    YAML::Node node = ln[vn];
    if (!node) {
      if (v == kBeta) continue;  // β defaults to 0
      throw InputError(Where(path, ln, ctx + "." + vn), "missing value");
    }
    link.nominal[v] = Number(node, path, ctx + "." + vn, /*allow_pi=*/IsAngle(v));
  }
  if (!ln["parameters"])
    throw InputError(Where(path, ln, ctx + ".parameters"),
                     "missing: list which of theta, alpha, a, d, beta are parameters");
  for (const std::string& p : StringList(ln["parameters"], path, ctx + ".parameters")) {
    const int v = LinkValueIndex(p + "1", 1);
    if (v < 0)
      throw InputError(Where(path, ln["parameters"], ctx + ".parameters"),
                       "unknown parameter '" + p + "'; expected theta, alpha, a, d or beta");
    link.is_parameter[v] = true;
  }
  if (ln["q_min"]) link.q_min = Number(ln["q_min"], path, ctx + ".q_min", true);
  if (ln["q_max"]) link.q_max = Number(ln["q_max"], path, ctx + ".q_max", true);
  if (!(link.q_min < link.q_max))
    throw InputError(Where(path, ln, ctx), "q_min must be below q_max");
  return link;
}

std::vector<Link> ParseLinks(const YAML::Node& root, const std::string& path) {
  YAML::Node links_node = root["links"];
  if (!links_node || !links_node.IsSequence() || links_node.size() == 0)
    throw InputError(yaml::Where(path, root, "links"), "expected a non-empty list of links");
  std::vector<Link> links;
  for (std::size_t i = 0; i < links_node.size(); ++i)
    links.push_back(ParseLink(links_node[i], path, "links[" + std::to_string(i) + "]"));
  return links;
}

// true_errors: units, then per link the errors of its parameters (SI out).
Eigen::VectorXd ParseTrueErrors(const YAML::Node& root, const std::string& path,
                                const std::vector<Link>& links) {
  using namespace yaml;
  Eigen::VectorXd errors = Eigen::VectorXd::Zero(kValuesPerLink * links.size());
  const YAML::Node te = root["true_errors"];
  if (!te) return errors;
  CheckKeys(te, {"angle_unit", "length_unit", "links", "ranger_offset_mm", "ranger_scale_ppm"},
            path, "true_errors");
  const double as = AngleScale(
      te["angle_unit"] ? String(te["angle_unit"], path, "true_errors.angle_unit") : "rad",
      Where(path, te["angle_unit"], "true_errors.angle_unit"));
  const double ls = LengthScale(
      te["length_unit"] ? String(te["length_unit"], path, "true_errors.length_unit") : "m",
      Where(path, te["length_unit"], "true_errors.length_unit"));
  const YAML::Node tl = te["links"];
  if (!tl || !tl.IsSequence() || tl.size() != links.size())
    throw InputError(
        Where(path, te, "true_errors.links"),
        "expected a list of " + std::to_string(links.size()) + " entries, one per link");
  for (std::size_t i = 0; i < tl.size(); ++i) {
    const std::string ctx = "true_errors.links[" + std::to_string(i) + "]";
    CheckKeys(tl[i], {"theta", "alpha", "a", "d", "beta"}, path, ctx);
    for (int v = 0; v < kValuesPerLink; ++v) {
      const YAML::Node node = tl[i][LinkValueName(v)];
      if (!node) continue;
      if (!links[i].is_parameter[v])
        throw InputError(Where(path, node, ctx + "." + LinkValueName(v)),
                         "an error is given for a value that is not a parameter of link " +
                             std::to_string(i + 1));
      errors[kValuesPerLink * i + v] =
          Number(node, path, ctx + "." + LinkValueName(v)) * (IsAngle(v) ? as : ls);
    }
  }
  return errors;
}

Plane ParseOnePlane(const YAML::Node& pl, const std::string& path, const std::string& key,
                    bool named) {
  using namespace yaml;
  if (named)
    CheckKeys(pl, {"normal", "offset", "name"}, path, key);
  else
    CheckKeys(pl, {"normal", "offset"}, path, key);
  const std::vector<double> n = NumberList(pl["normal"], path, key + ".normal");
  if (n.size() != 3)
    throw InputError(Where(path, pl["normal"], key + ".normal"), "expected 3 numbers");
  const double f = Number(pl["offset"], path, key + ".offset");
  return Plane::FromCoefficients(n[0], n[1], n[2], f, Where(path, pl, key));
}

// plane: {normal, offset} (one plane), or planes: a list of {normal, offset, name}.
std::optional<PlaneSet> ParsePlanes(const YAML::Node& root, const std::string& path) {
  using namespace yaml;
  const YAML::Node one = root["plane"];
  const YAML::Node list = root["planes"];
  if (one && list)
    throw InputError(Where(path, list, "planes"),
                     "give either plane: (one plane) or planes: (a list), not both");
  if (one) return PlaneSet(ParseOnePlane(one, path, "plane", false));
  if (!list) return std::nullopt;
  if (!list.IsSequence() || list.size() == 0)
    throw InputError(Where(path, list, "planes"),
                     "expected a list of planes, each {normal: [nx, ny, nz], offset: f, name: n}");
  std::vector<Plane> planes;
  std::vector<std::string> names;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string key = "planes[" + std::to_string(k) + "]";
    if (!list[k].IsMap())
      throw InputError(Where(path, list[k], key), "expected a mapping {normal, offset, name}");
    planes.push_back(ParseOnePlane(list[k], path, key, true));
    names.push_back(list[k]["name"] ? String(list[k]["name"], path, key + ".name") : "");
  }
  return PlaneSet(std::move(planes), std::move(names), Where(path, list, "planes"));
}

// base: / tool: {xyz: [x, y, z] (m), rpy: [roll, pitch, yaw] (rad)}, both optional (zero).
RigidTransform ParseFixedTransform(const YAML::Node& root, const std::string& path,
                                   const std::string& key) {
  using namespace yaml;
  const YAML::Node node = root[key];
  if (!node) return {};
  if (!node.IsMap())
    throw InputError(Where(path, node, key),
                     "expected a mapping {xyz: [x, y, z] (m), rpy: [roll, pitch, yaw] (rad)}");
  CheckKeys(node, {"xyz", "rpy"}, path, key);
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
  for (const char* part : {"xyz", "rpy"}) {
    if (!node[part]) continue;
    const std::vector<double> v = NumberList(node[part], path, key + "." + part);
    if (v.size() != 3)
      throw InputError(Where(path, node[part], key + "." + part), "expected 3 numbers");
    (std::string(part) == "xyz" ? xyz : rpy) = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  return RigidTransform::FromXyzRpy(xyz, rpy);
}

// masses: [{link: 2 | tool, mass: kg, com: [x, y, z] m}, ...]
MassModel ParseMasses(const YAML::Node& root, const std::string& path, int num_links) {
  using namespace yaml;
  MassModel out;
  const YAML::Node list = root["masses"];
  if (!list) return out;
  if (!list.IsSequence())
    throw InputError(Where(path, list, "masses"),
                     "expected a list of {link, mass, com} (kg, m in the link's frame)");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node m = list[i];
    const std::string ctx = "masses[" + std::to_string(i) + "]";
    RequireMap(m, path, ctx);
    CheckKeys(m, {"link", "mass", "com"}, path, ctx);
    for (const char* key : {"link", "mass"})
      if (!m[key])
        throw InputError(Where(path, m, ctx + "." + key), "missing: expected link (1 to " +
                                                              std::to_string(num_links) +
                                                              ", or tool), mass (kg) and com (m)");
    PointMass pm;
    if (m["link"].IsScalar() && m["link"].Scalar() == "tool") {
      pm.link = num_links + 1;
    } else {
      pm.link = Integer(m["link"], path, ctx + ".link");
      if (pm.link < 1 || pm.link > num_links)
        throw InputError(
            Where(path, m["link"], ctx + ".link"),
            "expected a link from 1 to " + std::to_string(num_links) + ", or tool for a payload");
    }
    pm.mass = Number(m["mass"], path, ctx + ".mass");
    if (!(pm.mass > 0))
      throw InputError(Where(path, m["mass"], ctx + ".mass"), "expected a positive mass in kg");
    if (m["com"]) {
      const std::vector<double> c = NumberList(m["com"], path, ctx + ".com");
      if (c.size() != 3)
        throw InputError(Where(path, m["com"], ctx + ".com"),
                         "expected 3 numbers (m, in the link's frame)");
      pm.com = Eigen::Vector3d(c[0], c[1], c[2]);
    }
    out.masses.push_back(pm);
  }
  return out;
}

// compliance: {unit: urad/Nm | rad/Nm, nominal: [N values], true: [N values]}
Eigen::VectorXd ParseCompliance(const YAML::Node& c, const std::string& path, const char* which,
                                int num_links, double unit) {
  using namespace yaml;
  if (!c || !c[which]) return {};
  const std::string key = std::string("compliance.") + which;
  const std::vector<double> v = NumberList(c[which], path, key);
  if (static_cast<int>(v.size()) != num_links)
    throw InputError(Where(path, c[which], key), "expected one compliance per joint (" +
                                                     std::to_string(num_links) + " numbers), got " +
                                                     std::to_string(v.size()));
  Eigen::VectorXd out(num_links);
  for (int j = 0; j < num_links; ++j) {
    if (v[static_cast<std::size_t>(j)] < 0)
      throw InputError(Where(path, c[which], key),
                       "joint " + std::to_string(j + 1) + "'s compliance is negative");
    out[j] = v[static_cast<std::size_t>(j)] * unit;
  }
  return out;
}

// compliance.unit: rad/(N·m) per unit of the file's numbers.
double ComplianceUnit(const YAML::Node& c, const std::string& path) {
  using namespace yaml;
  if (!c) return 1e-6;
  RequireMap(c, path, "compliance");
  CheckKeys(c, {"unit", "nominal", "true"}, path, "compliance");
  const std::string u = c["unit"] ? String(c["unit"], path, "compliance.unit") : "urad/Nm";
  if (u != "urad/Nm" && u != "rad/Nm")
    throw InputError(
        Where(path, c["unit"], "compliance.unit"),
        "expected urad/Nm or rad/Nm (m/N and um/N for a prismatic joint), got '" + u + "'");
  return u == "rad/Nm" ? 1.0 : 1e-6;
}

// One thermal coefficient in ppm/K (1/K out), `fallback` when the key is absent.
double Coefficient(const YAML::Node& t, const char* key, const std::string& path, double fallback) {
  if (!t || !t[key]) return fallback;
  return yaml::Number(t[key], path, std::string("thermal.") + key) * 1e-6;
}

// The links' coefficient at `key`: one number (one material) into `links`, or a list of one per
// link (a material per link) into `per_link` with `links` 0. Unchanged when the key is absent.
void LinkCoefficients(const YAML::Node& t, const char* key, const std::string& path, int n,
                      ThermalCoefficients* out) {
  if (!t || !t[key]) return;
  const std::string name = std::string("thermal.") + key;
  if (!t[key].IsSequence()) {
    out->links = yaml::Number(t[key], path, name) * 1e-6;
    out->per_link.resize(0);
    return;
  }
  const std::vector<double> v = yaml::NumberList(t[key], path, name);
  if (static_cast<int>(v.size()) != n)
    throw InputError(yaml::Where(path, t[key], name),
                     "expected one number (ppm/K) for every link, or a list of " +
                         std::to_string(n) + " (one per link), got " + std::to_string(v.size()));
  out->links = 0;
  out->per_link = Eigen::Map<const Eigen::VectorXd>(v.data(), n) * 1e-6;
}

// thermal: {reference_c, links_ppm_per_k, ranger_ppm_per_k, true_links_ppm_per_k,
// true_ranger_ppm_per_k}: the model's coefficients and the simulated arm's.
void ParseThermal(const YAML::Node& root, const std::string& path, int n,
                  ThermalCoefficients* model, ThermalCoefficients* truth) {
  using namespace yaml;
  const YAML::Node t = root["thermal"];
  if (t) {
    RequireMap(t, path, "thermal");
    CheckKeys(t,
              {"reference_c", "links_ppm_per_k", "ranger_ppm_per_k", "true_links_ppm_per_k",
               "true_ranger_ppm_per_k"},
              path, "thermal");
    if (t["reference_c"])
      model->reference_c = Number(t["reference_c"], path, "thermal.reference_c");
  }
  LinkCoefficients(t, "links_ppm_per_k", path, n, model);
  model->ranger = Coefficient(t, "ranger_ppm_per_k", path, 0);
  *truth = *model;
  LinkCoefficients(t, "true_links_ppm_per_k", path, n, truth);
  truth->ranger = Coefficient(t, "true_ranger_ppm_per_k", path, model->ranger);
}

// environment: {gravity: [x, y, z], temperature_c}: the defaults of data without the columns.
void ParseEnvironmentDefaults(const YAML::Node& root, const std::string& path,
                              Environment* defaults) {
  using namespace yaml;
  const YAML::Node e = root["environment"];
  if (!e) return;
  RequireMap(e, path, "environment");
  CheckKeys(e, {"gravity", "temperature_c"}, path, "environment");
  if (e["gravity"]) {
    const std::vector<double> g = NumberList(e["gravity"], path, "environment.gravity");
    if (g.size() != 3)
      throw InputError(Where(path, e["gravity"], "environment.gravity"),
                       "expected 3 numbers (m/s², base frame: [0, 0, -9.81] upright)");
    defaults->gravity = Eigen::Vector3d(g[0], g[1], g[2]);
  }
  if (e["temperature_c"])
    defaults->temperature_c = Number(e["temperature_c"], path, "environment.temperature_c");
}

void ParseNonGeometric(const YAML::Node& root, const std::string& path, RobotFile* file) {
  const int n = file->robot.num_links();
  NonGeometricModel& model = file->non_geometric;
  model.masses = ParseMasses(root, path, n);
  const YAML::Node c = root["compliance"];
  const double unit = ComplianceUnit(c, path);
  model.compliance = ParseCompliance(c, path, "nominal", n, unit);
  ThermalCoefficients truth;
  ParseThermal(root, path, n, &model.thermal, &truth);
  ParseEnvironmentDefaults(root, path, &model.defaults);
  file->true_non_geometric = model;
  file->true_non_geometric.thermal = truth;
  file->true_non_geometric.compliance = ParseCompliance(c, path, "true", n, unit);
  if (file->true_non_geometric.compliance.size() == 0)
    file->true_non_geometric.compliance = model.compliance;
  if (c && (c["true"] || c["nominal"]) && model.masses.empty())
    throw InputError(yaml::Where(path, c, "compliance"),
                     "a joint compliance bends the arm under gravity's load: give the arm's "
                     "masses: as well");
}

RangerSpec ParseRanger(const YAML::Node& root, const std::string& path) {
  using namespace yaml;
  RangerSpec ranger;
  const YAML::Node rg = root["ranger"];
  if (!rg) return ranger;
  CheckKeys(rg, {"min_range", "max_range", "max_incidence_deg"}, path, "ranger");
  if (rg["min_range"]) ranger.min_range = Number(rg["min_range"], path, "ranger.min_range");
  if (rg["max_range"]) ranger.max_range = Number(rg["max_range"], path, "ranger.max_range");
  if (rg["max_incidence_deg"])
    ranger.max_incidence =
        Number(rg["max_incidence_deg"], path, "ranger.max_incidence_deg") * M_PI / 180.0;
  try {
    ranger.Validate();
  } catch (const SettingError& e) {  // in the file's words: its line and key, its unit
    const char* key = e.spec().name;
    throw InputError(Where(path, rg[key] ? rg[key] : rg, std::string("ranger.") + key),
                     e.Problem());
  }
  return ranger;
}

}  // namespace

namespace {

// A covariance as lrcal writes it: symmetric (to the rounding of its computation), with
// non-negative variances and no negative eigenvalue beyond rounding. Anything else would give
// accuracy statements that look better than the data allow (a negative variance) or are
// meaningless (an asymmetric matrix).
void CheckCovariance(const Eigen::MatrixXd& c, const std::string& where) {
  const double scale = c.cwiseAbs().maxCoeff();
  if (!c.allFinite()) throw InputError(where, "expected finite numbers");
  if (c.size() == 0 || scale == 0) return;
  constexpr double kRounding = 1e-9;  // relative: LDLᵀ solves are symmetric to ~1e-15
  const Eigen::Index n = c.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (c(i, i) < 0)
      throw InputError(where, "row " + std::to_string(i) + " has a negative variance (" +
                                  FormatExact(c(i, i)) + "); expected a covariance matrix");
    for (Eigen::Index k = 0; k < i; ++k)
      if (std::fabs(c(i, k) - c(k, i)) > kRounding * scale)
        throw InputError(where, "is not symmetric: entries (" + std::to_string(i) + ", " +
                                    std::to_string(k) + ") and (" + std::to_string(k) + ", " +
                                    std::to_string(i) + ") differ; expected a covariance matrix");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (c + c.transpose()),
                                                           Eigen::EigenvaluesOnly);
  if (eig.eigenvalues().minCoeff() < -kRounding * scale)
    throw InputError(where, "has a negative eigenvalue (" +
                                FormatExact(eig.eigenvalues().minCoeff()) +
                                "): not a covariance matrix (positive semi-definite expected)");
}

}  // namespace

// calibration.estimate_shift: one row per parameter, one column per held term, finite.
void ParseEstimateShift(const YAML::Node& c, const std::string& path, CalibrationRecord* r) {
  using namespace yaml;
  const std::size_t k = r->held.size(), n = r->parameters.size();
  const YAML::Node shift = c["estimate_shift"];
  if (!shift || !shift.IsSequence() || shift.size() != n)
    throw InputError(Where(path, shift ? shift : c, "calibration.estimate_shift"),
                     "expected " + std::to_string(n) + " rows (one per parameter) of " +
                         std::to_string(k) + " numbers (one per held term)");
  r->estimate_shift.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(k));
  for (std::size_t i = 0; i < n; ++i) {
    const std::string key = "calibration.estimate_shift[" + std::to_string(i) + "]";
    const std::vector<double> row = NumberList(shift[i], path, key);
    if (row.size() != k)
      throw InputError(Where(path, shift[i], key), "expected " + std::to_string(k) + " numbers");
    for (std::size_t j = 0; j < k; ++j) {
      if (!std::isfinite(row[j]))
        throw InputError(Where(path, shift[i], key), "expected finite numbers");
      r->estimate_shift(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = row[j];
    }
  }
}

// calibration.held, held_sigma, held_defaulted, estimate_shift: the terms held at nominal.
void ParseHeldTerms(const YAML::Node& c, const std::string& path, CalibrationRecord* r) {
  using namespace yaml;
  if (!c["held"]) {
    for (const char* key : {"held_sigma", "held_defaulted", "estimate_shift"})
      if (c[key])
        throw InputError(Where(path, c[key], std::string("calibration.") + key),
                         "given without calibration.held (the terms it belongs to)");
    return;
  }
  r->held = StringList(c["held"], path, "calibration.held");
  const std::size_t k = r->held.size();
  const std::vector<double> sigma =
      c["held_sigma"] ? NumberList(c["held_sigma"], path, "calibration.held_sigma")
                      : std::vector<double>{};
  if (sigma.size() != k)
    throw InputError(Where(path, c["held_sigma"] ? c["held_sigma"] : c, "calibration.held_sigma"),
                     "expected one prior standard deviation (SI) per name in calibration.held");
  for (std::size_t i = 0; i < k; ++i)
    if (!(sigma[i] > 0) || !std::isfinite(sigma[i]))
      throw InputError(Where(path, c["held_sigma"], "calibration.held_sigma"),
                       "entry " + std::to_string(i + 1) + " (" + r->held[i] +
                           "): expected a standard deviation > 0, got " + FormatExact(sigma[i]));
  r->held_sigma = Eigen::Map<const Eigen::VectorXd>(sigma.data(), static_cast<Eigen::Index>(k));
  if (c["held_defaulted"]) {
    r->held_defaulted = StringList(c["held_defaulted"], path, "calibration.held_defaulted");
    for (const std::string& name : r->held_defaulted)
      if (std::find(r->held.begin(), r->held.end(), name) == r->held.end())
        throw InputError(Where(path, c["held_defaulted"], "calibration.held_defaulted"),
                         "'" + name + "' is not in calibration.held");
  }
  ParseEstimateShift(c, path, r);
}

// calibration: the record of identify --write-robot (parameters, estimate, covariance, sigma).
CalibrationRecord ParseCalibration(const YAML::Node& c, const std::string& path) {
  using namespace yaml;
  CheckKeys(c,
            {"data", "data_fnv1a", "date", "lrcal", "sigma", "sigma_source", "parameters",
             "estimate", "covariance", "held", "held_sigma", "held_defaulted", "estimate_shift"},
            path, "calibration");
  CalibrationRecord r;
  if (c["data"]) r.data_file = String(c["data"], path, "calibration.data");
  if (c["sigma"]) {
    r.sigma = Number(c["sigma"], path, "calibration.sigma");
    if (!(r.sigma >= 0))
      throw InputError(
          Where(path, c["sigma"], "calibration.sigma"),
          "expected the standard deviation of one reading, >= 0 (m), got " + FormatExact(r.sigma));
  }
  if (c["sigma_source"])
    r.sigma_source = String(c["sigma_source"], path, "calibration.sigma_source");
  if (c["parameters"]) r.parameters = StringList(c["parameters"], path, "calibration.parameters");
  const std::vector<double> estimate = c["estimate"]
                                           ? NumberList(c["estimate"], path, "calibration.estimate")
                                           : std::vector<double>{};
  r.estimate = Eigen::Map<const Eigen::VectorXd>(estimate.data(), estimate.size());
  const std::size_t n = r.parameters.size();
  if (estimate.size() != n)
    throw InputError(Where(path, c, "calibration.estimate"),
                     "expected one value per name in calibration.parameters");
  const YAML::Node cov = c["covariance"];
  if (cov && !cov.IsNull()) {
    if (!cov.IsSequence() || cov.size() != n)
      throw InputError(Where(path, cov, "calibration.covariance"),
                       "expected " + std::to_string(n) + " rows of " + std::to_string(n));
    r.covariance.resize(n, n);
    for (std::size_t i = 0; i < n; ++i) {
      const std::vector<double> row =
          NumberList(cov[i], path, "calibration.covariance[" + std::to_string(i) + "]");
      if (row.size() != n)
        throw InputError(Where(path, cov[i], "calibration.covariance[" + std::to_string(i) + "]"),
                         "expected " + std::to_string(n) + " numbers");
      for (std::size_t k = 0; k < n; ++k) r.covariance(i, k) = row[k];
    }
    CheckCovariance(r.covariance, Where(path, cov, "calibration.covariance"));
  }
  ParseHeldTerms(c, path, &r);
  return r;
}

// A standard deviation from a robot file: a number > 0 (SI out, `scale` from the file's unit).
double Tolerance(const YAML::Node& node, const std::string& path, const std::string& key,
                 double scale) {
  const double value = yaml::Number(node, path, key);
  if (!(value > 0))
    throw InputError(yaml::Where(path, node, key), "expected a standard deviation > 0");
  return value * scale;
}

// tolerances.every_link or tolerances.links[i]: a link's values' tolerances, as classes
// ("theta") or, for link `link` (1-based), names ("theta3").
void ParseLinkTolerances(const YAML::Node& node, const std::string& path, const std::string& ctx,
                         const std::vector<Link>& links, int link, double as, double ls,
                         PriorSigmas* priors) {
  yaml::CheckKeys(node, {"theta", "alpha", "a", "d", "beta"}, path, ctx);
  for (int v = 0; v < kValuesPerLink; ++v) {
    const YAML::Node value = node[LinkValueName(v)];
    if (!value) continue;
    const std::string key = ctx + "." + LinkValueName(v);
    if (link > 0 && !links[link - 1].is_parameter[v])
      throw InputError(yaml::Where(path, value, key),
                       "a tolerance is given for a value that is not a parameter of link " +
                           std::to_string(link));
    priors->entries.push_back({LinkValueName(v) + (link > 0 ? std::to_string(link) : std::string()),
                               Tolerance(value, path, key, IsAngle(v) ? as : ls)});
  }
}

// tolerances.planes: one {u, f} per plane of the file (u: both chart coordinates).
void ParsePlaneTolerances(const YAML::Node& tp, const std::string& path, int num_planes, double as,
                          double ls, PriorSigmas* priors) {
  if (!tp.IsSequence() || static_cast<int>(tp.size()) != num_planes)
    throw InputError(
        yaml::Where(path, tp, "tolerances.planes"),
        "expected a list of " + std::to_string(num_planes) + " entries, one per plane of the file");
  for (int p = 0; p < num_planes; ++p) {
    const std::string ctx = "tolerances.planes[" + std::to_string(p) + "]";
    yaml::CheckKeys(tp[p], {"u", "f"}, path, ctx);
    if (tp[p]["u"]) {
      const double u = Tolerance(tp[p]["u"], path, ctx + ".u", as);
      priors->entries.push_back({PlaneTermName(p, num_planes, "u1"), u});
      priors->entries.push_back({PlaneTermName(p, num_planes, "u2"), u});
    }
    if (tp[p]["f"])
      priors->entries.push_back(
          {PlaneTermName(p, num_planes, "f"), Tolerance(tp[p]["f"], path, ctx + ".f", ls)});
  }
}

// tolerances.base / tolerances.tool: {x, y, z (lengths), roll, pitch, yaw (angles)}.
void ParseFrameTolerances(const YAML::Node& node, const std::string& path, int frame, double as,
                          double ls, PriorSigmas* priors) {
  const std::string ctx = std::string("tolerances.") + kFrameNames[frame];
  yaml::CheckKeys(node, {"x", "y", "z", "roll", "pitch", "yaw"}, path, ctx);
  for (int k = 0; k < 6; ++k)
    if (const YAML::Node value = node[kFrameTermNames[k]])
      priors->entries.push_back(
          {FrameTermName(frame, k),
           Tolerance(value, path, ctx + "." + kFrameTermNames[k], k < 3 ? ls : as)});
}

// tolerances: the prior standard deviations `identify --prior` uses (identification/prior.h).
PriorSigmas ParseTolerances(const YAML::Node& root, const std::string& path,
                            const std::vector<Link>& links, int num_planes) {
  using namespace yaml;
  PriorSigmas priors;
  const YAML::Node t = root["tolerances"];
  if (!t) return priors;
  CheckKeys(t,
            {"angle_unit", "length_unit", "every_link", "links", "planes", "ranger_offset_mm",
             "ranger_scale_ppm", "base", "tool"},
            path, "tolerances");
  const double as =
      AngleScale(t["angle_unit"] ? String(t["angle_unit"], path, "tolerances.angle_unit") : "rad",
                 Where(path, t["angle_unit"], "tolerances.angle_unit"));
  const double ls =
      LengthScale(t["length_unit"] ? String(t["length_unit"], path, "tolerances.length_unit") : "m",
                  Where(path, t["length_unit"], "tolerances.length_unit"));
  if (t["every_link"])
    ParseLinkTolerances(t["every_link"], path, "tolerances.every_link", links, 0, as, ls, &priors);
  if (const YAML::Node tl = t["links"]) {
    if (!tl.IsSequence() || tl.size() != links.size())
      throw InputError(
          Where(path, tl, "tolerances.links"),
          "expected a list of " + std::to_string(links.size()) + " entries, one per link");
    for (std::size_t i = 0; i < tl.size(); ++i)
      ParseLinkTolerances(tl[i], path, "tolerances.links[" + std::to_string(i) + "]", links,
                          static_cast<int>(i) + 1, as, ls, &priors);
  }
  if (t["planes"]) ParsePlaneTolerances(t["planes"], path, num_planes, as, ls, &priors);
  for (int f = 0; f < 2; ++f)
    if (t[kFrameNames[f]]) ParseFrameTolerances(t[kFrameNames[f]], path, f, as, ls, &priors);
  if (t["ranger_offset_mm"])
    priors.entries.push_back({"ranger_offset", Tolerance(t["ranger_offset_mm"], path,
                                                         "tolerances.ranger_offset_mm", 1e-3)});
  if (t["ranger_scale_ppm"])
    priors.entries.push_back({"ranger_scale", Tolerance(t["ranger_scale_ppm"], path,
                                                        "tolerances.ranger_scale_ppm", 1e-6)});
  return priors;
}

// true_errors.ranger_offset_mm / ranger_scale_ppm: the true ranger's errors (SI out).
void ParseRangerErrors(const YAML::Node& root, const std::string& path, RobotFile* file) {
  using namespace yaml;
  const YAML::Node te = root["true_errors"];
  if (!te) return;
  if (te["ranger_offset_mm"])
    file->truth.ranger_offset =
        Number(te["ranger_offset_mm"], path, "true_errors.ranger_offset_mm") * 1e-3;
  if (te["ranger_scale_ppm"]) {
    file->truth.ranger_scale =
        Number(te["ranger_scale_ppm"], path, "true_errors.ranger_scale_ppm") * 1e-6;
    if (!(std::fabs(file->truth.ranger_scale) < 0.5))
      throw InputError(Where(path, te["ranger_scale_ppm"], "true_errors.ranger_scale_ppm"),
                       "expected a scale error in ppm, below 500,000 in magnitude");
  }
}

PriorSigmas PriorsFor(const RobotFile& rig, bool use_tolerances, const std::string& prior_sigma,
                      const std::string& tolerances_option, const std::string& prior_sigma_option) {
  PriorSigmas priors;
  if (use_tolerances) {
    if (rig.tolerances.empty())
      throw InputError(tolerances_option, "the robot file " + rig.path +
                                              " has no tolerances: (docs/FILE_FORMATS.md); give "
                                              "them there, or the priors by name");
    priors = rig.tolerances;
  }
  if (!prior_sigma.empty())
    priors = priors.OverriddenBy(PriorSigmas::Parse(prior_sigma, prior_sigma_option));
  return priors;
}

namespace {

// links[k].couple: {joint: j (1-based link number), multiplier: m, offset: o}.
std::vector<FileCoupling> ParseCouplings(const YAML::Node& root, const std::string& path) {
  const YAML::Node links = root["links"];
  const auto n = static_cast<int>(links.size());
  std::vector<FileCoupling> out;
  for (int k = 0; k < n; ++k) {
    const YAML::Node c = links[static_cast<std::size_t>(k)]["couple"];
    if (!c) continue;
    const std::string ctx = "links[" + std::to_string(k) + "].couple";
    if (!c.IsMap())
      throw InputError(yaml::Where(path, c, ctx),
                       "expected {joint: j, multiplier: m, offset: o}: the link number whose "
                       "joint this one follows");
    yaml::CheckKeys(c, {"joint", "multiplier", "offset"}, path, ctx);
    if (!c["joint"]) throw InputError(yaml::Where(path, c, ctx + ".joint"), "missing");
    FileCoupling f;
    f.link = k;
    const double j = yaml::Number(c["joint"], path, ctx + ".joint", false);
    if (j != std::floor(j) || j < 1 || j > n || static_cast<int>(j) == k + 1)
      throw InputError(yaml::Where(path, c["joint"], ctx + ".joint"),
                       "expected the number (1 to " + std::to_string(n) +
                           ") of another link, whose joint this one follows");
    f.follows = static_cast<int>(j) - 1;
    if (c["multiplier"]) f.multiplier = yaml::Number(c["multiplier"], path, ctx + ".multiplier");
    if (c["offset"]) f.offset = yaml::Number(c["offset"], path, ctx + ".offset", true);
    if (!std::isfinite(f.multiplier) || !std::isfinite(f.offset))
      throw InputError(yaml::Where(path, c, ctx), "expected a finite multiplier and offset");
    out.push_back(f);
  }
  for (const FileCoupling& f : out)
    for (const FileCoupling& g : out)
      if (g.link == f.follows)
        throw InputError(yaml::Where(path, links[static_cast<std::size_t>(f.link)]["couple"],
                                     "links[" + std::to_string(f.link) + "].couple.joint"),
                         "link " + std::to_string(f.follows + 1) +
                             " is itself coupled: follow the joint it follows");
  return out;
}

RobotFile ReadRobotYaml(const std::string& path, bool allow_couplings) {
  YAML::Node root = yaml::LoadFile(path);
  yaml::CheckKeys(
      root,
      {"name", "description", "links", "base", "tool", "true_errors", "tolerances", "plane",
       "planes", "ranger", "calibration", "masses", "compliance", "thermal", "environment"},
      path, "");
  if (root["calibration"] && !root["calibration"].IsMap())
    throw InputError(yaml::Where(path, root["calibration"], "calibration"),
                     "expected a mapping (the record lrcal identify --write-robot writes)");
  const std::string name = root["name"] ? yaml::String(root["name"], path, "name") : path;
  const std::vector<Link> links = ParseLinks(root, path);
  RobotFile file;
  file.couplings = ParseCouplings(root, path);
  if (!allow_couplings && !file.couplings.empty()) {
    const std::string ctx = "links[" + std::to_string(file.couplings[0].link) + "].couple";
    throw InputError(yaml::Where(path, root["links"][file.couplings[0].link]["couple"], ctx),
                     "a coupled link is calibrated as a tree of one chain (identify, "
                     "identifiability, design, simulate --sensor point|pose and studies read it "
                     "so); this command reads arms without couplings");
  }
  file.robot = RobotModel(name, links, path, ParseFixedTransform(root, path, "base"),
                          ParseFixedTransform(root, path, "tool"));
  file.truth.link_errors = ParseTrueErrors(root, path, links);
  file.planes = ParsePlanes(root, path);
  file.ranger = ParseRanger(root, path);
  file.path = path;
  file.robot.source = path;
  ParseRangerErrors(root, path, &file);
  ParseNonGeometric(root, path, &file);
  file.tolerances = ParseTolerances(root, path, links, file.planes ? file.planes->size() : 0);
  if (root["calibration"]) file.calibration = ParseCalibration(root["calibration"], path);
  return file;
}

}  // namespace

RobotFile LoadCoupledRobotFile(const std::string& path) {
  if (IsUrdfPath(path))
    throw InputError(path, "a URDF's couplings are its mimic joints (LoadUrdfChains)");
  return ReadRobotYaml(path, true);
}

RobotFile LoadRobotFile(const std::string& path, const std::string& tool_link,
                        const std::string& base_link) {
  if (IsUrdfPath(path)) return LoadUrdfRobotFile(path, tool_link, base_link);
  if (!tool_link.empty())
    throw SettingError(SettingSpec::Named("setup", "tool_link", "tool_link", "the ranger's link"),
                       "applies to a URDF robot; '" + path +
                           "' is a robot YAML file (its last frame is the tool)");
  if (!base_link.empty())
    throw SettingError(
        SettingSpec::Named("setup", "base_link", "base_link", "the chain's base link"),
        "applies to a URDF robot; '" + path +
            "' is a robot YAML file (its base frame is the chain's first)");
  return ReadRobotYaml(path, false);
}

namespace {

std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string LinkLine(const Link& link, const double* values) {
  std::string line = "  - {";
  if (link.joint == JointType::kPrismatic) line += "joint: prismatic, ";
  for (int v = 0; v < kValuesPerLink; ++v)
    line += std::string(LinkValueName(v)) + ": " + FileNumber(values[v]) + ", ";
  line += "parameters: [";
  bool first = true;
  for (int v = 0; v < kValuesPerLink; ++v)
    if (link.is_parameter[v]) {
      line += std::string(first ? "" : ", ") + LinkValueName(v);
      first = false;
    }
  return line + "], q_min: " + FileNumber(link.q_min) + ", q_max: " + FileNumber(link.q_max) +
         "}\n";
}

// base: / tool: lines for the transforms that are not the identity (m, rad).
std::string FixedTransformText(const RobotModel& robot) {
  std::string t;
  const std::pair<const char*, const RigidTransform*> frames[] = {{"base", &robot.base()},
                                                                  {"tool", &robot.tool()}};
  for (const auto& [key, transform] : frames) {
    if (transform->IsIdentity()) continue;
    const Eigen::Vector3d xyz = transform->translation, rpy = transform->Rpy();
    t += std::string(key) + ": {xyz: [" + FileNumber(xyz.x()) + ", " + FileNumber(xyz.y()) + ", " +
         FileNumber(xyz.z()) + "], rpy: [" + FileNumber(rpy.x()) + ", " + FileNumber(rpy.y()) +
         ", " + FileNumber(rpy.z()) + "]}  # m, rad\n";
  }
  return t;
}

std::string MatrixRows(const Eigen::MatrixXd& m) {
  std::string t;
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    t += "    - [";
    for (Eigen::Index j = 0; j < m.cols(); ++j) t += (j ? ", " : "") + FileNumber(m(i, j));
    t += "]\n";
  }
  return t;
}

std::string RecordText(const CalibrationRecord& r) {
  std::string t = "calibration:\n";
  t += "  data: " + Quoted(r.data_file) + "\n  data_fnv1a: " + Quoted(r.data_fnv1a) +
       "\n  date: " + Quoted(r.date) + "\n  lrcal: " + Quoted(r.lrcal) + "\n";
  t += "  sigma: " + FileNumber(r.sigma) + "  # m, one reading\n";
  t += "  sigma_source: " + Quoted(r.sigma_source) + "\n";
  t += "  parameters: [";
  for (std::size_t k = 0; k < r.parameters.size(); ++k) t += (k ? ", " : "") + r.parameters[k];
  t += "]\n  estimate: [";  // SI
  for (Eigen::Index k = 0; k < r.estimate.size(); ++k)
    t += (k ? ", " : "") + FileNumber(r.estimate[k]);
  t += "]\n  covariance:";
  if (r.covariance.size() == 0) {
    t += " null  # undefined: no residual degrees of freedom\n";
  } else {
    t += "  # SI, in the order of parameters\n";
    t += MatrixRows(r.covariance);
  }
  if (r.held.empty()) return t;
  t += "  held: [" + JoinList(r.held) + "]  # terms held at nominal\n  held_sigma: [";
  for (Eigen::Index k = 0; k < r.held_sigma.size(); ++k)
    t += (k ? ", " : "") + FileNumber(r.held_sigma[k]);
  t += "]  # SI, their prior standard deviations\n";
  t += "  held_defaulted: [" + JoinList(r.held_defaulted) + "]  # sigma is lrcal's default\n";
  t += "  estimate_shift:  # d(estimate)/d(held term): rows parameters, columns held\n";
  return t + MatrixRows(r.estimate_shift);
}

}  // namespace

std::string RobotFileText(const RobotFile& rig, const Eigen::VectorXd& link_values,
                          const std::optional<PlaneSet>& planes, const std::string& name,
                          const CalibrationRecord* record) {
  const RobotModel& robot = rig.robot;
  std::string t = "name: " + Quoted(name) + "\nlinks:\n";
  for (int i = 0; i < robot.num_links(); ++i)
    t += LinkLine(robot.links()[i], link_values.data() + kValuesPerLink * i);
  t += FixedTransformText(robot);
  const auto plane_text = [](const Plane& plane) {
    return "{normal: [" + FileNumber(plane.normal.x()) + ", " + FileNumber(plane.normal.y()) +
           ", " + FileNumber(plane.normal.z()) + "], offset: " + FileNumber(plane.offset);
  };
  if (planes && planes->size() == 1) {
    t += "plane: " + plane_text((*planes)[0]) + "}\n";
  } else if (planes) {
    t += "planes:\n";
    for (int p = 0; p < planes->size(); ++p)
      t += "  - " + plane_text((*planes)[p]) +
           (planes->name(p).empty() ? "" : ", name: " + Quoted(planes->name(p))) + "}\n";
  }
  t += "ranger: {min_range: " + FileNumber(rig.ranger.min_range) +
       ", max_range: " + FileNumber(rig.ranger.max_range) +
       ", max_incidence_deg: " + FileNumber(rig.ranger.max_incidence * 180.0 / M_PI) + "}\n";
  return record ? t + RecordText(*record) : t;
}

void WriteCalibratedRobotFile(const std::string& path, const RobotFile& rig,
                              const Eigen::VectorXd& link_values, const PlaneSet& planes,
                              const CalibrationRecord& record) {
  const std::string header = "# A calibrated robot: written by lrcal identify --write-robot from " +
                             record.data_file + ".\n# Nominal values are the estimates (SI: rad, " +
                             "m); the record below says from what.\n";
  WriteFileAtomically(path, header + RobotFileText(rig, link_values, planes,
                                                   rig.robot.name() + " (calibrated)", &record));
}

}  // namespace lrcal
