// The steps of a tree cell (tool_link: "left_tool,right_tool"): a tracker cell whose kind is the
// TreeMeasurement of the URDF's chains (tree_measurement.h), so that the chains' common joints'
// terms are estimated once from every chain's values. Per cell: the chains from the base link to
// each tool link (io/urdf.h LoadRobotChains; a robot YAML file's one chain with coupled links
// too); a pool and validation set of whole-robot
// configurations, every joint uniform in its range (the draws of UniformTreeConfigurations), kept
// where each chain's Jacobian (the judged chain's only, for the validation) has σ_min ≥
// pool.min_singular_value, as a one-chain cell keeps its draws; then a tracker cell's steps on the
// tree's kind (identifiability, block selection, covariance). Per trial: every term of every chain
// drawn (a shared link's terms once, so every chain sees the same torso), the chains' values at
// that truth plus noise, lrcal's LM on the tree's kind, and the judged chain's tool judged on the
// validation poses: the records and the prediction are that arm's.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/core/error.h"
#include "lrcal/measurement/pose_measurement.h"
#include "lrcal/measurement/tree_measurement.h"
#include "study/trial_pipeline.h"

namespace lrcal {

namespace {

constexpr int kDrawsPerConfiguration = 20;  // uniform draws allowed per kept configuration

void LoadTreeRig(const Study& study, const CellSettings& s, CellContext* c) {
  // A tree's settings are checked when the study is read; a robot with a coupled joint on its one
  // chain is known to be one here.
  if (s.sensor.kind != "point" && s.sensor.kind != "pose")
    throw InputError("sensor.kind",
                     "a robot with a coupled joint is studied with a tracker: "
                     "expected point or pose, got " +
                         s.sensor.kind);
  if (!s.truth.random)
    throw InputError("truth.mode",
                     "a robot with a coupled joint is studied with drawn true errors; expected "
                     "random");
  auto tree = std::make_unique<TreeCell>();
  const std::vector<std::string> links = s.ToolLinks();
  tree->tree = LoadRobotChains(ResolveRobotPath(s.robot, study.folder()), links, s.base_link);
  if (!s.validation_tool_link.empty())
    tree->judged = static_cast<int>(std::find(links.begin(), links.end(), s.validation_tool_link) -
                                    links.begin());
  const RobotFile& judged = tree->tree.chains[static_cast<std::size_t>(tree->judged)];
  c->robot = std::make_shared<RobotModel>(judged.robot);
  c->ranger = judged.ranger;
  // A tracker reads no plane: the horizontal plane through the base only tags configurations.
  c->planes = s.plane_from_robot ? PlaneSet(Plane{}) : s.planes;
  c->file_true_errors = Eigen::VectorXd::Zero(c->robot->num_values());
  c->tree = std::move(tree);
}

// The chains' kinds on their arms (every term), their TreeMeasurement, and the cell's estimate:
// without identification.fix. Per term, the σ of its true error (a link value's: the truth's
// angle or length σ; the instrument's, a target's, a coupling's gain: 0, nominal as in a one-arm
// tracker cell) and the judged arm's value it is.
void BuildTreeKind(const CellSettings& s, CellContext* c) {
  TreeCell& t = *c->tree;
  const std::string source = "identification.fix";
  for (std::size_t k = 0; k < t.tree.chains.size(); ++k) {
    const RobotModel& arm = t.tree.chains[k].robot;
    std::shared_ptr<const MeasurementKind> kind;
    if (s.sensor.kind == "pose")
      kind = std::make_shared<PoseMeasurement>(arm, s.sensor.tracker, std::vector<std::string>{},
                                               source);
    else
      kind = std::make_shared<PointMeasurement>(arm, s.sensor.tracker, std::vector<std::string>{},
                                                source);
    t.chains.push_back(std::make_shared<ChainMeasurement>(kind, t.tree.placements[k]));
  }
  t.full = std::make_unique<TreeMeasurement>(t.chains);
  const std::vector<std::string>& names = t.full->parameter_names();
  for (const std::string& name : s.fixed)
    if (std::find(names.begin(), names.end(), name) == names.end())
      throw InputError(source, "'" + name +
                                   "' is not a term of the tree's chains (a chain's own term is "
                                   "written with its tool link: left_tool.theta4)");
  c->kind = t.full->Without(s.fixed);
  t.truth_sigma.assign(names.size(), 0.0);
  t.judged_value.assign(names.size(), -1);
  for (std::size_t k = 0; k < t.chains.size(); ++k) {
    const ChainMeasurement& chain = *t.chains[k];
    const RobotModel& arm = t.tree.chains[k].robot;
    const std::vector<std::string>& own = chain.parameter_names();
    const std::vector<int>& column = chain.layout().inner_column;
    for (std::size_t i = 0; i < column.size(); ++i) {
      const int value =
          arm.FindValue(chain.kind().parameter_names()[static_cast<std::size_t>(column[i])]);
      if (value < 0) continue;  // the instrument's or the target's
      const auto term =
          static_cast<std::size_t>(std::find(names.begin(), names.end(), own[i]) - names.begin());
      t.truth_sigma[term] =
          IsAngle(value % kValuesPerLink) ? s.truth.angle_sigma : s.truth.length_sigma;
      if (static_cast<int>(k) == t.judged) t.judged_value[term] = value;
    }
  }
  // The judged arm's link terms alone: the validation poses' Jacobian (ValidationPoseJacobian).
  c->model = std::make_unique<MeasurementModel>(
      *c->robot, c->planes,
      MakeParameterSet(*c->robot, std::vector<PlaneTerms>(c->planes.size()), {}, source));
}

// Per estimated term: its place in the full layout and the judged arm's value (-1: none).
void MapTreeTerms(CellContext* c) {
  TreeCell& t = *c->tree;
  const std::vector<std::string>& all = t.full->parameter_names();
  c->parameter_names = c->kind->parameter_names();
  t.estimated.clear();
  c->kind_link_values.clear();
  for (const std::string& name : c->parameter_names) {
    const auto k = static_cast<int>(std::find(all.begin(), all.end(), name) - all.begin());
    t.estimated.push_back(k);
    c->kind_link_values.push_back(t.judged_value[static_cast<std::size_t>(k)]);
  }
}

// True when every chain of `which` (all: -1) is well conditioned (IsWellConditioned) at
// whole-robot configuration i, `per_chain` its chains' joints.
bool WellConditioned(const TreeCell& t, const std::vector<TargetedConfigurations>& per_chain, int i,
                     int which, double min_sv) {
  for (std::size_t k = 0; k < t.chains.size(); ++k)
    if ((which < 0 || static_cast<int>(k) == which) &&
        !IsWellConditioned(t.tree.chains[k].robot, per_chain[k].q(i), min_sv))
      return false;
  return true;
}

// `count` whole-robot configurations from `stream`, kept in draw order where the chains (`which`:
// one, or -1 every one) are well conditioned. Throws InputError (`key`) when too few are.
TargetedConfigurations DrawTreeConfigurations(const CellSettings& s, const TreeCell& t, int count,
                                              const RandomStream& stream, int which,
                                              const std::string& key, SamplingReport* report) {
  const int attempts = count * kDrawsPerConfiguration;
  const TargetedConfigurations drawn = UniformTreeConfigurations(t.tree, attempts, stream);
  std::vector<TargetedConfigurations> per_chain;
  for (const auto& chain : t.chains) per_chain.push_back(chain->ChainConfigurations(drawn));
  std::vector<int> kept;
  int tried = 0;
  for (; tried < attempts && static_cast<int>(kept.size()) < count; ++tried)
    if (WellConditioned(t, per_chain, tried, which, s.min_singular_value)) kept.push_back(tried);
  if (report) {
    report->requested = count;
    report->accepted = static_cast<int>(kept.size());
    report->attempts = tried;
    if (tried > report->accepted) report->rejected["singular"] = tried - report->accepted;
  }
  if (static_cast<int>(kept.size()) < count)
    throw InputError(key, "only " + std::to_string(kept.size()) + " of " +
                              std::to_string(attempts) + " whole-robot draws have " +
                              (which < 0 ? std::string("every chain's") : "the judged chain's") +
                              " Jacobian σ_min ≥ pool.min_singular_value; lower it or ask for "
                              "fewer");
  return drawn.Subset(kept);
}

// A tree's configurations from a study's file: every joint of the tree by name.
TargetedConfigurations ReadTreeFile(const Study& study, const std::string& file,
                                    const std::string& key, const TreeCell& t) {
  try {
    return ReadTreeConfigurations(ResolveStudyFile(file, study.folder()), t.tree, nullptr);
  } catch (const InputError& e) {
    throw InputError(key, e.what());
  }
}

// The pool (every chain well conditioned) and the validation set (the judged chain's tool; its
// draws depend on the validation settings, the robot and the pool's, as a one-arm cell's do).
void DrawTreeCellConfigurations(const Study& study, const CellSettings& s, CellContext* c) {
  const TreeCell& t = *c->tree;
  c->pool_stream =
      StreamId(c->cell->settings, {"robot", "robot_file_fnv1a", "pool", "truth", "sensor"});
  c->validation_stream = ValidationStreamId(c->cell->settings);
  c->selection_seed = s.pool_file.empty() ? study.seed : 0;
  if (!s.pool_file.empty()) {
    AcceptPoolFile(s, ReadTreeFile(study, s.pool_file, "pool.file", t), c);
  } else {
    c->pool = DrawTreeConfigurations(s, t, s.pool_size,
                                     RandomStream(c->seed, c->pool_stream, 0, RandomPurpose::kPool),
                                     -1, "pool.size", &c->pool_report);
  }
  const TargetedConfigurations whole =
      !s.validation_file.empty()
          ? ReadTreeFile(study, s.validation_file, "validation.file", t)
          : DrawTreeConfigurations(
                s, t, s.validation_size,
                RandomStream(study.seed, c->validation_stream, 0, RandomPurpose::kValidation),
                t.judged, "validation.size", nullptr);
  c->validation = t.chains[static_cast<std::size_t>(t.judged)]->ChainConfigurations(whole);
}

}  // namespace

void PrepareTreeCell(const Study& study, const CellSettings& s, CellContext* c) {
  LoadTreeRig(study, s, c);
  BuildTreeKind(s, c);
  DrawTreeCellConfigurations(study, s, c);
  CheckTrackerIdentifiability(s, c);
  MapTreeTerms(c);
  CheckValuesForTerms(s, *c);
  SelectTrackerDesign(s, c);
  PredictValidation(c);
}

TrialTruth DrawTreeTruth(const CellContext& c, long long trial) {
  const TreeCell& t = *c.tree;
  const RandomStream stream(c.seed, 0, static_cast<std::uint64_t>(trial), RandomPurpose::kTruth);
  TrialTruth truth;
  const auto n = static_cast<Eigen::Index>(t.truth_sigma.size());
  truth.tree_delta.resize(n);
  truth.errors = Eigen::VectorXd::Zero(c.robot->num_values());
  for (Eigen::Index k = 0; k < n; ++k) {
    const double sigma = t.truth_sigma[static_cast<std::size_t>(k)];
    truth.tree_delta[k] = sigma > 0 ? stream.Normal(static_cast<std::uint64_t>(k)) * sigma : 0.0;
    const int value = t.judged_value[static_cast<std::size_t>(k)];
    if (value >= 0) truth.errors[value] = truth.tree_delta[k];
  }
  truth.values = c.robot->nominal_values() + truth.errors;
  truth.delta.resize(static_cast<Eigen::Index>(t.estimated.size()));
  for (std::size_t j = 0; j < t.estimated.size(); ++j)
    truth.delta[static_cast<Eigen::Index>(j)] = truth.tree_delta[t.estimated[j]];
  return truth;
}

void SimulateTreeValues(const CellContext& c, const TrialTruth& truth, const NoiseModel& noise,
                        const RandomStream& stream, MeasuredValues* values) {
  const MeasurementKind& full = *c.tree->full;
  const TargetedConfigurations& configs = c.design.configs;
  std::vector<double> exact(
      static_cast<std::size_t>(configs.size() * full.rows_per_configuration()));
  if (!full.Bind(configs)->Predict(truth.tree_delta.data(), exact.data(), nullptr))
    throw std::runtime_error("tree cell: the chains' values are undefined at the trial's truth");
  AddMeasurementNoise(full, exact, full.MissReasons(configs, truth.tree_delta.data()), configs,
                      noise, stream, values);
}

}  // namespace lrcal
