// lrcal export: a robot (a calibrated robot file, a URDF, a shipped robot) written for the
// robot's software: URDF, a D-H table (CSV) or a robot YAML file.
#include <iostream>

#include "cli_common.h"
#include "lrcal/core/json.h"
#include "lrcal/core/strings.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/io/urdf.h"
#include "lrcal/kinematics/joint_offsets.h"

namespace lrcal::cli {

namespace {

// Writes `text` to --out (atomically) or standard output.
void Emit(const po::variables_map& vm, const std::string& text) {
  if (!vm.count("out")) {
    std::cout << text;
    return;
  }
  WriteFileAtomically(vm["out"].as<std::string>(), text);
  std::cerr << "lrcal export: wrote " << vm["out"].as<std::string>() << "\n";
}

// export --format joint-offsets: the offsets that make --nominal approximate --robot, fitted and
// judged at --count configurations drawn over the joint ranges (WorkspacePoses).
int ExportJointOffsets(const po::variables_map& vm) {
  for (const char* option : {"like", "plane"})
    if (vm.count(option))
      throw InputError(std::string("--") + option, "is not taken by --format joint-offsets");
  if (!vm.count("nominal"))
    throw InputError("--nominal",
                     "missing: joint offsets are against the model the controller "
                     "runs; name it (a robot file, or a URDF with --tool-link)");
  const std::string robot_path = vm["robot"].as<std::string>();
  const std::string nominal_path = vm["nominal"].as<std::string>();
  const RobotFile calibrated = LoadRobotWithToolLink(robot_path, vm);
  const RobotFile nominal = LoadNominalRobot(vm, calibrated);
  const int n = nominal.robot.num_links();
  const int count = vm["count"].as<int>();
  if (count < 1 || count > 100000)  // WorkspacePosesSetting's range
    throw InputError("--count",
                     "expected 1 to 100000 configurations, got " + std::to_string(count));
  const ConfigurationSet configs =
      WorkspacePoses(nominal.robot, count, static_cast<std::uint64_t>(ParseSeed(vm)));
  const JointOffsetFit fit = FitJointOffsets(nominal.robot, calibrated.robot, configs);
  std::string text =
      "# Joint offsets of " + robot_path + " against " + nominal_path +
      ": the calibrated arm at joint values q is the nominal model at q + offset (add the offset "
      "to "
      "a joint reading before the nominal model uses it; subtract it from a command planned on the "
      "nominal model).\n# Fitted to the calibrated model's tool poses (positions, and orientations "
      "weighed as points 0.1 m from the tool origin) at " +
      std::to_string(count) + " configurations drawn over the joint ranges (seed " +
      std::to_string(ParseSeed(vm)) + ").\n# The simplification's error there: tool position RMS " +
      Fixed(fit.rms * 1e3) + " mm, worst " + Fixed(fit.worst * 1e3) + " mm; orientation RMS " +
      Fixed(fit.orientation_rms * 1e3) + " mrad, worst " + Fixed(fit.orientation_worst * 1e3) +
      " mrad (the nominal model alone: RMS " + Fixed(fit.nominal_rms * 1e3) + " mm, worst " +
      Fixed(fit.nominal_worst * 1e3) + " mm).\njoint,name,offset,unit\n";
  for (int j = 0; j < n; ++j) {
    const Link& link = nominal.robot.links()[static_cast<std::size_t>(j)];
    text += std::to_string(j + 1) + "," + link.joint_name + "," + FileNumber(fit.offsets[j]) + "," +
            (link.joint == JointType::kPrismatic ? "m" : "rad") + "\n";
  }
  Emit(vm, text);
  return 0;
}

}  // namespace

int ExportCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal export options");
  o.add_options()("robot", po::value<std::string>()->default_value("paper"),
                  "robot file (YAML or URDF) or shipped robot name; its nominal values are "
                  "written (a calibrated file's are the estimates)")(
      "tool-link", po::value<std::string>(),
      "URDF robots: the ranger's link; with --like, the tool link of that URDF")(
      "base-link", po::value<std::string>(),
      "URDF robots: the link the chain starts from (default: the root)")(
      "like", po::value<std::string>(),
      "urdf: write the calibration into this URDF (the user's own): every element kept, only "
      "the origins of the chain's joints to --tool-link changed")(
      "plane", po::value<std::vector<std::string>>()->composing(),
      "yaml: plane(s) n.p + f = 0 as nx,ny,nz,f (base frame, f in m) to write instead of the "
      "robot file's")("format", po::value<std::string>()->default_value("urdf"),
                      "urdf, dh-table, yaml or joint-offsets")(
      "nominal", po::value<std::string>(),
      "joint-offsets: the robot (file or URDF, with --tool-link) the controller runs; the offsets "
      "make it approximate --robot")(
      "count", po::value<int>()->default_value(1000),
      "joint-offsets: configurations drawn over the joint ranges (non-singular, as accuracy "
      "--workspace draws them) the offsets are fitted and judged at")(
      "seed", po::value<long long>()->default_value(1), "joint-offsets: their random seed")(
      "out", po::value<std::string>(), "file to write (default: standard output)");
  po::variables_map vm;
  if (!Parse("export",
             "--robot R --format urdf|dh-table|yaml|joint-offsets [--like USER.urdf] [--nominal N] "
             "[--out F]",
             o, args, &vm))
    return 0;
  if (vm["format"].as<std::string>() == "joint-offsets") return ExportJointOffsets(vm);
  if (vm.count("like") && vm["format"].as<std::string>() != "urdf")
    throw InputError("--like", "writes into a URDF: give --format urdf (the default)");
  if (vm.count("like") && vm.count("base-link"))
    throw InputError("--base-link",
                     "--like writes a chain from the URDF's root link into it; a "
                     "chain from another link is exported with --format urdf or "
                     "dh-table");
  if (vm.count("like") && vm.count("plane"))
    throw InputError("--plane", "a URDF holds no planes; --like writes the arm only");
  // With --like, --tool-link names the link of that URDF (and of --robot if it is a URDF too).
  const RobotFile rig =
      vm.count("like") ? LoadRobotWithToolLink(vm["robot"].as<std::string>(), vm) : LoadRobot(vm);
  const std::string text =
      vm.count("like")
          ? UrdfLikeText(vm["like"].as<std::string>(),
                         vm.count("tool-link") ? vm["tool-link"].as<std::string>() : "", rig.robot,
                         rig.robot.nominal_values())
          : RobotExportText(
                rig, vm["format"].as<std::string>(),
                vm.count("plane") ? std::optional<PlaneSet>(ResolvePlanes(rig, vm)) : rig.planes);
  Emit(vm, text);
  return 0;
}

}  // namespace lrcal::cli
