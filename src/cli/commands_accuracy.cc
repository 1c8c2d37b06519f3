// lrcal accuracy, and identify --predict-at: the calibrated arm's predicted accuracy at poses;
// accuracy --measured: its error where a tracker measured the tool; accuracy --sockets: its
// consistency with socket data.
#include <iostream>

#include "cli_common.h"
#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/identification/measured_accuracy.h"
#include "lrcal/io/calibration_record.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/socket_data.h"
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
    Json j = {{"measured", file}};
    j.update(MeasuredAccuracyJson(r));
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "measured points: " << file << " (model " << rig.path << ")\n" << r.ToString();
  }
  return 0;
}

// accuracy --sockets: the model's consistency with socket data not used in its calibration
// (measured_accuracy.h ConsistencyAtSockets).
int SocketAccuracyCommand(const po::variables_map& vm) {
  const RobotFile rig = LoadRobot(vm);
  const std::string file = vm["sockets"].as<std::string>();
  const SocketData data = ReadSocketData(file, rig.robot);
  const PointSetup point = ResolvePointSetup(vm);
  if (point.targets.size() != 1)
    throw InputError("--target", "--sockets takes one tool point as x,y,z (m, tool frame)");
  const SocketConsistency r = ConsistencyAtSockets(rig.robot, point.targets[0], data.values.configs,
                                                   data.ids, ResolveSocketDistances(vm));
  if (ResolveFormat(vm) == Format::kJson) {
    Json j;
    j["sockets_file"] = file;
    j["rms_spread"] = r.rms_spread;
    Json sockets = Json::array(), distances = Json::array();
    for (const SocketConsistency::Socket& s : r.sockets)
      sockets.push_back({{"id", s.id},
                         {"configurations", s.count},
                         {"centre", {s.centre.x(), s.centre.y(), s.centre.z()}},
                         {"rms_spread", s.rms_spread},
                         {"worst_spread", s.worst_spread}});
    for (const SocketConsistency::Distance& d : r.distances)
      distances.push_back({{"sockets", {d.known.a, d.known.b}},
                           {"known", d.known.metres},
                           {"predicted", d.predicted},
                           {"error", d.error}});
    j["sockets"] = sockets;
    j["distances"] = distances;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "socket data: " << file << " (model " << rig.path << ")\n" << r.ToString();
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
      "target offsets (--target) registered to them")(
      "sockets", po::value<std::string>(),
      "or: socket data (q1..qN, socket: docs/FILE_FORMATS.md) not used in the calibration: the "
      "spread of the model's tool point (--target, default the tool frame's origin) in each "
      "socket and, with --socket-distance, the error of the sockets' distances")(
      "socket-distance", po::value<std::vector<std::string>>()->composing(),
      "with --sockets: a known distance between two sockets as A,B=METRES; repeatable");
  AddTrackerGeometryOptions(o);
  po::variables_map vm;
  if (!Parse("accuracy", "--robot CAL.yaml --configs P.csv|--workspace N [options]", o, args, &vm))
    return 0;
  if (vm.count("sockets")) {
    if (vm.count("configs") || vm.count("workspace") || vm.count("measured"))
      throw InputError("--sockets",
                       "give poses to predict at (--configs, --workspace), measured points "
                       "(--measured) or socket data (--sockets): one of them");
    return SocketAccuracyCommand(vm);
  }
  if (vm.count("socket-distance"))
    throw InputError("--socket-distance", "goes with --sockets (socket data to judge a model on)");
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
