#include "lrcal/trial.h"

#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>

#include "lrcal/error.h"
#include "lrcal/simulation.h"

namespace lrcal {

const char* TrialStatusName(TrialStatus s) {
  switch (s) {
    case TrialStatus::kOk: return "ok";
    case TrialStatus::kRankDeficient: return "rank_deficient";
    case TrialStatus::kNotConverged: return "not_converged";
    case TrialStatus::kNumericalFailure: return "numerical_failure";
    case TrialStatus::kBeamMissed: return "beam_missed";
  }
  return "unknown";
}

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

namespace {

// Stream id of a draw family: a hash of the settings it depends on.
std::uint64_t StreamId(const Json& settings, std::initializer_list<const char*> keys) {
  Json part;
  for (const char* k : keys) part[k] = settings[k];
  return Fnv1a(part.dump());
}

// The truth of a trial in link values (5N), and in the estimate layout (robot deltas; plane 0).
void DrawTruth(const CellContext& c, long long trial, Eigen::VectorXd* values,
               Eigen::VectorXd* delta) {
  const CellSettings& s = c.cell->typed;
  const RobotModel& robot = *c.robot;
  Eigen::VectorXd errors(robot.num_values());
  if (s.truth_random) {
    RandomStream stream(c.seed, 0, static_cast<std::uint64_t>(trial), RandomPurpose::kTruth);
    for (int k = 0; k < robot.num_values(); ++k) {
      const bool is_param = robot.links()[k / kValuesPerLink].is_parameter[k % kValuesPerLink];
      errors[k] = is_param ? stream.Normal(k) * (IsAngle(k % kValuesPerLink) ? s.truth_angle_sigma
                                                                              : s.truth_length_sigma)
                           : 0.0;
    }
  } else {
    errors = robot.true_errors() * s.truth_scale;
  }
  *values = robot.nominal_values() + errors;
  const ParameterSet& ps = c.model->parameters();
  delta->setZero(ps.size());
  for (int k = 0; k < ps.num_robot(); ++k) (*delta)[k] = errors[ps.robot_values[k]];
}

// G of a candidate pool at the nominal model, scaled as the cell's selection says (the paper:
// SI). Expected-error scaling uses the truth's prior σ (truth.angle_sigma_mrad,
// truth.length_sigma_mm) for robot parameters and plane terms alike.
Eigen::MatrixXd DesignJacobian(const CellContext& c, const ConfigurationSet& pool) {
  const CellSettings& s = c.cell->typed;
  const ParameterSet& ps = c.model->parameters();
  Eigen::VectorXd expected(ps.size());
  for (int k = 0; k < ps.size(); ++k)
    expected[k] = ps.IsAngular(k) ? s.truth_angle_sigma : s.truth_length_sigma;
  return ScaleColumns(IdentificationJacobian(*c.model, pool), s.scaling, expected);
}

ConfigurationSet SamplePool(const CellContext& c, long long trial, const Eigen::VectorXd& truth,
                            SamplingReport* report) {
  const CellSettings& s = c.cell->typed;
  SamplingOptions o;
  o.min_jacobian_singular_value = s.min_singular_value;
  o.true_link_values = truth;
  o.true_plane = c.plane;
  return SampleConfigurations(*c.robot, c.plane, s.pool_size,
                              RandomStream(c.seed, c.pool_stream, static_cast<std::uint64_t>(trial),
                                           RandomPurpose::kPool),
                              o, report);
}

}  // namespace

std::unique_ptr<CellContext> PrepareCell(const Study& study, const Cell& cell) {
  auto c = std::make_unique<CellContext>();
  c->cell = &cell;
  c->seed = study.seed;
  const CellSettings& s = cell.typed;
  const std::string where = study.path + " cell '" + cell.label + "' (" + cell.id + ")";
  try {
    c->robot = std::make_shared<RobotModel>(LoadRobotModel(ResolveRobotPath(s.robot)));
    if (s.plane_from_robot) {
      if (!c->robot->default_plane)
        throw InputError("plane", "the robot file has no plane; give plane: in the study");
      c->plane = *c->robot->default_plane;
    } else {
      c->plane = s.plane;
    }
    ParameterSet ps = MakeParameterSet(*c->robot, s.plane_terms, s.fixed, "identification.fix");
    c->model = std::make_unique<MeasurementModel>(*c->robot, c->plane, ps);
    if (s.select_count < ps.size())
      throw InputError("selection.count",
                       "selecting " + std::to_string(s.select_count) + " configurations for " +
                           std::to_string(ps.size()) + " parameters: need at least as many");
    c->pool_stream = StreamId(cell.settings, {"robot", "robot_file_fnv1a", "plane", "pool", "truth"});
    c->validation_stream = StreamId(cell.settings, {"robot", "robot_file_fnv1a", "validation", "pool"});

    Eigen::VectorXd truth_values, truth_delta;
    if (!s.truth_random) {
      DrawTruth(*c, 0, &truth_values, &truth_delta);
      c->true_values_fixed = truth_values;
      c->true_delta_fixed = truth_delta;
    } else {
      truth_values = c->robot->nominal_values();
    }
    // Pool (sampled against the nominal, and the fixed truth if any) and the design.
    c->pool = SamplePool(*c, 0, s.truth_random ? c->robot->nominal_values() : truth_values,
                         &c->pool_report);
    SamplingOptions vo;
    vo.min_jacobian_singular_value = s.min_singular_value;
    vo.require_beam_hit = false;
    c->validation = SampleConfigurations(
        *c->robot, c->plane, s.validation_size,
        RandomStream(study.seed, c->validation_stream, 0, RandomPurpose::kValidation), vo);

    // Identifiability of the parameter set on the whole pool (the design is checked below).
    IdentifiabilityReport rep = AnalyzeIdentifiability(*c->model, c->pool);
    if (!rep.full_rank()) {
      if (s.fix_dependent) {
        c->fixed_for_rank = rep.suggested_fixed;
        std::vector<std::string> fixed = s.fixed;
        fixed.insert(fixed.end(), rep.suggested_fixed.begin(), rep.suggested_fixed.end());
        c->model = std::make_unique<MeasurementModel>(
            *c->robot, c->plane, MakeParameterSet(*c->robot, s.plane_terms, fixed));
        if (!s.truth_random) DrawTruth(*c, 0, &truth_values, &c->true_delta_fixed);
      } else {
        c->rank_deficient = true;
        c->rank_message = rep.ToString();
      }
    }
    c->parameter_names = c->model->parameters().names;

    const Eigen::MatrixXd G = DesignJacobian(*c, c->pool);
    if (s.selection_redraw) c->pool_design_G = G;
    SelectionResult sel = SelectConfigurations(
        G, s.select_count, s.selection,
        RandomStream(study.seed, c->pool_stream, 0, RandomPurpose::kSelection));
    c->selected = sel.indices;
    c->design = c->pool.Subset(sel.indices);
    // The design's Jacobian at the nominal model: its σ_min, the predicted covariance, and the
    // first linearisation of every trial all come from this one matrix.
    const int n = c->model->num_parameters();
    const Eigen::MatrixXd Gd = IdentificationJacobian(*c->model, c->design);
    const Eigen::MatrixXd GtG = Gd.transpose() * Gd;
    c->design_sigma_min = CriterionScore(GtG, c->design.size(), DesignCriterion::kE);
    const IdentifiabilityReport design_report =
        c->rank_deficient ? IdentifiabilityReport{} : AnalyzeIdentifiability(*c->model, c->design);
    if (!c->rank_deficient && design_report.full_rank()) {
      const Eigen::MatrixXd A = s.repetitions * GtG;
      Eigen::MatrixXd cov = s.sigma * s.sigma * A.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
      c->predicted_std = cov.diagonal().cwiseSqrt();
    } else {
      if (!c->rank_deficient) c->rank_message = design_report.ToString();
      c->rank_deficient = true;
      c->predicted_std = Eigen::VectorXd::Constant(n, std::nan(""));
    }
    // The first linearisation of every trial (the nominal model on the design), once.
    {
      std::vector<BeamMiss> unused;
      ExactReadings(*c->robot, c->robot->nominal_values(), c->plane, c->design,
                    &c->design_nominal.h, &unused);
      c->design_nominal.G = Gd;
      c->design_nominal.Factorize();
    }
    if (!s.truth_random) {
      ExactReadings(*c->robot, c->true_values_fixed, c->plane, c->design, &c->design_true_h,
                    &c->design_true_miss);
      if (s.selection_redraw)
        ExactReadings(*c->robot, c->true_values_fixed, c->plane, c->pool, &c->pool_true_h,
                      &c->pool_true_miss);
      c->validation_true_poses = ToolPoses(*c->robot, c->true_values_fixed, c->validation);
    }
    if (!s.truth_random)
      c->nominal_validation =
          ComparePoses(*c->robot, c->true_values_fixed, c->robot->nominal_values(), c->validation)
              .stats;
  } catch (const InputError& e) {
    throw InputError(where, e.what());
  }
  return c;
}

TrialRecord RunTrial(const CellContext& c, long long trial, TrialWorkspace* ws,
                     TrialDetails* details) {
  const auto start = std::chrono::steady_clock::now();
  const CellSettings& s = c.cell->typed;
  TrialRecord rec;
  rec.cell_id = c.cell->id;
  rec.trial = trial;
  rec.sigma_min = c.design_sigma_min;
  auto finish = [&](TrialStatus status) {
    rec.status = status;
    rec.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return rec;
  };
  Eigen::VectorXd truth_values, truth_delta;
  if (s.truth_random) {
    DrawTruth(c, trial, &truth_values, &truth_delta);
  } else {
    truth_values = c.true_values_fixed;
    truth_delta = c.true_delta_fixed;
  }
  const PoseErrorStats nominal =
      s.truth_random
          ? ComparePoses(*c.robot, truth_values, c.robot->nominal_values(), c.validation).stats
          : c.nominal_validation;
  rec.nominal = Flatten(nominal);
  if (c.rank_deficient) return finish(TrialStatus::kRankDeficient);

  // The design of this trial.
  const ConfigurationSet* design = &c.design;
  const std::vector<int>* slots = &c.selected;
  ConfigurationSet redrawn_design;
  std::vector<int> redrawn_selected;
  if (s.pool_redraw) {
    ConfigurationSet pool;
    try {
      pool = SamplePool(c, trial, truth_values, nullptr);
    } catch (const InputError&) {
      return finish(TrialStatus::kBeamMissed);
    }
    const Eigen::MatrixXd G = DesignJacobian(c, pool);
    SelectionResult sel = SelectConfigurations(
        G, s.select_count, s.selection,
        RandomStream(c.seed, c.pool_stream, static_cast<std::uint64_t>(trial),
                     RandomPurpose::kSelection));
    redrawn_selected = sel.indices;
    redrawn_design = pool.Subset(sel.indices);
    design = &redrawn_design;
    slots = &redrawn_selected;
    Eigen::MatrixXd Gd = IdentificationJacobian(*c.model, redrawn_design);
    rec.sigma_min = CriterionScore(Gd.transpose() * Gd, redrawn_design.size(), DesignCriterion::kE);
  }

  // A new selection from the cell's pool in every trial (e.g. the random baseline).
  if (s.selection_redraw && !s.pool_redraw) {
    SelectionResult sel = SelectConfigurations(
        c.pool_design_G, s.select_count, s.selection,
        RandomStream(c.seed, c.pool_stream, static_cast<std::uint64_t>(trial),
                     RandomPurpose::kSelection));
    redrawn_selected = sel.indices;
    redrawn_design = c.pool.Subset(sel.indices);
    design = &redrawn_design;
    slots = &redrawn_selected;
    Eigen::MatrixXd Gd = IdentificationJacobian(*c.model, redrawn_design);
    rec.sigma_min = CriterionScore(Gd.transpose() * Gd, redrawn_design.size(), DesignCriterion::kE);
  }
  const bool redrawn = s.pool_redraw || s.selection_redraw;
  NoiseModel noise{s.sigma, s.repetitions, /*draw_mean=*/true};
  const RandomStream noise_stream(c.seed, 0, static_cast<std::uint64_t>(trial), RandomPurpose::kNoise);
  int missed;
  if (!s.truth_random && !redrawn) {
    missed = AddNoise(c.design_true_h, c.design_true_miss, *design, noise, noise_stream, &ws->data,
                      nullptr, slots);
  } else if (!s.truth_random && !s.pool_redraw) {  // selection redrawn: the pool's readings
    ws->exact_h.clear();
    ws->exact_miss.clear();
    for (int i : *slots) {
      ws->exact_h.push_back(c.pool_true_h[i]);
      ws->exact_miss.push_back(c.pool_true_miss[i]);
    }
    missed = AddNoise(ws->exact_h, ws->exact_miss, *design, noise, noise_stream, &ws->data, nullptr,
                      slots);
  } else {
    missed = SimulateReadings(*c.robot, truth_values, c.plane, *design, noise, noise_stream,
                              &ws->data, nullptr, nullptr, slots);
  }
  if (missed > 0) return finish(TrialStatus::kBeamMissed);
  ws->weights.assign(ws->data.repetitions.begin(), ws->data.repetitions.end());
  IdentificationOptions options = s.identification;
  const LevenbergMarquardt::Result r =
      ws->solver.Solve(*c.model, ws->data.configs, ws->data.mean_h.data(), ws->weights.data(),
                       options, &ws->e, redrawn ? nullptr : &c.design_nominal);
  rec.iterations = r.iterations;
  const int m = ws->data.size(), n = c.model->num_parameters();
  rec.residual_rms = std::sqrt(2 * r.final_cost / (m * s.repetitions));  // per-config mean residual
  rec.sigma_hat = m > n ? std::sqrt(2 * r.final_cost / (m - n)) : 0.0;
  switch (r.termination) {
    case Termination::kConverged: break;
    case Termination::kRankDeficient: return finish(TrialStatus::kRankDeficient);
    case Termination::kMaxIterations: return finish(TrialStatus::kNotConverged);
    case Termination::kBeamMissed: return finish(TrialStatus::kBeamMissed);
    default: return finish(TrialStatus::kNumericalFailure);
  }
  rec.errors.resize(n);
  for (int k = 0; k < n; ++k) rec.errors[k] = ws->e[k] - truth_delta[k];
  const Eigen::VectorXd identified = c.model->LinkValues(ws->e.data());
  rec.validation = Flatten(
      (s.truth_random ? ComparePoses(*c.robot, truth_values, identified, c.validation)
                      : ComparePoses(*c.robot, c.validation_true_poses, identified, c.validation))
          .stats);
  if (details) {
    const Eigen::VectorXd& nominal_values = c.robot->nominal_values();
    std::vector<double> h_nominal, h_identified;
    std::vector<BeamMiss> unused;
    ExactReadings(*c.robot, nominal_values, c.plane, ws->data.configs, &h_nominal, &unused);
    ExactReadings(*c.robot, identified, c.model->PlaneAt(ws->e.data()), ws->data.configs,
                  &h_identified, &unused);
    details->distance_error_nominal.clear();
    details->distance_error_identified.clear();
    for (int i = 0; i < ws->data.size(); ++i) {
      details->distance_error_nominal.push_back(ws->data.mean_h[i] - h_nominal[i]);
      details->distance_error_identified.push_back(ws->data.mean_h[i] - h_identified[i]);
    }
    details->measurement_nominal = ComparePoses(*c.robot, truth_values, nominal_values, ws->data.configs);
    details->measurement_identified = ComparePoses(*c.robot, truth_values, identified, ws->data.configs);
    details->validation_nominal = ComparePoses(*c.robot, truth_values, nominal_values, c.validation);
    details->validation_identified = ComparePoses(*c.robot, truth_values, identified, c.validation);
  }
  return finish(TrialStatus::kOk);
}

}  // namespace lrcal
