#include "lrcal/design/task_criterion.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <utility>

#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/measurement/ranger_measurement.h"

namespace lrcal {

TaskPoses TaskPosesAt(const MeasurementModel& model, const ConfigurationSet& poses,
                      std::string source) {
  TaskPoses task;
  task.count = poses.size();
  task.source = std::move(source);
  const std::vector<double> zero(model.num_parameters(), 0.0);
  task.position_rows = PositionRows(PoseJacobian(model, zero.data(), poses));
  task.names = model.parameters().names;
  return task;
}

Eigen::MatrixXd PositionRowsFor(const TaskPoses& task, const std::vector<std::string>& names) {
  if (names == task.names) return task.position_rows;
  Eigen::MatrixXd P =
      Eigen::MatrixXd::Zero(task.position_rows.rows(), static_cast<Eigen::Index>(names.size()));
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto it = std::find(task.names.begin(), task.names.end(), names[k]);
    if (it != task.names.end())
      P.col(static_cast<Eigen::Index>(k)) = task.position_rows.col(it - task.names.begin());
  }
  return P;
}

Eigen::MatrixXd TaskDesignJacobian(const MeasurementKind& kind, const TargetedConfigurations& pool,
                                   const TaskPoses& task) {
  return TaskWeightedJacobian(DesignJacobian(kind, pool, DesignScaling::kSI, 0, 0),
                              PositionRowsFor(task, kind.parameter_names()));
}

Eigen::MatrixXd TaskDesignJacobian(const MeasurementModel& model,
                                   const TargetedConfigurations& pool, const TaskPoses& task) {
  return TaskDesignJacobian(RangerMeasurement(model), pool, task);
}

double TaskRmsPositionPerUnitSigma(const MeasurementKind& kind,
                                   const TargetedConfigurations& design, const TaskPoses& task) {
  const Eigen::MatrixXd G = DesignJacobian(kind, design, DesignScaling::kSI, 0, 0);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(G.transpose() * G);
  const Eigen::MatrixXd P = PositionRowsFor(task, kind.parameter_names());
  return std::sqrt((P * ldlt.solve(P.transpose())).trace() / task.count);
}

double TaskRmsPositionPerUnitSigma(const MeasurementModel& model,
                                   const TargetedConfigurations& design, const TaskPoses& task) {
  return TaskRmsPositionPerUnitSigma(RangerMeasurement(model), design, task);
}

}  // namespace lrcal
