#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/hash.h"
#include "lrcal/design/design_certificate.h"
#include "lrcal/design/task_criterion.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/identification/prior.h"
#include "lrcal/identification/total_accuracy.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/urdf.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/simulation.h"
#include "study/preparation_memo.h"
#include "study/trial_pipeline.h"

namespace lrcal {

std::array<double, 12> Flatten(const PoseErrorStats& s) {
  std::array<double, 12> a{};
  for (int k = 0; k < 3; ++k) {
    a[k] = s.rms_position[k];
    a[3 + k] = s.rms_orientation[k];
    a[6 + k] = s.max_position[k];
    a[9 + k] = s.max_orientation[k];
  }
  return a;
}

// ---------------------------------------------------------------------------------------------
// Steps shared by the cell and the trial (and by tracker_trial.cc).

std::uint64_t StreamId(const Json& settings, std::initializer_list<const char*> keys) {
  Json identity = CellIdentity(settings);
  // The ranger's errors do not change which beams hit the plane: cells that differ only in
  // them share their pools and validation sets.
  if (identity.contains("truth") && identity["truth"].is_object())
    for (const char* k : {"ranger_offset_mm", "ranger_scale_ppm"}) identity["truth"].erase(k);
  Json part;
  for (const char* k : keys) part[k] = identity[k];
  return Fnv1a(part.dump());
}

std::uint64_t ValidationStreamId(const Json& settings) {
  return StreamId(settings, {"robot", "robot_file_fnv1a", "validation", "pool"});
}

// The truth of a trial: the robot file's errors × scale, or errors drawn per trial.
namespace {

// A cell in an environment: the true compliance and thermal coefficient as deviations from the
// calibration's nominal model, at their terms in `delta`.
void AddNonGeometricTruth(const CellContext& c, Eigen::VectorXd* delta) {
  for (std::size_t k = 0; k < c.parameter_names.size(); ++k) {
    const int j = ComplianceTermJoint(c.parameter_names[k]);
    if (j >= 0) (*delta)[static_cast<Eigen::Index>(k)] = c.true_non_geometric.Compliance(j);
    // The common correction: exact when the truth's per-link coefficients are the model's.
    if (c.parameter_names[k] == kThermalLinksTerm)
      (*delta)[static_cast<Eigen::Index>(k)] =
          c.true_non_geometric.thermal.links - c.model_non_geometric.thermal.links;
  }
}

}  // namespace

TrialTruth DrawTruth(const CellContext& c, long long trial) {
  if (c.tree) return DrawTreeTruth(c, trial);
  const CellSettings& s = c.cell->typed;
  const RobotModel& robot = *c.robot;
  TrialTruth truth;
  truth.errors.resize(robot.num_values());
  if (s.truth.random) {
    RandomStream stream(c.seed, 0, static_cast<std::uint64_t>(trial), RandomPurpose::kTruth);
    for (int k = 0; k < robot.num_values(); ++k) {
      const bool is_param = robot.links()[k / kValuesPerLink].is_parameter[k % kValuesPerLink];
      const double sigma = IsAngle(k % kValuesPerLink) ? s.truth.angle_sigma : s.truth.length_sigma;
      truth.errors[k] = is_param ? stream.Normal(k) * sigma : 0.0;
    }
  } else {
    truth.errors = c.file_true_errors * s.truth.scale;
  }
  truth.values = robot.nominal_values() + truth.errors;
  if (c.kind) {  // a tracker's terms: the arm's errors; the instrument and target as nominal
    truth.delta.setZero(static_cast<Eigen::Index>(c.kind_link_values.size()));
    for (std::size_t k = 0; k < c.kind_link_values.size(); ++k)
      if (c.kind_link_values[k] >= 0)
        truth.delta[static_cast<Eigen::Index>(k)] = truth.errors[c.kind_link_values[k]];
    if (c.environment) AddNonGeometricTruth(c, &truth.delta);
    return truth;
  }
  const ParameterSet& ps = c.model->parameters();
  truth.delta.setZero(ps.size());
  for (int k = 0; k < ps.num_robot(); ++k) truth.delta[k] = truth.errors[ps.robot_values[k]];
  if (ps.ranger_offset_index >= 0) truth.delta[ps.ranger_offset_index] = c.ranger_offset;
  if (ps.ranger_scale_index >= 0) truth.delta[ps.ranger_scale_index] = c.ranger_scale;
  return truth;
}

namespace {

// G of a candidate pool at the nominal model, scaled as the cell's selection says (the paper:
// SI). Expected-error scaling uses the truth's prior σ (truth.angle_sigma_mrad,
// truth.length_sigma_mm) for robot parameters and plane terms alike.
Eigen::MatrixXd CellDesignJacobian(const CellContext& c, const TargetedConfigurations& pool) {
  const CellSettings& s = c.cell->typed;
  return DesignJacobian(*c.model, pool, s.scaling, s.truth.angle_sigma, s.truth.length_sigma);
}

}  // namespace

std::vector<int> PerPlaneCounts(const CellSettings& s, const PlaneSet& planes, int total) {
  const int np = planes.size();
  std::vector<double> share(np, 1.0);
  if (static_cast<int>(s.plane_shares.size()) == np) share = s.plane_shares;
  double sum = 0;
  for (double w : share) sum += w;
  std::vector<int> counts(np);
  std::vector<std::pair<double, int>> remainders;
  int given = 0;
  for (int p = 0; p < np; ++p) {
    const double exact = total * share[p] / sum;
    counts[p] = static_cast<int>(std::floor(exact));
    given += counts[p];
    remainders.emplace_back(-(exact - counts[p]), p);
  }
  std::stable_sort(remainders.begin(), remainders.end());
  for (int k = 0; given < total; ++k, ++given) ++counts[remainders[k % np].second];
  return counts;
}

namespace {

bool SamePlanes(const PlaneSet& a, const PlaneSet& b) {
  if (a.size() != b.size()) return false;
  for (int p = 0; p < a.size(); ++p)
    if (a[p].normal != b[p].normal || a[p].offset != b[p].offset) return false;
  return true;
}

// A random stream's address (core/random.h).
struct StreamAddress {
  std::uint64_t seed, stream, trial;
  RandomPurpose purpose;
  RandomStream Stream() const { return RandomStream(seed, stream, trial, purpose); }
  bool operator==(const StreamAddress& o) const {
    return seed == o.seed && stream == o.stream && trial == o.trial && purpose == o.purpose;
  }
};

bool SameSamplingOptions(const SamplingOptions& a, const SamplingOptions& b) {
  return a.min_jacobian_singular_value == b.min_jacobian_singular_value &&
         a.require_beam_hit == b.require_beam_hit &&
         a.max_attempts_per_configuration == b.max_attempts_per_configuration &&
         a.ranger.min_range == b.ranger.min_range && a.ranger.max_range == b.ranger.max_range &&
         a.ranger.max_incidence == b.ranger.max_incidence &&
         a.true_link_values.has_value() == b.true_link_values.has_value() &&
         (!a.true_link_values || SameMatrix(*a.true_link_values, *b.true_link_values)) &&
         a.true_planes.has_value() == b.true_planes.has_value() &&
         (!a.true_planes || SamePlanes(*a.true_planes, *b.true_planes));
}

// Every input of SampleConfigurations: the robot (by identity: LoadRigFile shares it), the
// planes, the counts, the stream and the options.
struct SamplingKey {
  const RobotModel* robot;
  PlaneSet planes;
  std::vector<int> counts;
  StreamAddress stream;
  SamplingOptions options;
  bool operator==(const SamplingKey& o) const {
    return robot == o.robot && SamePlanes(planes, o.planes) && counts == o.counts &&
           stream == o.stream && SameSamplingOptions(options, o.options);
  }
};

struct SampledConfigurations {
  TargetedConfigurations configs;
  SamplingReport report;
};

// SampleConfigurations on the cell's robot and planes. A cell's own draws (trial 0) go through a
// memo: the cells of a sweep over the noise draw the same pool and validation poses.
TargetedConfigurations SampleCellConfigurations(const CellContext& c,
                                                const std::vector<int>& counts,
                                                const StreamAddress& stream,
                                                const SamplingOptions& o, SamplingReport* report) {
  const auto sample = [&] {
    SampledConfigurations out;
    out.configs = SampleConfigurations(*c.robot, c.planes, counts, stream.Stream(), o, &out.report);
    return out;
  };
  static PreparationMemo<SamplingKey, SampledConfigurations> memo;
  SampledConfigurations sampled =
      stream.trial == 0 ? memo.Get(SamplingKey{c.robot.get(), c.planes, counts, stream, o}, sample)
                        : sample();
  if (report != nullptr) *report = sampled.report;
  return std::move(sampled.configs);
}

TargetedConfigurations SamplePool(const CellContext& c, long long trial,
                                  const Eigen::VectorXd& truth, SamplingReport* report) {
  const CellSettings& s = c.cell->typed;
  SamplingOptions o;
  o.ranger = c.ranger;
  o.min_jacobian_singular_value = s.min_singular_value;
  o.true_link_values = truth;
  o.true_planes = c.planes;
  return SampleCellConfigurations(
      c, PerPlaneCounts(s, c.planes, s.pool_size),
      {c.seed, c.pool_stream, static_cast<std::uint64_t>(trial), RandomPurpose::kPool}, o, report);
}

// Every input of a cell's selection: the pool's scaled G, the count, the selection settings (as
// the study spells them: CellSettings::selection is read from them alone) and the stream.
struct SelectionKey {
  Eigen::MatrixXd G;
  int count;
  std::string selection;
  std::uint64_t seed, stream, trial;
  bool operator==(const SelectionKey& o) const {
    return count == o.count && seed == o.seed && stream == o.stream && trial == o.trial &&
           selection == o.selection && SameMatrix(G, o.G);
  }
};

// Selects the design of trial `trial` (0 for the cell's own) from a pool and its scaled G. The
// cell's own goes through a memo (a trial's redrawn selection is its own).
TrialDesign SelectDesign(const CellContext& c, long long trial, const TargetedConfigurations& pool,
                         const Eigen::MatrixXd& pool_G) {
  const CellSettings& s = c.cell->typed;
  const auto t = static_cast<std::uint64_t>(trial);
  const RandomStream stream(c.selection_seed, c.pool_stream, t, RandomPurpose::kSelection);
  const auto select = [&] {
    return SelectConfigurations(pool_G, s.select_count, s.selection, stream).indices;
  };
  TrialDesign d;
  if (trial == 0) {
    static PreparationMemo<SelectionKey, std::vector<int>> memo;
    d.slots = memo.Get(
        SelectionKey{pool_G, s.select_count, c.cell->settings.value("selection", Json()).dump(),
                     c.selection_seed, c.pool_stream, t},
        select);
  } else {
    d.slots = select();
  }
  d.configs = pool.Subset(d.slots);
  return d;
}

double DesignSigmaMin(const Eigen::MatrixXd& GtG, int m) {
  return CriterionScore(GtG, m, DesignCriterion::kE);
}

// ---------------------------------------------------------------------------------------------
// The cell's steps.

// A robot file as loaded, with its model shared by every cell that loads the same bytes (so the
// configurations' memos below can match the robot by identity).
struct LoadedRig {
  std::shared_ptr<const RobotFile> file;
  std::shared_ptr<const RobotModel> robot;
};

struct RigKey {
  std::string path, tool_link, base_link, bytes;
  bool operator==(const RigKey& o) const {
    return path == o.path && tool_link == o.tool_link && base_link == o.base_link &&
           bytes == o.bytes;
  }
};

// The key of a robot file as it is now: its path, the cell's links and its bytes (a file edited
// between two cells' preparations is read again).
RigKey RigKeyOf(const std::string& path, const CellSettings& s) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return RigKey{path, s.tool_link, s.base_link, bytes.str()};
}

// RobotChainIsCoupled (a coupled chain is prepared as a tree), matched on the file's key: the
// cells of a plan on one robot file parse it once.
bool RigIsCoupled(const RigKey& key) {
  static PreparationMemo<RigKey, bool, 8> memo;
  return memo.Get(key, [&] { return RobotChainIsCoupled(key.path, key.tool_link, key.base_link); });
}

// LoadRobotFile, matched on the file's key.
LoadedRig LoadRigFile(const RigKey& key) {
  static PreparationMemo<RigKey, LoadedRig, 8> memo;
  return memo.Get(key, [&] {
    auto file = std::make_shared<RobotFile>(LoadRobotFile(key.path, key.tool_link, key.base_link));
    auto robot = std::make_shared<const RobotModel>(file->robot);
    return LoadedRig{std::move(file), std::move(robot)};
  });
}

// The cell's arm from its robot file (`key`: RigKeyOf the resolved path).
void LoadRig(const RigKey& key, const CellSettings& s, CellContext* c) {
  const LoadedRig rig = LoadRigFile(key);
  const RobotFile& file = *rig.file;
  c->robot = rig.robot;
  c->ranger = file.ranger;
  if (s.in_environment) {
    c->environment = true;
    c->model_non_geometric = file.non_geometric;
    c->model_non_geometric.compliance.resize(0);  // a calibration starts stiff
    if (!s.estimate_thermal) c->model_non_geometric.thermal = ThermalCoefficients{};
    c->true_non_geometric = file.true_non_geometric;
    if (c->ranger_offset != 0 || c->ranger_scale != 0)
      throw InputError("truth.ranger_offset_mm",
                       "a ranger in an environment is simulated without offset or scale errors "
                       "(they and thermal growth share the reading's scale): set "
                       "truth.ranger_offset_mm and truth.ranger_scale_ppm to 0");
    if (s.estimate_compliance && file.non_geometric.masses.empty())
      throw InputError(
          "identification.estimate",
          "compliance is seen through gravity's torque on the joints: the robot file " + file.path +
              " has no masses:");
  }
  const double scale = s.truth.random ? 1.0 : s.truth.scale;
  c->file_true_errors = file.truth.LinkErrors(*c->robot);
  c->ranger_offset =
      s.truth.ranger_offset ? *s.truth.ranger_offset : file.truth.ranger_offset * scale;
  c->ranger_scale = s.truth.ranger_scale ? *s.truth.ranger_scale : file.truth.ranger_scale * scale;
  for (const PriorSigmas::Entry& e : file.tolerances.entries)
    if (s.plane_from_robot || TermClass(e.key).rfind("plane", 0) != 0)
      c->tolerances.entries.push_back(e);
  if (!s.plane_from_robot) {
    c->planes = s.planes;
  } else if (file.planes) {
    c->planes = *file.planes;
  } else if (s.sensor.kind == "point" || s.sensor.kind == "pose" || s.sensor.kind == "socket") {
    // A tracker reads no plane: the horizontal plane through the base only tags the sampled
    // configurations and completes the arm's model; nothing is measured on it.
    c->planes = PlaneSet(Plane{});
  } else {
    throw InputError("plane", "the robot file has no plane; give plane: in the study");
  }
}

}  // namespace

std::vector<PlaneTerms> CellPlaneTerms(const CellSettings& s, int num_planes) {
  std::vector<PlaneTerms> terms(static_cast<std::size_t>(num_planes), s.plane_terms);
  for (std::size_t p = 0; p < s.plane_estimate.size() && p < terms.size(); ++p)
    if (!s.plane_estimate[p].empty()) terms[p] = PlaneTerms::Parse(s.plane_estimate[p], "plane");
  return terms;
}

namespace {

void BuildParameterSet(const CellSettings& s, CellContext* c) {
  const std::vector<PlaneTerms> terms = CellPlaneTerms(s, c->planes.size());
  ParameterSet ps =
      MakeParameterSet(*c->robot, terms, s.fixed, "identification.fix", s.ranger_terms);
  c->model = std::make_unique<MeasurementModel>(*c->robot, c->planes, ps);
  if (s.select_count < ps.size())
    throw InputError("selection.count", "selecting " + std::to_string(s.select_count) +
                                            " configurations for " + std::to_string(ps.size()) +
                                            " parameters: need at least as many");
}

}  // namespace

TargetedConfigurations ReadStudyConfigurations(const Study& study, const std::string& file,
                                               const std::string& key, const RobotModel& robot,
                                               const PlaneSet* planes) {
  try {
    const std::string path = ResolveStudyFile(file, study.folder());
    return planes ? ReadConfigurations(path, robot.num_links(), planes)
                  : TargetedConfigurations(ReadPoses(path, robot.num_links()));
  } catch (const InputError& e) {
    throw InputError(key, e.what());
  }
}

namespace {

// The candidates of a pool file whose beam hits the plane (nominal model, and the fixed truth
// when there is one); the others are reported like a drawn pool's rejections.
TargetedConfigurations UsablePoolFromFile(const Study& study, const CellSettings& s,
                                          CellContext* c) {
  const TargetedConfigurations given =
      ReadStudyConfigurations(study, s.pool_file, "pool.file", *c->robot, &c->planes);
  CandidatePool usable = UsableCandidates(*c->robot, c->planes, c->ranger, given);
  if (!s.truth.random) {  // the true beam must hit too
    std::vector<double> h;
    std::vector<BeamMiss> misses;
    ExactReadings(*c->robot, c->fixed_truth.values, c->planes, c->ranger, usable.configs, &h,
                  &misses);
    TargetedConfigurations kept(usable.configs.num_joints());
    for (int i = 0; i < usable.configs.size(); ++i) {
      if (misses[i] == BeamMiss::kNone) {
        kept.AddFrom(usable.configs, i);
      } else {
        ++usable.report.rejected[std::string("true model: ") + BeamMissName(misses[i])];
      }
    }
    usable.configs = kept;
  }
  c->pool_report = usable.report;
  c->pool_report.requested = static_cast<int>(given.size());
  c->pool_report.accepted = static_cast<int>(usable.configs.size());
  c->pool_report.attempts = static_cast<int>(given.size());
  if (static_cast<int>(usable.configs.size()) < s.select_count)
    throw InputError("pool.file",
                     "'" + s.pool_file + "' has " + std::to_string(given.size()) +
                         " configurations, " + std::to_string(usable.configs.size()) +
                         " of them usable (" + c->pool_report.ToString() +
                         "): fewer than selection.count = " + std::to_string(s.select_count));
  return usable.configs;
}

void DrawCellConfigurations(const Study& study, const CellSettings& s, CellContext* c) {
  c->pool_stream =
      StreamId(c->cell->settings, {"robot", "robot_file_fnv1a", "plane", "pool", "truth"});
  c->validation_stream = ValidationStreamId(c->cell->settings);
  // With the pool from a file, the selection's random draws (sampled, exchange, random) do not
  // depend on the seed: with the validation set from a file too, another seed changes only the
  // noise (and a drawn truth).
  c->selection_seed = s.pool_file.empty() ? study.seed : 0;
  // The pool must give readings on the nominal model and, for a fixed truth, on the true one.
  if (!s.truth.random) c->fixed_truth = DrawTruth(*c, 0);
  if (!s.pool_file.empty()) {
    c->pool = UsablePoolFromFile(study, s, c);
  } else {
    c->pool = SamplePool(*c, 0, s.truth.random ? c->robot->nominal_values() : c->fixed_truth.values,
                         &c->pool_report);
  }
  if (!s.validation_file.empty()) {
    c->validation =
        ReadStudyConfigurations(study, s.validation_file, "validation.file", *c->robot, nullptr);
    return;
  }
  SamplingOptions vo;
  vo.ranger = c->ranger;
  vo.min_jacobian_singular_value = s.min_singular_value;
  vo.require_beam_hit = false;  // validation judges poses over the whole workspace
  c->validation = SampleCellConfigurations(
      *c, PerPlaneCounts(s, c->planes, s.validation_size),
      {study.seed, c->validation_stream, 0, RandomPurpose::kValidation}, vo, nullptr);
}

// Priors or errors in variables (identification.prior_sigma, errors_in_variables): the trials
// solve with Identify()'s kind-neutral path and the prediction is the posterior covariance.
bool ModelledUncertainty(const CellSettings& s) {
  return !s.identification.priors.empty() || s.identification.encoder_sigma > 0;
}

// The posterior information of the cell's parameters on `configs`, whose identification
// Jacobian is G: each configuration's weight its effective readings, with errors in variables
// their weights (identification.h).
PriorInformation PosteriorOn(const CellSettings& s, const CellContext& c,
                             const TargetedConfigurations& configs, const Eigen::MatrixXd& G) {
  std::vector<double> w(static_cast<std::size_t>(configs.size()), s.noise.EffectiveReadings());
  if (s.identification.encoder_sigma > 0) {
    MeasuredValues values{configs, std::vector<double>(w.size(), 0.0),
                          std::vector<int>(w.size(), s.noise.repetitions), w};
    w = ErrorsInVariablesWeights(RangerMeasurement(*c.model), values, s.identification.sigma,
                                 s.identification.encoder_sigma);
  }
  return InformationFromPriors(G, w, s.identification.sigma, s.identification.priors,
                               c.model->parameters().names);
}

// Every input of AnalyzeJacobian with its default options: G, the terms' names and the count.
struct IdentifiabilityKey {
  Eigen::MatrixXd G;
  std::vector<std::string> names;
  int num_configurations;
  bool operator==(const IdentifiabilityKey& o) const {
    return num_configurations == o.num_configurations && names == o.names && SameMatrix(G, o.G);
  }
};

// AnalyzeIdentifiability(*c.model, c.pool) (which is AnalyzeJacobian of the pool's G), with the
// SVD of G through a memo: the cells of a plan over noise settings share their pool, hence G.
IdentifiabilityReport AnalyzePool(const CellContext& c) {
  static PreparationMemo<IdentifiabilityKey, IdentifiabilityReport> memo;
  IdentifiabilityKey key{IdentificationJacobian(*c.model, c.pool), c.model->parameters().names,
                         c.pool.size()};
  return memo.Get(key, [&] { return AnalyzeJacobian(key.G, key.names, key.num_configurations); });
}

// Identifiability of the parameter set on the whole pool (the design is checked later).
void CheckIdentifiability(const CellSettings& s, CellContext* c) {
  const IdentifiabilityReport rep = AnalyzePool(*c);
  if (rep.full_rank()) return;
  // Priors that set every direction the readings cannot see: nothing to fix.
  if (!s.identification.priors.empty() &&
      PosteriorOn(s, *c, c->pool, IdentificationJacobian(*c->model, c->pool)).defined)
    return;
  if (!s.fix_dependent) {
    c->rank_deficient = true;
    c->rank_message = rep.ToString();
    return;
  }
  c->fixed_for_rank = rep.suggested_fixed;
  c->model = std::make_unique<MeasurementModel>(
      *c->robot, c->planes,
      WithoutParameters(*c->robot, c->model->parameters(), rep.suggested_fixed));
  if (!s.truth.random) c->fixed_truth.delta = DrawTruth(*c, 0).delta;
}

// The task criterion's selection matrix (selection.criterion: I), weighted by the validation
// configurations (task_criterion.h).
Eigen::MatrixXd TaskDesignJacobian(const CellContext& c, const TargetedConfigurations& pool) {
  return TaskDesignJacobian(*c.model, pool, TaskPosesAt(*c.model, c.validation, "validation"));
}

// The selected design, its σ_min and the predicted covariance at the nominal model; the
// design's Jacobian also gives the first linearisation of every trial, computed once here.
// CertifyDesign is a pure function of (G, the chosen rows, the criterion, the steps), which the
// cells of a sweep or a sensitivity plan over noise settings share (preparation_memo.h).
struct CertificateKey {
  Eigen::MatrixXd G;
  std::vector<int> chosen;
  DesignCriterion criterion;
  int steps;
  bool operator==(const CertificateKey& o) const {
    return criterion == o.criterion && steps == o.steps && chosen == o.chosen && SameMatrix(G, o.G);
  }
};

DesignCertificate CertifyCellDesign(const Eigen::MatrixXd& G, const std::vector<int>& chosen,
                                    DesignCriterion criterion, int steps) {
  static PreparationMemo<CertificateKey, DesignCertificate> memo;
  return memo.Get(CertificateKey{G, chosen, criterion, steps},
                  [&] { return CertifyDesign(G, chosen, criterion, steps); });
}

void SelectCellDesign(const CellSettings& s, CellContext* c) {
  const Eigen::MatrixXd G =
      s.task_criterion ? TaskDesignJacobian(*c, c->pool) : CellDesignJacobian(*c, c->pool);
  if (s.selection_redraw) c->pool_design_G = G;
  c->design = SelectDesign(*c, 0, c->pool, G);
  c->design_efficiency = std::nan("");
  if (!s.selection_redraw && !s.pool_redraw && !c->for_trials_only) {
    // 300 relaxation steps (~20 ms a cell, against ~100 ms for `lrcal design`'s 1500): the bound
    // is looser, so the efficiency stated is a lower bound that 1500 steps raise by up to 0.3 %
    // (tests/study/trial_test.cc).
    const DesignCertificate certificate =
        CertifyCellDesign(G, c->design.slots, s.selection.criterion, 300);
    if (certificate.available) c->design_efficiency = certificate.efficiency;
  }
  const int n = c->model->num_parameters();
  const Eigen::MatrixXd Gd = IdentificationJacobian(*c->model, c->design.configs);
  const Eigen::MatrixXd GtG = Gd.transpose() * Gd;
  c->design.sigma_min = DesignSigmaMin(GtG, c->design.configs.size());
  const IdentifiabilityReport design_report =
      c->rank_deficient ? IdentifiabilityReport{}
                        : AnalyzeIdentifiability(*c->model, c->design.configs);
  const PriorInformation posterior = !c->rank_deficient && ModelledUncertainty(s)
                                         ? PosteriorOn(s, *c, c->design.configs, Gd)
                                         : PriorInformation{};
  if (posterior.defined) {
    SetPredictedCovariance(c, posterior.posterior_covariance, 1.0);
    c->predicted_std = posterior.posterior_sigma;
  } else if (!c->rank_deficient && !ModelledUncertainty(s) && design_report.full_rank()) {
    SetPredictedCovariance(c, ParameterCovariance(s.noise.EffectiveReadings() * GtG, 1.0),
                           s.noise.sigma);
  } else {
    if (!c->rank_deficient) c->rank_message = design_report.ToString();
    c->rank_deficient = true;
    c->predicted_std = Eigen::VectorXd::Constant(n, std::nan(""));
  }
  std::vector<BeamMiss> unused;
  ExactReadings(*c->robot, c->robot->nominal_values(), c->planes, c->ranger, c->design.configs,
                &c->design_nominal.h, &unused);
  c->design_nominal.G = Gd;
  c->design_nominal.Factorize();
}

// For a fixed truth: exact true readings and poses, once per cell.
void CacheTruth(const CellSettings& s, CellContext* c) {
  if (s.truth.random) return;
  const Eigen::VectorXd& truth = c->fixed_truth.values;
  ExactReadings(*c->robot, truth, c->planes, c->ranger, c->design.configs, &c->design_true_h,
                &c->design_true_miss);
  if (s.selection_redraw)
    ExactReadings(*c->robot, truth, c->planes, c->ranger, c->pool, &c->pool_true_h,
                  &c->pool_true_miss);
  c->validation_true_poses = ToolPoses(*c->robot, truth, c->validation);
  // The Cramér–Rao bound of least squares (not of a posterior or errors in variables).
  if (!c->rank_deficient && !s.selection_redraw && !s.pool_redraw && !ModelledUncertainty(s)) {
    const Eigen::MatrixXd Gt =
        IdentificationJacobian(*c->model, c->design.configs, c->fixed_truth.delta.data());
    c->predicted_std_truth =
        ParameterCovariance(s.noise.EffectiveReadings() * (Gt.transpose() * Gt), s.noise.sigma)
            .diagonal()
            .cwiseSqrt();
  }
  c->nominal_validation =
      ComparePoses(*c->robot, truth, c->robot->nominal_values(), c->validation).stats;
}

// Per draw and axis (position xyz, orientation xyz), the sum of squares and the largest
// magnitude of pose errors over the validation poses, added a block of poses at a time (6 rows
// per pose, one column per draw), the poses in order.
struct PartSums {
  Eigen::MatrixXd ss, max;  // draws × 6
  explicit PartSums(int draws)
      : ss(Eigen::MatrixXd::Zero(draws, 6)), max(Eigen::MatrixXd::Zero(draws, 6)) {}
  void Add(Eigen::Index d, int a, double x) {
    ss(d, a) += x * x;
    max(d, a) = std::max(max(d, a), std::fabs(x));
  }
  // draws × 12: rms pos xyz, rms ori xyz, max pos xyz, max ori xyz over `m` poses.
  Eigen::MatrixXd Metrics(int m) const {
    Eigen::MatrixXd out(ss.rows(), 12);
    out.leftCols(6) = (ss / m).cwiseSqrt();
    out.rightCols(6) = max;
    return out;
  }
};

// Adds a block of poses' unit data-part errors E and, if given, held-part errors H (6 rows per
// pose, one column per draw) to the sums of each part, in one pass; the total's data part is
// scale · E.
void AddPoseBlock(const Eigen::MatrixXd& E, const Eigen::MatrixXd* H, PartSums* data,
                  PartSums* held, PartSums* total, double scale = 1) {
  const auto poses = static_cast<int>(E.rows() / 6);
  for (Eigen::Index d = 0; d < E.cols(); ++d)
    for (int a = 0; a < 6; ++a)  // position xyz, orientation xyz
      for (int j = 0; j < poses; ++j) {
        const double x = E(6 * j + a, d);
        data->Add(d, a, x);
        if (H == nullptr) continue;
        const double y = (*H)(6 * j + a, d);
        held->Add(d, a, y);
        total->Add(d, a, scale * x + y);
      }
}

// A covariance as scale² · unit (CellContext::unit_covariance).
struct ScaledCovariance {
  Eigen::MatrixXd unit;
  double scale = 1;
  bool defined() const { return unit.size() > 0 && unit.allFinite() && std::isfinite(scale); }
};

// The factor L of a covariance (L·Lᵀ = C, from its eigendecomposition, negative eigenvalues as 0).
Eigen::MatrixXd CovarianceFactor(const Eigen::MatrixXd& C) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(C);
  return eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
}

// The data part's metrics of unit draws (draws × 12): Z (n × draws) from the validation set's
// prediction stream pushed through L (the factor of the unit covariance) and the validation poses'
// Jacobian J6, and, when `held` has columns, the held part from the stream's next k × draws
// normals and the total of scale · (data) + held.
struct UnitDraws {
  Eigen::MatrixXd data, held, total;
};

UnitDraws ComputeUnitDraws(const CellContext& c, int draws, const Eigen::MatrixXd& unit,
                           double scale, const Eigen::MatrixXd& J6, const Eigen::MatrixXd& held) {
  const auto n = static_cast<int>(unit.rows());
  const int m = c.validation.size();
  const auto k = static_cast<int>(held.cols());
  const Eigen::MatrixXd L = CovarianceFactor(unit);
  Eigen::MatrixXd Z(n, draws);
  const RandomStream stream(0, c.validation_stream, 0, RandomPurpose::kPrediction);
  stream.Normals(0, static_cast<std::uint64_t>(n) * draws, Z.data());
  const Eigen::MatrixXd LZ = L * Z;  // n × draws
  Eigen::MatrixXd W(k, draws);
  if (k > 0)
    stream.Normals(static_cast<std::uint64_t>(n) * draws, static_cast<std::uint64_t>(k) * draws,
                   W.data());
  // The poses' pose Jacobian (6 rows per pose: position, then orientation; its sign is
  // irrelevant here, the draws are symmetric and enter through squares and magnitudes),
  // applied to the draws a block of poses at a time: memory per validation pose stays about
  // 1 KB, not 6 × draws doubles. Each draw's sums run over the poses in order, so the bits do not
  // depend on the block.
  constexpr int kPosesPerBlock = 256;
  PartSums data(draws), held_part(draws), total(draws);
  for (int j0 = 0; j0 < m; j0 += kPosesPerBlock) {
    const int mc = std::min(kPosesPerBlock, m - j0);
    const Eigen::MatrixXd E = J6.middleRows(6 * j0, 6 * mc) * LZ;  // 6·mc × draws, unit
    if (k == 0) {
      AddPoseBlock(E, nullptr, &data, nullptr, nullptr);
      continue;
    }
    const Eigen::MatrixXd H = held.middleRows(6 * j0, 6 * mc) * W;
    AddPoseBlock(E, &H, &data, &held_part, &total, scale);
  }
  return {data.Metrics(m), held_part.Metrics(m), total.Metrics(m)};
}

// The unit draws without held terms (what predicts a cell's means): every input of them.
struct UnitDrawsKey {
  int draws;
  std::uint64_t stream;
  Eigen::MatrixXd unit, J6;
  bool operator==(const UnitDrawsKey& o) const {
    return draws == o.draws && stream == o.stream && SameMatrix(unit, o.unit) &&
           SameMatrix(J6, o.J6);
  }
};

// The first-order draws of the validation metrics: `draws` Gaussian parameter errors from the
// covariance C = scale² · unit pushed through the validation poses' Jacobian (the data part) and,
// when `held` has columns, the held terms' part M·w and the sum of both. Z (n × draws) and
// w (k × draws) come from the validation set's prediction stream, Z first, so every call on a
// cell uses the same normals (common random numbers). The data part is scale × the metrics of
// the unit covariance's draws (RMS and max are homogeneous of degree 1), so cells that differ in
// σ alone share them (a memo of the unit draws). Without held columns the held part is zero and the
// total the data part.
FirstOrderDraws LinearisedPartDraws(const CellContext& c, int draws, const ScaledCovariance& C,
                                    const Eigen::MatrixXd& held) {
  FirstOrderDraws out;
  out.data = out.held = out.total = Eigen::MatrixXd::Constant(draws, 12, std::nan(""));
  if (c.rank_deficient || !C.defined() || c.validation.size() == 0) return out;
  const Eigen::MatrixXd J6 = ValidationPoseJacobian(c);
  if (held.cols() == 0) {
    static PreparationMemo<UnitDrawsKey, Eigen::MatrixXd, 160> memo;
    out.data = C.scale * memo.Get(UnitDrawsKey{draws, c.validation_stream, C.unit, J6}, [&] {
      return ComputeUnitDraws(c, draws, C.unit, 1.0, J6, Eigen::MatrixXd()).data;
    });
    out.total = out.data;
    out.held.setZero();
    return out;
  }
  UnitDraws unit = ComputeUnitDraws(c, draws, C.unit, C.scale, J6, held);
  out.data = C.scale * unit.data;
  out.held = std::move(unit.held);
  out.total = std::move(unit.total);
  return out;
}

Eigen::MatrixXd LinearisedDraws(const CellContext& c, int draws) {
  return LinearisedPartDraws(c, draws, {c.unit_covariance, c.covariance_scale}, Eigen::MatrixXd())
      .data;
}

// The accuracy planner (accuracy_plan.h) states the ranger's totals: a tracker cell is refused.
void RefuseTrackerPlan(const CellContext& c) {
  if (c.kind)
    throw InputError("sensor.kind", std::string("the accuracy planner models the ranger's "
                                                "campaigns; this cell's sensor is ") +
                                        c.kind->name());
}

// The cell's settings with `repetitions` readings per configuration (InputError below 1).
CellSettings WithRepetitions(const CellSettings& s, int repetitions) {
  if (repetitions < 1)
    throw InputError("repetitions", "expected 1 or more readings per configuration, got " +
                                        std::to_string(repetitions));
  CellSettings out = s;
  out.noise.repetitions = repetitions;
  return out;
}

// The covariance predicted for the cell's design under settings `s` (as SelectCellDesign predicts
// it for the cell's own); empty when it is undefined.
ScaledCovariance DesignCovariance(const CellSettings& s, const CellContext& c) {
  if (c.rank_deficient) return {};
  const Eigen::MatrixXd& Gd = c.design_nominal.G;
  if (ModelledUncertainty(s)) {
    const PriorInformation posterior = PosteriorOn(s, c, c.design.configs, Gd);
    return {posterior.defined ? posterior.posterior_covariance : Eigen::MatrixXd(), 1.0};
  }
  return {ParameterCovariance(s.noise.EffectiveReadings() * (Gd.transpose() * Gd), 1.0),
          s.noise.sigma};
}

// The terms a calibration of the cell's design under settings `s` holds at nominal, at the
// nominal model: each at the identification's prior, else the robot file's tolerance, else
// lrcal's default (FindUnestimatedTerms), as `identify --predict-at` states them.
UnestimatedTerms DesignHeldTerms(const CellSettings& s, const CellContext& c) {
  const int n = c.model->num_parameters(), m = c.design.configs.size();
  IdentificationSummary at_nominal;
  at_nominal.delta = Eigen::VectorXd::Zero(n);
  MeasurementSet design;
  design.configs = c.design.configs;
  design.mean_h.assign(static_cast<std::size_t>(m), 0.0);
  design.repetitions.assign(static_cast<std::size_t>(m), s.noise.repetitions);
  if (!s.noise.average.IsMean())
    design.variance_factor.assign(static_cast<std::size_t>(m),
                                  s.noise.repetitions / s.noise.EffectiveReadings());
  return FindUnestimatedTerms(*c.model, at_nominal, design, s.identification,
                              c.tolerances.OverriddenBy(s.identification.priors));
}

}  // namespace

// The first-order prediction of the validation metrics' means, the planner's estimate: the
// covariance predicted at the nominal model propagated to the validation poses through their
// Jacobian (linear in the parameter errors), then each metric's mean over 4000 Gaussian draws
// of those linear errors (the RMS and max of correlated errors have no closed form). Draws are
// addressed by the validation set's stream, so the prediction is a function of the settings.
void SetPredictedCovariance(CellContext* c, Eigen::MatrixXd unit, double scale) {
  c->predicted_covariance = (scale * scale) * unit;
  c->predicted_std = c->predicted_covariance.diagonal().cwiseSqrt();
  c->unit_covariance = std::move(unit);
  c->covariance_scale = scale;
}

void PredictValidation(CellContext* c) {
  if (c->for_trials_only) {  // the stored row holds it
    c->predicted_validation.fill(std::nan(""));
    return;
  }
  constexpr int kDraws = 4000;
  const Eigen::MatrixXd draws = LinearisedDraws(*c, kDraws);
  std::array<double, 12> sum{};
  for (int d = 0; d < kDraws; ++d)  // in draw order (a fixed summation order: fixed bits)
    for (int k = 0; k < 12; ++k) sum[k] += draws(d, k);
  for (int k = 0; k < 12; ++k) c->predicted_validation[k] = sum[k] / kDraws;
}

namespace {

// What a calibration of this cell states at its validation poses at the nominal model, for the
// estimate's covariance C (SI): the data part and the total with the terms held at nominal
// (DesignHeldTerms), as `identify --predict-at` states them.
AccuracyPrediction StatedAtValidation(const CellSettings& s, const CellContext& c,
                                      const Eigen::MatrixXd& C) {
  const std::vector<double> zero(static_cast<std::size_t>(c.model->num_parameters()), 0.0);
  return PredictTotalAccuracy(*c.model, zero.data(), C, DesignHeldTerms(s, c), c.validation);
}

// validation.coverage: what a calibration of this cell would state at each validation pose, at
// the nominal model: the 95 % position radius of the predicted covariance (the data part) and of
// the total, with every term the cell holds at nominal (plane and ranger terms, fixed
// parameters) at the identification's prior, else the robot file's tolerance, else lrcal's
// default, as `identify --predict-at` states them.
void StateCoverageRadii(const CellSettings& s, CellContext* c) {
  if (!s.coverage || c->rank_deficient || c->predicted_covariance.size() == 0) return;
  const AccuracyPrediction stated = StatedAtValidation(s, *c, c->predicted_covariance);
  for (const PoseAccuracy& pose : stated.poses) {
    c->coverage_radius.push_back(pose.position_radius_95);
    c->coverage_radius_total.push_back(pose.position_radius_95_total);
  }
}

// The share of the validation poses whose position error lies within each stated radius.
void RecordCoverage(const CellContext& c, const PoseErrors& errors, TrialRecord* rec) {
  if (c.coverage_radius.empty()) return;
  const auto m = static_cast<Eigen::Index>(c.coverage_radius.size());
  int inside = 0, inside_total = 0;
  for (Eigen::Index j = 0; j < m; ++j) {
    const double error = errors.position.col(j).norm();
    inside += error <= c.coverage_radius[j];
    inside_total += error <= c.coverage_radius_total[j];
  }
  rec->coverage = static_cast<double>(inside) / static_cast<double>(m);
  rec->coverage_total = static_cast<double>(inside_total) / static_cast<double>(m);
}

// ---------------------------------------------------------------------------------------------
// The trial's steps.

// The design of a trial: the cell's, or redrawn (a new pool, or a new selection from the cell's
// pool). Returns false if a redrawn pool cannot be sampled (the true beam misses too often).
bool DesignOfTrial(const CellContext& c, long long trial, const TrialTruth& truth,
                   TrialDesign* redrawn, const TrialDesign** design) {
  const CellSettings& s = c.cell->typed;
  *design = &c.design;
  if (!s.pool_redraw && !s.selection_redraw) return true;
  if (s.pool_redraw) {
    TargetedConfigurations pool;
    try {
      pool = SamplePool(c, trial, truth.values, nullptr);
    } catch (const InputError&) {
      return false;
    }
    *redrawn = SelectDesign(
        c, trial, pool,
        c.cell->typed.task_criterion ? TaskDesignJacobian(c, pool) : CellDesignJacobian(c, pool));
  } else {
    *redrawn = SelectDesign(c, trial, c.pool, c.pool_design_G);
  }
  const Eigen::MatrixXd Gd = IdentificationJacobian(*c.model, redrawn->configs);
  redrawn->sigma_min = DesignSigmaMin(Gd.transpose() * Gd, redrawn->configs.size());
  *design = redrawn;
  return true;
}

// Noisy mean readings of the design into ws->data; returns the number of missed beams. Exact
// true readings cached per cell are reused when the truth is fixed.
int SimulateTrialReadings(const CellContext& c, long long trial, const TrialTruth& truth,
                          const TrialDesign& design, TrialWorkspace* ws) {
  const CellSettings& s = c.cell->typed;
  NoiseModel noise = s.noise;
  noise.draw_mean = true;
  noise.ranger_offset = c.ranger_offset;
  noise.ranger_scale = c.ranger_scale;
  const RandomStream stream(c.seed, 0, static_cast<std::uint64_t>(trial), RandomPurpose::kNoise);
  if (s.truth.random || s.pool_redraw || noise.DisturbsGeometry())
    return SimulateReadings(*c.robot, truth.values, c.planes, c.ranger, design.configs, noise,
                            stream, &ws->data, nullptr, nullptr, &design.slots);
  if (!s.selection_redraw)
    return AddNoise(c.design_true_h, c.design_true_miss, design.configs, noise, stream, &ws->data,
                    nullptr, &design.slots);
  ws->exact_h.clear();
  ws->exact_miss.clear();
  for (int i : design.slots) {
    ws->exact_h.push_back(c.pool_true_h[i]);
    ws->exact_miss.push_back(c.pool_true_miss[i]);
  }
  return AddNoise(ws->exact_h, ws->exact_miss, design.configs, noise, stream, &ws->data, nullptr,
                  &design.slots);
}

struct SolveOutcome {
  Termination termination = Termination::kInvalidInput;
  int iterations = 0;
  double final_cost = 0;
  /// With priors or errors in variables the cost is not Σ R·r² of the readings alone (prior
  /// rows, errors-in-variables weights): the summary's residual RMS and σ̂ (m), NaN otherwise.
  double residual_rms = std::nan(""), sigma_hat = std::nan("");
};

// Identifies from ws->data into ws->e with the cell's solver. lrcal's LM starts from the cell's
// cached nominal linearisation when the design is the cell's own.
SolveOutcome IdentifyTrial(const CellContext& c, bool cell_design, TrialWorkspace* ws) {
  const CellSettings& s = c.cell->typed;
  SolveOutcome out;
  if (s.identification.solver == IdentificationOptions::Solver::kCeres || ModelledUncertainty(s)) {
    IdentificationOptions options = s.identification;
    options.robust_fit_check = false;  // a trial records no fit verdict: no draws for it
    const IdentificationSummary summary = Identify(*c.model, ws->data, options);
    if (ModelledUncertainty(s)) {
      out.residual_rms = summary.residual_rms;
      out.sigma_hat = std::isfinite(summary.sigma_hat) ? summary.sigma_hat : 0.0;
    }
    out.termination = summary.termination;
    out.iterations = summary.iterations;
    out.final_cost = summary.final_cost;
    ws->e = summary.delta;
    return out;
  }
  ws->data.FillWeights(&ws->weights);
  const LevenbergMarquardt::Result r =
      ws->solver.Solve(*c.model, ws->data.configs, ws->data.mean_h.data(), ws->weights.data(),
                       s.identification, &ws->e, cell_design ? &c.design_nominal : nullptr);
  out.termination = r.termination;
  out.iterations = r.iterations;
  out.final_cost = r.final_cost;
  return out;
}

TrialStatus StatusOf(Termination t) {
  switch (t) {
    case Termination::kConverged:
      return TrialStatus::kOk;
    case Termination::kRankDeficient:
      return TrialStatus::kRankDeficient;
    case Termination::kMaxIterations:
      return TrialStatus::kNotConverged;
    case Termination::kBeamMissed:
      return TrialStatus::kBeamMissed;
    default:
      return TrialStatus::kNumericalFailure;
  }
}

void FillDetails(const CellContext& c, const TrialTruth& truth, const Eigen::VectorXd& identified,
                 const TrialWorkspace& ws, TrialDetails* details) {
  const Eigen::VectorXd& nominal = c.robot->nominal_values();
  const TargetedConfigurations& configs = ws.data.configs;
  std::vector<double> h_nominal, h_identified;
  std::vector<BeamMiss> unused;
  ExactReadings(*c.robot, nominal, c.planes, c.ranger, configs, &h_nominal, &unused);
  ExactReadings(*c.robot, identified, c.model->PlanesAt(ws.e.data()), c.ranger, configs,
                &h_identified, &unused);
  ModelPoint point;  // the identified ranger terms, if any
  c.model->Prepare(ws.e.data(), &point);
  c.model->ApplyRanger(point, static_cast<int>(h_identified.size()), h_identified.data(), nullptr);
  details->distance_error_nominal.clear();
  details->distance_error_identified.clear();
  for (int i = 0; i < ws.data.size(); ++i) {
    details->distance_error_nominal.push_back(ws.data.mean_h[i] - h_nominal[i]);
    details->distance_error_identified.push_back(ws.data.mean_h[i] - h_identified[i]);
  }
  details->measurement_nominal = ComparePoses(*c.robot, truth.values, nominal, configs);
  details->measurement_identified = ComparePoses(*c.robot, truth.values, identified, configs);
  details->validation_nominal = ComparePoses(*c.robot, truth.values, nominal, c.validation);
  details->validation_identified = ComparePoses(*c.robot, truth.values, identified, c.validation);
}

// A ranger cell's preparation after its rig is loaded.
void PrepareRangerCell(const Study& study, const CellSettings& s, CellContext* c) {
  BuildParameterSet(s, c);
  DrawCellConfigurations(study, s, c);
  CheckIdentifiability(s, c);
  c->parameter_names = c->model->parameters().names;
  SelectCellDesign(s, c);
  CacheTruth(s, c);
  PredictValidation(c);
  StateCoverageRadii(s, c);
}

}  // namespace

std::unique_ptr<CellContext> PrepareCell(const Study& study, const Cell& cell,
                                         CellPreparation what) {
  auto c = std::make_unique<CellContext>();
  c->cell = &cell;
  c->for_trials_only = what == CellPreparation::kForTrials;
  c->seed = study.seed;
  const CellSettings& s = cell.typed;
  try {
    // The robot file read once: whether its chain is coupled and, if not, its arm.
    const RigKey rig =
        s.IsTree() ? RigKey{} : RigKeyOf(ResolveRobotPath(s.robot, study.folder()), s);
    if (s.IsTree() || RigIsCoupled(rig)) {
      PrepareTreeCell(study, s, c.get());
    } else {
      LoadRig(rig, s, c.get());
      if (!s.sensor.IsRanger() || s.in_environment)
        PrepareTrackerCell(study, s, c.get());
      else
        PrepareRangerCell(study, s, c.get());
    }
  } catch (const InputError& e) {
    throw InputError(study.path + " cell '" + cell.label + "' (" + cell.id + ")", e.what());
  }
  if (s.truth.random)
    c->validation_nominal_poses = ToolPoses(*c->robot, c->robot->nominal_values(), c->validation);
  return c;
}

TrialRecord RunTrial(const CellContext& c, long long trial, TrialWorkspace* ws,
                     TrialDetails* details) {
  const auto start = std::chrono::steady_clock::now();
  const CellSettings& s = c.cell->typed;
  TrialRecord rec;
  rec.cell_id = c.cell->id;
  rec.trial = trial;
  rec.sigma_min = c.design.sigma_min;
  auto finish = [&](TrialStatus status) {
    rec.status = status;
    rec.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return rec;
  };
  const TrialTruth truth = s.truth.random ? DrawTruth(c, trial) : c.fixed_truth;
  // The true validation poses, computed once a trial (the nominal's errors and the identified
  // arm's are both taken against them).
  std::vector<Pose<double>> drawn_true_poses;
  if (s.truth.random) drawn_true_poses = TruePoses(c, truth.values, c.validation);
  const std::vector<Pose<double>>& validation_true =
      s.truth.random ? drawn_true_poses : c.validation_true_poses;
  rec.nominal =
      Flatten(s.truth.random ? ComparePoses(validation_true, c.validation_nominal_poses).stats
                             : c.nominal_validation);
  if (c.rank_deficient) return finish(TrialStatus::kRankDeficient);
  if (c.kind) return finish(RunTrackerTrial(c, trial, truth, validation_true, &rec, details, ws));

  TrialDesign redrawn;
  const TrialDesign* design = nullptr;
  if (!DesignOfTrial(c, trial, truth, &redrawn, &design)) return finish(TrialStatus::kBeamMissed);
  rec.sigma_min = design->sigma_min;
  // A configuration whose true beam misses its plane has no reading: it is left out, and the
  // trial goes on with the others unless fewer readings than parameters remain.
  rec.missed_configurations = SimulateTrialReadings(c, trial, truth, *design, ws);
  const int m = ws->data.size(), n = c.model->num_parameters();
  if (m < n) return finish(TrialStatus::kBeamMissed);

  // The cell's cached nominal linearisation holds for its own design only when nothing is missing.
  const SolveOutcome r =
      IdentifyTrial(c, design == &c.design && rec.missed_configurations == 0, ws);
  rec.iterations = r.iterations;
  rec.residual_rms =
      std::isnan(r.residual_rms)
          ? std::sqrt(2 * r.final_cost / (m * s.noise.EffectiveReadings()))  // per-config mean
          : r.residual_rms;
  rec.sigma_hat =
      std::isnan(r.sigma_hat) ? (m > n ? std::sqrt(2 * r.final_cost / (m - n)) : 0.0) : r.sigma_hat;
  if (StatusOf(r.termination) != TrialStatus::kOk) return finish(StatusOf(r.termination));

  rec.errors.resize(n);
  for (int k = 0; k < n; ++k) rec.errors[k] = ws->e[k] - truth.delta[k];
  const Eigen::VectorXd identified = c.model->LinkValues(ws->e.data());
  const PoseErrors validation = ComparePoses(*c.robot, validation_true, identified, c.validation);
  rec.validation = Flatten(validation.stats);
  RecordCoverage(c, validation, &rec);
  if (details) FillDetails(c, truth, identified, *ws, details);
  return finish(TrialStatus::kOk);
}

const char* TrialStatusReason(TrialStatus s) {
  switch (s) {
    case TrialStatus::kOk:
      return "";
    case TrialStatus::kRankDeficient:
      return "the parameter set is not identifiable from the cell's configurations (with "
             "identification.on_rank_deficient: fix, the suggested parameters are fixed instead)";
    case TrialStatus::kNotConverged:
      return "the solver stopped at identification.max_iterations without meeting a tolerance";
    case TrialStatus::kNumericalFailure:
      return "a non-finite cost or a failed factorisation during the identification";
    case TrialStatus::kBeamMissed:
      return "a beam missed its plane: the true arm's beams at so many configurations of the "
             "design that fewer readings than parameters remained, or the model's beam at an "
             "iterate of the identification";
  }
  return "";
}

Eigen::MatrixXd LinearisedValidationDraws(const CellContext& c, int draws) {
  return LinearisedDraws(c, draws);
}

FirstOrderDraws LinearisedValidationDraws(const CellContext& c, int draws, int repetitions) {
  RefuseTrackerPlan(c);
  const CellSettings s = WithRepetitions(c.cell->typed, repetitions);
  const ScaledCovariance C = DesignCovariance(s, c);
  Eigen::MatrixXd held;
  if (C.defined()) {
    const std::vector<double> zero(static_cast<std::size_t>(c.model->num_parameters()), 0.0);
    held = HeldTermPoseColumns(*c.model, zero.data(), DesignHeldTerms(s, c), c.validation);
  }
  return LinearisedPartDraws(c, draws, C, held);
}

std::optional<AccuracyPrediction> StatedValidationAccuracy(const CellContext& c, int repetitions) {
  RefuseTrackerPlan(c);
  const CellSettings s = WithRepetitions(c.cell->typed, repetitions);
  const ScaledCovariance C = DesignCovariance(s, c);
  if (!C.defined()) return std::nullopt;
  return StatedAtValidation(s, c, (C.scale * C.scale) * C.unit);
}

}  // namespace lrcal
