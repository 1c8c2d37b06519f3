// Replaying one recorded trial of a run: the trial recomputed from the run's study with
// everything in it, and checked against the stored record bit for bit (`lrcal trial`).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/io/result_json.h"
#include "lrcal/measurement/targeted_configurations.h"
#include "lrcal/study/trial.h"

namespace lrcal {

struct TrialReplay {
  std::string run_dir, cell_id, cell_label;
  long long trial = 0;
  TrialRecord recomputed;
  std::optional<TrialRecord> stored;  ///< the run's record, if the trial is recorded
  /// Fields of the record that differ from the stored one (empty: identical to the bit;
  /// the trial's wall time is not compared).
  std::vector<std::string> differences;
  std::vector<std::string> parameter_names;
  // What the trial used and found (SI):
  TargetedConfigurations configurations;  ///< the design's configurations, one per reading mean
  std::vector<double> mean_h;             ///< m, the simulated mean readings
  std::vector<int> repetitions;           ///< readings averaged per configuration
  Eigen::VectorXd estimate_delta;         ///< identified errors in the estimate layout
  TrialDetails details;                   ///< residuals and pose errors, nominal and identified
  bool identical() const { return stored.has_value() && differences.empty(); }
  /// `lrcal trial --format json`: the record, the failure's reason, every configuration with its
  /// reading and residuals, the estimate (SI).
  ResultJson ToJson() const;
  /// `lrcal trial`'s text: the trial, its parameter and validation errors (mm, mrad, ppm) and
  /// whether it matches its record.
  std::string ToText() const;
};

/// Replays trial `trial` of the cell `cell` (its id or label) of the run in `run_dir`. The study
/// is re-read from the file the run recorded (manifest study_file) and must have the run's seed,
/// trials and base settings. Throws InputError naming what is wrong (not a run directory, no such
/// cell or trial, a study file that changed since the run).
TrialReplay ReplayTrial(const std::string& run_dir, const std::string& cell, long long trial);

}  // namespace lrcal
