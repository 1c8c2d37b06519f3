// The accuracy planner, `lrcal plan-accuracy` and Python's lrcal.plan_accuracy(): the cheapest
// campaign (configurations × readings per configuration, and which candidate planes) that meets
// an accuracy target with a stated confidence, found with the first-order prediction and
// confirmed by Monte Carlo.
//
// The set-up is a study file's base settings (robot, plane, truth, noise σ per reading, pool,
// selection method and criterion, validation set); its sweep is ignored. The target is on the
// distribution over calibrations of the largest per-axis validation metric (e.g. rms_pos: the
// largest of the RMS position errors along x, y, z over the validation poses): its quantile at the
// confidence must not exceed the target.
//
// Search: for each number of configurations k the study's selection chooses the design; the
// first-order prediction (PreparedCell::LinearisedValidationDraws, 4000 draws) at R readings per
// configuration gives the quantile q(k, R) of the data part (the estimate's covariance at R
// readings; q₁(k)/√R without priors), of the held terms' part (every term the calibration holds
// at nominal at its tolerance: identification.prior_sigma, else the robot file's tolerances,
// else lrcal's stated defaults) and of their total. The fewest readings R(k) are the first R of
// the range whose quantile of the plan's basis (plan_on: total by default) is at most the target,
// found by bisection (the quantile falls as R grows; the held terms' part does not fall with R,
// so a target below it is out of reach). Cost: k·(configuration cost) + k·R·(reading cost)
// (+ planes·(plane cost)). Confirmation: the cheapest campaign, the next cheaper one (one reading
// fewer per configuration) and the runner-ups are run as an ordinary study (a file in the plan's
// folder, rerunnable with another seed). The Monte Carlo simulates the study's truth: the held
// terms count there only as far as that truth moves them.
//
// Candidate planes: when the study's plane is a list of two or more, every subset of them (with
// a number of planes in `planes`) is searched like the whole set-up, each with its own pool drawn
// for its planes; the confirmation study then sweeps the plane lists and pools too.
//
// It lives in the report layer because it runs studies and writes their tables, as `lrcal run`
// does (run_tables.h).
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/core/json.h"
#include "lrcal/core/settings.h"
#include "lrcal/core/text_table.h"
#include "lrcal/identification/total_accuracy.h"
#include "lrcal/io/result_json.h"
#include "lrcal/kinematics/validation_metric.h"
#include "lrcal/study/study.h"

namespace lrcal {

/// The accuracy a plan must reach: a validation metric's worst axis at most `value`.
struct AccuracyTarget {
  ValidationMetric metric = ValidationMetric::kRmsPosition;
  double value = 0;  ///< SI (m or rad)

  /// "rms_pos=0.05mm", "rms_ori=0.1mrad" (the unit is required). Throws SettingError (`target`).
  static AccuracyTarget Parse(const std::string& text);
  const char* name() const { return NameOf(kValidationMetricNames, metric); }
  std::string unit() const { return TableUnit(metric); }
  double shown() const { return value * 1e3; }  ///< in unit()
  /// The index of the metric's x component in TrialRecord::validation.
  int first() const { return 3 * static_cast<int>(metric); }
};

/// What a plan's target is held against: the first-order total (the reading noise's part plus
/// every term the calibration holds at nominal, at its tolerance) or the reading noise's part
/// alone (the estimated parameters' covariance).
enum class PlanBasis { kTotal, kData };
inline constexpr EnumName<PlanBasis> kPlanBasisNames[] = {{PlanBasis::kTotal, "total"},
                                                          {PlanBasis::kData, "data"}};

/// "total" or "data". Throws SettingError (`plan_on`).
PlanBasis ParsePlanBasis(const std::string& text);

/// What a campaign costs, in seconds.
struct CampaignCosts {
  double per_configuration = 30;  ///< s, one move to a configuration
  double per_reading = 1;         ///< s, one reading
  double per_plane = 0;           ///< s, setting one plane up
  /// "configuration=30s,reading=1s[,plane=600s]". Throws SettingError (`cost`).
  static CampaignCosts Parse(const std::string& text);
  /// The text Parse reads back: "configuration=30s,reading=1s" (plane= when per_plane > 0).
  std::string ToString() const;
};

/// The planner's settings (see the file comment).
struct AccuracyPlanOptions {
  AccuracyTarget target;
  double confidence = 0.95;  ///< share of calibrations that must meet the target, in (0, 1)
  CampaignCosts cost;
  /// FIRST:LAST[:STEP] configurations to consider; empty: parameters+1 to the pool size, step 5.
  std::string configurations;
  std::string repetitions = "1:100";  ///< FIRST:LAST[:STEP] readings per configuration
  /// FIRST:LAST candidate planes a campaign may use (the study's plane a list of two or more);
  /// empty: 1 to all.
  std::string planes;
  int trials = 10000;         ///< Monte-Carlo trials per confirmed campaign, 100 to 10,000,000
  double stop_precision = 0;  ///< 0, or stop a campaign at this relative precision, in (0, 1)
  std::optional<std::uint64_t> seed;  ///< of the confirmation runs; none: the study's
  /// The plan's folder (its settings in plan.json; a folder holding another plan's settings is
  /// refused). Empty: output/STUDY-plan-HASH, STUDY the study's name and HASH 8 hex digits of
  /// the settings, so that another seed, cost or target gets a folder of its own.
  std::string out_dir;
  int threads = 0;  ///< 0: all cores
  /// The total by default: a plan on the data part alone promises what the held terms (a plane
  /// or a ranger offset taken as known) may not allow.
  PlanBasis plan_on = PlanBasis::kTotal;

  /// Every setting's name at the interfaces (target, confidence, cost, configurations,
  /// repetitions, planes, trials, stop_precision, seed, out, plan_on), for SettingError.
  static const std::vector<SettingSpec>& Settings();
  /// The numeric ones bound to their members, their defaults this struct's: confidence (a share
  /// in (0, 1)), trials (100 to 10,000,000), stop_precision ([0, 1): 0 runs every trial). The
  /// command line and Python take their options and defaults from it.
  static const std::vector<SettingField<AccuracyPlanOptions>>& NumericSettings();
  /// Throws SettingError naming the setting and what was expected.
  void Validate() const;
};

/// Which of the set-up's candidate planes a campaign measures on (all of them when the set-up
/// has no candidates to choose from), with its own pool of candidate configurations.
struct PlaneSubset {
  Json planes;                     ///< the study's plane list for it; null: the set-up's as given
  std::string label;               ///< e.g. "table+wall", empty without candidates
  std::vector<std::string> names;  ///< the planes' names (or 1-based indices)
  std::string pool_file;
  std::vector<int> counts;  ///< configurations to consider
  int num_planes = 1;       ///< planes to set up (for the cost)
};

/// A campaign: predicted, and when confirmed, measured by Monte Carlo.
struct PlannedCampaign {
  int subset = 0;  ///< index into the plan's plane subsets
  int configurations = 0, repetitions = 0;
  double predicted = 0;        ///< SI: the quantile predicted of the plan's basis (plan_on)
  double predicted_data = 0;   ///< SI: the quantile of the reading noise's part alone
  double predicted_total = 0;  ///< SI: the quantile of the total
  double cost = 0;             ///< seconds
  double mc = NAN, mc_low = NAN, mc_high = NAN;  ///< SI: the quantile and its 95 % interval
  long long trials = 0;
  std::string label;  ///< "chosen", "one reading fewer", "runner-up 1", ...
};

/// A finished plan.
struct AccuracyPlan {
  AccuracyPlanOptions options;
  Table search_table{{}};  ///< the first-order search, one row per candidate campaign
  std::vector<PlaneSubset> subsets;
  std::vector<PlannedCampaign> campaigns;  ///< the confirmed ones
  /// Held terms that took lrcal's default tolerance, and base and tool terms taken as exact,
  /// over every plane subset (total_accuracy.h).
  std::vector<std::string> defaulted, exact;
  DefaultTolerances defaults;
  /// The chosen campaign's total by source at the validation poses (first order at its
  /// readings: the statement a calibration of it would make); none when not predicted.
  std::optional<AccuracyPrediction> chosen_statement;
  double search_seconds = 0;
  std::string study_path;  ///< the confirmation study
  std::string run_dir;     ///< its run

  /// "yes" (the quantile's whole 95 % interval at or below the target), "no" (wholly above),
  /// "undecided (...)" or "—" (no trials).
  std::string Meets(const PlannedCampaign& c) const;
  /// The search table, the campaigns table and where the study and run are.
  std::string ToText() const;
  ResultJson ToJson() const;
};

/// Plans for `study`'s set-up. Throws SettingError (a setting, or a target no campaign in the
/// ranges reaches), InputError (the study) or StorageError.
AccuracyPlan PlanAccuracy(const Study& study, const AccuracyPlanOptions& options);

}  // namespace lrcal
