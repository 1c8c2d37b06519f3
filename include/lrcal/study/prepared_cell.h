// A study cell prepared for its trials, and its trials run one at a time: the public face of the
// trial pipeline (src/study/trial_pipeline.h), for the report, the accuracy planner and any
// program that wants one trial of a study in detail.
//
// Preparing a cell loads its rig, builds its parameter set, draws its candidate pool and its
// validation poses, checks identifiability, selects its design and predicts its covariance at the
// nominal model. A trial is then a pure function of (cell settings, study seed, trial index):
// Run(t) gives the same record, bit for bit, as the runner stored for trial t.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/identification/total_accuracy.h"
#include "lrcal/measurement/targeted_configurations.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial.h"

namespace lrcal {

struct CellContext;
struct TrialWorkspace;

/// A cell's first-order draws of the validation metrics (draws × 12 each, the layout of
/// TrialRecord::validation, SI), by part: the reading noise's (the estimate's covariance: the data
/// part), the held terms' (every term the calibration holds at nominal, each at its tolerance:
/// the identification's prior_sigma, else the robot file's tolerances, else lrcal's stated
/// defaults) and their sum, the total (identification/total_accuracy.h). Draw d of each part
/// comes from the same normals.
struct FirstOrderDraws {
  Eigen::MatrixXd data, held, total;
};

class PreparedCell {
 public:
  /// Prepares `cell` of `study`. Throws InputError (naming the study and the cell) when the cell
  /// cannot run at all: no pool can be sampled, fewer configurations than parameters, ...
  static PreparedCell Prepare(const Study& study, const Cell& cell);

  PreparedCell(PreparedCell&&) noexcept;
  PreparedCell& operator=(PreparedCell&&) noexcept;
  ~PreparedCell();

  /// The candidate pool the design is selected from, and the validation poses every trial is
  /// judged on (rad).
  const TargetedConfigurations& pool() const;
  const ConfigurationSet& validation() const;
  /// The estimated parameters after any fixed for rank deficiency, and their names.
  int num_parameters() const;
  const std::vector<std::string>& parameter_names() const;
  /// The number of target planes of the cell's set-up.
  int num_planes() const;

  /// `draws` Gaussian parameter-error draws from the cell's predicted covariance pushed through
  /// the validation poses' Jacobian (first order): draws × 12 validation metrics in the layout of
  /// TrialRecord::validation (SI); NaN when the covariance cannot be predicted.
  Eigen::MatrixXd LinearisedValidationDraws(int draws) const;
  /// The same at `repetitions` readings per configuration of the cell's design (the covariance
  /// and the held terms' estimate shift computed for them: exact with priors and any averaging),
  /// by part: the data part's draws equal the call above at the cell's own readings; the held
  /// terms' part is, per draw, M·w (HeldTermPoseColumns, w ~ N(0, I)); the total their sum. The
  /// draws use common random numbers across `repetitions`, so the metrics vary smoothly with it.
  /// NaN when the covariance cannot be predicted. Throws InputError for repetitions < 1.
  FirstOrderDraws LinearisedValidationDraws(int draws, int repetitions) const;
  /// The total statement a calibration of this cell's design with `repetitions` readings per
  /// configuration would make at the validation poses, at the nominal model (its sources,
  /// defaulted and exact terms); none when the covariance cannot be predicted.
  std::optional<AccuracyPrediction> StatedValidationAccuracy(int repetitions) const;

  /// Runs trial `trial` (and fills `details` with the realisation, if given). Safe to call from
  /// several threads at once; each call has its own scratch space.
  TrialRecord Run(long long trial, TrialDetails* details = nullptr) const;

  /// The pipeline's own view (private to lrcal's sources: src/study/trial_pipeline.h).
  const CellContext& context() const { return *context_; }

 private:
  explicit PreparedCell(std::unique_ptr<CellContext> context);
  std::unique_ptr<CellContext> context_;
};

}  // namespace lrcal
