// The calibration-core subcommands: kinematics, sample, simulate, identify, identifiability,
// paper.
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "cli_common.h"
#include "lrcal/core/json.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/design/identifiability_remedies.h"
#include "lrcal/identification/cross_validation.h"
#include "lrcal/identification/identification.h"
#include "lrcal/identification/measured_accuracy.h"
#include "lrcal/identification/significance.h"
#include "lrcal/io/calibration_record.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/kinematics_report.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/tracker_data.h"
#include "lrcal/io/urdf.h"
#include "lrcal/measurement/chain_measurement.h"
#include "lrcal/measurement/mixed_measurement.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/simulation.h"
#include "lrcal/measurement/truth.h"
#include "lrcal/paper/paper_case.h"
#include "lrcal/report/calibration_report.h"

namespace lrcal::cli {

namespace {

// The one file of a repeatable file option (--data, --configs) for a single kind.
std::string SingleFile(const po::variables_map& vm, const char* option) {
  const auto& files = vm[option].as<std::vector<std::string>>();
  if (files.size() != 1)
    throw InputError(std::string("--") + option,
                     "given " + std::to_string(files.size()) +
                         " times: for several files name one kind per file in --sensor "
                         "(--sensor point,contact --" +
                         option + " a.csv --" + option + " b.csv)");
  return files[0];
}

std::string DataFile(const po::variables_map& vm) { return SingleFile(vm, "data"); }

// --prior (the robot file's tolerances:) and --prior-sigma (over them): the priors to use.
PriorSigmas ResolvePriors(const po::variables_map& vm, const RobotFile& rig) {
  return PriorsFor(rig, vm.count("prior") && vm["prior"].as<bool>(),
                   vm.count("prior-sigma") ? vm["prior-sigma"].as<std::string>() : "", "--prior",
                   "--prior-sigma");
}

// What is known of the terms a calibration holds at nominal: the robot file's tolerances (used
// for this whether or not --prior makes them priors), with --prior-sigma over them.
PriorSigmas KnownTolerances(const po::variables_map& vm, const RobotFile& rig) {
  return PriorsFor(rig, !rig.tolerances.empty(),
                   vm.count("prior-sigma") ? vm["prior-sigma"].as<std::string>() : "", "--prior",
                   "--prior-sigma");
}

IdentificationOptions ResolveIdentificationOptions(const po::variables_map& vm,
                                                   const RobotFile& rig) {
  IdentificationOptions options;
  options.solver = ParseName(kSolverNames, vm["solver"].as<std::string>(), "--solver", "solver");
  options.loss = ParseName(kRobustLossNames, vm["loss"].as<std::string>(), "--loss", "loss");
  ReadSettingOptions(vm, IdentificationOptions::Settings(), &options);
  if (options.loss_scale_sigma > 0 && vm.count("loss-scale-mm") && !vm["loss-scale-mm"].defaulted())
    throw InputError("--loss-scale-sigma",
                     "give the loss scale once: in mm (--loss-scale-mm) or in multiples of "
                     "--sigma-mm (--loss-scale-sigma), not both");
  options.fix_dependent_parameters = vm["auto-fix"].as<bool>();
  options.priors = ResolvePriors(vm, rig);
  options.encoder_sigma = vm["encoder-sigma-mrad"].as<double>() * 1e-3;
  options.check_linearisation = true;  // one fit: the check's cost is not noticed
  options.Validate();
  return options;
}

}  // namespace

int KinematicsCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal kinematics options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>()->required(),
                  "configurations CSV (q1..qN, rad)")(
      "model", po::value<std::string>()->default_value("nominal"),
      "nominal, or true: the simulated truth (every true link value, the ranger's true offset and "
      "scale): what simulate --sigma-mm 0 reads")("jacobian", po::bool_switch(),
                                                  "also print the identification Jacobian row")(
      "estimate-ranger", po::value<std::string>()->default_value("none"),
      "ranger terms to estimate: none, offset, scale, offset,scale (reading = (1+s) h + o)")(
      "estimate-plane", po::value<std::string>()->default_value("none"),
      "plane terms in the Jacobian: none, normal, offset, normal,offset")(
      "fix", po::value<std::string>(), "parameters left out of the Jacobian, comma-separated");
  AddFrameTermOptions(o);
  po::variables_map vm;
  if (!Parse("kinematics", "--configs C.csv [options]", o, args, &vm)) return 0;
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  const std::string which = vm["model"].as<std::string>();
  if (which != "nominal" && which != "true")
    throw InputError("--model", "expected nominal or true, got '" + which + "'");
  const TargetedConfigurations configs =
      ReadRobotConfigurations(vm["configs"].as<std::string>(), robot, &planes);
  const KinematicsReport report =
      ReportKinematics(rig, planes, ResolveParameterSet(robot, vm, planes.size()), which == "true",
                       configs, vm["jacobian"].as<bool>());
  if (ResolveFormat(vm) == Format::kJson) {
    std::cout << report.rows.dump(2) << "\n";
  } else {
    std::cout << report.ToText();
  }
  return 0;
}

int SampleCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal sample options");
  AddCommonOptions(o);
  o.add_options()("count", po::value<int>()->default_value(101),
                  "configurations to draw (per plane when several planes are given)")(
      "seed", po::value<long long>()->default_value(1), "random seed")(
      "validation", po::bool_switch(), "validation set: anywhere in the workspace, no beam needed")(
      "out", po::value<std::string>()->required(), "output CSV (q1..qN)");
  AddSettingOptions(o, SamplingOptions::Settings(), {"min_singular_value"});
  po::variables_map vm;
  if (!Parse("sample", "--out C.csv [options]", o, args, &vm)) return 0;
  CheckOutputFile(vm["out"].as<std::string>(), "--out");
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  const int count = vm["count"].as<int>();
  if (count < 1 || count > 1000000)
    throw InputError("--count",
                     "expected 1 to 1,000,000 configurations, got " + std::to_string(count));
  SamplingOptions options;
  options.ranger = rig.ranger;
  ReadSettingOptions(vm, SamplingOptions::Settings(), &options);
  options.require_beam_hit = !vm["validation"].as<bool>();
  options.Validate();
  SamplingReport report;
  const bool validation = vm["validation"].as<bool>();
  TargetedConfigurations configs = SampleConfigurations(
      robot, planes, std::vector<int>(planes.size(), count),
      RandomStream(ParseSeed(vm), 0, 0,
                   validation ? RandomPurpose::kValidation : RandomPurpose::kPool),
      options, &report);
  WriteConfigurations(vm["out"].as<std::string>(), configs);
  std::cerr << "lrcal sample: " << report.ToString() << "; wrote " << vm["out"].as<std::string>()
            << "\n";
  return 0;
}

namespace {

// simulate --sensor point|pose: the tracker's values of the true arm (the robot file's
// true_errors; the instrument and targets as given), each the mean of --repetitions readings.
// The tracker `truth` read at `configs` with the options' noise, written for `nominal` (its
// instrument and targets) to --out.
int SimulateTracker(const po::variables_map& vm, const std::string& sensor,
                    const PointMeasurement& truth, const PointMeasurement& nominal,
                    const TargetedConfigurations& configs, const std::string& note) {
  NoiseModel noise;
  ReadSettingOptions(vm, NoiseModel::Settings(), &noise);
  noise.sigma_angle = ResolveSigmaAngle(vm, true);
  MeasuredValues data;
  SimulateMeasurements(truth, configs, noise,
                       RandomStream(ParseSeed(vm), 0, 0, RandomPurpose::kNoise), &data);
  const std::string path = vm["out"].as<std::string>();
  WriteTrackerMeasurements(path, nominal, data);
  std::cerr << "lrcal simulate: " << data.size() << " " << sensor
            << " measurements (each the mean of " << noise.repetitions << " readings" << note
            << ") written to " << path << "\n";
  return 0;
}

int TrackerSimulate(const po::variables_map& vm, const std::string& sensor) {
  RefuseRangerOptions(
      vm, sensor,
      {"plane", "encoder-sigma-mrad", "form-sigma-mm", "outlier-fraction", "outlier-sigma-mm"});
  const RobotFile rig = LoadRobot(vm);
  const std::unique_ptr<PointMeasurement> nominal = MakeTrackerKind(rig.robot, sensor, vm);
  const RobotModel true_robot = rig.truth.TrueRobot(rig.robot);
  const std::unique_ptr<PointMeasurement> truth = TrackerKindOn(true_robot, *nominal);
  const TargetedConfigurations configs =
      ReadRobotTargetConfigurations(vm["configs"].as<std::string>(), rig.robot,
                                    static_cast<int>(nominal->setup().targets.size()));
  return SimulateTracker(vm, sensor, *truth, *nominal, configs, "");
}

// simulate on a URDF chain with a mimic joint (a tree run of one chain): the tracker kinds, the
// coupled joint's value computed from the joint it follows whatever the file says of it
// (chain_measurement.h), written in the chain's columns. Several tool links are refused: simulate
// writes one chain's file.
int CoupledChainSimulate(const po::variables_map& vm, const std::string& sensor) {
  const UrdfChains tree = LoadTreeChains(vm);
  if (tree.chains.size() != 1)
    throw InputError("--tool-link",
                     "simulate writes one chain's file: run it once per tool link "
                     "(the same --configs log serves every chain)");
  if (sensor != "point" && sensor != "pose")
    throw InputError("--sensor",
                     "a chain with a coupled joint is simulated for a tracker (point "
                     "or pose); " +
                         sensor + " is not yet");
  RefuseRangerOptions(
      vm, sensor,
      {"plane", "encoder-sigma-mrad", "form-sigma-mm", "outlier-fraction", "outlier-sigma-mm"});
  const RobotFile& rig = tree.chains[0];
  const std::shared_ptr<const PointMeasurement> kind = MakeTrackerKind(rig.robot, sensor, vm);
  const ChainMeasurement chain(kind, tree.placements[0]);
  const std::string file = vm["configs"].as<std::string>();
  const TargetedConfigurations logged =
      TargetConfigurations(ReadChainCsv(file, tree, 0), rig.robot.num_links(),
                           static_cast<int>(kind->setup().targets.size()));
  const TargetedConfigurations configs =
      chain.ChainConfigurations(chain.RobotConfigurations(logged));
  CheckJointRanges(configs, rig.robot, file);
  return SimulateTracker(vm, sensor, *kind, *kind, configs,
                         ", the coupled joints following theirs");
}

// simulate --sensor socket: the configurations (a CSV with a socket column: where to start)
// moved until the true arm's tool point sits in its socket (--socket x,y,z per socket id, in
// order of the ids) plus a play of --sigma-mm per axis.
int SocketSimulate(const po::variables_map& vm) {
  RefuseRangerOptions(
      vm, "socket",
      {"plane", "encoder-sigma-mrad", "form-sigma-mm", "outlier-fraction", "outlier-sigma-mm"});
  const RobotFile rig = LoadRobot(vm);
  const SocketData starts = ReadSocketData(vm["configs"].as<std::string>(), rig.robot);
  if (!vm.count("socket"))
    throw InputError("--socket",
                     "--sensor socket simulates sockets at known true positions: "
                     "give --socket x,y,z (m, base frame) for each socket id of the "
                     "configurations, in ascending order of id");
  const std::vector<Eigen::Vector3d> positions = ResolveSocketPositions(vm);
  if (positions.size() != starts.ids.size())
    throw InputError("--socket", "the configurations name " + std::to_string(starts.ids.size()) +
                                     " socket(s); " + std::to_string(positions.size()) +
                                     " --socket positions given");
  const RobotModel true_robot = rig.truth.TrueRobot(rig.robot);
  SocketSetup setup;
  setup.ids = starts.ids;
  setup.positions = positions;
  const PointSetup point = ResolvePointSetup(vm);
  setup.tool_point = point.targets[0];
  setup.distances = ResolveSocketDistances(vm);
  const SocketMeasurement truth(true_robot, setup);
  NoiseModel noise;
  ReadSettingOptions(vm, NoiseModel::Settings(), &noise);
  // One seating per row unless --repetitions says otherwise (a ranger's default is 10 readings).
  if (vm.count("repetitions") && vm["repetitions"].defaulted()) noise.repetitions = 1;
  MeasuredValues data;
  std::vector<std::string> misses;
  const int missed = SimulateSocketMeasurements(
      truth, starts.values.configs, noise, RandomStream(ParseSeed(vm), 0, 0, RandomPurpose::kNoise),
      &data, &misses);
  const std::string path = vm["out"].as<std::string>();
  WriteSocketData(path, setup.ids, data);
  std::cerr << "lrcal simulate: " << data.size() << " socket seatings written to " << path;
  if (missed > 0) std::cerr << " (" << missed << " start(s) out of reach, left out)";
  std::cerr << "\n";
  return 0;
}

// simulate --sensor contact: the configurations (a CSV with a plane column: where to start)
// moved until the true arm's tool point touches its plane (and, with --flush, the tool is square
// to it), plus a play of --sigma-mm along the normal and a tilt of --sigma-mrad.
int ContactSimulate(const po::variables_map& vm) {
  RefuseRangerOptions(
      vm, "contact",
      {"encoder-sigma-mrad", "form-sigma-mm", "outlier-fraction", "outlier-sigma-mm"});
  const Setup setup = ResolveSetup(vm);
  const RobotModel true_robot = setup.rig.truth.TrueRobot(setup.rig.robot);
  const bool flush = vm["flush"].as<bool>();
  const ContactData starts =
      ReadContactData(vm["configs"].as<std::string>(), setup.rig.robot, setup.planes, flush);
  const std::unique_ptr<ContactMeasurement> truth =
      MakeContactKind(true_robot, setup.planes, starts.flush, vm);
  NoiseModel noise;
  ReadSettingOptions(vm, NoiseModel::Settings(), &noise);
  noise.sigma_angle = ResolveSigmaAngle(vm, true);
  // One contact per row unless --repetitions says otherwise (a ranger's default is 10 readings).
  if (vm["repetitions"].defaulted()) noise.repetitions = 1;
  MeasuredValues data;
  const int missed =
      SimulateContactMeasurements(*truth, starts.values.configs, noise,
                                  RandomStream(ParseSeed(vm), 0, 0, RandomPurpose::kNoise), &data);
  const std::string path = vm["out"].as<std::string>();
  WriteContactData(path, data, starts.flush);
  std::cerr << "lrcal simulate: " << data.size() << (starts.flush ? " flush" : "")
            << " contacts written to " << path;
  if (missed > 0) std::cerr << " (" << missed << " start(s) out of reach, left out)";
  std::cerr << "\n";
  return 0;
}

// simulate --sensor scanner: every beam of the fan read at each configuration of the CSV
// (q…, plane) by the true arm (the robot file's true errors) from the nominal scanner on the
// nominal planes, each reading the mean of --repetitions with noise --sigma-mm.
int ScannerSimulate(const po::variables_map& vm) {
  RefuseRangerOptions(
      vm, "scanner",
      {"encoder-sigma-mrad", "form-sigma-mm", "outlier-fraction", "outlier-sigma-mm"});
  const Setup setup = ResolveSetup(vm);
  const RobotModel true_robot = setup.rig.truth.TrueRobot(setup.rig.robot);
  const TargetedConfigurations configs =
      ReadRobotConfigurations(vm["configs"].as<std::string>(), setup.rig.robot, &setup.planes);
  const std::unique_ptr<ScannerMeasurement> truth =
      MakeScannerKind(true_robot, setup.planes, setup.rig.ranger, vm);
  NoiseModel noise;
  ReadSettingOptions(vm, NoiseModel::Settings(), &noise);
  MeasuredValues data;
  std::vector<std::string> misses;
  const int missed = SimulateMeasurements(*truth, configs, noise,
                                          RandomStream(ParseSeed(vm), 0, 0, RandomPurpose::kNoise),
                                          &data, &misses);
  const std::string path = vm["out"].as<std::string>();
  WriteScannerData(path, data, truth->num_beams());
  std::cerr << "lrcal simulate: " << data.size() << " scans of " << truth->num_beams()
            << " beam(s) written to " << path;
  if (missed > 0) {
    const auto first =
        std::find_if(misses.begin(), misses.end(), [](const std::string& m) { return m != "ok"; });
    std::cerr << " (" << missed << " configuration(s) left out: " << *first << ", ...)";
  }
  std::cerr << "\n";
  return 0;
}

}  // namespace

int SimulateCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal simulate options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>()->required(), "configurations CSV")(
      "seed", po::value<long long>()->default_value(1), "random seed")(
      "out", po::value<std::string>()->required(), "measurement CSV to write");
  AddSensorOptions(o);
  AddSettingOptions(o, NoiseModel::Settings());
  AddOrientationNoiseOption(o);
  AddEnvironmentOptions(o);
  o.add_options()("socket", po::value<std::vector<std::string>>()->composing(),
                  "--sensor socket: a socket's true position as x,y,z (m, base frame), one per "
                  "socket id of the configurations, in ascending order of id");
  po::variables_map vm;
  if (!Parse("simulate", "--configs C.csv --out M.csv [options]", o, args, &vm)) return 0;
  CheckOutputFile(vm["out"].as<std::string>(), "--out");
  const std::string sensor = ResolveSensor(vm);
  if (sensor != "mixed" && IsTreeRun(vm)) return CoupledChainSimulate(vm, sensor);
  if (sensor == "mixed")
    throw InputError("--sensor",
                     "simulate writes one kind's file: run it once per kind, then "
                     "calibrate from all of them with identify --sensor " +
                         vm["sensor"].as<std::string>() + " and one --data per kind");
  if (sensor == "socket") return SocketSimulate(vm);
  if (sensor == "contact") return ContactSimulate(vm);
  if (sensor == "scanner") return ScannerSimulate(vm);
  if (vm.count("socket"))
    throw InputError("--socket",
                     "is the socket sensor's; --sensor " + sensor + " does not take it");
  if (sensor != "ranger") {
    for (const char* option : {"gravity", "temperature-c"})
      if (vm.count(option))
        throw InputError(std::string("--") + option,
                         "an environment is simulated for the ranger; --sensor " + sensor +
                             " reads the geometric arm");
    return TrackerSimulate(vm, sensor);
  }
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  const TargetedConfigurations configs =
      ReadRobotConfigurations(vm["configs"].as<std::string>(), robot, &planes);
  NoiseModel noise;
  noise.ranger_offset = rig.truth.ranger_offset;  // the robot file's true ranger errors
  noise.ranger_scale = rig.truth.ranger_scale;
  ReadSettingOptions(vm, NoiseModel::Settings(), &noise);
  if (static_cast<double>(noise.repetitions) * configs.size() > static_cast<double>(kMaxCsvRows))
    throw InputError("--repetitions", "would write " + std::to_string(configs.size()) + " x " +
                                          std::to_string(noise.repetitions) +
                                          " readings; at most " + std::to_string(kMaxCsvRows) +
                                          " lines per file (what lrcal reads back)");
  if (SimulatesEnvironment(vm, rig, configs))
    return NonGeometricSimulate(vm, rig, planes, configs, noise);
  MeasurementSet data;
  std::vector<BeamMiss> misses;
  std::vector<double> raw;
  const int missed = SimulateReadings(
      robot, rig.truth.LinkValues(robot), planes, rig.ranger, configs, noise,
      RandomStream(ParseSeed(vm), 0, 0, RandomPurpose::kNoise), &data, &misses, &raw);
  const std::string path = vm["out"].as<std::string>();
  WriteReadings(path, data.configs, raw, noise.repetitions);
  for (int i = 0; i < configs.size(); ++i)
    if (misses[i] != BeamMiss::kNone)
      std::cerr << "lrcal simulate: configuration " << i + 1 << " (line " << i + 2
                << "): no reading, " << BeamMissName(misses[i]) << "\n";
  std::cerr << "lrcal simulate: " << data.size() << " configurations x " << noise.repetitions
            << " readings written to " << path << (missed ? ", " : "")
            << (missed ? std::to_string(missed) + " skipped (beam missed)" : "") << "\n";
  return 0;
}

// identify --write-robot: the calibrated model as a robot file with its record.
void WriteRobot(const std::string& path, const std::string& data_file, const RobotFile& rig,
                const MeasurementModel& model, const IdentificationSummary& s,
                const IdentificationOptions& options, const UnestimatedTerms& held) {
  WriteCalibratedRobot(path, DataSource::File(data_file), rig, model, s, options, held);
  std::cerr << "lrcal identify: calibrated robot written to " << path << "\n";
}

// identify --predict-at: the total predicted accuracy at the poses (total_accuracy.h): the fit's
// covariance (ChooseSigma's σ) and the terms held at nominal.
void PredictAt(const std::string& file, const MeasurementModel& model,
               const IdentificationSummary& s, const IdentificationOptions& options,
               const UnestimatedTerms& held, Json* json, std::string* text) {
  const ConfigurationSet poses = ReadRobotPoses(file, model.robot());
  const std::optional<AccuracyPrediction> predicted =
      PredictAccuracyAfterFit(model, s, options, held, poses);
  if (!predicted)
    throw InputError("--predict-at",
                     "the covariance is undefined (as many configurations as parameters); "
                     "give --sigma-mm");
  *json = PoseAccuracyJson(*predicted, poses);
  *text = AccuracyPredictionText(*predicted);
}

// identify --only-significant K (identification/significance.h): the corrections within K
// standard deviations held at nominal and the rest refitted, their possible deviation a held
// term's tolerance in every accuracy statement; both models' predicted tool position error at the
// measured configurations stated side by side (the filtered one set by identify from the held
// terms it finds anyway; the full one when nothing is held).
struct SignificanceFilter {
  InsignificantCorrections held;
  double full_rms = std::nan(""), filtered_rms = std::nan("");  // m
  int configurations = 0;

  ::lrcal::Json Json() const {
    ::lrcal::Json list = ::lrcal::Json::array();
    for (const InsignificantCorrections::Term& h : held.terms)
      list.push_back({{"name", h.name},
                      {"delta", h.delta},
                      {"std", h.sd},
                      {"ratio", std::abs(h.delta) / h.sd}});
    return {{"k", held.k},
            {"held", list},
            {"predicted_rms_full_mm", full_rms * 1e3},
            {"predicted_rms_filtered_mm", filtered_rms * 1e3},
            {"configurations", configurations}};
  }
  std::string Text() const {
    std::ostringstream out;
    out << "only significant corrections (|delta| >= " << held.k << " std): ";
    if (held.terms.empty()) {
      out << "every correction is significant; nothing held\n";
      return out.str();
    }
    out << "held at nominal and the rest refitted:";
    for (const InsignificantCorrections::Term& h : held.terms)
      out << " " << h.name << " (" << Fixed(std::abs(h.delta) / h.sd, 2) << " std)";
    out << "\npredicted tool position error at the " << configurations
        << " measured configurations (RMS; readings' noise, and the held terms' possible "
           "deviation from the full fit): full model "
        << Fixed(full_rms * 1e3, 4) << " mm, only significant " << Fixed(filtered_rms * 1e3, 4)
        << " mm\n";
    return out.str();
  }
};

// The RMS of the predicted total tool position error of fit `s` on `model`, with the terms it
// holds `held`, at the measured configurations (NaN when the covariance is undefined).
double PredictedRmsAtData(const MeasurementModel& model, const IdentificationSummary& s,
                          const IdentificationOptions& options, const UnestimatedTerms& held,
                          const MeasurementSet& data) {
  const std::optional<AccuracyPrediction> p =
      PredictAccuracyAfterFit(model, s, options, held, data.configs);
  return p ? p->rms_position_total : std::nan("");
}

std::optional<SignificanceFilter> FilterInsignificant(
    const po::variables_map& vm, const MeasurementSet& data, const IdentificationOptions& options,
    MeasurementModel* model, IdentificationSummary* s, PriorSigmas* known) {
  if (!vm.count("only-significant")) return std::nullopt;
  const double k = vm["only-significant"].as<double>();
  if (!(k > 0) || !std::isfinite(k))
    throw InputError(
        "--only-significant",
        "expected a positive number of standard deviations (e.g. 2), got " + FormatExact(k));
  SignificanceFilter f;
  f.held.k = k;
  if (!s->IsSolutionUsable()) return f;
  f.held = FindInsignificantCorrections(*s, options, k);
  f.configurations = data.size();
  f.full_rms = PredictedRmsAtData(
      *model, *s, options, FindUnestimatedTerms(SolvedModel(*model, *s), *s, data, options, *known),
      data);
  if (f.held.terms.empty()) return f;
  *model = MeasurementModel(
      model->robot(), model->nominal_planes(),
      WithoutParameters(model->robot(), SolvedModel(*model, *s).parameters(), f.held.Names()));
  *s = Identify(*model, data, options);
  *known = known->OverriddenBy(f.held.Tolerances());
  return f;
}

// identify's output: the fit, and what --predict-at and --holdout add, as text or JSON.
void PrintIdentifyResults(const po::variables_map& vm, const MeasurementModel& model,
                          const MeasurementSet& data, const IdentificationSummary& s,
                          const IdentificationOptions& options, const UnestimatedTerms& held,
                          const std::optional<SignificanceFilter>& filter) {
  Json accuracy;
  std::string accuracy_text;
  if (vm.count("predict-at") && s.IsSolutionUsable())
    PredictAt(vm["predict-at"].as<std::string>(), model, s, options, held, &accuracy,
              &accuracy_text);
  std::optional<CrossValidation> cv;
  if (vm.count("holdout") && s.IsSolutionUsable())
    cv = CrossValidate(model, data, vm["holdout"].as<int>(), options);
  const std::string average = Averaging::Parse(vm["average"].as<std::string>()).Name();
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentificationJson(s);
    if (!accuracy.is_null()) j["accuracy"] = accuracy;
    if (cv) j["holdout"] = CrossValidationJson(*cv);
    if (filter) j["only_significant"] = filter->Json();
    j["average"] = average;
    std::cout << j.dump(2) << "\n";
  } else {
    if (average != "mean" && data.size() > 0)
      std::cout << "readings: the " << average
                << " of each configuration's readings, weighted R/c (c = "
                << Fixed(data.variance_factor.front(), 3) << " for " << data.repetitions.front()
                << " readings: the variance of the " << average << " relative to a mean)\n";
    std::cout << s.FullReport();
    if (filter) std::cout << filter->Text();
    std::cout << accuracy_text << (cv ? cv->ToString() : "");
  }
}

// calibration.json and the calibrated robot in `dir` (report/calibration_report.h), then
// report.html from python3 -m lrcal.report --calibration DIR.
void WriteReportFolder(const std::string& dir, const CalibrationReportInputs& in) {
  WriteCalibrationReportData(dir, in);  // a SettingError names --report (main.cc)
  if (in.summary->IsSolutionUsable())
    std::cerr << "lrcal identify: calibrated robot written to " << dir << "/calibrated.yaml\n";
  const int code = RunReportModule({"--calibration", dir});
  if (code != 0)
    throw StorageError(dir + "/report.html: python3 -m lrcal.report --calibration failed (exit " +
                       std::to_string(code) +
                       "); calibration.json and the calibrated robot file are written");
  std::cerr << "lrcal identify: calibration report written to " << dir << "/report.html\n";
}

// identify --report DIR: the ranger's report, with --measured tracker points and --holdout.
void WriteCalibrationReport(const std::string& dir, const po::variables_map& vm,
                            const RobotFile& rig, const MeasurementModel& model,
                            const MeasurementSet& data, const IdentificationSummary& s,
                            const IdentificationOptions& options, const UnestimatedTerms& held) {
  CalibrationReportInputs in{DataSource::File(DataFile(vm)), &rig, &model, &data, &s, options};
  in.held = held;
  MeasuredValues measured;
  if (vm.count("measured")) {
    in.measured_setup = ResolvePointSetup(vm);
    in.measured_file = vm["measured"].as<std::string>();
    measured =
        ReadTrackerMeasurements(in.measured_file, RegistrationKind(rig.robot, in.measured_setup));
    in.measured = &measured;
  }
  if (vm.count("holdout")) in.holdout = vm["holdout"].as<int>();
  WriteReportFolder(dir, in);
}

// identify's options (its settings from the schema are added by the command).
void AddIdentifyOptions(po::options_description& o) {
  AddCommonOptions(o);
  o.add_options()("data", po::value<std::vector<std::string>>()->required()->composing(),
                  "measurement CSV (q1..qN, h in m; rows with equal q are averaged); repeat it "
                  "with one kind per file in --sensor to calibrate from several kinds at once "
                  "(--sensor point,contact --data p.csv --data c.csv), or give --sensor mixed and "
                  "files whose sensor column says each row's kind")(
      "estimate-ranger", po::value<std::string>()->default_value("none"),
      "ranger terms to estimate: none, offset, scale, offset,scale (reading = (1+s) h + o)")(
      "estimate-plane", po::value<std::string>()->default_value("none"),
      "plane terms to estimate: none, normal, offset, normal,offset")(
      "fix", po::value<std::string>(), "parameters to keep at nominal, comma-separated")(
      "only-significant", po::value<double>(),
      "hold at nominal the corrections smaller than K standard deviations, refit the rest and "
      "state both models' predicted accuracy (e.g. --only-significant 2)")(
      "auto-fix", po::bool_switch(),
      "if the set is rank-deficient, fix the suggested parameters and go on")(
      "prior-sigma", po::value<std::string>(),
      "prior standard deviations around the nominal values, by class or term, each with its "
      "unit: theta=1mrad,a=0.5mm,d6=0.2mm,ranger_scale=200ppm (classes: theta, alpha, a, d, "
      "beta, plane_u, plane_f, ranger_offset, ranger_scale). With --sigma-mm: the maximum "
      "a-posteriori estimate; a direction the readings cannot see is set by its prior")(
      "prior", po::bool_switch(),
      "use the robot file's tolerances: as priors (--prior-sigma entries replace the same keys)")(
      "encoder-sigma-mrad", po::value<double>()->default_value(0),
      "errors in variables: standard deviation of each recorded joint value (mrad; mm for a "
      "prismatic joint), one error per configuration; weights, covariance, chi-squared and "
      "accuracy account for it (needs --sigma-mm)")(
      "solver", po::value<std::string>()->default_value("lm"), "lm (lrcal's) or ceres")(
      "loss", po::value<std::string>()->default_value("none"),
      "robust loss: none, huber, cauchy (either solver)")(
      "average", po::value<std::string>()->default_value("mean"),
      "how a configuration's repeated readings become its value: mean, median or trimmed:F "
      "(F in (0, 0.5) cut from each end); the weights account for the median's larger "
      "variance")(
      "predict-at", po::value<std::string>(),
      "poses (a configurations CSV) to predict the calibrated arm's accuracy at, from the "
      "estimate's covariance (given sigma if --sigma-mm, else residual-based)")(
      "write-robot", po::value<std::string>(),
      "write the calibrated model as a robot file (estimates as nominal values, with their "
      "covariance and the data's provenance); every command takes it as --robot")(
      "holdout", po::value<int>(),
      "K-fold cross-validation over the configurations (configuration i in fold i mod K): "
      "held-out readings against the fit's own prediction of their error")(
      "report", po::value<std::string>(),
      "write a calibration report into this folder: report.html (fit check, residuals, "
      "parameters, correlation, identifiability, cross-validation, accuracy over the "
      "workspace), calibration.json and the calibrated robot file")(
      "measured", po::value<std::string>(),
      "--report: points a tracker measured, not used in the fit (accuracy --measured's file, "
      "with --instrument and --target): the calibrated model's error at each in the report");
  AddFrameTermOptions(o);
}

namespace {

// What identify writes, checked before the fit (not after): a calibrated robot file that could
// not be written, and measured points with no report to put them in.
void CheckIdentifyOutputs(const po::variables_map& vm) {
  if (vm.count("write-robot"))
    CheckOutputFile(vm["write-robot"].as<std::string>(), "--write-robot");
  if (vm.count("measured") && !vm.count("report"))
    throw InputError("--measured",
                     "goes into the calibration report: give --report DIR too "
                     "(or judge a robot file with lrcal accuracy --measured)");
}

// The start of identify for a kind other than the ranger: the ranger's options refused by name
// (a kind that reads no plane refuses --plane and --estimate-plane too), and a calibrated robot
// file that could not be written refused before the fit, not after.
void StartKindIdentify(const po::variables_map& vm, const std::string& sensor, bool reads_planes) {
  std::vector<std::string> refused = {"estimate-ranger", "estimate-base", "estimate-tool",
                                      "average", "only-significant"};
  if (!reads_planes) refused.insert(refused.begin(), {"plane", "estimate-plane"});
  RefuseRangerOptions(vm, sensor, refused);
  CheckIdentifyOutputs(vm);
}

// identify --sensor point|pose: the tracker's terms from its measurement file (tracker_data.h).
// A pose's orientation rows weigh (σ/σ_angle)² per reading against its positions.
// What every identify of a kind other than the ranger does after its fit (`lrcal identify
// --sensor point|pose|socket|contact|scanner`): too few values for the terms is the data file's
// error; the report (text after `heading`, or JSON with the sensor, its values per configuration
// and `extra`); the rank advice (exit 3); the calibrated robot file; the fit check against the
// stated noise (`noise`: the options it names; exit 4).
struct KindFit {
  const RobotFile& rig;
  const MeasurementKind& kind;
  const MeasuredValues& data;
  const std::string& file;
  std::string sensor, heading, noise = "--sigma-mm";
  Json extra = Json::object();
};

// --write-robot and --report of a kind's fit.
void WriteKindFitFiles(const po::variables_map& vm, const KindFit& f,
                       const IdentificationSummary& s, const IdentificationOptions& options) {
  if (vm.count("write-robot") && s.IsSolutionUsable()) {
    WriteTrackerCalibratedRobot(vm["write-robot"].as<std::string>(), DataSource::File(f.file),
                                f.rig, f.kind, f.data, s, options);
    std::cerr << "lrcal identify: calibrated robot written to "
              << vm["write-robot"].as<std::string>() << "\n";
  }
  if (!vm.count("report")) return;
  CalibrationReportInputs in{DataSource::File(f.file), &f.rig, nullptr, nullptr, &s, options};
  in.kind = &f.kind;
  in.values = &f.data;
  if (vm.count("holdout")) in.holdout = vm["holdout"].as<int>();
  MeasuredValues measured;
  if (vm.count("measured")) {  // the tracker's points of --target, its frame --instrument
    in.measured_setup = ResolvePointSetup(vm);
    in.measured_file = vm["measured"].as<std::string>();
    measured =
        ReadTrackerMeasurements(in.measured_file, RegistrationKind(f.rig.robot, in.measured_setup));
    in.measured = &measured;
  }
  WriteReportFolder(vm["report"].as<std::string>(), in);
}

// --predict-at: the calibrated arm's predicted accuracy at the poses from its record, what
// `lrcal accuracy --robot` says of --write-robot's file (the arm's terms; the held ones at their
// tolerances).
void KindPredictAt(const po::variables_map& vm, const KindFit& f, const IdentificationSummary& s,
                   const IdentificationOptions& options, Json* json, std::string* text) {
  const RobotFile calibrated =
      TrackerCalibratedRobot(DataSource::File(f.file), f.rig, f.kind, f.data, s, options);
  if (!calibrated.calibration || calibrated.calibration->covariance.size() == 0)
    throw InputError("--predict-at",
                     "the covariance is undefined (as many values as terms); give --sigma-mm");
  const std::string file = vm["predict-at"].as<std::string>();
  const ConfigurationSet poses = ReadRobotPoses(file, calibrated.robot);
  const AccuracyPrediction predicted =
      PredictCalibratedAccuracy(calibrated, ResolvePlanes(f.rig, vm), poses);
  *json = PoseAccuracyJson(predicted, poses);
  *text = AccuracyPredictionText(predicted);
}

int ReportKindFit(const po::variables_map& vm, const KindFit& f, const IdentificationSummary& s,
                  const IdentificationOptions& options) {
  if (s.termination == Termination::kInvalidInput &&
      f.data.size() * f.kind.rows_per_configuration() < f.kind.num_parameters())
    throw InputError(f.file, s.message);
  Json accuracy;
  std::string accuracy_text;
  if (vm.count("predict-at") && s.IsSolutionUsable())
    KindPredictAt(vm, f, s, options, &accuracy, &accuracy_text);
  // --holdout K: each fold's configurations predicted by the fit of the others.
  std::optional<CrossValidation> cv;
  if (vm.count("holdout") && s.IsSolutionUsable())
    cv = CrossValidate(f.kind, f.data, vm["holdout"].as<int>(), options);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentificationJson(s);
    j["sensor"] = f.sensor;
    j["values_per_configuration"] = f.kind.rows_per_configuration();
    for (const auto& [key, value] : f.extra.items()) j[key] = value;
    if (!accuracy.is_null()) j["accuracy"] = accuracy;
    if (cv) j["holdout"] = CrossValidationJson(*cv);
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "sensor: " << f.sensor << " (" << f.heading << "; lengths in m, angles in rad)\n"
              << s.FullReport() << accuracy_text;
    if (cv) std::cout << cv->ToString();
  }
  if (s.termination == Termination::kRankDeficient) {
    std::string list;
    for (const auto& name : s.identifiability.suggested_fixed)
      list += (list.empty() ? "" : ",") + name;
    std::cerr << "lrcal identify: the " << f.sensor
              << " terms are not identifiable from these configurations; fix the suggested ones "
                 "(--fix "
              << list << ") or pass --auto-fix\n";
    return 3;
  }
  WriteKindFitFiles(vm, f, s, options);
  if (s.IsSolutionUsable() && !s.fit.consistent) {
    std::cerr << "lrcal identify: the fit is inconsistent with " << f.noise
              << " (p = " << s.fit.p_value << " < 0.001); see the fit line above\n";
    return 4;
  }
  return s.IsSolutionUsable() ? 0 : 1;
}

int TrackerIdentify(const po::variables_map& vm, const std::string& sensor) {
  StartKindIdentify(vm, sensor, false);
  const RobotFile rig = LoadRobot(vm);
  const std::unique_ptr<PointMeasurement> kind = MakeTrackerKind(rig.robot, sensor, vm);
  const std::string file = DataFile(vm);
  MeasuredValues data = ReadTrackerMeasurements(file, *kind);
  const IdentificationOptions options = ResolveIdentificationOptions(vm, rig);
  if (sensor == "pose")
    WeighAngleRows(*kind, options.sigma > 0 ? options.sigma : NoiseModel{}.sigma,
                   ResolveSigmaAngle(vm, false), &data);
  const IdentificationSummary s = Identify(*kind, data, options);
  return ReportKindFit(vm,
                       {rig, *kind, data, file, sensor,
                        std::to_string(data.size()) + " measurements of " +
                            std::to_string(kind->setup().targets.size()) + " target(s)",
                        sensor == "pose" ? "--sigma-mm and --sigma-mrad" : "--sigma-mm"},
                       s, options);
}

// identify --sensor socket: the arm's terms, the tool point and the sockets from socket data
// (socket_data.h); the sockets' nominal positions are the nominal model's mean tool points.
int SocketIdentify(const po::variables_map& vm) {
  StartKindIdentify(vm, "socket", false);
  const RobotFile rig = LoadRobot(vm);
  const std::string file = DataFile(vm);
  const SocketData data = ReadSocketData(file, rig.robot);
  const std::unique_ptr<SocketMeasurement> kind = MakeSocketKind(rig.robot, data, vm);
  const IdentificationOptions options = ResolveIdentificationOptions(vm, rig);
  const IdentificationSummary s = Identify(*kind, data.values, options);
  return ReportKindFit(vm,
                       {rig, *kind, data.values, file, "socket",
                        std::to_string(data.values.size()) + " seatings in " +
                            std::to_string(data.ids.size()) + " socket(s)",
                        "--sigma-mm, the play in the sockets", Json{{"sockets", data.ids}}},
                       s, options);
}

// identify --sensor contact: the arm's terms, the tool point and the planes' estimated terms
// from contact data (contact_data.h); a flush contact's tilt rows weigh (σ/σ_angle)².
int ContactIdentify(const po::variables_map& vm) {
  StartKindIdentify(vm, "contact", true);
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const std::string file = DataFile(vm);
  ContactData data = ReadContactData(file, rig.robot, setup.planes, vm["flush"].as<bool>());
  const std::unique_ptr<ContactMeasurement> kind =
      MakeContactKind(rig.robot, setup.planes, data.flush, vm);
  const IdentificationOptions options = ResolveIdentificationOptions(vm, rig);
  if (data.flush)
    WeighAngleRows(*kind, options.sigma > 0 ? options.sigma : NoiseModel{}.sigma,
                   ResolveSigmaAngle(vm, false), &data.values);
  const IdentificationSummary s = Identify(*kind, data.values, options);
  return ReportKindFit(vm,
                       {rig, *kind, data.values, file, "contact",
                        std::to_string(data.values.size()) + (data.flush ? " flush" : "") +
                            " contacts on " + std::to_string(setup.planes.size()) + " plane(s)",
                        data.flush ? "--sigma-mm and --sigma-mrad" : "--sigma-mm"},
                       s, options);
}

// identify --sensor scanner: the arm's terms, the scanner's frame and the planes' estimated terms
// from scanner data (scanner_data.h).
int ScannerIdentify(const po::variables_map& vm) {
  StartKindIdentify(vm, "scanner", true);
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const std::string file = DataFile(vm);
  const std::unique_ptr<ScannerMeasurement> kind =
      MakeScannerKind(rig.robot, setup.planes, rig.ranger, vm);
  const MeasuredValues data = ReadScannerData(file, rig.robot, setup.planes, kind->num_beams());
  const IdentificationOptions options = ResolveIdentificationOptions(vm, rig);
  const IdentificationSummary s = Identify(*kind, data, options);
  return ReportKindFit(
      vm,
      {rig, *kind, data, file, "scanner",
       std::to_string(data.size()) + " scans of " + std::to_string(kind->num_beams()) +
           " beam(s) on " + std::to_string(setup.planes.size()) + " plane(s)"},
      s, options);
}

// One file of a mixed run (--sensor point,contact --data p.csv --data c.csv): its kind, made
// without --fix (the mixed kind holds the named terms), and its values.
struct MixedFile {
  std::string sensor, file;
  std::shared_ptr<const MeasurementKind> kind;
  MeasuredValues values;
};

// `configs` with zero values: the configurations of an identifiability question.
MeasuredValues ZeroValues(const MeasurementKind& kind, TargetedConfigurations configs) {
  MeasuredValues v{std::move(configs), {}, {}};
  v.y.assign(static_cast<std::size_t>(v.size()) * kind.rows_per_configuration(), 0.0);
  v.repetitions.assign(static_cast<std::size_t>(v.size()), 1);
  return v;
}

// Reads the table `t` (a file, or a mixed file's rows of one kind) as `sensor`'s data, with the
// same readers and columns as --sensor alone; `configs_only`: the configurations of an
// identifiability question (a tracker's or ranger's rows need no measured columns).
MixedFile LoadMixedTable(const po::variables_map& vm, const Setup& setup, const std::string& sensor,
                         const CsvTable& t, bool configs_only) {
  const RobotModel& robot = setup.rig.robot;
  const int n = robot.num_links();
  MixedFile f{sensor, t.path, nullptr, {}};
  if (sensor == "point" || sensor == "pose") {
    std::unique_ptr<PointMeasurement> kind = MakeTrackerKind(robot, sensor, vm, true);
    if (configs_only) {
      f.values = ZeroValues(
          *kind, TargetConfigurations(t, n, static_cast<int>(kind->setup().targets.size())));
      CheckJointRanges(f.values.configs, robot, t.path);
    } else {
      f.values = TrackerMeasurementsFromTable(t, *kind);
    }
    f.kind = std::move(kind);
  } else if (sensor == "socket") {
    const SocketData data = SocketDataFromTable(t, robot);
    f.kind = MakeSocketKind(robot, data, vm, true);
    f.values = data.values;
  } else if (sensor == "contact") {
    const ContactData data = ContactDataFromTable(t, robot, setup.planes, vm["flush"].as<bool>());
    f.kind = MakeContactKind(robot, setup.planes, data.flush, vm, true);
    f.values = data.values;
  } else if (sensor == "scanner") {
    std::unique_ptr<ScannerMeasurement> kind =
        MakeScannerKind(robot, setup.planes, setup.rig.ranger, vm, true);
    if (configs_only && t.Column("beam") < 0) {
      f.values = ZeroValues(*kind, Configurations(t, n, &setup.planes));
      CheckJointRanges(f.values.configs, robot, t.path);
    } else {
      f.values = ScannerDataFromTable(t, robot, setup.planes, kind->num_beams());
    }
    f.kind = std::move(kind);
  } else {
    auto kind = std::make_shared<RangerMeasurement>(
        MeasurementModel(robot, setup.planes,
                         ResolveParameterSet(robot, vm, setup.planes.size(), true)),
        setup.rig.ranger);
    if (configs_only) {
      f.values = ZeroValues(*kind, Configurations(t, n, &setup.planes));
      CheckJointRanges(f.values.configs, robot, t.path);
    } else {
      MeasurementSet data = Measurements(t, n, &setup.rig.ranger, &setup.planes,
                                         Averaging::Parse(vm["average"].as<std::string>()));
      CheckJointRanges(data.configs, robot, t.path);
      f.values = ToMeasuredValues(data);
    }
    f.kind = std::move(kind);
  }
  return f;
}

// The options a calibration of several parts (kinds, or a tree's chains) does not take, and the
// kinds' own options when no part is of that kind, refused by name.
void RefuseOptionsOfOneKind(const po::variables_map& vm, const std::vector<std::string>& sensors,
                            const std::string& what) {
  const auto has = [&](std::initializer_list<const char*> kinds) {
    for (const char* kind : kinds)
      if (std::find(sensors.begin(), sensors.end(), kind) != sensors.end()) return true;
    return false;
  };
  std::vector<std::pair<std::string, bool>> refused = {
      {"predict-at", false},
      {"holdout", false},
      {"report", false},
      {"only-significant", false},
      {"measured", false},
      {"prior", false},
      {"prior-sigma", false},
      {"estimate-ranger", has({"ranger"})},
      {"average", has({"ranger"})},
      {"estimate-base", has({"ranger"})},
      {"estimate-tool", has({"ranger"})},
      {"plane", has({"ranger", "contact", "scanner"})},
      {"estimate-plane", has({"ranger", "contact", "scanner"})}};
  for (const auto& [name, taken] : refused)
    if (!taken && vm.count(name) && !vm[name].defaulted())
      throw InputError("--" + name, "is not taken by a calibration from " + what);
}

// The files of a mixed run, one per kind of --sensor, read; the options no kind in the list takes
// refused by name.
std::vector<MixedFile> LoadMixedFiles(const po::variables_map& vm, const Setup& setup,
                                      const char* option, bool configs_only) {
  const std::vector<std::string> listed = ResolveSensors(vm);
  const auto& files = vm[option].as<std::vector<std::string>>();
  // --sensor mixed: every file's rows say their kind (a sensor column); else one kind per file.
  std::vector<std::pair<std::string, CsvTable>> tables;
  if (listed.size() == 1 && listed[0] == "mixed") {
    for (const std::string& file : files)
      for (auto& group : SplitBySensor(ReadRobotCsv(file, setup.rig.robot)))
        tables.push_back(std::move(group));
  } else if (files.size() == listed.size()) {
    for (std::size_t k = 0; k < files.size(); ++k)
      tables.emplace_back(listed[k], ReadRobotCsv(files[k], setup.rig.robot));
  }
  std::vector<std::string> sensors;
  for (const auto& table : tables) sensors.push_back(table.first);
  if (tables.empty())
    throw InputError(std::string("--") + option,
                     "given " + std::to_string(files.size()) + " time(s) for the " +
                         std::to_string(listed.size()) + " kinds of --sensor " +
                         vm["sensor"].as<std::string>() + ": expected one file per kind, in order");
  RefuseOptionsOfOneKind(vm, sensors,
                         "several kinds (--sensor " + vm["sensor"].as<std::string>() + ")");
  std::vector<MixedFile> out;
  for (const auto& [sensor, table] : tables)
    out.push_back(LoadMixedTable(vm, setup, sensor, table, configs_only));
  return out;
}

// The mixed kind of `files` (labels: the kind, numbered when a kind repeats) with --fix held.
std::unique_ptr<MeasurementKind> MakeMixedKind(const po::variables_map& vm, const RobotModel& robot,
                                               const std::vector<MixedFile>& files,
                                               const std::vector<std::string>& labels = {}) {
  std::vector<std::shared_ptr<const MeasurementKind>> kinds;
  for (const MixedFile& f : files) kinds.push_back(f.kind);
  std::vector<MixedPart> parts = PartsLabelledByKind(kinds);
  for (std::size_t p = 0; p < labels.size(); ++p) {
    parts[p].label = labels[p];  // a tree's chains: their terms named by ChainMeasurement
    parts[p].names_are_shared = true;
  }
  auto mixed = std::make_unique<MixedMeasurement>(std::move(parts));
  const std::vector<std::string> fixed = FixList(vm, robot);
  if (fixed.empty()) return mixed;
  for (const std::string& name : fixed)
    if (std::find(mixed->parameter_names().begin(), mixed->parameter_names().end(), name) ==
        mixed->parameter_names().end())
      throw InputError("--fix", "'" + CellExcerpt(name) +
                                    "' is not a term of this calibration (a kind's own term "
                                    "shared by name with another kind's is written with its "
                                    "label: contact.target_x)");
  return mixed->Without(fixed);
}

// The parts of a mixed run as JSON and in words.
Json MixedPartsJson(const MixedMeasurement& kind, const std::vector<MixedFile>& files) {
  Json parts = Json::array();
  for (int p = 0; p < kind.num_parts(); ++p) {
    const MixedFile& f = files[static_cast<std::size_t>(p)];
    parts.push_back({{"label", kind.part(p).label},
                     {"sensor", f.sensor},
                     {"file", f.file},
                     {"configurations", f.values.size()},
                     {"values_per_configuration", kind.part(p).kind->rows_per_configuration()},
                     {"terms", kind.part(p).kind->num_parameters()}});
  }
  return parts;
}

std::string MixedPartsText(const MixedMeasurement& kind, const std::vector<MixedFile>& files) {
  std::string text;
  for (int p = 0; p < kind.num_parts(); ++p) {
    const MixedFile& f = files[static_cast<std::size_t>(p)];
    text += (p ? "; " : "") + kind.part(p).label + ": " + f.file + ", " +
            std::to_string(f.values.size()) + " configurations of " +
            std::to_string(kind.part(p).kind->rows_per_configuration()) + " value(s)";
  }
  return text;
}

// Each file's values, a kind's angle rows weighed (σ/σ_angle)² (*angles: whether any was).
std::vector<MeasuredValues> WeighedValues(const po::variables_map& vm,
                                          const IdentificationOptions& options,
                                          std::vector<MixedFile>* files, bool* angles) {
  const double sigma = options.sigma > 0 ? options.sigma : NoiseModel{}.sigma;
  std::vector<MeasuredValues> values;
  for (MixedFile& f : *files) {
    for (int c = 0; c < f.kind->rows_per_configuration(); ++c)
      if (f.kind->RowIsAngle(c)) {
        WeighAngleRows(*f.kind, sigma, ResolveSigmaAngle(vm, false), &f.values);
        *angles = true;
        break;
      }
    values.push_back(f.values);
  }
  return values;
}

// The rank of `mixed`'s terms at its files' configurations, with the options' tolerance.
IdentifiabilityReport FilesIdentifiability(const po::variables_map& vm,
                                           const MixedMeasurement& mixed,
                                           const std::vector<MixedFile>& files) {
  std::vector<MeasuredValues> values;
  for (const MixedFile& f : files) values.push_back(f.values);
  IdentifiabilityOptions options;
  ReadSettingOptions(vm, IdentifiabilityOptions::Settings(), &options);
  return AnalyzeIdentifiability(mixed, mixed.Combine(values).configs, nullptr, options);
}

// identify --sensor a,b --data A.csv --data B.csv: the terms of every kind, the arm's and the
// planes' shared (mixed_measurement.h), from all the files at once.
int MixedIdentify(const po::variables_map& vm) {
  if (vm.count("write-robot"))
    CheckOutputFile(vm["write-robot"].as<std::string>(), "--write-robot");
  const Setup setup = ResolveSetup(vm);
  std::vector<MixedFile> files = LoadMixedFiles(vm, setup, "data", false);
  const IdentificationOptions options = ResolveIdentificationOptions(vm, setup.rig);
  bool angles = false;
  const std::vector<MeasuredValues> values = WeighedValues(vm, options, &files, &angles);
  const std::unique_ptr<MeasurementKind> kind = MakeMixedKind(vm, setup.rig.robot, files);
  const auto& mixed = dynamic_cast<const MixedMeasurement&>(*kind);
  const MeasuredValues data = mixed.Combine(values);
  const IdentificationSummary s = Identify(mixed, data, options);
  std::string sources;
  for (const MixedFile& f : files) sources += (sources.empty() ? "" : " + ") + f.file;
  return ReportKindFit(
      vm,
      {setup.rig, mixed, data, sources, "mixed",
       MixedPartsText(mixed, files) + "; one entry per measured value",
       angles ? "--sigma-mm and --sigma-mrad" : "--sigma-mm",
       Json{{"parts", MixedPartsJson(mixed, files)}, {"values_per_configuration", nullptr}}},
      s, options);
}

// identifiability --sensor a,b --configs A.csv --configs B.csv: the rank of every kind's terms
// together at their configurations.
int MixedIdentifiability(const po::variables_map& vm) {
  const Setup setup = ResolveSetup(vm);
  const std::vector<MixedFile> files = LoadMixedFiles(vm, setup, "configs", true);
  const std::unique_ptr<MeasurementKind> kind = MakeMixedKind(vm, setup.rig.robot, files);
  const auto& mixed = dynamic_cast<const MixedMeasurement&>(*kind);
  const IdentifiabilityReport r = FilesIdentifiability(vm, mixed, files);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentifiabilityJson(r);
    j["sensor"] = "mixed";
    j["parts"] = MixedPartsJson(mixed, files);
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "sensor: mixed (" << MixedPartsText(mixed, files)
              << "; one entry per measured value)\n"
              << r.ToString();
  }
  return 0;
}

// A tree's run (--tool-link a,b: several tool links of one URDF): each chain's file read for its
// chain's robot by its kind's reader (one --sensor for every chain, or one per chain), its
// configurations made the whole robot's (chain_measurement.h), the parts labelled by their tool
// links.
struct TreeRun {
  UrdfChains tree;
  std::vector<std::unique_ptr<Setup>> setups;  // per chain; its kind refers to its robot
  std::vector<MixedFile> files;
  std::vector<std::string> labels;
};

TreeRun LoadTreeRun(const po::variables_map& vm, const char* option, bool configs_only) {
  TreeRun run;
  run.tree = LoadTreeChains(vm);
  run.labels = run.tree.tool_links();
  std::vector<std::string> sensors = ResolveSensors(vm);
  if (sensors.size() == 1 && sensors[0] != "mixed") sensors.assign(run.labels.size(), sensors[0]);
  if (sensors.size() != run.labels.size())
    throw InputError("--sensor",
                     "expected one kind for every chain, or one per tool link of "
                     "--tool-link (" +
                         std::to_string(run.labels.size()) + "), got " +
                         vm["sensor"].as<std::string>());
  const auto& files = vm[option].as<std::vector<std::string>>();
  if (files.size() != run.labels.size())
    throw InputError(std::string("--") + option,
                     "given " + std::to_string(files.size()) + " time(s) for the " +
                         std::to_string(run.labels.size()) +
                         " chains of --tool-link: expected one file per tool link, in order");
  RefuseOptionsOfOneKind(vm, sensors,
                         "a tree's chains (--tool-link " + OptionalString(vm, "tool-link") + ")");
  if (vm.count("write-robot"))
    throw InputError("--write-robot",
                     "writes one chain's robot file; a tree's chains are "
                     "calibrated together but not yet written (identify each "
                     "chain's file from the JSON estimate)");
  for (std::size_t c = 0; c < files.size(); ++c) {
    const RobotFile& chain = run.tree.chains[c];
    auto& setup = run.setups.emplace_back(std::make_unique<Setup>(Setup{chain, PlaneSet{}}));
    if (sensors[c] != "point" && sensors[c] != "pose" && sensors[c] != "socket")
      setup->planes = ResolvePlanes(chain, vm);  // the kinds that see planes
    MixedFile f =
        LoadMixedTable(vm, *setup, sensors[c],
                       ReadChainCsv(files[c], run.tree, static_cast<int>(c)), configs_only);
    const auto part = std::make_shared<ChainMeasurement>(f.kind, run.tree.placements[c]);
    f.values.configs = part->RobotConfigurations(f.values.configs);
    f.kind = part;
    run.files.push_back(std::move(f));
  }
  return run;
}

// The terms the chains share (unlabelled) and each chain's own, as JSON.
Json TreeJson(const TreeRun& run, const MixedMeasurement& kind) {
  Json shared = Json::array(), own = Json::object();
  for (const std::string& name : kind.parameter_names()) {
    const auto dot = name.find('.');
    if (dot == std::string::npos)
      shared.push_back(name);
    else
      own[name.substr(0, dot)].push_back(name);
  }
  return {{"tool_links", run.labels},
          {"joints", run.tree.joint_names},
          {"shared_terms", shared},
          {"own_terms", own}};
}

std::string TreeText(const TreeRun& run, const MixedMeasurement& kind) {
  std::string couplings;
  for (std::size_t c = 0; c < run.tree.placements.size(); ++c)
    for (const JointCoupling& coupling : run.tree.placements[c].couplings)
      couplings +=
          (couplings.empty() ? "" : ", ") +
          run.tree.chains[c].robot.links()[static_cast<std::size_t>(coupling.link)].joint_name +
          " = " + FormatExact(coupling.multiplier) + " x " +
          run.tree.joint_names[static_cast<std::size_t>(coupling.joint)] + " + " +
          FormatExact(coupling.offset);
  if (run.labels.size() == 1)
    return "chain to " + run.labels[0] + " over " + std::to_string(run.tree.joint_names.size()) +
           " joints, coupled: " + couplings + "\n";
  const Json j = TreeJson(run, kind);
  std::string text =
      "tree: " + std::to_string(run.labels.size()) + " chains (" + JoinList(run.labels) +
      ") over " + std::to_string(run.tree.joint_names.size()) +
      " joints; terms shared by every chain: " + std::to_string(j["shared_terms"].size());
  for (const auto& [label, names] : j["own_terms"].items())
    text += "; " + label + "'s own: " + std::to_string(names.size());
  const std::vector<std::string> shared = j["shared_terms"].get<std::vector<std::string>>();
  return text + "\nshared: " + (shared.empty() ? "none" : JoinList(shared)) + "\n" +
         (couplings.empty() ? "" : "coupled: " + couplings + "\n");
}

// identify --tool-link a,b --data A.csv --data B.csv: the chains' terms together, the shared
// joints' once.
int TreeIdentify(const po::variables_map& vm) {
  TreeRun run = LoadTreeRun(vm, "data", false);
  const RobotFile& first = run.tree.chains[0];
  const IdentificationOptions options = ResolveIdentificationOptions(vm, first);
  bool angles = false;
  const std::vector<MeasuredValues> values = WeighedValues(vm, options, &run.files, &angles);
  const std::unique_ptr<MeasurementKind> kind =
      MakeMixedKind(vm, first.robot, run.files, run.labels);
  const auto& mixed = dynamic_cast<const MixedMeasurement&>(*kind);
  const MeasuredValues data = mixed.Combine(values);
  const IdentificationSummary s = Identify(mixed, data, options);
  std::string sources;
  for (const MixedFile& f : run.files) sources += (sources.empty() ? "" : " + ") + f.file;
  if (ResolveFormat(vm) != Format::kJson) std::cout << TreeText(run, mixed);
  return ReportKindFit(vm,
                       {first, mixed, data, sources, "mixed",
                        MixedPartsText(mixed, run.files) + "; one entry per measured value",
                        angles ? "--sigma-mm and --sigma-mrad" : "--sigma-mm",
                        Json{{"parts", MixedPartsJson(mixed, run.files)},
                             {"tree", TreeJson(run, mixed)},
                             {"values_per_configuration", nullptr}}},
                       s, options);
}

// identifiability --tool-link a,b --configs A.csv --configs B.csv.
int TreeIdentifiability(const po::variables_map& vm) {
  const TreeRun run = LoadTreeRun(vm, "configs", true);
  const std::unique_ptr<MeasurementKind> kind =
      MakeMixedKind(vm, run.tree.chains[0].robot, run.files, run.labels);
  const auto& mixed = dynamic_cast<const MixedMeasurement&>(*kind);
  const IdentifiabilityReport r = FilesIdentifiability(vm, mixed, run.files);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentifiabilityJson(r);
    j["sensor"] = "mixed";
    j["parts"] = MixedPartsJson(mixed, run.files);
    j["tree"] = TreeJson(run, mixed);
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << TreeText(run, mixed) << "sensor: mixed (" << MixedPartsText(mixed, run.files)
              << "; one entry per measured value)\n"
              << r.ToString();
  }
  return 0;
}

// identify with a tree's chains, several kinds or one kind other than the ranger; nothing for
// the ranger's own calibration, which IdentifyCommand does.
// --estimate-compliance and --estimate-thermal are the ranger's for now (one arm, one kind).
void RefuseNonGeometricForOtherSensors(const po::variables_map& vm) {
  if (!AsksNonGeometric(vm)) return;
  const std::string sensor = IsTreeRun(vm) ? "tree" : ResolveSensor(vm);
  if (sensor != "ranger")
    throw InputError(vm["estimate-compliance"].as<std::string>() != "none" ? "--estimate-compliance"
                                                                           : "--estimate-thermal",
                     "is available for --sensor ranger on one arm; the " + sensor +
                         " path fits the geometric model (the library's EnvironmentMeasurement "
                         "wraps any kind)");
}

std::optional<int> IdentifyOtherThanOneRanger(const po::variables_map& vm) {
  if (IsTreeRun(vm)) return TreeIdentify(vm);
  const std::string sensor = ResolveSensor(vm);
  if (sensor == "mixed") return MixedIdentify(vm);
  if (sensor == "socket") return SocketIdentify(vm);
  if (sensor == "contact") return ContactIdentify(vm);
  if (sensor == "scanner") return ScannerIdentify(vm);
  if (sensor != "ranger") return TrackerIdentify(vm, sensor);
  return std::nullopt;
}

}  // namespace

int IdentifyCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal identify options");
  AddIdentifyOptions(o);
  AddEstimatePresetOption(o);
  AddSettingOptions(o, IdentificationOptions::Settings(),
                    {"loss_scale_mm", "loss_scale_sigma", "sigma_mm"});
  AddSensorOptions(o);
  AddOrientationNoiseOption(o);
  AddNonGeometricOptions(o);
  po::variables_map vm;
  if (!Parse("identify", "--data M.csv [options]", o, args, &vm)) return 0;
  RefuseNonGeometricForOtherSensors(vm);
  if (const std::optional<int> done = IdentifyOtherThanOneRanger(vm)) return *done;
  CheckIdentifyOutputs(vm);
  if (AsksNonGeometric(vm))
    return NonGeometricIdentify(vm, DataFile(vm), ResolveIdentificationOptions(vm, LoadRobot(vm)));
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  const MeasurementSet data = ReadRobotMeasurements(
      DataFile(vm), rig, &planes, Averaging::Parse(vm["average"].as<std::string>()));
  MeasurementModel model(robot, planes, ResolveParameterSet(robot, vm, planes.size()));
  const IdentificationOptions options = ResolveIdentificationOptions(vm, rig);
  IdentificationSummary s = Identify(model, data, options);
  if (s.termination == Termination::kInvalidInput && data.size() < model.num_parameters())
    throw InputError(DataFile(vm), s.message);
  PriorSigmas known = KnownTolerances(vm, rig);
  std::optional<SignificanceFilter> filter =
      FilterInsignificant(vm, data, options, &model, &s, &known);

  const UnestimatedTerms held =
      s.IsSolutionUsable() ? FindUnestimatedTerms(SolvedModel(model, s), s, data, options, known)
                           : UnestimatedTerms{};
  if (filter && s.IsSolutionUsable())
    filter->filtered_rms = PredictedRmsAtData(model, s, options, held, data);
  PrintIdentifyResults(vm, model, data, s, options, held, filter);
  if (s.termination == Termination::kRankDeficient) {
    std::cerr << "lrcal identify: the parameter set is not identifiable from these "
                 "configurations; fix the suggested parameters (--fix "
              <<
        [&] {
          std::string l;
          for (const auto& f : s.identifiability.suggested_fixed) l += (l.empty() ? "" : ",") + f;
          return l;
        }() << ") or pass --auto-fix\n";
    return 3;
  }
  if (vm.count("write-robot") && s.IsSolutionUsable())
    WriteRobot(vm["write-robot"].as<std::string>(), DataFile(vm), rig, model, s, options, held);
  if (vm.count("report"))
    WriteCalibrationReport(vm["report"].as<std::string>(), vm, rig, model, data, s, options, held);
  if (s.IsSolutionUsable() && !s.fit.consistent) {
    std::cerr << "lrcal identify: the fit is inconsistent with --sigma-mm (p = " << s.fit.p_value
              << " < 0.001); see the fit line above\n";
    return 4;
  }
  return s.IsSolutionUsable() ? 0 : 1;
}

namespace {

// identifiability --prior-sigma: what readings of the stated noise at these configurations tell
// against the priors (prior.h).
std::optional<PriorInformation> PriorInformationAt(const po::variables_map& vm,
                                                   const RobotFile& rig,
                                                   const MeasurementModel& model,
                                                   const TargetedConfigurations& configs) {
  const PriorSigmas priors = ResolvePriors(vm, rig);
  if (priors.empty()) return std::nullopt;
  NoiseModel noise;
  ReadSettingOptions(vm, NoiseModel::Settings(), &noise);
  return InformationFromPriors(RangerMeasurement(model), configs, noise, priors);
}

// identifiability --sensor point|pose: the tracker's terms at the configurations (a `target`
// column says which target each row sees).
int TrackerIdentifiability(const po::variables_map& vm, const std::string& sensor) {
  RefuseRangerOptions(vm, sensor,
                      {"plane", "estimate-ranger", "estimate-plane", "estimate-base",
                       "estimate-tool", "prior-sigma", "prior"});
  const RobotFile rig = LoadRobot(vm);
  const std::unique_ptr<PointMeasurement> kind = MakeTrackerKind(rig.robot, sensor, vm);
  const TargetedConfigurations configs = ReadRobotTargetConfigurations(
      SingleFile(vm, "configs"), rig.robot, static_cast<int>(kind->setup().targets.size()));
  IdentifiabilityOptions options;
  ReadSettingOptions(vm, IdentifiabilityOptions::Settings(), &options);
  const IdentifiabilityReport r = AnalyzeIdentifiability(*kind, configs, nullptr, options);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentifiabilityJson(r);
    j["sensor"] = sensor;
    j["values_per_configuration"] = kind->rows_per_configuration();
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "sensor: " << sensor << " ("
              << (sensor == "pose" ? "x, y, z in m and an orientation in rad" : "x, y, z in m")
              << " per configuration, in the instrument's frame)\n"
              << r.ToString();
  }
  return 0;
}

// identifiability --sensor socket: the arm's terms, the tool point and the sockets at the
// configurations (a `socket` column says which socket each row is in).
int SocketIdentifiability(const po::variables_map& vm) {
  RefuseRangerOptions(vm, "socket",
                      {"plane", "estimate-ranger", "estimate-plane", "estimate-base",
                       "estimate-tool", "prior-sigma", "prior"});
  const RobotFile rig = LoadRobot(vm);
  const SocketData data = ReadSocketData(SingleFile(vm, "configs"), rig.robot);
  const std::unique_ptr<SocketMeasurement> kind = MakeSocketKind(rig.robot, data, vm);
  IdentifiabilityOptions options;
  ReadSettingOptions(vm, IdentifiabilityOptions::Settings(), &options);
  const IdentifiabilityReport r =
      AnalyzeIdentifiability(*kind, data.values.configs, nullptr, options);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentifiabilityJson(r);
    j["sensor"] = "socket";
    j["values_per_configuration"] = 3;
    j["sockets"] = data.ids;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "sensor: socket (the tool point at its socket: x, y, z in m per configuration, "
                 "in the base frame; "
              << data.ids.size() << " socket(s), " << kind->setup().distances.size()
              << " known distance(s))\n"
              << r.ToString();
  }
  return 0;
}

// identifiability --sensor contact: the arm's terms, the tool point and the planes' terms at
// the configurations (a `plane` column says which plane each row touches).
int ContactIdentifiability(const po::variables_map& vm) {
  RefuseRangerOptions(
      vm, "contact", {"estimate-ranger", "estimate-base", "estimate-tool", "prior-sigma", "prior"});
  const Setup setup = ResolveSetup(vm);
  const ContactData data = ReadContactData(SingleFile(vm, "configs"), setup.rig.robot, setup.planes,
                                           vm["flush"].as<bool>());
  const std::unique_ptr<ContactMeasurement> kind =
      MakeContactKind(setup.rig.robot, setup.planes, data.flush, vm);
  IdentifiabilityOptions options;
  ReadSettingOptions(vm, IdentifiabilityOptions::Settings(), &options);
  const IdentifiabilityReport r =
      AnalyzeIdentifiability(*kind, data.values.configs, nullptr, options);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentifiabilityJson(r);
    j["sensor"] = "contact";
    j["values_per_configuration"] = kind->rows_per_configuration();
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "sensor: contact (the tool point on its plane: a distance in m"
              << (data.flush ? " and the tool's tilt in rad" : "") << " per configuration; "
              << setup.planes.size() << " plane(s))\n"
              << r.ToString();
  }
  return 0;
}

// identifiability --sensor scanner: at the configurations of a CSV (q…, plane; a scanner data
// file's rows of one configuration count once).
int ScannerIdentifiability(const po::variables_map& vm) {
  RefuseRangerOptions(
      vm, "scanner", {"estimate-ranger", "estimate-base", "estimate-tool", "prior-sigma", "prior"});
  const Setup setup = ResolveSetup(vm);
  const std::unique_ptr<ScannerMeasurement> kind =
      MakeScannerKind(setup.rig.robot, setup.planes, setup.rig.ranger, vm);
  const std::string file = SingleFile(vm, "configs");
  const TargetedConfigurations configs =
      ReadCsv(file).Column("beam") >= 0
          ? ReadScannerData(file, setup.rig.robot, setup.planes, kind->num_beams()).configs
          : ReadRobotConfigurations(file, setup.rig.robot, &setup.planes);
  IdentifiabilityOptions options;
  ReadSettingOptions(vm, IdentifiabilityOptions::Settings(), &options);
  const IdentifiabilityReport r = AnalyzeIdentifiability(*kind, configs, nullptr, options);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentifiabilityJson(r);
    j["sensor"] = "scanner";
    j["values_per_configuration"] = kind->rows_per_configuration();
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "sensor: scanner (" << kind->num_beams()
              << " beam(s): a distance in m each per configuration; " << setup.planes.size()
              << " plane(s))\n"
              << r.ToString();
  }
  return 0;
}

}  // namespace

int IdentifiabilityCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal identifiability options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::vector<std::string>>()->required()->composing(),
                  "configurations CSV; repeat it with one kind per file in --sensor for the "
                  "terms several kinds identify together (--sensor point,contact)")(
      "estimate-ranger", po::value<std::string>()->default_value("none"),
      "ranger terms to estimate: none, offset, scale, offset,scale (reading = (1+s) h + o)")(
      "estimate-plane", po::value<std::string>()->default_value("none"),
      "plane terms in the set: none, normal, offset, normal,offset")(
      "fix", po::value<std::string>(), "parameters to leave out, comma-separated")(
      "prior-sigma", po::value<std::string>(),
      "prior standard deviations as identify takes them (theta=1mrad,a=0.5mm,...): also say, "
      "per term, how much readings with --sigma-mm and --repetitions would inform it against "
      "its prior (posterior/prior std; above 0.9 the prior alone sets it)")(
      "prior", po::bool_switch(),
      "the same with the robot file's tolerances: (--prior-sigma entries replace the same keys)");
  AddFrameTermOptions(o);
  AddSensorOptions(o);
  AddEstimatePresetOption(o);
  AddSettingOptions(o, NoiseModel::Settings(), {"sigma_mm", "repetitions"});
  AddSettingOptions(o, IdentifiabilityOptions::Settings(), {"rank_tolerance"});
  AddNonGeometricOptions(o);
  po::variables_map vm;
  if (!Parse("identifiability", "--configs C.csv [options]", o, args, &vm)) return 0;
  RefuseNonGeometricForOtherSensors(vm);
  if (IsTreeRun(vm)) return TreeIdentifiability(vm);
  const std::string sensor = ResolveSensor(vm);
  if (sensor == "mixed") return MixedIdentifiability(vm);
  if (sensor == "socket") return SocketIdentifiability(vm);
  if (sensor == "contact") return ContactIdentifiability(vm);
  if (sensor == "scanner") return ScannerIdentifiability(vm);
  if (sensor != "ranger") return TrackerIdentifiability(vm, sensor);
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  IdentifiabilityOptions options;
  ReadSettingOptions(vm, IdentifiabilityOptions::Settings(), &options);
  if (AsksNonGeometric(vm))
    return NonGeometricIdentifiability(vm, SingleFile(vm, "configs"), options);
  const TargetedConfigurations configs =
      ReadRobotConfigurations(SingleFile(vm, "configs"), robot, &planes);
  MeasurementModel model(robot, planes, ResolveParameterSet(robot, vm, planes.size()));
  const IdentifiabilityReport r = AnalyzeIdentifiability(model, configs, nullptr, options);
  RemedyOptions remedy_options;
  remedy_options.ranger = rig.ranger;
  remedy_options.identifiability = options;
  const RemedyReport remedies = FindRemedies(model, configs, r, remedy_options);
  const std::optional<PriorInformation> priors = PriorInformationAt(vm, rig, model, configs);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentifiabilityJson(r);
    if (!r.full_rank()) j["remedies"] = RemediesJson(remedies);
    if (priors) j["priors"] = PriorInformationJson(*priors);
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << r.ToString();
    if (!r.full_rank()) std::cout << "how to recover what is lost:\n" << remedies.ToString();
    if (priors) std::cout << priors->ToString();
  }
  return 0;
}

int PaperCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal paper options");
  o.add_options()("robot", po::value<std::string>()->default_value("paper"), "robot file or name")(
      "seed", po::value<long long>()->default_value(1), "random seed of the realisation")(
      "case1-selection", po::value<std::string>()->default_value("backward"),
      "how case 1 picks 50 of 101: backward, exchange, greedy, sampled (the paper's), random")(
      "format", po::value<std::string>()->default_value("text"), "text or json");
  AddSettingOptions(o, SelectionOptions::Settings(), {"samples"});
  po::variables_map vm;
  if (!Parse("paper", "[--seed K] [options]", o, args, &vm)) return 0;
  const RobotFile rig = LoadRobot(vm["robot"].as<std::string>());
  PaperCaseOptions options;
  options.seed = ParseSeed(vm);
  options.case1_selection.method =
      ParseSelectionMethod(vm["case1-selection"].as<std::string>(), "--case1-selection");
  ReadSettingOptions(vm, SelectionOptions::Settings(), &options.case1_selection);
  const PaperCasesResult r = RunPaperCases(rig, options);
  if (ResolveFormat(vm) == Format::kJson) {
    std::cout << PaperCasesJson(r, options).dump(2) << "\n";
  } else {
    std::cout << PaperCasesText(rig.robot, r, options);
  }
  return 0;
}

}  // namespace lrcal::cli
