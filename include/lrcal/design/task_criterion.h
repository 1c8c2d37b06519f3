// Criterion I, the task criterion: choose the configurations whose calibration predicts the
// smallest mean-square position error at the poses where the arm will work.
//
// With C = σ²(GᵀG)⁻¹ the estimate's covariance (SI) and P (3M×n) the position rows of
// ∂(pose)/∂e at the M task poses, the summed mean-square position error there is σ²·tr(PᵀP·C/σ²):
// criterion A on the task-weighted G (TaskWeightedJacobian) minimises it. The study's
// `selection.criterion: I` weights by its validation poses, `lrcal design --criterion I` by
// --poses or --workspace poses; both go through this header.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/design/experiment_design.h"
#include "lrcal/measurement/measurement_model.h"

namespace lrcal {

/// The poses criterion I weighs by, with the position rows of the pose Jacobian at them.
struct TaskPoses {
  int count = 0;                  ///< M; 0: no task (another criterion)
  std::string source;             ///< where they come from: a file name, "workspace", "validation"
  Eigen::MatrixXd position_rows;  ///< 3M × n: rows 3j..3j+2 are ∂(position of pose j)/∂e (m/unit)
  std::vector<std::string> names;  ///< the term of each column of position_rows
};

/// The task's position rows laid out for the terms `names` (a measurement kind's): a term's
/// column where the task has it, zero for a term the task does not know (a sensor's own term,
/// which moves no tool pose).
Eigen::MatrixXd PositionRowsFor(const TaskPoses& task, const std::vector<std::string>& names);

/// The task of `poses` for `model` at its nominal parameters (e = 0), from the shared pose
/// Jacobian (PoseJacobian, pose_accuracy.h).
TaskPoses TaskPosesAt(const MeasurementModel& model, const ConfigurationSet& poses,
                      std::string source);

/// Criterion I's selection matrix for `pool`: the pool's Jacobian of `kind` at its nominal
/// terms (SI) weighted by the task (TaskWeightedJacobian, PositionRowsFor the kind's terms);
/// criterion A on it is criterion I.
Eigen::MatrixXd TaskDesignJacobian(const MeasurementKind& kind, const TargetedConfigurations& pool,
                                   const TaskPoses& task);
/// The ranger's: TaskDesignJacobian of RangerMeasurement(model).
Eigen::MatrixXd TaskDesignJacobian(const MeasurementModel& model,
                                   const TargetedConfigurations& pool, const TaskPoses& task);

/// What criterion I predicts for the configurations `design`: √(tr(PᵀP·(GᵀG)⁻¹)/M), the RMS
/// position error at the task poses (m) per 1 m of reading noise σ (equally mm per mm), from G of
/// `design` directly (no ridge; the selection score loses ~1e-6 to its conditioning).
double TaskRmsPositionPerUnitSigma(const MeasurementKind& kind,
                                   const TargetedConfigurations& design, const TaskPoses& task);
double TaskRmsPositionPerUnitSigma(const MeasurementModel& model,
                                   const TargetedConfigurations& design, const TaskPoses& task);

}  // namespace lrcal
