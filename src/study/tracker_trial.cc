// The trial pipeline of the cells of every sensor but the ranger (sensor.kind scanner, point,
// pose, contact, socket): the ranger's steps (trial_pipeline.h) with a measurement kind in place
// of the ranger's model. Per cell: the pool is drawn over the workspace (a tracker sees its target
// anywhere: no beam has to hit), or aimed at the planes and kept where every beam of a scanner's
// fan meets its plane, or seated on the nominal arm (contacts on the planes, a ball in its
// sockets); the terms the pool cannot separate are fixed or the cell is marked rank deficient;
// the design is a block selection (block_selection.h: a configuration brings its kind's rows);
// the covariance σ²(GᵀWG)⁻¹ is predicted at the nominal model (W: the repetitions, and
// (σ/σ_angle)² on angle rows). Per trial: the sensor on the true arm reads the design (its exact
// values cached for a fixed truth), or each contact or ball is seated on the true arm with the
// trial's play; lrcal's LM fits the values on the kind's evaluator; the identified arm is judged
// on the validation poses as the ranger's is.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/core/error.h"
#include "lrcal/design/block_selection.h"
#include "lrcal/design/measurable_pool.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/measurement/contact_measurement.h"
#include "lrcal/measurement/pose_measurement.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/scanner_measurement.h"
#include "lrcal/measurement/socket_measurement.h"
#include "study/trial_pipeline.h"

namespace lrcal {

namespace {

// The arm with `values` (5N link values, SI) as its nominal values: a trial's true arm.
std::shared_ptr<const RobotModel> ArmWithValues(const RobotModel& robot,
                                                const Eigen::VectorXd& values) {
  std::vector<Link> links = robot.links();
  for (int index = 0; index < robot.num_values(); ++index)
    links[index / kValuesPerLink].nominal[index % kValuesPerLink] = values[index];
  auto arm = std::make_shared<RobotModel>(robot.name(), std::move(links), robot.source,
                                          robot.base(), robot.tool());
  arm->source = robot.source;
  return arm;
}

// A ranger cell in an environment: the full ranger on `arm` inside the non-geometric model. The
// calibration's (`truth` false) estimates identification.estimate's terms (every joint's
// compliance, the links' thermal coefficient) and holds identification.fix, the ranger terms not
// in identification.estimate_ranger and, without geometric, every link value; the simulated
// arm's (`truth`) has the robot file's true compliance and coefficients and estimates nothing.
std::unique_ptr<MeasurementKind> RangerInEnvironment(const CellSettings& s, const CellContext& c,
                                                     const RobotModel& arm, bool truth) {
  const auto inner = std::make_shared<RangerMeasurement>(
      MeasurementModel(arm, c.planes,
                       MakeParameterSet(arm, CellPlaneTerms(s, c.planes.size()), {},
                                        "identification.fix", RangerTerms{true, true})),
      c.ranger);
  if (truth)
    return std::make_unique<EnvironmentMeasurement>(inner, *c.robot, c.true_non_geometric,
                                                    NonGeometricTerms{}, std::vector<std::string>{},
                                                    "identification.estimate");
  std::vector<std::string> held = s.fixed;
  if (!s.ranger_terms.offset) held.push_back("ranger_offset");
  if (!s.ranger_terms.scale) held.push_back("ranger_scale");
  if (!s.estimate_geometric)
    for (int v : arm.parameter_indices()) held.push_back(arm.ValueName(v));
  std::sort(held.begin(), held.end());
  held.erase(std::unique(held.begin(), held.end()), held.end());
  NonGeometricTerms terms;
  if (s.estimate_compliance)
    for (int j = 0; j < arm.num_links(); ++j) terms.compliance_joints.push_back(j);
  terms.thermal_links = s.estimate_thermal;
  return std::make_unique<EnvironmentMeasurement>(inner, *c.robot, c.model_non_geometric, terms,
                                                  held, "identification.estimate");
}

// The cell's sensor on `arm` with every term but identification.fix: on the nominal arm the
// truth's template, on a trial's true arm (`truth`) the sensor that simulates its values.
std::unique_ptr<MeasurementKind> SensorKindOn(const CellSettings& s, const CellContext& c,
                                              const RobotModel& arm, bool truth = false) {
  const std::string source = "identification.fix";
  const StudySensor& sensor = s.sensor;
  if (c.environment) return RangerInEnvironment(s, c, arm, truth);
  if (sensor.kind == "contact") {
    ContactSetup setup;
    setup.planes = c.planes;
    setup.plane_terms = CellPlaneTerms(s, c.planes.size());
    setup.tool_point = sensor.tracker.targets.at(0);
    setup.flush = sensor.flush;
    return std::make_unique<ContactMeasurement>(arm, setup, s.fixed, source);
  }
  if (sensor.kind == "scanner") {
    ScannerSetup setup;
    setup.planes = c.planes;
    setup.plane_terms = CellPlaneTerms(s, c.planes.size());
    setup.origin = sensor.scanner_frame.translation;
    setup.orientation = sensor.scanner_frame.rotation;
    setup.beam_angles = sensor.beam_angles;
    setup.range = c.ranger;
    return std::make_unique<ScannerMeasurement>(arm, setup, s.fixed, source);
  }
  if (sensor.kind == "socket") {
    return std::make_unique<SocketMeasurement>(
        arm,
        SocketSetup::Numbered(sensor.sockets, sensor.tracker.targets.at(0),
                              sensor.socket_distances),
        s.fixed, source);
  }
  // A tracker on a true arm reads its orientations in the nominal kind's chart.
  if (c.sensor_kind)
    return TrackerKindOn(arm, dynamic_cast<const PointMeasurement&>(*c.sensor_kind));
  if (sensor.kind == "pose")
    return std::make_unique<PoseMeasurement>(arm, sensor.tracker, s.fixed, source);
  return std::make_unique<PointMeasurement>(arm, sensor.tracker, s.fixed, source);
}

void BuildTrackerKind(const CellSettings& s, CellContext* c) {
  c->sensor_kind = SensorKindOn(s, *c, *c->robot);
  c->seated = s.sensor.kind == "contact" || s.sensor.kind == "socket";
  c->kind = c->sensor_kind->Without({});
  // The arm's link terms alone: the validation poses' Jacobian (ValidationPoseJacobian).
  c->model = std::make_unique<MeasurementModel>(
      *c->robot, c->planes,
      MakeParameterSet(*c->robot, std::vector<PlaneTerms>(c->planes.size()), {},
                       "identification.fix"));
}

void MapLinkValues(CellContext* c) {
  c->parameter_names = c->kind->parameter_names();
  c->kind_link_values.clear();
  for (const std::string& name : c->parameter_names)
    c->kind_link_values.push_back(c->robot->FindValue(name));
}

// A study's environment phase into the configurations that do not say theirs (a file's columns
// win): its gravity, and its temperatures in turn (configuration i the (i mod n)-th).
void TakeEnvironment(const CellSettings::EnvironmentPhase& phase, TargetedConfigurations* configs) {
  for (int i = 0; i < configs->size(); ++i) {
    Environment e = configs->environment(i);
    if (!e.gravity.allFinite()) e.gravity = phase.gravity;
    if (!(e.temperature_c == e.temperature_c) && !phase.temperatures_c.empty())
      e.temperature_c =
          phase.temperatures_c[static_cast<std::size_t>(i) % phase.temperatures_c.size()];
    configs->SetEnvironment(i, e);
  }
}

// The pool: configurations over the workspace (only σ_min of the arm's Jacobian is asked), or
// a pool file's; and the validation poses, drawn from the same stream as a ranger cell's of the
// same robot and validation settings (common poses across sensors).
void DrawTrackerConfigurations(const Study& study, const CellSettings& s, CellContext* c) {
  c->pool_stream =
      StreamId(c->cell->settings, {"robot", "robot_file_fnv1a", "pool", "truth", "sensor"});
  c->validation_stream = ValidationStreamId(c->cell->settings);
  c->selection_seed = s.pool_file.empty() ? study.seed : 0;
  SamplingOptions o;
  o.ranger = c->ranger;
  o.min_jacobian_singular_value = s.min_singular_value;
  o.require_beam_hit = false;
  const Plane tag = c->planes[0];  // targets are tagged 0: the one target
  // Aimed at their planes (the ranger's pool: the tool faces the plane within reach).
  SamplingOptions aimed = o;
  aimed.require_beam_hit = true;
  const std::string& kind = s.sensor.kind;
  if (!s.pool_file.empty()) {
    TargetedConfigurations file =
        ReadStudyConfigurations(study, s.pool_file, "pool.file", *c->robot,
                                kind == "contact" || kind == "scanner" ? &c->planes : nullptr);
    if (kind == "contact")  // seated on the nominal arm: the design is chosen where contacts are
      file = SeatedConfigurations(*c->robot, *c->kind, file);
    if (kind == "scanner")  // where every beam meets its plane
      file = MeasurableConfigurations(*c->kind, file);
    AcceptPoolFile(s, std::move(file), c);
  } else if (kind == "contact") {
    // Moved until the nominal tool point touches: the design is chosen where contacts are.
    // Those that seat within the joint ranges (a start that cannot is left out).
    SamplingReport drawn;
    c->pool = SeatedConfigurations(
        *c->robot, *c->kind,
        SampleConfigurations(*c->robot, c->planes, PerPlaneCounts(s, c->planes, s.pool_size),
                             RandomStream(c->seed, c->pool_stream, 0, RandomPurpose::kPool), aimed,
                             &drawn),
        &c->pool_report);
    c->pool_report.attempts = drawn.attempts;
    if (c->pool.size() < s.select_count)
      throw InputError("pool.size", std::to_string(c->pool.size()) + " of " +
                                        std::to_string(s.pool_size) +
                                        " drawn configurations seat on their planes: fewer "
                                        "than selection.count = " +
                                        std::to_string(s.select_count));
  } else if (kind == "scanner") {
    c->pool = SampleScannerConfigurations(dynamic_cast<const ScannerMeasurement&>(*c->sensor_kind),
                                          PerPlaneCounts(s, c->planes, s.pool_size), c->seed,
                                          c->pool_stream, o, &c->pool_report);
  } else if (kind == "ranger") {  // a ranger in an environment: aimed at its planes
    c->pool = SampleConfigurations(*c->robot, c->planes, PerPlaneCounts(s, c->planes, s.pool_size),
                                   RandomStream(c->seed, c->pool_stream, 0, RandomPurpose::kPool),
                                   aimed, &c->pool_report);
  } else if (kind == "socket") {
    c->pool = SampleSocketConfigurations(dynamic_cast<const SocketMeasurement&>(*c->sensor_kind),
                                         s.pool_size, c->seed, c->pool_stream, o, &c->pool_report);
  } else {
    c->pool = SampleConfigurations(*c->robot, tag, s.pool_size,
                                   RandomStream(c->seed, c->pool_stream, 0, RandomPurpose::kPool),
                                   o, &c->pool_report);
  }
  if (!s.validation_file.empty()) {
    c->validation =
        ReadStudyConfigurations(study, s.validation_file, "validation.file", *c->robot, nullptr);
  } else {
    // The ranger cell's call (the planes' shares, no beam to hit): the same poses.
    c->validation = SampleConfigurations(
        *c->robot, c->planes, PerPlaneCounts(s, c->planes, s.validation_size),
        RandomStream(study.seed, c->validation_stream, 0, RandomPurpose::kValidation), o);
  }
  if (c->environment) {
    TakeEnvironment(s.calibration_environment, &c->pool);
    TakeEnvironment(s.validation_environment, &c->validation);
  }
}

}  // namespace

std::vector<Pose<double>> TruePoses(const CellContext& c, const Eigen::VectorXd& true_values,
                                    const TargetedConfigurations& configs) {
  return c.environment ? EnvironmentToolPoses(*c.robot, true_values, c.true_non_geometric, configs)
                       : ToolPoses(*c.robot, true_values, configs);
}

namespace {

// The poses of the identified model (link values `identified`, estimate e over the cell's terms)
// at `configs` in their environments: its compliance and thermal coefficient those estimated
// (the nominal coefficient where thermal is in the model but was held), none where the model has
// none.
std::vector<Pose<double>> IdentifiedPoses(const CellContext& c, const Eigen::VectorXd& identified,
                                          const Eigen::VectorXd& e,
                                          const TargetedConfigurations& configs) {
  NonGeometricModel model = c.model_non_geometric;
  model.compliance = Eigen::VectorXd::Zero(c.robot->num_links());
  for (std::size_t k = 0; k < c.parameter_names.size(); ++k) {
    const int j = ComplianceTermJoint(c.parameter_names[k]);
    if (j >= 0) model.compliance[j] += e[static_cast<Eigen::Index>(k)];
    if (c.parameter_names[k] == kThermalLinksTerm)
      model.thermal.links += e[static_cast<Eigen::Index>(k)];
  }
  return EnvironmentToolPoses(*c.robot, identified, model, configs);
}

// The identified model against the truth at `configs`: in their environments for a cell in one.
PoseErrors CompareIdentified(const CellContext& c, const std::vector<Pose<double>>& true_poses,
                             const Eigen::VectorXd& identified, const Eigen::VectorXd& e,
                             const TargetedConfigurations& configs) {
  if (!c.environment) return ComparePoses(*c.robot, true_poses, identified, configs);
  return ComparePoses(true_poses, IdentifiedPoses(c, identified, e, configs));
}

void CacheTrackerTruth(const CellSettings& s, CellContext* c) {
  if (s.truth.random) return;
  c->true_robot = ArmWithValues(*c->robot, c->fixed_truth.values);
  c->validation_true_poses = TruePoses(*c, c->fixed_truth.values, c->validation);
  c->nominal_validation =
      ComparePoses(*c->robot, c->validation_true_poses, c->robot->nominal_values(), c->validation)
          .stats;
  c->true_kind = SensorKindOn(s, *c, *c->true_robot, true);
  if (c->seated) return;  // seated anew in every trial
  const std::vector<double> zero(static_cast<std::size_t>(c->true_kind->num_parameters()), 0.0);
  c->design_true_values.resize(
      static_cast<std::size_t>(c->design.configs.size() * c->true_kind->rows_per_configuration()));
  c->true_kind->Bind(c->design.configs)
      ->Predict(zero.data(), c->design_true_values.data(), nullptr);
  c->design_true_reasons = c->true_kind->MissReasons(c->design.configs, zero.data());
}

// Each start seated by the sensor on the true arm (a contact or socket kind) with the play of
// the noise.
void SeatOnTruth(const MeasurementKind& truth, const TargetedConfigurations& starts,
                 const NoiseModel& noise, const RandomStream& stream, MeasuredValues* values) {
  if (const auto* socket = dynamic_cast<const SocketMeasurement*>(&truth)) {
    SimulateSocketMeasurements(*socket, starts, noise, stream, values);
    return;
  }
  SimulateContactMeasurements(dynamic_cast<const ContactMeasurement&>(truth), starts, noise, stream,
                              values);
}

// The noisy values the sensor on the true arm reads at the design (each the mean of the cell's
// repetitions, drawn directly), with its angle rows weighed; or, for a seated kind, the design's
// configurations seated on the true arm with the trial's play.
void SimulateTrackerValues(const CellContext& c, long long trial, const TrialTruth& truth,
                           MeasuredValues* values) {
  const CellSettings& s = c.cell->typed;
  NoiseModel noise = s.noise;
  noise.draw_mean = true;
  noise.sigma_angle = s.sensor.sigma_angle;
  const RandomStream stream(c.seed, 0, static_cast<std::uint64_t>(trial), RandomPurpose::kNoise);
  if (c.tree) {
    SimulateTreeValues(c, truth, noise, stream, values);
    return;
  }
  if (!s.truth.random && c.seated) {
    SeatOnTruth(*c.true_kind, c.design.configs, noise, stream, values);
    return;
  }
  if (!s.truth.random) {
    AddMeasurementNoise(*c.true_kind, c.design_true_values, c.design_true_reasons, c.design.configs,
                        noise, stream, values);
    return;
  }
  const std::shared_ptr<const RobotModel> arm = ArmWithValues(*c.robot, truth.values);
  const std::unique_ptr<MeasurementKind> sensor = SensorKindOn(s, c, *arm, true);
  if (c.seated)
    SeatOnTruth(*sensor, c.design.configs, noise, stream, values);
  else
    SimulateMeasurements(*sensor, c.design.configs, noise, stream, values);
}

}  // namespace

// Identifiability on the pool: the terms it cannot separate (d1 with the instrument's height,
// ...) are fixed when the cell says so, else every trial fails as rank deficient.
void CheckTrackerIdentifiability(const CellSettings& s, CellContext* c) {
  const IdentifiabilityReport rep = AnalyzeIdentifiability(*c->kind, c->pool);
  if (rep.full_rank()) return;
  if (!s.fix_dependent) {
    c->rank_deficient = true;
    c->rank_message = rep.ToString();
    return;
  }
  c->fixed_for_rank = rep.suggested_fixed;
  c->kind = c->kind->Without(rep.suggested_fixed);
}

namespace {

// Each measured value's weight: the effective readings, times (σ/σ_angle)² on an angle row.
Eigen::VectorXd TrackerRowWeights(const CellSettings& s, const MeasurementKind& kind, int m) {
  const int k = kind.rows_per_configuration();
  Eigen::VectorXd w(static_cast<Eigen::Index>(m) * k);
  const double ratio = s.noise.sigma / s.sensor.sigma_angle;
  for (int i = 0; i < m; ++i)
    for (int r = 0; r < k; ++r)
      w[static_cast<Eigen::Index>(i) * k + r] =
          s.noise.EffectiveReadings() * (kind.RowIsAngle(r) ? ratio * ratio : 1.0);
  return w;
}

}  // namespace

void SelectTrackerDesign(const CellSettings& s, CellContext* c) {
  const Eigen::MatrixXd G =
      DesignJacobian(*c->kind, c->pool, s.scaling, s.truth.angle_sigma, s.truth.length_sigma);
  const RandomStream stream(c->selection_seed, c->pool_stream, 0, RandomPurpose::kSelection);
  c->design.slots =
      SelectBlocks(G, c->kind->rows_per_configuration(), s.select_count, s.selection, stream)
          .indices;
  c->design.configs = c->pool.Subset(c->design.slots);
  c->design_efficiency = std::nan("");  // no certificate for blocks
  const int n = c->kind->num_parameters(), m = c->design.configs.size();
  // The design's values and Jacobian at the nominal model, from one evaluation.
  const std::vector<double> zero(static_cast<std::size_t>(n), 0.0);
  std::vector<double> h(static_cast<std::size_t>(m * c->kind->rows_per_configuration()));
  Eigen::MatrixXd Gd(static_cast<Eigen::Index>(h.size()), n);
  c->kind->Bind(c->design.configs)->Predict(zero.data(), h.data(), Gd.data());
  c->design.sigma_min = CriterionScore(Gd.transpose() * Gd, m, DesignCriterion::kE);
  const IdentifiabilityReport design_report =
      c->rank_deficient ? IdentifiabilityReport{}
                        : AnalyzeIdentifiability(*c->kind, c->design.configs);
  if (!c->rank_deficient && design_report.full_rank()) {
    // The first linearisation of every tracker trial's fit (the design is the cell's own; a
    // contact trial's configurations are where the true arm touched, its own each trial).
    if (!c->seated) {
      c->design_nominal.h = h;
      c->design_nominal.G = Gd;
      c->design_nominal.Factorize();
    }
    const Eigen::VectorXd w = TrackerRowWeights(s, *c->kind, m);
    SetPredictedCovariance(c, ParameterCovariance(Gd.transpose() * w.asDiagonal() * Gd, 1.0),
                           s.noise.sigma);
    return;
  }
  if (!c->rank_deficient) c->rank_message = design_report.ToString();
  c->rank_deficient = true;
  c->predicted_std = Eigen::VectorXd::Constant(n, std::nan(""));
}

void AcceptPoolFile(const CellSettings& s, TargetedConfigurations pool, CellContext* c) {
  c->pool = std::move(pool);
  c->pool_report.requested = c->pool_report.accepted = c->pool_report.attempts = c->pool.size();
  if (c->pool.size() < s.select_count)
    throw InputError("pool.file", "'" + s.pool_file + "' has " + std::to_string(c->pool.size()) +
                                      " configurations: fewer than selection.count = " +
                                      std::to_string(s.select_count));
}

void CheckValuesForTerms(const CellSettings& s, const CellContext& c) {
  if (s.select_count * c.kind->rows_per_configuration() < c.kind->num_parameters())
    throw InputError("selection.count", std::to_string(s.select_count) + " configurations of " +
                                            std::to_string(c.kind->rows_per_configuration()) +
                                            " values for " +
                                            std::to_string(c.kind->num_parameters()) +
                                            " terms: need at least as many values as terms");
}

void PrepareTrackerCell(const Study& study, const CellSettings& s, CellContext* c) {
  BuildTrackerKind(s, c);
  MapLinkValues(c);
  DrawTrackerConfigurations(study, s, c);
  CheckTrackerIdentifiability(s, c);
  MapLinkValues(c);
  CheckValuesForTerms(s, *c);
  if (!s.truth.random) c->fixed_truth = DrawTruth(*c, 0);  // in the reduced layout
  SelectTrackerDesign(s, c);
  CacheTrackerTruth(s, c);
  PredictValidation(c);
}

namespace {

struct TrackerFit {
  Termination termination = Termination::kInvalidInput;
  int iterations = 0;
  double residual_rms = 0, sigma_hat = 0;  ///< m
};

// The fit of a trial's values into ws->e. lrcal's LM runs on the cell's evaluator from the cell's
// nominal linearisation: the cell checked identifiability on its design once, so the trial does
// not repeat Identify()'s rank analysis and statistics (which cost two thirds of a tracker
// trial). Ceres goes through Identify(kind).
TrackerFit FitTrackerTrial(const CellContext& c, TrialWorkspace* ws) {
  const CellSettings& s = c.cell->typed;
  const MeasuredValues& values = ws->values;
  IdentificationOptions options = s.identification;
  options.robust_fit_check = false;  // a trial records no fit verdict
  TrackerFit fit;
  if (options.solver == IdentificationOptions::Solver::kCeres) {
    const IdentificationSummary summary = Identify(*c.kind, values, options);
    ws->e = summary.delta;
    fit.termination = summary.termination;
    fit.iterations = summary.iterations;
    fit.residual_rms = summary.residual_rms;
    fit.sigma_hat = std::isfinite(summary.sigma_hat) ? summary.sigma_hat : 0.0;
    return fit;
  }
  // The design's evaluator and nominal linearisation serve a trial that measured the whole
  // design; seated configurations (where the true arm seated) and a design some of whose
  // configurations missed (a scanner's beam off its plane on the true arm) are the trial's own.
  const bool whole_design = !c.seated && values.configs.size() == c.design.configs.size();
  if (!whole_design) {
    ws->evaluator = c.kind->Bind(values.configs);
    ws->evaluator_cell = nullptr;
  } else if (ws->evaluator_cell != &c) {
    ws->evaluator = c.kind->Bind(c.design.configs);
    ws->evaluator_cell = &c;
  }
  const int k = c.kind->rows_per_configuration(), n = c.kind->num_parameters();
  const std::vector<double> weights = values.RowWeights(k);
  const LevenbergMarquardt::Result r =
      ws->solver.Solve(*ws->evaluator, values.y.data(), weights.data(), options, &ws->e,
                       whole_design ? &c.design_nominal : nullptr);
  fit.termination = r.termination;
  fit.iterations = r.iterations;
  const auto rows = static_cast<int>(values.y.size());
  std::vector<double> y(values.y.size());
  if (ws->evaluator->Predict(ws->e.data(), y.data(), nullptr)) {
    double ss = 0;
    for (int i = 0; i < rows; ++i) ss += (values.y[i] - y[i]) * (values.y[i] - y[i]);
    fit.residual_rms = std::sqrt(ss / rows);
  }
  fit.sigma_hat = rows > n ? std::sqrt(2 * r.final_cost / (rows - n)) : 0.0;
  return fit;
}

}  // namespace

TrialStatus RunTrackerTrial(const CellContext& c, long long trial, const TrialTruth& truth,
                            const std::vector<Pose<double>>& validation_true, TrialRecord* rec,
                            TrialDetails* details, TrialWorkspace* ws) {
  MeasuredValues& values = ws->values;
  SimulateTrackerValues(c, trial, truth, &values);
  rec->missed_configurations = c.design.configs.size() - values.size();
  if (static_cast<int>(values.y.size()) < c.kind->num_parameters())
    return TrialStatus::kBeamMissed;  // too few contacts could be seated
  const TrackerFit fit = FitTrackerTrial(c, ws);
  rec->iterations = fit.iterations;
  rec->residual_rms = fit.residual_rms;
  rec->sigma_hat = fit.sigma_hat;
  switch (fit.termination) {
    case Termination::kConverged:
      break;
    case Termination::kRankDeficient:
      return TrialStatus::kRankDeficient;
    case Termination::kMaxIterations:
      return TrialStatus::kNotConverged;
    default:
      return TrialStatus::kNumericalFailure;
  }
  const auto n = static_cast<Eigen::Index>(c.parameter_names.size());
  rec->errors.resize(static_cast<std::size_t>(n));
  Eigen::VectorXd identified = c.robot->nominal_values();
  for (Eigen::Index k = 0; k < n; ++k) {
    rec->errors[static_cast<std::size_t>(k)] = ws->e[k] - truth.delta[k];
    const int v = c.kind_link_values[static_cast<std::size_t>(k)];
    if (v >= 0) identified[v] += ws->e[k];
  }
  const PoseErrors validation =
      CompareIdentified(c, validation_true, identified, ws->e, c.validation);
  rec->validation = Flatten(validation.stats);
  if (details) {  // a tracker has no distance errors: the poses only
    const Eigen::VectorXd& nominal = c.robot->nominal_values();
    details->distance_error_nominal.clear();
    details->distance_error_identified.clear();
    // A tree's measured configurations are the whole robot's: the judged arm's joints of them.
    const TargetedConfigurations measured =
        c.tree ? c.tree->chains[static_cast<std::size_t>(c.tree->judged)]->ChainConfigurations(
                     values.configs)
               : values.configs;
    const std::vector<Pose<double>> measured_true = TruePoses(c, truth.values, measured);
    details->measurement_nominal = ComparePoses(*c.robot, measured_true, nominal, measured);
    details->measurement_identified =
        CompareIdentified(c, measured_true, identified, ws->e, measured);
    details->validation_nominal = ComparePoses(*c.robot, validation_true, nominal, c.validation);
    details->validation_identified = validation;
  }
  return TrialStatus::kOk;
}

namespace {

// The column of link value `value` among the arm's pose Jacobian's (c.model's robot terms), −1.
int ArmColumn(const CellContext& c, int value) {
  const ParameterSet& ps = c.model->parameters();
  for (int j = 0; j < ps.num_robot(); ++j)
    if (ps.robot_values[static_cast<std::size_t>(j)] == value) return j;
  return -1;
}

// Validation pose i's rows (6 × 1) of the non-geometric term `name`: joint j's column times τ_j
// for c_j, every length's column times ℓ·ΔT for thermal_links; zero otherwise.
Eigen::Matrix<double, 6, 1> NonGeometricPoseColumn(const CellContext& c, const Eigen::MatrixXd& arm,
                                                   int i, const std::string& name,
                                                   const Eigen::VectorXd& tau, double dt) {
  const RobotModel& robot = *c.robot;
  Eigen::Matrix<double, 6, 1> out = Eigen::Matrix<double, 6, 1>::Zero();
  const int joint = ComplianceTermJoint(name);
  if (joint >= 0) {
    const bool revolute =
        robot.links()[static_cast<std::size_t>(joint)].joint == JointType::kRevolute;
    const int col = ArmColumn(c, joint * kValuesPerLink + (revolute ? kTheta : kD));
    if (col >= 0) out = arm.block<6, 1>(6 * i, col) * tau[joint];
    return out;
  }
  if (name != kThermalLinksTerm) return out;
  for (int v : robot.parameter_indices()) {
    const int col = ArmColumn(c, v);
    if (!IsAngle(v % kValuesPerLink) && col >= 0)
      out += arm.block<6, 1>(6 * i, col) * robot.nominal_values()[v] * dt;
  }
  return out;
}

// A cell in an environment: how each validation pose moves with the non-geometric terms, in the
// validation environment (first order at the nominal model): c_j moves joint j by τ_j(q, g),
// thermal_links every length ℓ by ℓ·ΔT.
void AddNonGeometricPoseColumns(const CellContext& c, const Eigen::MatrixXd& arm,
                                Eigen::MatrixXd* J) {
  const RobotModel& robot = *c.robot;
  for (int i = 0; i < c.validation.size(); ++i) {
    const Environment env = c.validation.environment(i).Or(c.model_non_geometric.defaults);
    const Eigen::VectorXd tau =
        GravityTorques(robot, robot.nominal_values().data(), c.model_non_geometric.masses,
                       c.validation.q(i), env.gravity);
    const double dt = env.temperature_c - c.model_non_geometric.thermal.reference_c;
    for (std::size_t k = 0; k < c.parameter_names.size(); ++k) {
      const std::string& name = c.parameter_names[k];
      if (ComplianceTermJoint(name) >= 0 || name == kThermalLinksTerm)
        J->block<6, 1>(6 * i, static_cast<Eigen::Index>(k)) =
            NonGeometricPoseColumn(c, arm, i, name, tau, dt);
    }
  }
}

}  // namespace

Eigen::MatrixXd ValidationPoseJacobian(const CellContext& c) {
  const std::vector<double> zero(static_cast<std::size_t>(c.model->num_parameters()), 0.0);
  const Eigen::MatrixXd arm = PoseJacobian(*c.model, zero.data(), c.validation);
  if (!c.kind) return arm;
  // The tracker's link terms are columns of the arm's; its instrument and target move no pose.
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(arm.rows(), c.kind->num_parameters());
  for (std::size_t k = 0; k < c.kind_link_values.size(); ++k)
    if (const int j = ArmColumn(c, c.kind_link_values[k]); j >= 0)
      J.col(static_cast<Eigen::Index>(k)) = arm.col(j);
  if (c.environment) AddNonGeometricPoseColumns(c, arm, &J);
  return J;
}

}  // namespace lrcal
