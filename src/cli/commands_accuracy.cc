// lrcal accuracy, and identify --predict-at: the calibrated arm's predicted accuracy at poses.
#include <iostream>

#include "cli_common.h"
#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/io/calibration_record.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"

namespace lrcal::cli {

int AccuracyCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal accuracy options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>(),
                  "poses to predict at: a configurations CSV (q1..qN, rad)")(
      "workspace", po::value<int>(),
      "or: this many poses drawn over the robot's joint ranges (non-singular arm)")(
      "seed", po::value<long long>()->default_value(1), "seed of the --workspace draw");
  po::variables_map vm;
  if (!Parse("accuracy", "--robot CAL.yaml --configs P.csv|--workspace N [options]", o, args, &vm))
    return 0;
  if (vm.count("configs") == vm.count("workspace"))
    throw InputError("--configs/--workspace",
                     "give exactly one: a poses CSV or a number of poses to draw");
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const ConfigurationSet configs =
      vm.count("configs") ? ReadRobotPoses(vm["configs"].as<std::string>(), rig.robot)
                          : WorkspacePoses(rig.robot, vm["workspace"].as<int>(), ParseSeed(vm));
  const AccuracyPrediction poses = PredictCalibratedAccuracy(rig, setup.planes, configs);
  const CalibrationRecord& r = *rig.calibration;
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = PoseAccuracyJson(poses, configs);
    j["sigma"] = r.sigma;
    if (vm.count("workspace"))
      j["workspace"] = {{"poses", configs.size()}, {"seed", vm["seed"].as<long long>()}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "covariance of " << rig.path << " (sigma " << Fixed(r.sigma * 1e3, 4)
              << " mm per reading)\n";
    if (vm.count("workspace"))
      std::cout << configs.size() << " poses drawn over the joint ranges (seed "
                << vm["seed"].as<long long>() << ")\n";
    std::cout << AccuracyPredictionText(poses);
  }
  return 0;
}

}  // namespace lrcal::cli
