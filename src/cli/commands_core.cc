// The calibration-core subcommands: kinematics, sample, simulate, identify, identifiability,
// paper.
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "cli_common.h"
#include "lrcal/build_info.h"
#include "lrcal/core/hash.h"
#include "lrcal/core/json.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/design/identifiability_remedies.h"
#include "lrcal/identification/cross_validation.h"
#include "lrcal/identification/identification.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/urdf.h"
#include "lrcal/measurement/simulation.h"
#include "lrcal/paper/paper_case.h"

namespace lrcal::cli {

namespace {

std::uint64_t ParseSeed(const po::variables_map& vm) {
  const long long s = vm["seed"].as<long long>();
  if (s < 0) throw InputError("--seed", "expected a non-negative integer");
  return static_cast<std::uint64_t>(s);
}

Json IdentifiabilityJson(const IdentifiabilityReport& r) {
  Json j;
  j["n_params"] = r.num_params();
  j["n_configurations"] = r.num_configurations;
  j["rank"] = r.rank;
  j["parameters"] = r.names;
  j["singular_values"] = ToJson(r.singular_values);
  j["condition_number"] = std::isfinite(r.condition_number) ? Json(r.condition_number) : Json();
  j["unidentifiable"] = r.unidentifiable;
  Json deps = Json::array();
  for (const auto& d : r.dependencies) {
    Json terms = Json::array();
    for (const auto& [name, c] : d.terms) terms.push_back({{"name", name}, {"coefficient", c}});
    deps.push_back(terms);
  }
  j["dependencies"] = deps;
  j["suggested_fixed"] = r.suggested_fixed;
  return j;
}

// What each remedy recovers; `cheapest_fix` has one entry per lost direction (null: none found).
Json RemediesJson(const RemedyReport& r) {
  Json j;
  j["lost"] = r.lost;
  Json list = Json::array();
  for (const auto& m : r.remedies) {
    Json e{{"kind", RemedyKindName(m.kind)}, {"action", m.action}, {"recovers", m.recovers}};
    if (!m.parameter.empty()) e["parameter"] = m.parameter;
    if (m.kind == Remedy::Kind::kAddPlane || m.kind == Remedy::Kind::kAddKnownDistance)
      e["plane"] = {{"normal", {m.plane.normal[0], m.plane.normal[1], m.plane.normal[2]}},
                    {"offset", m.plane.offset}};
    list.push_back(e);
  }
  j["remedies"] = list;
  Json cheapest = Json::array();
  for (int c : r.cheapest) cheapest.push_back(c >= 0 ? Json(r.remedies[c].action) : Json());
  j["cheapest_fix"] = cheapest;
  j["unreachable"] = r.unreachable;
  return j;
}

Json IdentificationJson(const IdentificationSummary& s) {
  Json j;
  Json params = Json::array();
  for (std::size_t k = 0; k < s.names.size() && s.IsSolutionUsable(); ++k) {
    params.push_back({{"name", s.names[k]},
                      {"nominal", s.nominal[k]},
                      {"estimate", s.estimate[k]},
                      {"delta", s.delta[k]},
                      {"std", s.std_residual[k]},
                      {"std_given_sigma", s.std_given.size() ? Json(s.std_given[k]) : Json()}});
  }
  j["parameters"] = params;
  j["covariance"] = s.IsSolutionUsable() ? ToJson(s.covariance_residual) : Json();
  j["covariance_given_sigma"] = s.covariance_given.size() ? ToJson(s.covariance_given) : Json();
  j["correlation"] = s.IsSolutionUsable() ? ToJson(s.correlation) : Json();
  j["rank"] = s.identifiability.rank;
  j["n_params"] = s.identifiability.num_params();
  j["fixed_for_rank"] = s.fixed;
  j["iterations"] = s.iterations;
  j["termination"] = TerminationName(s.termination);
  j["usable"] = s.IsSolutionUsable();
  j["message"] = s.message;
  j["residual_rms"] = s.residual_rms;
  const auto number = [](double x) { return std::isnan(x) ? Json() : Json(x); };
  j["sigma_hat"] = number(s.sigma_hat);
  if (s.IsSolutionUsable()) {
    Json fit = {{"dof", s.fit.dof}, {"standardized_residuals", s.fit.standardized}};
    Json suspects = Json::array();
    for (int i : s.fit.suspects) suspects.push_back(i + 1);
    fit["suspects"] = suspects;  // 1-based configurations
    if (s.fit.sigma_given) {
      fit["chi2"] = s.fit.chi2;
      fit["p_value"] = number(s.fit.p_value);
      fit["consistent"] = s.fit.consistent;
    } else {
      fit["chi2"] = fit["p_value"] = fit["consistent"] = nullptr;  // no σ given: no test
    }
    j["fit"] = fit;
  }
  j["n_configurations"] = s.num_configurations;
  j["solver"] = s.solver;
  j["loss"] = s.loss;
  if (!s.identifiability.full_rank()) j["identifiability"] = IdentifiabilityJson(s.identifiability);
  return j;
}

void PrintIdentification(const IdentificationSummary& s) {
  std::cout << s.BriefReport() << "\n";
  if (!s.IsSolutionUsable()) {
    std::cout << s.message << "\n";
    if (!s.identifiability.full_rank()) std::cout << s.identifiability.ToString();
    return;
  }
  std::cout << "sigma_hat per reading: "
            << (std::isnan(s.sigma_hat) ? std::string("undefined")
                                        : Fixed(s.sigma_hat * 1e3, 4) + " mm")
            << "\n"
            << s.fit.Explain() << s.ParameterTable();
  if (!s.fixed.empty()) {
    std::cout << "fixed at nominal because of rank deficiency:";
    for (const auto& f : s.fixed) std::cout << " " << f;
    std::cout << "\n";
  }
}

IdentificationOptions ResolveIdentificationOptions(const po::variables_map& vm) {
  IdentificationOptions options;
  options.solver = ParseName(kSolverNames, vm["solver"].as<std::string>(), "--solver", "solver");
  options.loss = ParseName(kRobustLossNames, vm["loss"].as<std::string>(), "--loss", "loss");
  ReadSettingOptions(vm, IdentificationOptions::Settings(), &options);
  options.fix_dependent_parameters = vm["auto-fix"].as<bool>();
  options.Validate();
  return options;
}

// Tool pose, beam and reading (and the Jacobian row) of configuration i, as JSON and a row of
// `table`.
Json KinematicsRow(const MeasurementModel& model, const ModelPoint& point,
                   const ConfigurationSet& configs, int i, const RangerSpec& ranger, bool jacobian,
                   Table* table) {
  const ParameterSet& ps = model.parameters();
  std::vector<double> row(ps.size());
  double h;
  const double nb = model.Evaluate(point, configs, i, &h, jacobian ? row.data() : nullptr);
  const BeamMiss miss = ClassifyReading(h, nb, ranger);
  const Pose<double> pose = ToolPose(point, configs, i);
  Json j;
  j["q"] = std::vector<double>(configs.q(i), configs.q(i) + configs.num_joints());
  j["position"] = {pose.p_BT.x(), pose.p_BT.y(), pose.p_BT.z()};
  j["rotation"] = ToJson(Eigen::MatrixXd(pose.R_BT));
  j["beam"] = {pose.R_BT(0, 2), pose.R_BT(1, 2), pose.R_BT(2, 2)};
  j["h"] = miss == BeamMiss::kNone ? Json(h) : Json();
  j["status"] = BeamMissName(miss);
  if (jacobian) {
    Json g = Json::object();
    for (int k = 0; k < ps.size(); ++k) g[ps.names[k]] = row[k];
    j["jacobian"] = g;
  }
  table->AddRow({std::to_string(i + 1), Fixed(pose.p_BT.x(), 6), Fixed(pose.p_BT.y(), 6),
                 Fixed(pose.p_BT.z(), 6), Fixed(pose.R_BT(0, 2), 6), Fixed(pose.R_BT(1, 2), 6),
                 Fixed(pose.R_BT(2, 2), 6),
                 miss == BeamMiss::kNone ? Fixed(h, 6) : std::string("—"), BeamMissName(miss)});
  return j;
}

Table JacobianTable(const std::vector<std::string>& names, const Json& rows) {
  std::vector<std::string> header = {"#"};
  for (const auto& n : names) header.push_back(n);
  Table t(header, "Identification Jacobian rows dh/de (m/rad for angles, m/m for lengths)");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::vector<std::string> r = {std::to_string(i + 1)};
    for (const auto& n : names) r.push_back(Fixed(rows[i]["jacobian"][n].get<double>(), 5));
    t.AddRow(r);
  }
  return t;
}

}  // namespace

int KinematicsCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal kinematics options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>()->required(),
                  "configurations CSV (q1..qN, rad)")(
      "model", po::value<std::string>()->default_value("nominal"), "nominal or true")(
      "jacobian", po::bool_switch(), "also print the identification Jacobian row")(
      "estimate-ranger", po::value<std::string>()->default_value("none"),
      "ranger terms to estimate: none, offset, scale, offset,scale (reading = (1+s) h + o)")(
      "estimate-plane", po::value<std::string>()->default_value("none"),
      "plane terms in the Jacobian: none, normal, offset, normal,offset")(
      "fix", po::value<std::string>(), "parameters left out of the Jacobian, comma-separated");
  po::variables_map vm;
  if (!Parse("kinematics", "--configs C.csv [options]", o, args, &vm)) return 0;
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  const std::string which = vm["model"].as<std::string>();
  if (which != "nominal" && which != "true")
    throw InputError("--model", "expected nominal or true, got '" + which + "'");
  const ConfigurationSet configs =
      ReadRobotConfigurations(vm["configs"].as<std::string>(), robot, &planes);
  const Eigen::VectorXd values = which == "true" ? robot.true_values() : robot.nominal_values();
  ParameterSet ps = ResolveParameterSet(robot, vm, planes.size());
  // The Jacobian is taken at the chosen model: its robot deltas relative to nominal.
  MeasurementModel model(robot, planes, ps);
  std::vector<double> e(ps.size(), 0.0);
  for (int k = 0; k < ps.num_robot(); ++k)
    e[k] = values[ps.robot_values[k]] - robot.nominal_values()[ps.robot_values[k]];
  ModelPoint point;
  model.Prepare(e.data(), &point);
  const bool jac = vm["jacobian"].as<bool>();
  Table table({"#", "x (m)", "y (m)", "z (m)", "beam x", "beam y", "beam z", "h (m)", "status"},
              "Tool pose and laser reading per configuration (" + which + " model)");
  Json out = Json::array();
  for (int i = 0; i < configs.size(); ++i)
    out.push_back(KinematicsRow(model, point, configs, i, rig.ranger, jac, &table));
  if (ResolveFormat(vm) == Format::kJson) {
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << table.ToText();
    if (jac) std::cout << "\n" << JacobianTable(ps.names, out).ToText();
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
      "min-singular-value", po::value<double>()->default_value(0.05),
      "reject arm configurations whose geometric Jacobian has a smaller singular value")(
      "out", po::value<std::string>()->required(), "output CSV (q1..qN)");
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
  options.min_jacobian_singular_value = vm["min-singular-value"].as<double>();
  options.require_beam_hit = !vm["validation"].as<bool>();
  options.Validate("--min-singular-value");
  SamplingReport report;
  const bool validation = vm["validation"].as<bool>();
  ConfigurationSet configs = SampleConfigurations(
      robot, planes, std::vector<int>(planes.size(), count),
      RandomStream(ParseSeed(vm), 0, 0,
                   validation ? RandomPurpose::kValidation : RandomPurpose::kPool),
      options, &report);
  WriteConfigurations(vm["out"].as<std::string>(), configs);
  std::cerr << "lrcal sample: " << report.ToString() << "; wrote " << vm["out"].as<std::string>()
            << "\n";
  return 0;
}

int SimulateCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal simulate options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>()->required(), "configurations CSV")(
      "seed", po::value<long long>()->default_value(1), "random seed")(
      "out", po::value<std::string>()->required(), "measurement CSV to write");
  AddSettingOptions(o, NoiseModel::Settings());
  po::variables_map vm;
  if (!Parse("simulate", "--configs C.csv --out M.csv [options]", o, args, &vm)) return 0;
  CheckOutputFile(vm["out"].as<std::string>(), "--out");
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  const ConfigurationSet configs =
      ReadRobotConfigurations(vm["configs"].as<std::string>(), robot, &planes);
  NoiseModel noise;
  noise.ranger_offset = rig.ranger_offset;  // the robot file's true ranger errors
  noise.ranger_scale = rig.ranger_scale;
  ReadSettingOptions(vm, NoiseModel::Settings(), &noise);
  if (static_cast<double>(noise.repetitions) * configs.size() > 1e7)
    throw InputError("--repetitions", "would write " + std::to_string(configs.size()) + " x " +
                                          std::to_string(noise.repetitions) +
                                          " readings; at most 10,000,000 lines per file");
  MeasurementSet data;
  std::vector<BeamMiss> misses;
  std::vector<double> raw;
  const int missed = SimulateReadings(
      robot, robot.true_values(), planes, rig.ranger, configs, noise,
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

// The model Identify solved: `model`'s parameter set without the parameters it fixed for rank
// deficiency (s.delta is laid out for it).
MeasurementModel SolvedModel(const MeasurementModel& model, const IdentificationSummary& s) {
  return MeasurementModel(model.robot(), model.nominal_planes(),
                          WithoutParameters(model.robot(), model.parameters(), s.fixed));
}

// The estimate's covariance: with the given σ when --sigma-mm was given, else residual-based.
const Eigen::MatrixXd& FitCovariance(const IdentificationSummary& s,
                                     const IdentificationOptions& options) {
  return options.sigma > 0 ? s.covariance_given : s.covariance_residual;
}

// identify --write-robot: the calibrated model (the parameter set Identify solved for, reduced
// if it fixed parameters for rank deficiency) as a robot file with its record.
void WriteCalibratedRobot(const std::string& path, const std::string& data_file,
                          const RobotFile& rig, const MeasurementModel& model,
                          const IdentificationSummary& s, const IdentificationOptions& options) {
  const MeasurementModel solved = SolvedModel(model, s);
  CalibrationRecord r;
  r.data_file = data_file;
  std::ifstream in(data_file, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  r.data_fnv1a = HashHex(bytes.str());
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &utc);
  r.date = date;
  r.lrcal = std::string(LRCAL_VERSION) + " (" + LRCAL_GIT_COMMIT + ")";
  const bool given = options.sigma > 0;
  r.sigma = given ? options.sigma : s.sigma_hat;
  r.sigma_source = given ? "given (--sigma-mm)" : "residual (sigma_hat)";
  r.parameters = s.names;
  r.estimate = s.estimate;
  if (given || !std::isnan(s.sigma_hat)) r.covariance = FitCovariance(s, options);
  WriteCalibratedRobotFile(path, rig, solved.LinkValues(s.delta.data()),
                           solved.PlanesAt(s.delta.data()), r);
  std::cerr << "lrcal identify: calibrated robot written to " << path << "\n";
}

// identify --holdout: configurations 1-based, like the fit's suspects.
Json CrossValidationJson(const CrossValidation& cv) {
  Json predictions = Json::array();
  for (const auto& p : cv.predictions)
    predictions.push_back({{"configuration", p.configuration + 1},
                           {"fold", p.fold},
                           {"error", p.error},
                           {"predicted_std", p.predicted_std},
                           {"z", p.z}});
  Json failed = Json::array();
  for (const auto& [fold, why] : cv.failed_folds)
    failed.push_back({{"fold", fold}, {"reason", why}});
  Json beyond = Json::array();
  for (int i : cv.beyond_4) beyond.push_back(i + 1);
  const bool any = !cv.predictions.empty();
  return {{"folds", cv.folds},
          {"assignment", "configuration i (0-based) in fold i mod K"},
          {"predictions", predictions},
          {"failed_folds", failed},
          {"rms_error", any ? Json(cv.rms_error) : Json()},
          {"rms_predicted", any ? Json(cv.rms_predicted) : Json()},
          {"ratio", any ? Json(cv.rms_error / cv.rms_predicted) : Json()},
          {"mean_z2", any ? Json(cv.mean_z2) : Json()},
          {"mean_z2_tolerance", any ? Json(cv.mean_z2_tolerance) : Json()},
          {"consistent", any ? Json(cv.consistent()) : Json()},
          {"beyond_4", beyond}};
}

// identify --predict-at: the fit's covariance (given σ, else residual-based) at the poses.
void PredictAt(const std::string& file, const MeasurementModel& model,
               const IdentificationSummary& s, const IdentificationOptions& options, Json* json,
               std::string* text) {
  const ConfigurationSet poses =
      ReadRobotConfigurations(file, model.robot(), &model.nominal_planes());
  const Eigen::MatrixXd& C = FitCovariance(s, options);
  if (!C.allFinite())
    throw InputError("--predict-at",
                     "the covariance is undefined (as many configurations as parameters); "
                     "give --sigma-mm");
  const std::vector<PoseAccuracy> predicted =
      PredictPoseAccuracy(SolvedModel(model, s), s.delta.data(), C, poses);
  *json = PoseAccuracyJson(predicted, poses);
  *text = PoseAccuracyText(predicted);
}

// identify's output: the fit, and what --predict-at and --holdout add, as text or JSON.
void PrintIdentifyResults(const po::variables_map& vm, const MeasurementModel& model,
                          const MeasurementSet& data, const IdentificationSummary& s,
                          const IdentificationOptions& options) {
  Json accuracy;
  std::string accuracy_text;
  if (vm.count("predict-at") && s.IsSolutionUsable())
    PredictAt(vm["predict-at"].as<std::string>(), model, s, options, &accuracy, &accuracy_text);
  std::optional<CrossValidation> cv;
  if (vm.count("holdout") && s.IsSolutionUsable())
    cv = CrossValidate(model, data, vm["holdout"].as<int>(), options);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentificationJson(s);
    if (!accuracy.is_null()) j["accuracy"] = accuracy;
    if (cv) j["holdout"] = CrossValidationJson(*cv);
    std::cout << j.dump(2) << "\n";
  } else {
    PrintIdentification(s);
    std::cout << accuracy_text << (cv ? cv->ToString() : "");
  }
}

// identify --report DIR: everything the page shows, as calibration.json (SI), the calibrated robot
// file, then report.html from analysis/calibration_report.py. Cross-validation uses --holdout K,
// else 5 folds; the accuracy map 500 poses over the joint ranges (seed 1).
void WriteCalibrationReport(const std::string& dir, const po::variables_map& vm,
                            const RobotFile& rig, const MeasurementModel& model,
                            const MeasurementSet& data, const IdentificationSummary& s,
                            const IdentificationOptions& options) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError("--report", "cannot create the folder '" + dir + "': " + ec.message());
  Json j = IdentificationJson(s);
  j["data"] = {{"file", vm["data"].as<std::string>()}, {"configurations", data.size()}};
  j["robot"] = rig.path;
  j["sigma_given"] = options.sigma > 0 ? Json(options.sigma) : Json();
  j["identifiability"] = IdentifiabilityJson(s.identifiability);
  if (s.IsSolutionUsable()) {
    const int folds = vm.count("holdout") ? vm["holdout"].as<int>() : std::min(5, data.size());
    if (folds >= 2) j["holdout"] = CrossValidationJson(CrossValidate(model, data, folds, options));
    const Eigen::MatrixXd& C = FitCovariance(s, options);
    if (C.allFinite()) {
      const ConfigurationSet poses = WorkspacePoses(model.robot(), 500, 1);
      j["workspace_accuracy"] = PoseAccuracyJson(
          PredictPoseAccuracy(SolvedModel(model, s), s.delta.data(), C, poses), poses);
    }
    WriteCalibratedRobot(dir + "/calibrated.yaml", vm["data"].as<std::string>(), rig, model, s,
                         options);
    j["calibrated_robot"] = "calibrated.yaml";
    // The same model as URDF, from the file just written (what lrcal export would write).
    const RobotFile calibrated = LoadRobotFile(dir + "/calibrated.yaml");
    WriteFileAtomically(dir + "/calibrated.urdf",
                        UrdfText(calibrated.robot, calibrated.robot.nominal_values()));
    j["calibrated_urdf"] = "calibrated.urdf";
  }
  WriteFileAtomically(dir + "/calibration.json", j.dump(2));
  const int code = RunAnalysisScript("analysis/calibration_report.py", dir);
  if (code != 0)
    throw StorageError(dir + "/report.html: analysis/calibration_report.py failed (exit " +
                       std::to_string(code) +
                       "); calibration.json and the calibrated robot file are written");
  std::cerr << "lrcal identify: calibration report written to " << dir << "/report.html\n";
}

int IdentifyCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal identify options");
  AddCommonOptions(o);
  o.add_options()("data", po::value<std::string>()->required(),
                  "measurement CSV (q1..qN, h in m; rows with equal q are averaged)")(
      "estimate-ranger", po::value<std::string>()->default_value("none"),
      "ranger terms to estimate: none, offset, scale, offset,scale (reading = (1+s) h + o)")(
      "estimate-plane", po::value<std::string>()->default_value("none"),
      "plane terms to estimate: none, normal, offset, normal,offset")(
      "fix", po::value<std::string>(), "parameters to keep at nominal, comma-separated")(
      "auto-fix", po::bool_switch(),
      "if the set is rank-deficient, fix the suggested parameters and go on")(
      "solver", po::value<std::string>()->default_value("lm"), "lm (lrcal's) or ceres")(
      "loss", po::value<std::string>()->default_value("none"),
      "robust loss: none, huber, cauchy (either solver)")(
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
      "workspace), calibration.json and the calibrated robot file");
  AddSettingOptions(o, IdentificationOptions::Settings(), {"loss_scale_mm", "sigma_mm"});
  po::variables_map vm;
  if (!Parse("identify", "--data M.csv [options]", o, args, &vm)) return 0;
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  const MeasurementSet data = ReadRobotMeasurements(vm["data"].as<std::string>(), rig, &planes);
  MeasurementModel model(robot, planes, ResolveParameterSet(robot, vm, planes.size()));
  const IdentificationOptions options = ResolveIdentificationOptions(vm);
  const IdentificationSummary s = Identify(model, data, options);
  if (s.termination == Termination::kInvalidInput && data.size() < model.num_parameters())
    throw InputError(vm["data"].as<std::string>(), s.message);

  PrintIdentifyResults(vm, model, data, s, options);
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
    WriteCalibratedRobot(vm["write-robot"].as<std::string>(), vm["data"].as<std::string>(), rig,
                         model, s, options);
  if (vm.count("report"))
    WriteCalibrationReport(vm["report"].as<std::string>(), vm, rig, model, data, s, options);
  if (s.IsSolutionUsable() && !s.fit.consistent) {
    std::cerr << "lrcal identify: the fit is inconsistent with --sigma-mm (p = " << s.fit.p_value
              << " < 0.001); see the fit line above\n";
    return 4;
  }
  return s.IsSolutionUsable() ? 0 : 1;
}

int IdentifiabilityCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal identifiability options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>()->required(), "configurations CSV")(
      "estimate-ranger", po::value<std::string>()->default_value("none"),
      "ranger terms to estimate: none, offset, scale, offset,scale (reading = (1+s) h + o)")(
      "estimate-plane", po::value<std::string>()->default_value("none"),
      "plane terms in the set: none, normal, offset, normal,offset")(
      "fix", po::value<std::string>(), "parameters to leave out, comma-separated")(
      "rank-tolerance", po::value<double>()->default_value(1e-8),
      "relative singular value below which a direction is unobservable");
  po::variables_map vm;
  if (!Parse("identifiability", "--configs C.csv [options]", o, args, &vm)) return 0;
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  const RobotModel& robot = rig.robot;
  const PlaneSet& planes = setup.planes;
  const ConfigurationSet configs =
      ReadRobotConfigurations(vm["configs"].as<std::string>(), robot, &planes);
  MeasurementModel model(robot, planes, ResolveParameterSet(robot, vm, planes.size()));
  IdentifiabilityOptions options;
  options.rank_tolerance = vm["rank-tolerance"].as<double>();
  options.Validate("--rank-tolerance");
  const IdentifiabilityReport r = AnalyzeIdentifiability(model, configs, nullptr, options);
  RemedyOptions remedy_options;
  remedy_options.ranger = rig.ranger;
  remedy_options.identifiability = options;
  const RemedyReport remedies = FindRemedies(model, configs, r, remedy_options);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = IdentifiabilityJson(r);
    if (!r.full_rank()) j["remedies"] = RemediesJson(remedies);
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << r.ToString();
    if (!r.full_rank()) std::cout << "how to recover what is lost:\n" << remedies.ToString();
  }
  return 0;
}

int PaperCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal paper options");
  o.add_options()("robot", po::value<std::string>()->default_value("paper"), "robot file or name")(
      "seed", po::value<long long>()->default_value(1), "random seed of the realisation")(
      "case1-selection", po::value<std::string>()->default_value("backward"),
      "how case 1 picks 50 of 101: backward, exchange, greedy, sampled (the paper's), random")(
      "samples", po::value<int>()->default_value(1000), "subsets tried by 'sampled'")(
      "format", po::value<std::string>()->default_value("text"), "text or json");
  po::variables_map vm;
  if (!Parse("paper", "[--seed K] [options]", o, args, &vm)) return 0;
  const RobotFile rig = LoadRobot(vm["robot"].as<std::string>());
  const RobotModel& robot = rig.robot;
  if (!rig.planes || rig.planes->size() != 1)
    throw InputError("--robot", "the robot file '" + rig.path +
                                    "' has no plane (the paper's study uses one plane)");
  PaperCaseOptions options;
  options.sampling.ranger = rig.ranger;
  options.seed = ParseSeed(vm);
  options.case1_selection.method =
      ParseSelectionMethod(vm["case1-selection"].as<std::string>(), "--case1-selection");
  options.case1_selection.samples = vm["samples"].as<int>();
  options.case1_selection.Validate("--samples");
  const PaperCasesResult r = RunPaperCases(robot, (*rig.planes)[0], options);
  const Table params = PaperParameterTable(robot, r);
  const Table validation = PaperValidationTable(r);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j;
    j["seed"] = options.seed;
    j["pool"] = r.pool_report.ToString();
    j["validation_sampling"] = r.validation_report.ToString();
    Json cases = Json::array();
    for (const auto& c : r.cases) {
      Json cj;
      cj["label"] = c.label;
      cj["selected"] = c.selection.indices;
      cj["sigma_min"] = c.selection.score;
      cj["termination"] = TerminationName(c.summary.termination);
      cj["iterations"] = c.summary.iterations;
      cj["residual_rms"] = c.summary.residual_rms;
      Json p = Json::object();
      for (std::size_t k = 0; k < c.summary.names.size() && c.summary.IsSolutionUsable(); ++k)
        p[c.summary.names[k]] = c.summary.delta[k];
      cj["delta"] = p;
      Json sd = Json::object();
      for (std::size_t k = 0; k < c.summary.names.size() && c.summary.IsSolutionUsable(); ++k)
        sd[c.summary.names[k]] = c.summary.std_given[k];
      cj["std_given_sigma"] = sd;
      cj["validation_rms_position"] = ToJson(Eigen::VectorXd(c.validation.stats.rms_position));
      cj["validation_rms_orientation"] =
          ToJson(Eigen::VectorXd(c.validation.stats.rms_orientation));
      cj["validation_max_position"] = ToJson(Eigen::VectorXd(c.validation.stats.max_position));
      cj["validation_max_orientation"] =
          ToJson(Eigen::VectorXd(c.validation.stats.max_orientation));
      cases.push_back(cj);
    }
    j["cases"] = cases;
    j["nominal_validation_rms_position"] =
        ToJson(Eigen::VectorXd(r.nominal_validation.stats.rms_position));
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "lrcal paper: one realisation (seed " << options.seed << ") of the paper's cases\n"
            << "candidate pool: " << r.pool_report.ToString() << "\n"
            << "validation set: " << r.validation_report.ToString() << "\n";
  for (const auto& c : r.cases) {
    std::cout << c.label << ": " << c.selection.indices.size() << " of " << r.pool.size()
              << " by E-optimality ("
              << SelectionMethodName(c.label == "case 1" ? options.case1_selection.method
                                                         : options.case2_selection.method)
              << ", " << c.selection.evaluations
              << " evaluations), sigma_min(G) = " << c.selection.score << "; "
              << c.summary.BriefReport() << "\n";
  }
  std::cout << "\n" << params.ToText() << "\n" << validation.ToText();
  std::cout << "\nOne realisation cannot reproduce the paper's digits; `lrcal run "
               "studies/paper.yaml` shows where they fall in the distribution.\n";
  return 0;
}

}  // namespace lrcal::cli
