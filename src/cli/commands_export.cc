// lrcal export: a robot (a calibrated robot file, a URDF, a shipped robot) written for the
// robot's software: URDF, a D-H table (CSV) or a robot YAML file.
#include <iostream>

#include "cli_common.h"
#include "lrcal/core/json.h"
#include "lrcal/io/urdf.h"

namespace lrcal::cli {

int ExportCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal export options");
  o.add_options()("robot", po::value<std::string>()->default_value("paper"),
                  "robot file (YAML or URDF) or shipped robot name; its nominal values are "
                  "written (a calibrated file's are the estimates)")(
      "tool-link", po::value<std::string>(),
      "URDF robots: the ranger's link; with --like, the tool link of that URDF")(
      "like", po::value<std::string>(),
      "urdf: write the calibration into this URDF (the user's own): every element kept, only "
      "the origins of the chain's joints to --tool-link changed")(
      "plane", po::value<std::vector<std::string>>()->composing(),
      "yaml: plane(s) n.p + f = 0 as nx,ny,nz,f (base frame, f in m) to write instead of the "
      "robot file's")("format", po::value<std::string>()->default_value("urdf"),
                      "urdf, dh-table or yaml")("out", po::value<std::string>(),
                                                "file to write (default: standard output)");
  po::variables_map vm;
  if (!Parse("export",
             "--robot R --format urdf|dh-table|yaml [--like USER.urdf --tool-link L] [--out FILE]",
             o, args, &vm))
    return 0;
  if (vm.count("like") && vm["format"].as<std::string>() != "urdf")
    throw InputError("--like", "writes into a URDF: give --format urdf (the default)");
  if (vm.count("like") && vm.count("plane"))
    throw InputError("--plane", "a URDF holds no planes; --like writes the arm only");
  // With --like, --tool-link names the link of that URDF (and of --robot if it is a URDF too).
  const RobotFile rig = vm.count("like") && !IsUrdfPath(vm["robot"].as<std::string>())
                            ? LoadRobot(vm["robot"].as<std::string>(), "")
                            : LoadRobot(vm);
  const std::string text =
      vm.count("like")
          ? UrdfLikeText(vm["like"].as<std::string>(),
                         vm.count("tool-link") ? vm["tool-link"].as<std::string>() : "", rig.robot,
                         rig.robot.nominal_values())
          : RobotExportText(
                rig, vm["format"].as<std::string>(),
                vm.count("plane") ? std::optional<PlaneSet>(ResolvePlanes(rig, vm)) : rig.planes);
  if (!vm.count("out")) {
    std::cout << text;
    return 0;
  }
  WriteFileAtomically(vm["out"].as<std::string>(), text);
  std::cerr << "lrcal export: wrote " << vm["out"].as<std::string>() << "\n";
  return 0;
}

}  // namespace lrcal::cli
