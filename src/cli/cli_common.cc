#include "cli_common.h"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string_view>

#include "lrcal/core/data_dir.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/urdf.h"

namespace lrcal::cli {

bool Parse(const std::string& command, const std::string& usage, po::options_description& options,
           const std::vector<std::string>& args, po::variables_map* vm,
           const po::positional_options_description* positional) {
  options.add_options()("help,h", "show this help");
  try {
    po::command_line_parser parser(args);
    parser.options(options);
    if (positional) parser.positional(*positional);
    po::store(parser.run(), *vm);
    if (vm->count("help")) {
      std::cout << "usage: lrcal " << command << " " << usage << "\n\n" << options << "\n";
      return false;
    }
    po::notify(*vm);
  } catch (const po::error& e) {
    throw InputError("command line", std::string(e.what()) + " (see lrcal " + command + " --help)");
  }
  return true;
}

void AddCommonOptions(po::options_description& options) {
  options.add_options()("robot", po::value<std::string>()->default_value("paper"),
                        "robot file (YAML or URDF) or shipped robot name")(
      "tool-link", po::value<std::string>(),
      "URDF robots: the link whose frame is the ranger's (default: the URDF's only end link)")(
      "base-link", po::value<std::string>(),
      "URDF robots: the link the chain starts from, its frame the base frame (default: the "
      "root); the path may run up the tree against the URDF, as from a foot to a hand")(
      "plane", po::value<std::vector<std::string>>()->composing(),
      "plane n.p + f = 0 as nx,ny,nz,f: the normal in the base frame (normalised) and f in m; "
      "repeat for several planes (a CSV's plane column numbers them from 1 in this order); "
      "default: the robot file's plane(s)")(
      "format", po::value<std::string>()->default_value("text"), "output: text or json");
}

RobotFile LoadRobot(const std::string& name_or_path, const std::string& tool_link) {
  return LoadRobotFile(ResolveRobotPath(name_or_path), tool_link);
}

namespace {
bool robot_defaulted = false;
}  // namespace

bool RobotWasDefaulted() { return robot_defaulted; }

std::string OptionalString(const po::variables_map& vm, const char* option) {
  return vm.count(option) ? vm[option].as<std::string>() : "";
}

RobotFile LoadRobot(const po::variables_map& vm) {
  robot_defaulted = vm["robot"].defaulted();
  return LoadRobotFile(ResolveRobotPath(vm["robot"].as<std::string>()),
                       OptionalString(vm, "tool-link"), OptionalString(vm, "base-link"));
}

bool IsTreeRun(const po::variables_map& vm) {
  if (vm.count("tool-link") && SplitList(vm["tool-link"].as<std::string>()).size() > 1) return true;
  // One chain with a coupled joint on it (a URDF's mimic joint, a robot YAML file's couple:): a
  // tree of one chain, its coupled joint a coupling.
  const std::string path = ResolveRobotPath(vm["robot"].as<std::string>());
  if (!IsUrdfPath(path) && (vm.count("tool-link") || vm.count("base-link")))
    return false;  // refused by name where the robot is read
  return RobotChainIsCoupled(path, OptionalString(vm, "tool-link"),
                             OptionalString(vm, "base-link"));
}

UrdfChains LoadTreeChains(const po::variables_map& vm) {
  const std::string path = ResolveRobotPath(vm["robot"].as<std::string>());
  std::vector<std::string> tools = SplitList(OptionalString(vm, "tool-link"));
  if (tools.empty()) tools.emplace_back();  // the URDF's only end link
  return LoadRobotChains(path, tools, OptionalString(vm, "base-link"));
}

RobotFile LoadRobotWithToolLink(const std::string& path, const po::variables_map& vm) {
  if (!IsUrdfPath(path)) return LoadRobot(path);
  return LoadRobotFile(ResolveRobotPath(path), OptionalString(vm, "tool-link"),
                       OptionalString(vm, "base-link"));
}

RobotFile LoadNominalRobot(const po::variables_map& vm, const RobotFile& calibrated) {
  RobotFile nominal = LoadRobotWithToolLink(vm["nominal"].as<std::string>(), vm);
  if (nominal.robot.num_links() != calibrated.robot.num_links())
    throw InputError("--nominal", "has " + std::to_string(nominal.robot.num_links()) +
                                      " joints but --robot has " +
                                      std::to_string(calibrated.robot.num_links()));
  return nominal;
}

PlaneSet ResolvePlanes(const RobotFile& rig, const po::variables_map& vm) {
  if (vm.count("plane")) {
    const auto& texts = vm["plane"].as<std::vector<std::string>>();
    std::vector<Plane> planes;
    for (std::size_t k = 0; k < texts.size(); ++k)
      planes.push_back(Plane::Parse(
          texts[k], texts.size() == 1 ? "--plane" : "--plane (" + std::to_string(k + 1) + ")"));
    return PlaneSet(std::move(planes), {}, "--plane");
  }
  if (rig.planes) return *rig.planes;
  throw InputError("--plane",
                   "the robot file '" + rig.path + "' has no plane: give --plane nx,ny,nz,f");
}

Setup ResolveSetup(const po::variables_map& vm) {
  Setup setup{LoadRobot(vm), PlaneSet{}};
  setup.planes = ResolvePlanes(setup.rig, vm);
  return setup;
}

void AddSensorOptions(po::options_description& o) {
  o.add_options()("sensor", po::value<std::string>()->default_value("ranger"),
                  "the measurement: ranger (a distance to a plane), point (a tracker's reflector "
                  "in the instrument's frame), pose (a 6-D probe: position and orientation), "
                  "socket (the tool point seated in fixed sockets: a CSV's socket column), "
                  "contact (the tool point on a plane: a CSV's plane column) or scanner (a fan of "
                  "beams, each reading its distance to the plane: a CSV's beam and h columns)");
  AddTrackerGeometryOptions(o);
  o.add_options()("beams", po::value<int>()->default_value(1),
                  "scanner: the number of beams in the fan (1 to 256)")(
      "fan-deg", po::value<double>()->default_value(0.0),
      "scanner: the fan's half angle (deg): the beams spread evenly over [-A, A] about the "
      "scanner's z axis, in its x-z plane")(
      "scanner", po::value<std::string>()->default_value("0,0,0,0,0,0"),
      "scanner: its frame in the tool frame as x,y,z,roll,pitch,yaw (m, rad): the beams' origin "
      "(terms target_x..z) and the fan's plane (terms scanner_roll, _pitch, _yaw)");
  o.add_options()("probe", po::value<std::string>(),
                  "mixed sensors: the tool point of the contacts or sockets as x,y,z (m, tool "
                  "frame) when --target is the tracker's (--sensor point,contact)");
  o.add_options()("flush", po::bool_switch(),
                  "contact: every contact is flush (the tool's z axis square to the plane: two "
                  "more values per configuration), where a file has no flush column");
  o.add_options()("socket-distance", po::value<std::vector<std::string>>()->composing(),
                  "socket: a known distance between two sockets as A,B=METRES (socket ids, m; "
                  "e.g. 0,1=0.05): the length reference that fixes the arm's scale; repeat for "
                  "several (a tree: each places one more socket)");
}

void AddTrackerGeometryOptions(po::options_description& o) {
  o.add_options()("instrument", po::value<std::string>()->default_value("0,0,0,0,0,0"),
                  "point and pose: the instrument's frame in the base frame as "
                  "x,y,z,roll,pitch,yaw (m, rad; URDF's origin convention); its six terms are "
                  "estimated unless fixed")(
      "target", po::value<std::vector<std::string>>()->composing(),
      "point and pose: a target's offset in the tool frame as x,y,z (m), for pose optionally "
      "x,y,z,roll,pitch,yaw (rad); repeat for several (a CSV's target column numbers them from "
      "1); default: one target at the tool frame's origin");
}

std::vector<std::string> ResolveSensors(const po::variables_map& vm) {
  const std::string text = vm["sensor"].as<std::string>();
  const std::vector<std::string> sensors = SplitList(text);
  // "mixed": each --data file says its rows' kinds in a sensor column (csv.h SplitBySensor).
  if (sensors.size() == 1 && sensors[0] == "mixed") return sensors;
  if (sensors.empty())
    throw InputError("--sensor",
                     "expected ranger, scanner, point, pose, socket or contact, or a "
                     "list of them (one per --data file)");
  for (const std::string& sensor : sensors)
    if (!IsMeasurementKindName(sensor))
      throw InputError("--sensor", "'" + CellExcerpt(sensor) +
                                       "' is not a sensor lrcal models: expected " +
                                       MeasurementKindNameList());
  const auto has = [&](const char* kind) {
    return std::find(sensors.begin(), sensors.end(), kind) != sensors.end();
  };
  const std::string named = sensors.size() == 1 ? "--sensor " + sensors[0] : "--sensor " + text;
  if (!has("scanner"))
    for (const char* option : {"beams", "fan-deg", "scanner"})
      if (vm.count(option) && !vm[option].defaulted())
        throw InputError(std::string("--") + option,
                         "is the scanner sensor's; " + named + " does not take it");
  if (!has("contact") && vm.count("flush") && vm["flush"].as<bool>())
    throw InputError("--flush", "is the contact sensor's; " + named + " does not take it");
  if (!has("socket") && vm.count("socket-distance"))
    throw InputError("--socket-distance", "is the socket sensor's; " + named + " does not take it");
  if (sensors.size() == 1 && vm.count("probe"))
    throw InputError("--probe",
                     "is the probe's tip when contacts or sockets are mixed with a "
                     "tracker; alone, " +
                         named + " takes its tool point from --target");
  return sensors;
}

std::string ResolveSensor(const po::variables_map& vm) {
  const std::vector<std::string> sensors = ResolveSensors(vm);
  return sensors.size() == 1 ? sensors[0] : "mixed";  // "mixed" itself too
}

namespace {

// "x,y,z" or "x,y,z,roll,pitch,yaw" (m, rad) as a transform; `sizes` says which counts are allowed.
RigidTransform ParseXyzRpy(const std::string& text, const std::string& option, bool allow_three) {
  const std::vector<std::string> parts = SplitList(text);
  const char* expected =
      allow_three ? "x,y,z (m) or x,y,z,roll,pitch,yaw (m, rad)" : "x,y,z,roll,pitch,yaw (m, rad)";
  if (parts.size() != 6 && !(allow_three && parts.size() == 3))
    throw InputError(option,
                     "expected " + std::string(expected) + "; got '" + CellExcerpt(text) + "'");
  double v[6] = {0, 0, 0, 0, 0, 0};
  for (std::size_t k = 0; k < parts.size(); ++k)
    if (!ParseAngleExpression(parts[k], &v[k]))
      throw InputError(
          option, "'" + CellExcerpt(parts[k]) + "' is not a number (expected " + expected + ")");
  return RigidTransform::FromXyzRpy(Eigen::Vector3d(v[0], v[1], v[2]),
                                    Eigen::Vector3d(v[3], v[4], v[5]));
}

}  // namespace

PointSetup ResolvePointSetup(const po::variables_map& vm) {
  PointSetup setup;
  setup.instrument = ParseXyzRpy(vm["instrument"].as<std::string>(), "--instrument", false);
  if (!vm.count("target")) return setup;
  const auto& texts = vm["target"].as<std::vector<std::string>>();
  setup.targets.clear();
  for (std::size_t k = 0; k < texts.size(); ++k) {
    const RigidTransform t = ParseXyzRpy(
        texts[k], texts.size() == 1 ? "--target" : "--target (" + std::to_string(k + 1) + ")",
        true);
    setup.targets.push_back(t.translation);
    setup.target_orientations.push_back(t.rotation);
  }
  if (static_cast<int>(texts.size()) > PointSetup::kMaxTargets)
    throw InputError("--target", "expected at most " + std::to_string(PointSetup::kMaxTargets) +
                                     " targets, got " + std::to_string(texts.size()));
  return setup;
}

void AddEstimatePresetOption(po::options_description& o) {
  o.add_options()("estimate", po::value<std::string>()->default_value("all"),
                  "which of the arm's terms to estimate: all, offsets (each joint's zero offset: "
                  "theta, or d for a prismatic joint; what most controllers take) or lengths (a "
                  "and d); --fix holds more (a class such as alpha holds every alpha)");
}

std::vector<std::string> FixList(const po::variables_map& vm, const RobotModel& robot) {
  std::vector<std::string> out;
  const auto hold = [&](const std::string& name) {
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  };
  const auto each_parameter = [&](const std::function<bool(int link, int value)>& held) {
    for (int k : robot.parameter_indices())
      if (held(k / kValuesPerLink, k % kValuesPerLink)) hold(robot.ValueName(k));
  };
  if (vm.count("fix"))
    for (const std::string& name : SplitList(vm["fix"].as<std::string>())) {
      int value = -1;
      for (int v = 0; v < kValuesPerLink; ++v)
        if (name == LinkValueName(v)) value = v;
      if (value < 0)
        hold(name);
      else  // a class: every parameter of it ("alpha": alpha1 ... alphaN)
        each_parameter([&](int, int v) { return v == value; });
    }
  const std::string preset =
      vm.count("estimate") ? vm["estimate"].as<std::string>() : std::string("all");
  if (preset == "offsets") {
    // Keep each joint's own offset: θ of a revolute joint, d of a prismatic one.
    each_parameter([&](int link, int v) {
      const bool prismatic =
          robot.links()[static_cast<std::size_t>(link)].joint == JointType::kPrismatic;
      return v != (prismatic ? kD : kTheta);
    });
  } else if (preset == "lengths") {
    each_parameter([](int, int v) { return v != kA && v != kD; });
  } else if (preset != "all") {
    throw InputError("--estimate", "'" + CellExcerpt(preset) +
                                       "' is not a preset: expected offsets (the joints' zero "
                                       "offsets), lengths (a and d) or all");
  }
  return out;
}

namespace {

// --fix as a list, or none in a mixed run (the mixed kind holds them: a name may be another
// kind's).
std::vector<std::string> FixedTerms(const po::variables_map& vm, const RobotModel& robot,
                                    bool in_mix) {
  if (in_mix) return {};
  return FixList(vm, robot);
}

}  // namespace

std::unique_ptr<PointMeasurement> MakeTrackerKind(const RobotModel& robot,
                                                  const std::string& sensor,
                                                  const po::variables_map& vm, bool in_mix) {
  const std::vector<std::string> fixed = FixedTerms(vm, robot, in_mix);
  PointSetup setup = ResolvePointSetup(vm);
  if (sensor == "pose") return std::make_unique<PoseMeasurement>(robot, setup, fixed, "--fix");
  for (std::size_t k = 0; k < setup.target_orientations.size(); ++k)
    if (!setup.target_orientations[k].isIdentity(0))
      throw InputError(
          setup.targets.size() == 1 ? "--target" : "--target (" + std::to_string(k + 1) + ")",
          "an orientation is given but --sensor point reads positions only: give "
          "x,y,z, or use --sensor pose");
  setup.target_orientations.clear();
  return std::make_unique<PointMeasurement>(robot, setup, fixed, "--fix");
}

void RefuseRangerOptions(const po::variables_map& vm, const std::string& sensor,
                         const std::vector<std::string>& options) {
  for (const std::string& option : options)
    if (vm.count(option) && !vm[option].defaulted())
      throw InputError(
          "--" + option,
          "is the ranger's; --sensor " + sensor + " does not take it (its own terms " +
              (sensor == "socket"    ? "are the tool point and the sockets: --target, "
                                       "--socket-distance, --fix)"
               : sensor == "contact" ? "are the tool point and the planes: --target, --plane, "
                                       "--estimate-plane, --flush, --fix)"
               : sensor == "scanner"
                   ? "are the scanner's frame and the planes: --scanner, --beams, "
                     "--fan-deg, --plane, --estimate-plane, --fix)"
                   : "are the instrument's frame and the targets: --instrument, "
                     "--target, --fix)"));
}

std::vector<Eigen::Vector3d> ResolveSocketPositions(const po::variables_map& vm) {
  std::vector<Eigen::Vector3d> positions;
  if (!vm.count("socket")) return positions;
  for (const std::string& text : vm["socket"].as<std::vector<std::string>>()) {
    const std::vector<std::string> parts = SplitList(text);
    double v[3];
    if (parts.size() != 3 || !ParseDecimal(parts[0], &v[0]) || !ParseDecimal(parts[1], &v[1]) ||
        !ParseDecimal(parts[2], &v[2]))
      throw InputError("--socket", "'" + CellExcerpt(text) + "': expected x,y,z (m)");
    positions.emplace_back(v[0], v[1], v[2]);
  }
  return positions;
}

std::vector<SocketDistance> ResolveSocketDistances(const po::variables_map& vm) {
  std::vector<SocketDistance> distances;
  if (!vm.count("socket-distance")) return distances;
  for (const std::string& text : vm["socket-distance"].as<std::vector<std::string>>())
    distances.push_back(SocketDistance::Parse(text, "--socket-distance"));
  return distances;
}

Eigen::Vector3d ResolveToolPoint(const po::variables_map& vm, const std::string& sensor,
                                 bool in_mix) {
  if (in_mix && vm.count("probe"))
    return ParseXyzRpy(vm["probe"].as<std::string>(), "--probe", true).translation;
  if (in_mix) {
    const std::vector<std::string> sensors = ResolveSensors(vm);
    const bool tracker = std::find(sensors.begin(), sensors.end(), "point") != sensors.end() ||
                         std::find(sensors.begin(), sensors.end(), "pose") != sensors.end() ||
                         (vm.count("instrument") && !vm["instrument"].defaulted());
    if (tracker)
      throw InputError("--probe", "missing: with --sensor " + vm["sensor"].as<std::string>() +
                                      " --target is the tracker's; give the " + sensor +
                                      "s' tool point as --probe x,y,z (m, tool frame)");
  }
  if (vm.count("instrument") && !vm["instrument"].defaulted())
    throw InputError("--instrument", "--sensor " + sensor +
                                         " has no instrument: the tool touches fixed things "
                                         "given in the base frame");
  const PointSetup point = ResolvePointSetup(vm);
  if (point.targets.size() != 1 ||
      (!point.target_orientations.empty() && !point.target_orientations[0].isIdentity(0)))
    throw InputError("--target",
                     "--sensor " + sensor + " takes one tool point as x,y,z (m, tool frame)");
  return point.targets[0];
}

std::unique_ptr<ContactMeasurement> MakeContactKind(const RobotModel& robot, const PlaneSet& planes,
                                                    bool flush, const po::variables_map& vm,
                                                    bool in_mix) {
  ContactSetup setup;
  setup.planes = planes;
  setup.tool_point = ResolveToolPoint(vm, "contact", in_mix);
  setup.flush = flush;
  const PlaneTerms terms = PlaneTerms::Parse(
      vm.count("estimate-plane") ? vm["estimate-plane"].as<std::string>() : "none");
  setup.plane_terms.assign(static_cast<std::size_t>(planes.size()), terms);
  const std::vector<std::string> fixed = FixedTerms(vm, robot, in_mix);
  return std::make_unique<ContactMeasurement>(robot, setup, fixed, "--fix");
}

std::unique_ptr<ScannerMeasurement> MakeScannerKind(const RobotModel& robot, const PlaneSet& planes,
                                                    const RangerSpec& range,
                                                    const po::variables_map& vm, bool in_mix) {
  ScannerSetup setup;
  setup.planes = planes;
  setup.range = range;
  const RigidTransform frame = ParseXyzRpy(vm["scanner"].as<std::string>(), "--scanner", false);
  setup.origin = frame.translation;
  setup.orientation = frame.rotation;
  setup.beam_angles = ScannerSetup::FanOf(vm["beams"].as<int>(), vm["fan-deg"].as<double>(),
                                          "--beams", "--fan-deg");
  const PlaneTerms terms = PlaneTerms::Parse(
      vm.count("estimate-plane") ? vm["estimate-plane"].as<std::string>() : "none");
  setup.plane_terms.assign(static_cast<std::size_t>(planes.size()), terms);
  const std::vector<std::string> fixed = FixedTerms(vm, robot, in_mix);
  return std::make_unique<ScannerMeasurement>(robot, setup, fixed, "--fix");
}

std::unique_ptr<SocketMeasurement> MakeSocketKind(const RobotModel& robot, const SocketData& data,
                                                  const po::variables_map& vm, bool in_mix) {
  const Eigen::Vector3d tool_point = ResolveToolPoint(vm, "socket", in_mix);
  const std::vector<std::string> fixed = FixedTerms(vm, robot, in_mix);
  return std::make_unique<SocketMeasurement>(
      robot,
      SocketSetupFromData(robot, data.ids, data.values.configs, tool_point,
                          ResolveSocketDistances(vm), "--socket-distance"),
      fixed, "--fix");
}

void AddOrientationNoiseOption(po::options_description& o) {
  o.add_options()("sigma-mrad", po::value<double>()->default_value(0.2),
                  "--sensor pose: standard deviation of one reading of an orientation component "
                  "(mrad); its rows weigh (sigma-mm/sigma-mrad)^2 against the positions'");
}

double ResolveSigmaAngle(const po::variables_map& vm, bool allow_zero) {
  const double sigma = vm["sigma-mrad"].as<double>();
  if (!(sigma > 0 || (allow_zero && sigma == 0)) || !std::isfinite(sigma))
    throw InputError("--sigma-mrad",
                     std::string("expected a finite standard deviation ") +
                         (allow_zero ? ">= 0" : "> 0 (it weighs the orientations)") +
                         " (mrad), got " + FormatExact(sigma));
  return sigma * 1e-3;
}

ParameterSet ResolveParameterSet(const RobotModel& robot, const po::variables_map& vm,
                                 int num_planes, bool in_mix) {
  PlaneTerms terms;
  if (vm.count("estimate-plane"))
    terms = PlaneTerms::Parse(vm["estimate-plane"].as<std::string>(), "--estimate-plane");
  const std::vector<std::string> fixed = FixedTerms(vm, robot, in_mix);
  RangerTerms ranger;
  if (vm.count("estimate-ranger"))
    ranger = RangerTerms::Parse(vm["estimate-ranger"].as<std::string>(), "--estimate-ranger");
  FrameTerms frames[2];
  for (int f = 0; f < 2; ++f) {
    const std::string option = std::string("estimate-") + kFrameNames[f];
    if (vm.count(option))
      frames[f] = FrameTerms::Parse(vm[option].as<std::string>(), "--" + option);
  }
  return MakeParameterSet(robot, std::vector<PlaneTerms>(num_planes, terms), fixed, "--fix", ranger,
                          frames[0], frames[1]);
}

void AddFrameTermOptions(po::options_description& o) {
  o.add_options()("estimate-base", po::value<std::string>()->default_value("none"),
                  "base transform terms to estimate: none, all, xyz, rpy, or a list of x, y, z, "
                  "roll, pitch, yaw (frame 0 in the base frame: p0 + xyz, R0 Rz Ry Rx)")(
      "estimate-tool", po::value<std::string>()->default_value("none"),
      "tool transform terms to estimate, as --estimate-base (the ranger's frame in the last "
      "link's frame)");
}

std::uint64_t ParseSeed(const po::variables_map& vm) {
  const long long s = vm["seed"].as<long long>();
  if (s < 0) throw InputError("--seed", "expected a non-negative integer");
  return static_cast<std::uint64_t>(s);
}

Format ResolveFormat(const po::variables_map& vm) {
  const std::string f = vm["format"].as<std::string>();
  if (f == "text") return Format::kText;
  if (f == "json") return Format::kJson;
  throw InputError("--format", "expected text or json, got '" + f + "'");
}

namespace {

// The folder that holds lrcal's Python package (lrcal/report/__main__.py), from this program's.
std::string PythonPackageParent() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path bin = fs::read_symlink("/proc/self/exe", ec).parent_path();
  std::vector<fs::path> candidates = {bin / "python"};  // the build tree
#ifdef LRCAL_PYTHON_DIR_FROM_BIN
  candidates.insert(candidates.begin(), bin / LRCAL_PYTHON_DIR_FROM_BIN);  // installed
#endif
  std::string tried;
  for (const fs::path& dir : candidates) {
    if (fs::exists(dir / "lrcal" / "report" / "__main__.py", ec))
      return fs::weakly_canonical(dir, ec).string();
    tried += (tried.empty() ? "" : ", ") + dir.string();
  }
  throw InputError("lrcal.report",
                   "lrcal's Python package is not next to this program (looked in " + tried +
                       "); it is built and installed with lrcal when python3 is found");
}

}  // namespace

int RunReportModule(const std::vector<std::string>& arguments) {
  const std::string parent = PythonPackageParent();
  // Debian's interpreter, where python3-pandas and python3-matplotlib are installed (a python3
  // earlier on PATH, e.g. from pyenv, may not have them); LRCAL_PYTHON overrides.
  std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  if (const char* p = std::getenv("LRCAL_PYTHON")) python = p;
  std::string path = parent;
  if (const char* p = std::getenv("PYTHONPATH"); p != nullptr && *p != '\0')
    path += ":" + std::string(p);
  // The interpreter is started directly (no shell, so no quoting), with this environment and
  // lrcal's package first on PYTHONPATH.
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e)
    if (std::string_view(*e).substr(0, 11) != "PYTHONPATH=") env.emplace_back(*e);
  env.push_back("PYTHONPATH=" + path);
  std::vector<std::string> args = {python, "-m", "lrcal.report"};
  args.insert(args.end(), arguments.begin(), arguments.end());
  const auto pointers = [](std::vector<std::string>& strings) {
    std::vector<char*> p;
    for (std::string& s : strings) p.push_back(s.data());
    p.push_back(nullptr);
    return p;
  };
  std::vector<char*> argv = pointers(args), envp = pointers(env);
  // As system() does: Ctrl-C and Ctrl-\ reach the interpreter, while lrcal waits for it and then
  // removes what it prepared; the child gets their default actions back.
  struct sigaction ignore {
  }, old_int{}, old_quit{};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGINT, &ignore, &old_int);
  sigaction(SIGQUIT, &ignore, &old_quit);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGQUIT);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
  std::cout.flush();
  std::cerr.flush();
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, python.c_str(), nullptr, &attr, argv.data(), envp.data());
  posix_spawnattr_destroy(&attr);
  int status = -1;  // not an exit status: a failed wait reads as failure
  if (spawned == 0) {
    pid_t waited = 0;
    do {
      waited = waitpid(pid, &status, 0);
    } while (waited < 0 && errno == EINTR);
  }
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGQUIT, &old_quit, nullptr);
  if (spawned != 0)
    throw InputError("LRCAL_PYTHON", "cannot run the Python interpreter '" + python +
                                         "': " + std::strerror(spawned));
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

}  // namespace lrcal::cli
