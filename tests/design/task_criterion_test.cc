// Criterion I: the task poses' rows come from the shared pose Jacobian, the selection matrix makes
// criterion A equal the summed predicted mean-square position error, and the stated prediction
// equals an independent computation.
#include "lrcal/design/task_criterion.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/LU>

#include "lrcal/design/configuration_sampling.h"
#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/measurement/parameter_set.h"
#include "test_util.h"

namespace lrcal {
namespace {

MeasurementModel PaperModel() {
  return MeasurementModel(testing::PaperRobot(), testing::PaperPlane(),
                          MakeParameterSet(testing::PaperRobot(), PlaneTerms{}));
}

TEST(TaskCriterion, PositionRowsAreThoseOfThePoseJacobianAtNominal) {
  const MeasurementModel model = PaperModel();
  const ConfigurationSet poses = WorkspacePoses(model.robot(), 7, 3);
  const TaskPoses task = TaskPosesAt(model, poses, "test");
  EXPECT_EQ(task.count, 7);
  EXPECT_EQ(task.source, "test");
  const std::vector<double> zero(model.num_parameters(), 0.0);
  const Eigen::MatrixXd J = PoseJacobian(model, zero.data(), poses);
  ASSERT_EQ(task.position_rows.rows(), 21);
  for (int j = 0; j < 7; ++j)
    EXPECT_THAT(Eigen::MatrixXd(task.position_rows.middleRows(3 * j, 3)),
                testing::EigenNear(Eigen::MatrixXd(J.middleRows(6 * j, 3)), 0.0));
}

TEST(TaskCriterion, AOnTheWeightedJacobianIsTheSummedMeanSquarePositionError) {
  const MeasurementModel model = PaperModel();
  const TargetedConfigurations pool =
      testing::ConfigurationsFacing(model.robot(), testing::PaperPlane(), 60, /*seed=*/5);
  const TaskPoses task = TaskPosesAt(model, WorkspacePoses(model.robot(), 20, 1), "workspace");
  const Eigen::MatrixXd Gt = TaskDesignJacobian(model, pool, task);
  // Independently: tr(W (GᵀG)⁻¹) with an explicit inverse, W = PᵀP plus the selection matrix's
  // ridge (1e-9·tr W/n on the diagonal, which keeps W invertible). The score comes from the
  // eigenvalues of the task-weighted normal matrix, whose conditioning costs it ~5e-6 relative
  // (the reason TaskRmsPositionPerUnitSigma computes the prediction directly).
  constexpr double kScoreConditioning = 2e-5;
  const Eigen::MatrixXd G = DesignJacobian(model, pool, DesignScaling::kSI, 0, 0);
  const Eigen::MatrixXd& P = task.position_rows;
  const Eigen::MatrixXd C = (G.transpose() * G).inverse();
  Eigen::MatrixXd W = P.transpose() * P;
  const double summed = (W * C).trace();
  W.diagonal().array() += 1e-9 * W.trace() / W.rows();
  const double a = CriterionScore(Gt.transpose() * Gt, pool.size(), DesignCriterion::kA);
  EXPECT_NEAR(-a, (W * C).trace(), kScoreConditioning * summed);
  EXPECT_NEAR(TaskRmsPositionPerUnitSigma(model, pool, task), std::sqrt(summed / task.count),
              1e-9 * std::sqrt(summed / task.count));
}

}  // namespace
}  // namespace lrcal
