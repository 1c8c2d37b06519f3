// lrcal accuracy, and identify --predict-at: the calibrated arm's predicted accuracy at poses;
// accuracy --measured: its error where a tracker measured the tool.
#include <iostream>

#include "cli_common.h"
#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/identification/measured_accuracy.h"
#include "lrcal/io/calibration_record.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/tracker_data.h"

namespace lrcal::cli {

namespace {

// accuracy --measured: the model's error where a tracker measured the tool (measured_accuracy.h).
int MeasuredAccuracyCommand(const po::variables_map& vm) {
  const RobotFile rig = LoadRobot(vm);
  const std::unique_ptr<PointMeasurement> tracker = MakeTrackerKind(rig.robot, "point", vm);
  const std::string file = vm["measured"].as<std::string>();
  const MeasuredValues points =
      ReadTrackerMeasurements(file, RegistrationKind(rig.robot, tracker->setup()));
  const MeasuredAccuracy r = AccuracyAtMeasuredPoints(rig.robot, tracker->setup(), points);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j;
    j["measured"] = file;
    j["points"] = r.num_points;
    j["rms"] = r.rms;
    j["worst"] = r.worst;
    j["worst_point"] = r.worst_index + 1;
    j["registered"] = r.registered;
    j["instrument"] = {{"xyz", ToJson(Eigen::VectorXd(r.instrument.translation))},
                       {"rpy", ToJson(Eigen::VectorXd(r.instrument.Rpy()))}};
    Json errors = Json::array(), targets = Json::array();
    for (const Eigen::Vector3d& e : r.errors) errors.push_back({e.x(), e.y(), e.z()});
    for (const Eigen::Vector3d& t : r.targets) targets.push_back({t.x(), t.y(), t.z()});
    j["errors"] = errors;
    j["targets"] = targets;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "measured points: " << file << " (model " << rig.path << ")\n" << r.ToString();
  }
  return 0;
}

}  // namespace

int AccuracyCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal accuracy options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>(),
                  "poses to predict at: a configurations CSV (q1..qN, rad)")(
      "workspace", po::value<int>(),
      "or: this many poses drawn over the robot's joint ranges (non-singular arm)")(
      "seed", po::value<long long>()->default_value(1), "seed of the --workspace draw")(
      "measured", po::value<std::string>(),
      "or: a tracker's points (q1..qN, target, x, y, z in m: docs/FILE_FORMATS.md) not used in "
      "the calibration: the model's error at each, the instrument's frame (--instrument) and "
      "target offsets (--target) registered to them");
  AddTrackerGeometryOptions(o);
  po::variables_map vm;
  if (!Parse("accuracy", "--robot CAL.yaml --configs P.csv|--workspace N [options]", o, args, &vm))
    return 0;
  if (vm.count("measured")) {
    if (vm.count("configs") || vm.count("workspace"))
      throw InputError("--measured",
                       "give poses to predict at (--configs, --workspace) or "
                       "measured points to compare with, not both");
    return MeasuredAccuracyCommand(vm);
  }
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
