// Shared pieces of the lrcal command-line program (private to src/cli).
#pragma once

#include <algorithm>
#include <boost/program_options.hpp>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "lrcal/core/error.h"
#include "lrcal/core/settings.h"
#include "lrcal/core/strings.h"
#include "lrcal/io/contact_data.h"
#include "lrcal/io/result_json.h"
#include "lrcal/io/robot_data.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/scanner_data.h"
#include "lrcal/io/socket_data.h"
#include "lrcal/io/urdf.h"
#include "lrcal/measurement/contact_measurement.h"
#include "lrcal/measurement/measurement_set.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/measurement/pose_measurement.h"
#include "lrcal/measurement/scanner_measurement.h"
#include "lrcal/measurement/socket_measurement.h"

namespace lrcal::cli {

namespace po = boost::program_options;
using Json = ResultJson;

/// A subcommand: name, one-line summary, and its entry point (args exclude the subcommand).
struct Command {
  std::string name;
  std::string summary;
  std::function<int(const std::vector<std::string>&)> run;
};
const std::vector<Command>& Commands();

/// Parses `args` against `options`; prints help and returns false for --help. Unknown options and
/// bad values become InputErrors naming the option.
bool Parse(const std::string& command, const std::string& usage, po::options_description& options,
           const std::vector<std::string>& args, po::variables_map* vm,
           const po::positional_options_description* positional = nullptr);

/// --robot: a path (robot YAML or URDF) or a shipped name ("paper"); `tool_link` for a URDF.
RobotFile LoadRobot(const std::string& name_or_path, const std::string& tool_link = "");
/// A string option's value, or "" when it is not given.
std::string OptionalString(const po::variables_map& vm, const char* option);
/// --robot, --tool-link and --base-link.
RobotFile LoadRobot(const po::variables_map& vm);
/// True when --tool-link lists several links, or the robot's one chain has a coupled joint on it
/// (a URDF's mimic joint, a robot YAML file's couple:): a tree's chains (io/urdf.h
/// LoadRobotChains).
bool IsTreeRun(const po::variables_map& vm);
/// The chains of --robot from --base-link to each link of --tool-link (a URDF), or a robot YAML
/// file's one coupled chain.
UrdfChains LoadTreeChains(const po::variables_map& vm);
/// The robot at `path`, with --tool-link when it is a URDF: what a command reading two robots
/// (one may be a YAML file, one a URDF) gives each (export --like, joint-offsets; compensate).
RobotFile LoadRobotWithToolLink(const std::string& path, const po::variables_map& vm);
/// --nominal (LoadRobotWithToolLink), the robot `calibrated` was calibrated from: InputError
/// naming --nominal when their numbers of joints differ.
RobotFile LoadNominalRobot(const po::variables_map& vm, const RobotFile& calibrated);
/// Whether the last LoadRobot(vm) used --robot's default (the paper's arm) because none was
/// given: an input error then says so, since a forgotten --robot shows as joint values out of
/// range or a wrong number of joints rather than as itself.
bool RobotWasDefaulted();
/// --plane (repeated: several planes, in order) if given, else the robot file's plane(s);
/// InputError if neither.
PlaneSet ResolvePlanes(const RobotFile& rig, const po::variables_map& vm);

/// What every science command starts from: the robot file (--robot) and the planes (--plane).
struct Setup {
  RobotFile rig;
  PlaneSet planes;
};
Setup ResolveSetup(const po::variables_map& vm);
/// --estimate-plane (for every plane), --estimate-ranger, --estimate-base, --estimate-tool and
/// --fix, for `num_planes` planes. In a mixed run (`in_mix`) --fix is not applied: the mixed
/// kind holds the named terms (a name may be another kind's).
ParameterSet ResolveParameterSet(const RobotModel& robot, const po::variables_map& vm,
                                 int num_planes = 1, bool in_mix = false);
/// --estimate-base and --estimate-tool (parameter_set.h FrameTerms), read by ResolveParameterSet.
void AddFrameTermOptions(po::options_description& o);

/// --sensor (ranger, point, pose), --instrument and --target: which measurement a command reads
/// or makes and, for a tracker's point or pose, the nominal geometry (point_measurement.h).
void AddSensorOptions(po::options_description& o);
/// --instrument and --target alone (what `accuracy --measured` registers).
void AddTrackerGeometryOptions(po::options_description& o);
/// The --sensor value, checked (InputError naming --sensor and the kinds available), or "mixed"
/// for a list of kinds (ResolveSensors).
std::string ResolveSensor(const po::variables_map& vm);
/// --sensor as a list (point,contact: one kind per --data or --configs file, a mixed run),
/// checked: each a kind lrcal models, a kind's own options (--flush, --beams, --socket-distance,
/// ...) only with that kind in the list, --probe only in a mix.
std::vector<std::string> ResolveSensors(const po::variables_map& vm);
/// The tracker's nominal geometry from --instrument and --target (InputError naming the option).
PointSetup ResolvePointSetup(const po::variables_map& vm);
/// The point or pose kind (`sensor`) on `robot` with --instrument, --target and --fix.
/// The kinds made here take `in_mix` for a mixed run: --fix is then left to the mixed kind, and
/// a contact's or socket's tool point is --probe (or --target when no tracker is mixed in).
std::unique_ptr<PointMeasurement> MakeTrackerKind(const RobotModel& robot,
                                                  const std::string& sensor,
                                                  const po::variables_map& vm, bool in_mix = false);
/// The one tool point of --target (x,y,z, m, tool frame) of a constraint kind (`sensor`: socket,
/// contact); in a mixed run (`in_mix`) --probe if given, else --target unless a tracker's terms
/// take it. Refuses --instrument (InputError naming the option).
Eigen::Vector3d ResolveToolPoint(const po::variables_map& vm, const std::string& sensor,
                                 bool in_mix);
/// --socket x,y,z (repeatable; m, base frame): sockets' positions, in order of their ids
/// (InputError naming --socket for a value that is not three numbers).
std::vector<Eigen::Vector3d> ResolveSocketPositions(const po::variables_map& vm);
/// --socket-distance A,B=METRES (repeatable): the known distances between sockets.
std::vector<SocketDistance> ResolveSocketDistances(const po::variables_map& vm);
/// The socket kind on `robot` for `data` (its socket ids; the sockets' nominal positions are the
/// nominal model's mean tool point per socket) with the tool point from --target (x,y,z, one),
/// --socket-distance and --fix. Refuses --instrument (InputError naming it).
/// The scanner kind of --sensor scanner on `planes` with the robot file's ranger limits `range`:
/// --scanner (its frame in the tool frame), --beams and --fan-deg (the fan), --estimate-plane,
/// --fix. Throws InputError naming the option.
std::unique_ptr<ScannerMeasurement> MakeScannerKind(const RobotModel& robot, const PlaneSet& planes,
                                                    const RangerSpec& range,
                                                    const po::variables_map& vm,
                                                    bool in_mix = false);
std::unique_ptr<SocketMeasurement> MakeSocketKind(const RobotModel& robot, const SocketData& data,
                                                  const po::variables_map& vm, bool in_mix = false);
/// The contact kind on `robot` and `planes` (--plane or the robot file's), flush or not, with the
/// tool point from --target (x,y,z, one), the planes' terms from --estimate-plane and --fix.
/// Refuses --instrument (InputError naming it).
std::unique_ptr<ContactMeasurement> MakeContactKind(const RobotModel& robot, const PlaneSet& planes,
                                                    bool flush, const po::variables_map& vm,
                                                    bool in_mix = false);
/// --sigma-mrad: the standard deviation of one reading of a pose's orientation component.
void AddOrientationNoiseOption(po::options_description& o);
/// --sigma-mrad in rad (InputError naming it unless finite and > 0, or ≥ 0 with `allow_zero`:
/// a simulation may be noise-free, a fit's weights need a σ).
double ResolveSigmaAngle(const po::variables_map& vm, bool allow_zero);
/// Throws InputError naming the first of `options` given on the command line (not defaulted):
/// they are the ranger's and mean nothing to `sensor`.
void RefuseRangerOptions(const po::variables_map& vm, const std::string& sensor,
                         const std::vector<std::string>& options);

/// The terms to hold at nominal: --fix's names, where a link value's class ("theta", "alpha", "a",
/// "d", "beta") stands for every parameter of that class on `robot`, and what --estimate's preset
/// holds (offsets: all but each joint's own offset, θ of a revolute joint or d of a prismatic one;
/// lengths: all but a and d; all: none). InputError naming --estimate for another preset.
std::vector<std::string> FixList(const po::variables_map& vm, const RobotModel& robot);
/// --estimate offsets|lengths|all (identify, identifiability).
void AddEstimatePresetOption(po::options_description& o);

/// --seed: a non-negative integer.
std::uint64_t ParseSeed(const po::variables_map& vm);

enum class Format { kText, kJson };
Format ResolveFormat(const po::variables_map& vm);

/// Adds --robot, --tool-link, --plane, --format to `options` (the options every science command
/// takes).
void AddCommonOptions(po::options_description& options);

/// A setting's value as its option's default shows it: 12 significant digits, as
/// SettingSpec::FromSi rounds it.
inline std::string ShortNumber(double value) {
  std::ostringstream out;
  out << std::setprecision(12) << value;
  return out.str();
}

/// Adds one option per setting of an option struct (settings.h): --NAME with the struct's
/// default in the setting's unit and its help line, the unit and range appended. `only`, if not
/// empty, names the settings to add (the others are not options of this command).
template <class Options>
void AddSettingOptions(po::options_description& options,
                       const std::vector<SettingField<Options>>& fields,
                       const std::vector<std::string>& only = {}) {
  for (const SettingField<Options>& f : fields) {
    if (!only.empty() && std::find(only.begin(), only.end(), f.spec.name) == only.end()) continue;
    const std::string option = f.spec.Spelling(Frontend::kCommandLine).substr(2);
    const std::string help = std::string(f.spec.help) + "; " + f.spec.Expected().substr(9);
    if (f.spec.integer)
      options.add_options()(
          option.c_str(),
          po::value<long long>()->default_value(static_cast<long long>(f.Default())), help.c_str());
    else  // shown as the schema rounds it (0.2, not 0.20000000000000001)
      options.add_options()(
          option.c_str(), po::value<double>()->default_value(f.Default(), ShortNumber(f.Default())),
          help.c_str());
  }
}

/// Reads the options AddSettingOptions added into `options`, each checked by its spec (exit 2
/// naming the option and the range in the option's unit).
template <class Options>
void ReadSettingOptions(const po::variables_map& vm,
                        const std::vector<SettingField<Options>>& fields, Options* options) {
  for (const SettingField<Options>& f : fields) {
    const std::string option = f.spec.Spelling(Frontend::kCommandLine).substr(2);
    if (!vm.count(option)) continue;  // not an option of this command
    const double value =
        f.spec.integer ? static_cast<double>(vm[option].as<long long>()) : vm[option].as<double>();
    const double si = value * f.spec.to_si;
    if (!f.spec.Allows(si)) throw SettingError(f.spec, si).Respelled(Frontend::kCommandLine);
    f.Set(options, si);
  }
}

// The non-geometric model (commands_environment.cc): --estimate-compliance and --estimate-thermal
// for identify and identifiability; --gravity and --temperature-c for simulate.
void AddNonGeometricOptions(po::options_description& o);
bool AsksNonGeometric(const po::variables_map& vm);
int NonGeometricIdentify(const po::variables_map& vm, const std::string& data_file,
                         const IdentificationOptions& options);
int NonGeometricIdentifiability(const po::variables_map& vm, const std::string& configs_file,
                                const IdentifiabilityOptions& options);
void AddEnvironmentOptions(po::options_description& o);
/// True when simulate must read the arm in its environment: --gravity or --temperature-c, the
/// configurations' environment columns, or a robot file whose true arm bends or grows.
bool SimulatesEnvironment(const po::variables_map& vm, const RobotFile& rig,
                          const TargetedConfigurations& configs);
int NonGeometricSimulate(const po::variables_map& vm, const RobotFile& rig, const PlaneSet& planes,
                         TargetedConfigurations configs, const NoiseModel& noise);

int KinematicsCommand(const std::vector<std::string>& args);
int SampleCommand(const std::vector<std::string>& args);
int SimulateCommand(const std::vector<std::string>& args);
int IdentifyCommand(const std::vector<std::string>& args);
int IdentifiabilityCommand(const std::vector<std::string>& args);
int PaperCommand(const std::vector<std::string>& args);
int RunCommand(const std::vector<std::string>& args);
int DesignCommand(const std::vector<std::string>& args);
int ReportCommand(const std::vector<std::string>& args);
int PlanCommand(const std::vector<std::string>& args);
int PlanAccuracyCommand(const std::vector<std::string>& args);
int StatusCommand(const std::vector<std::string>& args);
int MergeCommand(const std::vector<std::string>& args);
int AggregateCommand(const std::vector<std::string>& args);
int TrialCommand(const std::vector<std::string>& args);
int AccuracyCommand(const std::vector<std::string>& args);
int ExportCommand(const std::vector<std::string>& args);
int CompensateCommand(const std::vector<std::string>& args);
/// Runs `python3 -m lrcal.report ARGUMENTS` (the report pages, src/python/lrcal/report) with
/// Debian's /usr/bin/python3 (where python3-pandas and python3-matplotlib are; LRCAL_PYTHON
/// overrides) and lrcal's own Python package first on its path: next to this program in the build
/// tree (build/python), or where `cmake --install` put it. Returns the module's exit code (1 if
/// it did not exit normally). Throws InputError when the package is not found.
int RunReportModule(const std::vector<std::string>& arguments);
}  // namespace lrcal::cli
