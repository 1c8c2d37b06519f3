// The non-geometric model on the command line (issue 28; measurement/environment_measurement.h):
// identify and identifiability with --estimate-compliance and --estimate-thermal, and simulate of
// an arm that bends under gravity and grows with temperature (the robot file's masses:,
// compliance:, thermal: and environment:, the data's gravity_x,gravity_y,gravity_z and
// temperature_c columns, --gravity and --temperature-c).
#include <cmath>
#include <iostream>
#include <memory>

#include "cli_common.h"
#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/result_json.h"
#include "lrcal/io/robot_data.h"
#include "lrcal/measurement/ranger_measurement.h"

namespace lrcal::cli {

void AddNonGeometricOptions(po::options_description& o) {
  o.add_options()("estimate-compliance", po::value<std::string>()->default_value("none"),
                  "joint compliances to estimate (the joint turned by c_j times gravity's torque "
                  "from the robot file's masses:): none, all, or joints j2,j3,...")(
      "estimate-thermal", po::value<std::string>()->default_value("none"),
      "thermal coefficients to estimate (link lengths grown by 1 + alpha (T - T_ref), the "
      "ranger's scale by alpha_r (T - T_ref)): none, links, ranger, all");
}

bool AsksNonGeometric(const po::variables_map& vm) {
  return (vm.count("estimate-compliance") &&
          vm["estimate-compliance"].as<std::string>() != "none") ||
         (vm.count("estimate-thermal") && vm["estimate-thermal"].as<std::string>() != "none");
}

namespace {

// The kind identify and identifiability fit: the options' parameter set (--fix, --estimate-*)
// with the non-geometric terms asked for around it.
std::unique_ptr<EnvironmentMeasurement> NonGeometricKind(const po::variables_map& vm,
                                                         const RobotFile& rig,
                                                         const PlaneSet& planes) {
  const RobotModel& robot = rig.robot;
  const ParameterSet asked = ResolveParameterSet(robot, vm, planes.size());
  NonGeometricTerms terms;
  terms.compliance_joints = NonGeometricTerms::ParseCompliance(
      vm["estimate-compliance"].as<std::string>(), robot.num_links(), "--estimate-compliance");
  terms.ParseThermal(vm["estimate-thermal"].as<std::string>(), "--estimate-thermal");
  if (!terms.compliance_joints.empty() && rig.non_geometric.masses.empty())
    throw InputError(
        "--estimate-compliance",
        "a joint's compliance is seen through gravity's torque on it: the robot file " + rig.path +
            " has no masses: (docs/FILE_FORMATS.md)");
  return RangerInEnvironment(robot, robot, planes, asked, rig.ranger, rig.non_geometric, terms,
                             "--estimate-compliance/--estimate-thermal");
}

// What identify does with the ranger's model that this path does not do yet.
void RefuseRangerOnlyOutputs(const po::variables_map& vm) {
  for (const char* option :
       {"write-robot", "report", "predict-at", "holdout", "only-significant", "measured"})
    if (vm.count(option) && !vm[option].defaulted())
      throw InputError(std::string("--") + option,
                       "is not available with --estimate-compliance or --estimate-thermal: the "
                       "calibrated robot file, the report and the accuracy statements are the "
                       "geometric model's (docs/FILE_FORMATS.md, Non-geometric terms)");
}

// A fit refused as rank deficient: what to fix or leave out, and why each term was lost.
int ReportRankDeficient(const IdentificationSummary& s) {
  std::string fix;
  for (const auto& f : s.identifiability.suggested_fixed)
    if (ComplianceTermJoint(f) < 0 && f != kThermalLinksTerm && f != kThermalRangerTerm)
      fix += (fix.empty() ? "" : ",") + f;
  std::cerr << "lrcal identify: the terms are not identifiable from these measurements; pass "
               "--auto-fix, or "
            << (fix.empty() ? "" : "fix " + fix + " (--fix) and ")
            << "leave the lost compliance or thermal terms out of --estimate-compliance and "
               "--estimate-thermal\n";
  for (const std::string& x : s.identifiability.explanations)
    std::cerr << "lrcal identify: lost: " << x << "\n";
  return 3;
}

}  // namespace

int NonGeometricIdentify(const po::variables_map& vm, const std::string& data_file,
                         const IdentificationOptions& options) {
  RefuseRangerOnlyOutputs(vm);
  const Setup setup = ResolveSetup(vm);
  const MeasurementSet data = ReadRobotMeasurements(
      data_file, setup.rig, &setup.planes, Averaging::Parse(vm["average"].as<std::string>()));
  const std::unique_ptr<EnvironmentMeasurement> kind =
      NonGeometricKind(vm, setup.rig, setup.planes);
  MeasuredValues values = ToMeasuredValues(data);
  const IdentificationSummary s = Identify(*kind, values, options);
  if (s.termination == Termination::kInvalidInput && data.size() < kind->num_parameters())
    throw InputError(data_file, s.message);
  // Why the terms --auto-fix held were lost, in words.
  const std::vector<std::string> held = kind->ExplainLostTerms(values.configs, s.fixed);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentificationJson(s);
    if (!held.empty()) j["held_in_words"] = held;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << s.FullReport();
    for (const std::string& x : held) std::cout << "held at nominal: " << x << "\n";
  }
  if (s.termination == Termination::kRankDeficient) return ReportRankDeficient(s);
  if (s.IsSolutionUsable() && !s.fit.consistent) {
    std::cerr << "lrcal identify: the fit is inconsistent with --sigma-mm (p = " << s.fit.p_value
              << " < 0.001); see the fit line above\n";
    return 4;
  }
  return s.IsSolutionUsable() ? 0 : 1;
}

int NonGeometricIdentifiability(const po::variables_map& vm, const std::string& configs_file,
                                const IdentifiabilityOptions& options) {
  const Setup setup = ResolveSetup(vm);
  const TargetedConfigurations configs =
      ReadRobotConfigurations(configs_file, setup.rig.robot, &setup.planes);
  const std::unique_ptr<EnvironmentMeasurement> kind =
      NonGeometricKind(vm, setup.rig, setup.planes);
  const IdentifiabilityReport r = AnalyzeIdentifiability(*kind, configs, nullptr, options);
  if (ResolveFormat(vm) == Format::kJson) {
    std::cout << IdentifiabilityJson(r).dump(2) << "\n";
  } else {
    std::cout << r.ToString();
  }
  return 0;
}

void AddEnvironmentOptions(po::options_description& o) {
  o.add_options()("gravity", po::value<std::string>(),
                  "gravity in the base frame as X,Y,Z (m/s^2: 0,0,-9.81 upright on the ground, "
                  "0,0,0 on orbit) for configurations whose file has no gravity columns")(
      "temperature-c", po::value<double>(),
      "the arm's temperature (deg C) for configurations whose file has no temperature_c column");
}

namespace {

// --gravity and --temperature-c into the configurations that do not give them; refused where the
// file gives them (one source per value).
void ApplyEnvironmentOptions(const po::variables_map& vm, TargetedConfigurations* configs) {
  Environment given;
  if (vm.count("gravity")) {
    const std::vector<std::string> parts = SplitList(vm["gravity"].as<std::string>());
    if (parts.size() != 3)
      throw InputError("--gravity", "expected X,Y,Z (m/s^2, base frame), got '" +
                                        vm["gravity"].as<std::string>() + "'");
    for (int c = 0; c < 3; ++c)
      if (!ParseDecimal(parts[static_cast<std::size_t>(c)], &given.gravity[c]))
        throw InputError("--gravity", "'" + parts[static_cast<std::size_t>(c)] +
                                          "' is not a number: expected X,Y,Z in m/s^2");
  }
  if (vm.count("temperature-c")) {
    given.temperature_c = vm["temperature-c"].as<double>();
    if (!(given.temperature_c >= -273.15) || !std::isfinite(given.temperature_c))
      throw InputError("--temperature-c", "expected a temperature in deg C above absolute zero");
  }
  for (int i = 0; i < configs->size(); ++i) {
    const Environment& own = configs->environment(i);
    if (vm.count("gravity") && own.gravity.allFinite())
      throw InputError("--gravity",
                       "the configurations file gives gravity_x,gravity_y,gravity_z "
                       "already; give one or the other");
    if (vm.count("temperature-c") && own.temperature_c == own.temperature_c)
      throw InputError(
          "--temperature-c",
          "the configurations file gives temperature_c already; give one or the other");
    configs->SetEnvironment(i, own.Or(given));
  }
}

}  // namespace

bool SimulatesEnvironment(const po::variables_map& vm, const RobotFile& rig,
                          const TargetedConfigurations& configs) {
  return vm.count("gravity") || vm.count("temperature-c") || configs.HasEnvironments() ||
         !rig.true_non_geometric.IsGeometric();
}

int NonGeometricSimulate(const po::variables_map& vm, const RobotFile& rig, const PlaneSet& planes,
                         TargetedConfigurations configs, const NoiseModel& noise) {
  if (noise.DisturbsGeometry() || noise.outlier_fraction > 0 || !noise.average.IsMean())
    throw InputError("--encoder-sigma-mrad",
                     "encoder noise, plane form, outliers and robust averages are simulated for "
                     "the geometric ranger; an arm in an environment (compliance, temperature) "
                     "takes sigma, repetitions and the ranger's true errors");
  ApplyEnvironmentOptions(vm, &configs);
  for (int i = 0; i < configs.size(); ++i)  // every row says where it was read
    configs.SetEnvironment(i, configs.environment(i).Or(rig.true_non_geometric.defaults));
  const RobotModel& robot = rig.robot;
  const RobotModel true_arm = rig.truth.TrueRobot(robot);
  const std::unique_ptr<EnvironmentMeasurement> kind =
      RangerInEnvironment(true_arm, robot, planes,
                          MakeParameterSet(robot, std::vector<PlaneTerms>(planes.size()), {}, "fix",
                                           RangerTerms{true, true}),
                          rig.ranger, rig.true_non_geometric, NonGeometricTerms{}, "robot file");
  const EnvironmentMeasurement& truth = *kind;
  // The true ranger's offset and scale as the terms of the truth's ranger (e = 0 elsewhere).
  std::vector<double> e(static_cast<std::size_t>(truth.num_parameters()), 0.0);
  const std::vector<std::string>& names = truth.parameter_names();
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (names[k] == "ranger_offset") e[k] = rig.truth.ranger_offset;
    if (names[k] == "ranger_scale") e[k] = rig.truth.ranger_scale;
  }
  std::vector<double> exact(static_cast<std::size_t>(configs.size()));
  truth.Bind(configs)->Predict(e.data(), exact.data(), nullptr);
  const std::vector<std::string> reasons = truth.MissReasons(configs, e.data());
  // Reading r of configuration i: exact + σ z, z the standard normal at index i·R + r.
  const RandomStream stream(ParseSeed(vm), 0, 0, RandomPurpose::kNoise);
  const int R = noise.repetitions;
  TargetedConfigurations read(configs.num_joints());
  std::vector<double> raw;
  for (int i = 0; i < configs.size(); ++i) {
    if (reasons[static_cast<std::size_t>(i)] != "ok") {
      std::cerr << "lrcal simulate: configuration " << i + 1 << " (line " << i + 2
                << "): no reading, " << reasons[static_cast<std::size_t>(i)] << "\n";
      continue;
    }
    read.AddFrom(configs, i);
    for (int r = 0; r < R; ++r)
      raw.push_back(exact[static_cast<std::size_t>(i)] +
                    noise.sigma * stream.Normal(static_cast<std::uint64_t>(i) * R + r));
  }
  const std::string path = vm["out"].as<std::string>();
  WriteReadings(path, read, raw, R);
  std::cerr << "lrcal simulate: " << read.size() << " configurations x " << R
            << " readings written to " << path << " (the arm in its environment: "
            << (rig.true_non_geometric.IsGeometric() ? "no compliance or thermal growth"
                                                     : "compliance and thermal growth")
            << ")\n";
  return 0;
}

}  // namespace lrcal::cli
