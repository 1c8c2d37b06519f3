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
#include <string>
#include <vector>

#include "lrcal/kinematics/configuration_set.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial.h"

namespace lrcal {

struct CellContext;
struct TrialWorkspace;

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
  const ConfigurationSet& pool() const;
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
