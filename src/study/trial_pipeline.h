// One Monte-Carlo trial: a pure function of (cell settings, study seed, trial index), computed as
// a pipeline of small named steps (trial.cc).
//
// Per cell, once (PrepareCell → CellContext): load the rig (robot, plane, ranger); build the
// parameter set; draw the candidate pool and the validation set; check identifiability on the
// pool (and fix the suggested parameters if the cell says so); select the design and take its
// σ_min; predict the covariance σ²·(GᵀWG)⁻¹ at the nominal model (the bound the Monte-Carlo
// spread is compared with); cache the nominal linearisation and, for a fixed truth, the true
// readings and poses.
//
// Per trial (RunTrial): the truth of the trial; its design (redrawn if the cell says so); the
// noisy readings; the identification (lrcal's Levenberg–Marquardt, or Ceres if the cell says
// so); the record: parameter errors (estimate − truth) and the validation errors of the
// identified and of the nominal model.
//
// Random streams (core/random.h): pool and validation draws are keyed by a hash of the settings
// they depend on, so cells that share those settings share the configurations; noise and truth
// are keyed by the trial index only (common random numbers across cells).
//
// Private to src/: the runner, `lrcal report` and `lrcal plan` use it; tests and benchmarks too.
#pragma once

#include <Eigen/Eigenvalues>
#include <array>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "identification/levenberg_marquardt.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/identification/identification.h"
#include "lrcal/identification/prior.h"
#include "lrcal/identification/total_accuracy.h"
#include "lrcal/io/urdf.h"
#include "lrcal/kinematics/pose_errors.h"
#include "lrcal/measurement/chain_measurement.h"
#include "lrcal/measurement/contact_measurement.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/study/prepared_cell.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial.h"
#include "lrcal/study/trial_store.h"

namespace lrcal {

/// The truth of one trial.
struct TrialTruth {
  Eigen::VectorXd errors;  ///< errors of the 5N link values (SI)
  Eigen::VectorXd values;  ///< nominal + errors
  Eigen::VectorXd delta;   ///< the errors in the estimate layout (robot deltas; plane terms 0)
  /// A tree cell: every term's error in the layout of TreeCell::full (each chain's arm, shared
  /// links once); `errors` and `values` are then the judged chain's arm.
  Eigen::VectorXd tree_delta;
};

/// A tree cell (tool_link with several links; tree_trial.cc): every chain measured by the one
/// tracker at each whole-robot configuration, the chains' common joints' terms shared. The
/// cell's robot (CellContext::robot) is the judged chain's arm: the validation's poses, its
/// records and its prediction are that tool's.
struct TreeCell {
  UrdfChains tree;
  std::vector<std::shared_ptr<const ChainMeasurement>> chains;
  std::unique_ptr<MeasurementKind> full;  ///< every term: the truth's layout
  int judged = 0;                         ///< the chain whose tool the validation judges
  std::vector<double> truth_sigma;        ///< per term of `full`: its true error's σ (0: nominal)
  std::vector<int> judged_value;          ///< per term of `full`: the judged arm's value, or -1
  std::vector<int> estimated;             ///< per term of CellContext::kind: its index in `full`
};

/// The validation metrics (draws × 12, layout of TrialRecord::validation, SI) of `draws`
/// Gaussian parameter-error draws from the cell's predicted covariance pushed through the
/// validation poses' Jacobian (first order): what the prediction of the means averages, and the
/// planner's distribution of any validation statistic. NaN when there is no prediction.
struct CellContext;
Eigen::MatrixXd LinearisedValidationDraws(const CellContext& c, int draws);
/// The same at `repetitions` readings per configuration of the cell's design (its covariance and
/// its held terms recomputed for them), each part (prepared_cell.h).
FirstOrderDraws LinearisedValidationDraws(const CellContext& c, int draws, int repetitions);
/// The total statement at the validation poses, at the nominal model, for `repetitions`
/// readings per configuration of the design; none when the covariance is undefined.
std::optional<AccuracyPrediction> StatedValidationAccuracy(const CellContext& c, int repetitions);

/// A design: configurations and their slots in the pool (which address the noise).
struct TrialDesign {
  TargetedConfigurations configs;
  std::vector<int> slots;
  double sigma_min = 0;  ///< σ_min of the design's G (SI)
};

/// Per-cell prepared data, read-only and shared by all threads.
struct CellContext {
  const Cell* cell = nullptr;
  /// Prepared for its trials alone (CellPreparation::kForTrials): what only the cell's stored
  /// row holds (design_efficiency, predicted_validation) is not computed (NaN), and
  /// ToStoredCell refuses the context.
  bool for_trials_only = false;
  std::uint64_t seed = 0;
  /// The seed of the selection's random draws: the study's, or 0 when the pool comes from a
  /// file (the design then does not change with the seed).
  std::uint64_t selection_seed = 0;
  std::shared_ptr<const RobotModel> robot;
  PlaneSet planes;
  RangerSpec ranger;  ///< the robot file's ranger limits
  /// The robot file's true link errors (5N, SI): a robot_file truth's, × truth.scale.
  Eigen::VectorXd file_true_errors;
  /// The true ranger's errors (robot file × truth.scale for a robot_file truth): it reads
  /// (1 + ranger_scale)·h + ranger_offset (m).
  double ranger_offset = 0, ranger_scale = 0;
  std::unique_ptr<MeasurementModel> model;  ///< the (possibly reduced) parameter set
  std::vector<std::string> fixed_for_rank;  ///< parameters fixed because of rank deficiency
  bool rank_deficient = false;              ///< and not fixed: every trial fails
  std::string rank_message;
  std::uint64_t pool_stream = 0, validation_stream = 0;
  TargetedConfigurations pool;  ///< the cell's pool (a trial may redraw its own)
  SamplingReport pool_report;
  TrialDesign design;                          ///< the cell's selected design
  LevenbergMarquardt::Nominal design_nominal;  ///< h and G of the nominal model on the design
  Eigen::MatrixXd pool_design_G;    ///< scaled G of the pool (selection redrawn per trial)
  std::vector<double> pool_true_h;  ///< exact true readings on the pool (fixed truth)
  std::vector<BeamMiss> pool_true_miss;
  std::vector<double> design_true_h;  ///< exact true readings on the design (fixed truth)
  std::vector<BeamMiss> design_true_miss;
  std::vector<Pose<double>> validation_true_poses;  ///< true tool poses (fixed truth)
  /// The nominal arm's tool poses at `validation` (a drawn truth: every trial compares them).
  std::vector<Pose<double>> validation_nominal_poses;
  TargetedConfigurations validation;  ///< shared by every trial of the cell
  Eigen::VectorXd predicted_std;  ///< √diag σ²(GᵀWG)⁻¹ at nominal (SI), W = repetitions
  /// The same with G at the true parameters: the Cramér–Rao bound of the simulated experiment
  /// (fixed truth and design; empty otherwise).
  Eigen::VectorXd predicted_std_truth;
  /// The design's certified efficiency (design_certificate.h: share of the relaxation's upper
  /// bound on the criterion that the chosen design reaches); NaN when the criterion has no
  /// certificate or the design is redrawn per trial.
  double design_efficiency = 0;
  /// σ²·(GᵀWG)⁻¹ of the cell's design at the nominal model (SI; empty if rank deficient).
  Eigen::MatrixXd predicted_covariance;
  /// predicted_covariance as covariance_scale² · unit_covariance, bit for bit: (GᵀWG)⁻¹ and σ
  /// for least squares, a posterior's covariance and 1 with priors. The first-order draws take
  /// the factor of unit_covariance and scale it, so cells that differ only in σ (a noise sweep,
  /// a sensitivity plan) share them (SetPredictedCovariance).
  Eigen::MatrixXd unit_covariance;
  double covariance_scale = 1;
  /// First-order prediction of the mean of each validation metric of the identified model
  /// (layout of TrialRecord::validation, SI); NaN where the covariance cannot be predicted.
  std::array<double, 12> predicted_validation{};
  /// validation.coverage: the 95 % position radius stated at each validation pose (m; the data
  /// part from predicted_covariance, the total with the held terms: total_accuracy.h). Empty
  /// unless the cell asks for coverage.
  std::vector<double> coverage_radius, coverage_radius_total;
  /// The robot file's `tolerances:` (robot_file.h), its planes' only when the cell's planes are
  /// the file's: the held terms' σ in the stated total, as `identify` uses them.
  PriorSigmas tolerances;
  /// A cell of another sensor than the ranger (tracker_trial.cc): its kind on the nominal arm
  /// with every term but identification.fix (the truth's template), the kind estimated (after
  /// any terms fixed for rank), and per estimated term its link value index (-1: a term of the
  /// sensor: its instrument, target, scanner frame, plane or socket). `model` then holds the
  /// arm's link terms only (the validation poses' Jacobian). Null for the ranger.
  std::unique_ptr<MeasurementKind> sensor_kind;
  std::unique_ptr<MeasurementKind> kind;
  std::vector<int> kind_link_values;
  /// The kind seats its configurations (contact, socket): a trial's are where the true arm
  /// seated from the design, its own; there is no nominal linearisation to share.
  bool seated = false;
  /// A fixed truth: the true arm and the sensor on it.
  std::shared_ptr<const RobotModel> true_robot;
  /// A ranger cell in an environment (CellSettings::in_environment): the calibration's
  /// non-geometric model (the robot file's masses, defaults and, when estimated, its thermal
  /// coefficients; stiff) and the simulated arm's (the robot file's true compliance and thermal
  /// coefficients). The sensor kinds are EnvironmentMeasurements around the full ranger.
  bool environment = false;
  NonGeometricModel model_non_geometric{}, true_non_geometric{};
  std::unique_ptr<MeasurementKind> true_kind;
  /// The fixed truth's exact values at the design and why none misses ("ok"): each trial adds
  /// its noise (AddMeasurementNoise).
  std::vector<double> design_true_values;
  std::vector<std::string> design_true_reasons;
  TrialTruth fixed_truth;             ///< when the truth is fixed (robot file × scale)
  PoseErrorStats nominal_validation;  ///< nominal vs truth (fixed truth)
  std::vector<std::string> parameter_names;
  /// A tree cell's chains (null otherwise); `kind` is then their TreeMeasurement, reduced.
  std::unique_ptr<TreeCell> tree;
};

// Steps of trial.cc that the tracker cells' pipeline (tracker_trial.cc) shares.

/// The stream id of a draw family: a hash of the settings `keys` it depends on.
std::uint64_t StreamId(const Json& settings, std::initializer_list<const char*> keys);
/// The validation set's stream: a function of the robot, the validation and the pool settings
/// only, so that cells of every sensor (and noise, selection, ...) judge on the same poses.
std::uint64_t ValidationStreamId(const Json& settings);
/// The truth of trial `trial`: the robot file's errors × scale, or errors drawn per trial.
TrialTruth DrawTruth(const CellContext& c, long long trial);
/// `total` configurations split over the planes by the cell's shares (largest remainders, ties
/// to the earlier plane): every plane gets its part and the parts add up to `total`.
std::vector<int> PerPlaneCounts(const CellSettings& s, const PlaneSet& planes, int total);
/// Each plane's estimated terms: identification.estimate_plane, or the plane's own entry.
std::vector<PlaneTerms> CellPlaneTerms(const CellSettings& s, int num_planes);
/// A study's configuration file (pool.file, validation.file) read for the cell's robot;
/// `planes`: a pool's plane column resolved against them (null: configurations only).
TargetedConfigurations ReadStudyConfigurations(const Study& study, const std::string& file,
                                               const std::string& key, const RobotModel& robot,
                                               const PlaneSet* planes);
/// The first-order prediction of the validation metrics' means (predicted_validation).
void PredictValidation(CellContext* c);
/// Sets predicted_covariance = (scale · scale) · unit (the bits of ParameterCovariance(A, scale)
/// when unit is ParameterCovariance(A, 1)), its parts and predicted_std.
void SetPredictedCovariance(CellContext* c, Eigen::MatrixXd unit, double scale);

/// A tracker cell's preparation after its rig is loaded: the kind, the pool (no beam to hit),
/// the validation poses, identifiability, the block selection (block_selection.h), the
/// predicted covariance and the truth's cache.
void PrepareTrackerCell(const Study& study, const CellSettings& s, CellContext* c);
/// A tree cell's preparation (tree_trial.cc): its chains in place of LoadRig's one arm, then a
/// tracker cell's steps on their TreeMeasurement.
void PrepareTreeCell(const Study& study, const CellSettings& s, CellContext* c);
/// A tree cell's truth: every term of its chains drawn, the judged arm's values from them.
TrialTruth DrawTreeTruth(const CellContext& c, long long trial);
/// A tree cell's noisy values at its design: the chains' exact values at the trial's truth plus
/// `noise` drawn from `stream`.
void SimulateTreeValues(const CellContext& c, const TrialTruth& truth, const NoiseModel& noise,
                        const RandomStream& stream, MeasuredValues* values);
// A tracker cell's steps that a tree cell shares (tracker_trial.cc).
/// Identifiability of c->kind on the pool: the terms it cannot separate fixed (identification
/// on_rank_deficient: fix) or the cell marked rank deficient.
void CheckTrackerIdentifiability(const CellSettings& s, CellContext* c);
/// The design's block selection on c->kind, its σ_min, nominal linearisation and covariance.
void SelectTrackerDesign(const CellSettings& s, CellContext* c);
/// A pool read from pool.file as the cell's (its report: all accepted); InputError (pool.file)
/// when it holds fewer configurations than selection.count.
void AcceptPoolFile(const CellSettings& s, TargetedConfigurations pool, CellContext* c);
/// InputError (selection.count) when the design's values cannot outnumber c->kind's terms.
void CheckValuesForTerms(const CellSettings& s, const CellContext& c);
/// A tracker cell's trial after the truth and the nominal validation are in `rec`.
struct TrialWorkspace;
/// The true tool poses at `configs` of the arm with link values `true_values`: in their
/// environments (compliance, thermal growth) for a cell in one.
std::vector<Pose<double>> TruePoses(const CellContext& c, const Eigen::VectorXd& true_values,
                                    const TargetedConfigurations& configs);
/// `validation_true`: the true tool poses at c.validation (TruePoses at the trial's truth).
TrialStatus RunTrackerTrial(const CellContext& c, long long trial, const TrialTruth& truth,
                            const std::vector<Pose<double>>& validation_true, TrialRecord* rec,
                            TrialDetails* details, TrialWorkspace* ws);
/// The validation poses' Jacobian ∂(pose)/∂e at the nominal model in the cell's estimate layout
/// (6 rows per pose: position, then orientation).
Eigen::MatrixXd ValidationPoseJacobian(const CellContext& c);

/// What a cell is prepared for. kFull: everything, its stored row included. kForTrials: what its
/// trials read, bit for bit as kFull prepares it, without the parts that only its row holds
/// (the design's certificate, the first-order prediction of the validation metrics: about half
/// of a ranger cell's preparation), for a resume whose store already holds the row.
enum class CellPreparation { kFull, kForTrials };

/// Builds the context of a cell. Throws InputError (naming the study and the cell) when the cell
/// cannot run at all: no pool can be sampled, fewer configurations than parameters, ...
std::unique_ptr<CellContext> PrepareCell(const Study& study, const Cell& cell,
                                         CellPreparation what = CellPreparation::kFull);

/// Per-thread scratch space: reused by every trial the thread runs.
struct TrialWorkspace {
  LevenbergMarquardt solver;
  MeasurementSet data;
  Eigen::VectorXd e;
  std::vector<double> weights;
  std::vector<double> exact_h;
  std::vector<BeamMiss> exact_miss;
  /// A tracker cell's evaluator, bound to the design of `evaluator_cell` (rebound when the thread
  /// moves to another cell), and its measured values.
  const CellContext* evaluator_cell = nullptr;
  std::unique_ptr<MeasurementEvaluator> evaluator;
  MeasuredValues values;
};

TrialRecord RunTrial(const CellContext& context, long long trial, TrialWorkspace* workspace,
                     TrialDetails* details = nullptr);

/// What the trial store records of a prepared cell (trial_store.h); std::logic_error for a
/// context prepared for its trials alone.
StoredCell ToStoredCell(const CellContext& context);

}  // namespace lrcal
