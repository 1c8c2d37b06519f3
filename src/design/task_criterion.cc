#include "lrcal/design/task_criterion.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <utility>

#include "lrcal/identification/pose_accuracy.h"

namespace lrcal {

TaskPoses TaskPosesAt(const MeasurementModel& model, const ConfigurationSet& poses,
                      std::string source) {
  TaskPoses task;
  task.count = poses.size();
  task.source = std::move(source);
  const std::vector<double> zero(model.num_parameters(), 0.0);
  task.position_rows = PositionRows(PoseJacobian(model, zero.data(), poses));
  return task;
}

Eigen::MatrixXd TaskDesignJacobian(const MeasurementModel& model,
                                   const TargetedConfigurations& pool, const TaskPoses& task) {
  return TaskWeightedJacobian(DesignJacobian(model, pool, DesignScaling::kSI, 0, 0),
                              task.position_rows);
}

double TaskRmsPositionPerUnitSigma(const MeasurementModel& model,
                                   const TargetedConfigurations& design, const TaskPoses& task) {
  const Eigen::MatrixXd G = DesignJacobian(model, design, DesignScaling::kSI, 0, 0);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(G.transpose() * G);
  const Eigen::MatrixXd& P = task.position_rows;
  return std::sqrt((P * ldlt.solve(P.transpose())).trace() / task.count);
}

}  // namespace lrcal
