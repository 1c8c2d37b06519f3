// What one Monte-Carlo trial leaves behind (a row of the trial store) and, for the report, one
// realisation in detail. How a trial is computed: src/study/trial_pipeline.h.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "lrcal/core/enum_names.h"
#include "lrcal/kinematics/pose_errors.h"

namespace lrcal {

enum class TrialStatus { kOk, kRankDeficient, kNotConverged, kNumericalFailure, kBeamMissed };
inline constexpr EnumName<TrialStatus> kTrialStatusNames[] = {
    {TrialStatus::kOk, "ok"},
    {TrialStatus::kRankDeficient, "rank_deficient"},
    {TrialStatus::kNotConverged, "not_converged"},
    {TrialStatus::kNumericalFailure, "numerical_failure"},
    {TrialStatus::kBeamMissed, "beam_missed"}};
inline const char* TrialStatusName(TrialStatus s) { return NameOf(kTrialStatusNames, s); }
/// Why a trial ends with status `s`, in words ("" for kOk).
const char* TrialStatusReason(TrialStatus s);

/// What one trial leaves behind: one row of the trial store.
struct TrialRecord {
  std::string cell_id;
  long long trial = 0;
  TrialStatus status = TrialStatus::kOk;
  int iterations = 0;
  double residual_rms = 0;     ///< m
  double sigma_hat = 0;        ///< m, residual-based per-reading σ
  double sigma_min = 0;        ///< σ_min of the design's G (SI)
  std::vector<double> errors;  ///< estimate − truth per parameter (SI); empty unless ok
  /// Validation of the identified model: rms pos xyz, rms ori xyz, max pos xyz, max ori xyz (SI).
  std::array<double, 12> validation{};
  /// The same for the nominal (uncalibrated) model.
  std::array<double, 12> nominal{};
  double seconds = 0;  ///< wall time of the trial (not part of any table)
  /// Configurations of the design whose true beam missed its plane: they have no reading and are
  /// left out of the fit (the trial fails as beam_missed only when fewer readings than
  /// parameters remain).
  int missed_configurations = 0;
  /// validation.coverage: the share of the validation poses whose true position error lies
  /// within the cell's stated 95 % radius, the data part (`coverage`) and the total with the
  /// terms the calibration holds at nominal (`coverage_total`; total_accuracy.h). NaN unless
  /// the cell asks for it and the trial identified.
  double coverage = std::numeric_limits<double>::quiet_NaN();
  double coverage_total = std::numeric_limits<double>::quiet_NaN();
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

/// Flattens PoseErrorStats into the record's 12-number layout.
std::array<double, 12> Flatten(const PoseErrorStats& s);

}  // namespace lrcal
