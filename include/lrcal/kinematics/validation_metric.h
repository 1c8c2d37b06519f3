// The validation metrics of a model against the truth over a set of validation poses: the RMS and
// the largest position and orientation errors, each per axis of the base frame (pose_errors.h).
// One name list for the tables, the trial store's columns, study keys (sensitivity.metric),
// accuracy targets (plan-accuracy --target) and what Python's load_run reads.
#pragma once

#include "lrcal/core/enum_names.h"

namespace lrcal {

enum class ValidationMetric { kRmsPosition, kRmsOrientation, kMaxPosition, kMaxOrientation };
inline constexpr EnumName<ValidationMetric> kValidationMetricNames[] = {
    {ValidationMetric::kRmsPosition, "rms_pos"},
    {ValidationMetric::kRmsOrientation, "rms_ori"},
    {ValidationMetric::kMaxPosition, "max_pos"},
    {ValidationMetric::kMaxOrientation, "max_ori"}};
inline constexpr int kNumValidationMetrics = 4;
/// The axes of the base frame each metric is given for.
inline constexpr const char* kAxisNames[3] = {"x", "y", "z"};
/// The metrics × axes, metric-major: the layout of TrialRecord::validation and of the store's
/// columns (rms_pos_x, rms_pos_y, ..., max_ori_z).
inline constexpr int kNumValidationColumns = 3 * kNumValidationMetrics;

/// Orientation metrics are angles (rad inside, mrad in tables); position metrics are lengths
/// (m inside, mm in tables).
constexpr bool IsAngular(ValidationMetric m) {
  return m == ValidationMetric::kRmsOrientation || m == ValidationMetric::kMaxOrientation;
}
/// The unit of the metric in tables: "mrad" or "mm".
constexpr const char* TableUnit(ValidationMetric m) { return IsAngular(m) ? "mrad" : "mm"; }
/// The metric of column k (0 ≤ k < kNumValidationColumns).
constexpr ValidationMetric MetricOfColumn(int k) { return static_cast<ValidationMetric>(k / 3); }
/// Column k's name: the metric's name and the axis, "rms_pos_x" ... "max_ori_z".
const char* ValidationColumnName(int k);

}  // namespace lrcal
