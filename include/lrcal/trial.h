// One Monte-Carlo trial: a pure function of (cell settings, study seed, trial index).
//
// Per cell, once (CellContext): the robot, the plane, the parameter set (checked for
// identifiability, and reduced if the cell says to fix dependent parameters), the candidate pool
// and the validation set (unless redrawn per trial), the selected design and its σ_min, and the
// predicted covariance σ²·(GᵀWG)⁻¹ at the nominal model: the theoretical bound the Monte-Carlo
// spread is compared with.
//
// Per trial (RunTrial): draw the truth (robot file × scale, or random), the pool and selection if
// redrawn, the noise; identify with lrcal's Levenberg–Marquardt; record the parameter errors
// (estimate − truth) and the validation errors of the identified and of the nominal model.
//
// Random streams (random.h): pool and validation draws are keyed by a hash of the settings they
// depend on, so cells that share those settings share the configurations; noise and truth are
// keyed by the trial index only (common random numbers across cells).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/configuration_sampling.h"
#include "lrcal/identification.h"
#include "lrcal/study.h"
#include "lrcal/validation.h"

namespace lrcal {

/// Per-cell prepared data, read-only and shared by all threads.
struct CellContext {
  const Cell* cell = nullptr;
  std::uint64_t seed = 0;
  std::shared_ptr<const RobotModel> robot;
  Plane plane;
  std::unique_ptr<MeasurementModel> model;  ///< the (possibly reduced) parameter set
  std::vector<std::string> fixed_for_rank;  ///< parameters fixed because of rank deficiency
  bool rank_deficient = false;              ///< and not fixed: every trial fails
  std::string rank_message;
  std::uint64_t pool_stream = 0, validation_stream = 0;
  ConfigurationSet pool;             ///< when not redrawn
  SamplingReport pool_report;
  std::vector<int> selected;         ///< pool indices, when the pool is fixed and selection fixed
  double design_sigma_min = 0;       ///< σ_min of G (SI) of the selected design
  ConfigurationSet design;           ///< the selected configurations
  LevenbergMarquardt::Nominal design_nominal;  ///< h and G of the nominal model on the design
  Eigen::MatrixXd pool_design_G;               ///< scaled G of the pool (selection redrawn per trial)
  std::vector<double> pool_true_h;             ///< exact true readings on the pool (fixed truth)
  std::vector<BeamMiss> pool_true_miss;
  std::vector<double> design_true_h;           ///< exact true readings on the design (fixed truth)
  std::vector<BeamMiss> design_true_miss;
  std::vector<Pose<double>> validation_true_poses;  ///< true tool poses (fixed truth)
  ConfigurationSet validation;       ///< when not redrawn (validation is always shared per cell)
  Eigen::VectorXd predicted_std;     ///< √diag σ²(GᵀWG)⁻¹ at nominal (SI), W = repetitions
  Eigen::VectorXd true_delta_fixed;  ///< truth (estimate-vector layout) when the truth is fixed
  Eigen::VectorXd true_values_fixed; ///< true link values when the truth is fixed
  PoseErrorStats nominal_validation; ///< nominal vs truth (fixed truth)
  std::vector<std::string> parameter_names;
};

/// Builds the context of a cell. Throws InputError (naming the study and the cell) when the cell
/// cannot run at all: no pool can be sampled, fewer configurations than parameters, ...
std::unique_ptr<CellContext> PrepareCell(const Study& study, const Cell& cell);

enum class TrialStatus { kOk, kRankDeficient, kNotConverged, kNumericalFailure, kBeamMissed };
const char* TrialStatusName(TrialStatus s);

/// What one trial leaves behind: one row of the trial store.
struct TrialRecord {
  std::string cell_id;
  long long trial = 0;
  TrialStatus status = TrialStatus::kOk;
  int iterations = 0;
  double residual_rms = 0;  ///< m
  double sigma_hat = 0;     ///< m, residual-based per-reading σ
  double sigma_min = 0;     ///< σ_min of the design's G (SI)
  std::vector<double> errors;  ///< estimate − truth per parameter (SI); empty unless ok
  /// Validation of the identified model: rms pos xyz, rms ori xyz, max pos xyz, max ori xyz (SI).
  std::array<double, 12> validation{};
  /// The same for the nominal (uncalibrated) model.
  std::array<double, 12> nominal{};
  double seconds = 0;  ///< wall time of the trial (not part of any table)
};

/// Per-thread scratch space: reused by every trial the thread runs.
struct TrialWorkspace {
  LevenbergMarquardt solver;
  MeasurementSet data;
  Eigen::VectorXd e;
  std::vector<double> weights;
  std::vector<double> exact_h;
  std::vector<BeamMiss> exact_miss;
};

/// One realisation in detail (the paper's figures): per measurement configuration the distance
/// errors, and per measurement and validation configuration the pose errors, of the nominal and
/// the identified model (SI).
struct TrialDetails {
  std::vector<double> distance_error_nominal;     ///< m, h̄ − h_nominal(q)
  std::vector<double> distance_error_identified;  ///< m, h̄ − h_identified(q)
  PoseErrors measurement_nominal, measurement_identified;
  PoseErrors validation_nominal, validation_identified;
};

TrialRecord RunTrial(const CellContext& context, long long trial, TrialWorkspace* workspace,
                     TrialDetails* details = nullptr);

/// Flattens PoseErrorStats into the record's 12-number layout.
std::array<double, 12> Flatten(const PoseErrorStats& s);

}  // namespace lrcal
