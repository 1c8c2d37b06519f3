// The first-order prediction of the validation metrics' means (CellContext::predicted_validation)
// against two independent computations: the same Gaussian parameter errors pushed through the
// exact (non-linear) pose comparison instead of the Jacobian, and the Monte-Carlo means of a
// real study.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <fstream>
#include <list>
#include <random>

#include "lrcal/core/random.h"
#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/kinematics/validation_metric.h"
#include "lrcal/report/run_tables.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/statistics.h"
#include "study/trial_pipeline.h"
#include "test_util.h"

namespace lrcal {
namespace {

std::string PredictionStudy(const std::string& dir, int trials, int validation_poses = 15) {
  const std::string path = dir + "/prediction.yaml";
  std::ofstream(path) << "name: prediction\nseed: 8\ntrials: " << trials
                      << "\nrobot: " << testing::SourcePath("studies/robots/paper.yaml")
                      << "\npool: {size: 60}\nselection: {count: 40}\nvalidation: {size: "
                      << validation_poses << "}\n";
  return path;
}

// Many validation poses are pushed through the Jacobian a block at a time (memory per pose stays
// about 1 KB): the draws have the bits of the whole 6M × draws product, summed pose by pose.
TEST(ValidationPrediction, BlocksOfPosesGiveTheBitsOfTheWholeProduct) {
  const std::string dir = testing::TempDir("prediction_blocks");
  const Study study = LoadStudy(PredictionStudy(dir, 1, 700));
  const auto c = PrepareCell(study, study.cells[0]);
  constexpr int kDraws = 50;
  const Eigen::MatrixXd blocked = LinearisedValidationDraws(*c, kDraws);
  // The whole product, as lrcal computed it before the blocks.
  const int n = c->model->num_parameters(), m = c->validation.size();
  ASSERT_EQ(m, 700);
  // The draws of the unit covariance, scaled by σ (CellContext::unit_covariance).
  ASSERT_EQ(c->predicted_covariance,
            (c->covariance_scale * c->covariance_scale) * c->unit_covariance);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(c->unit_covariance);
  const Eigen::MatrixXd L =
      eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  Eigen::MatrixXd Z(n, kDraws);
  RandomStream(0, c->validation_stream, 0, RandomPurpose::kPrediction)
      .Normals(0, n * kDraws, Z.data());
  const std::vector<double> zero(n, 0.0);
  const Eigen::MatrixXd E = PoseJacobian(*c->model, zero.data(), c->validation) * (L * Z);
  for (int d = 0; d < kDraws; ++d)
    for (int k = 0; k < 6; ++k) {
      double ss = 0, max = 0;
      for (int j = 0; j < m; ++j) {
        ss += E(6 * j + k, d) * E(6 * j + k, d);
        max = std::max(max, std::fabs(E(6 * j + k, d)));
      }
      EXPECT_EQ(blocked(d, k), c->covariance_scale * std::sqrt(ss / m)) << d << " " << k;
      EXPECT_EQ(blocked(d, 6 + k), c->covariance_scale * max) << d << " " << k;
    }
}

TEST(ValidationPrediction, LinearPropagationMatchesTheExactPoseErrorsOfGaussianParameterErrors) {
  const std::string dir = testing::TempDir("prediction_exact");
  const Study study = LoadStudy(PredictionStudy(dir, 1));
  const auto c = PrepareCell(study, study.cells[0]);
  ASSERT_FALSE(std::isnan(c->predicted_validation[0]));
  // Independent: draws of N(0, C) (another generator) through ComparePoses itself.
  const Eigen::MatrixXd L = Eigen::LLT<Eigen::MatrixXd>(c->predicted_covariance).matrixL();
  std::mt19937_64 rng(4);  // test data only
  std::normal_distribution<double> z;
  const int n = c->model->num_parameters(), draws = 4000;
  std::array<double, 12> mean{};
  Eigen::VectorXd e(n);
  for (int d = 0; d < draws; ++d) {
    for (int k = 0; k < n; ++k) e[k] = z(rng);
    const Eigen::VectorXd delta = L * e;
    const std::array<double, 12> m =
        Flatten(ComparePoses(*c->robot, c->robot->nominal_values(),
                             c->model->LinkValues(delta.data()), c->validation)
                    .stats);
    for (int k = 0; k < 12; ++k) mean[k] += m[k] / draws;
  }
  // Both are Monte-Carlo means of 4000 draws (coefficient of variation of a metric ≲ 0.6): they
  // agree within 4 % when the Jacobian and the propagation are right.
  for (int k = 0; k < 12; ++k)
    EXPECT_NEAR(c->predicted_validation[k] / mean[k], 1.0, 0.04) << ValidationColumnName(k);
}

TEST(ValidationPrediction, PredictsTheMonteCarloMeansOfAStudy) {
  const std::string dir = testing::TempDir("prediction_study");
  RunOptions o;
  o.out_dir = dir + "/run";
  o.threads = 2;
  o.progress = false;
  const RunResult r = RunStudyAndWriteTables(LoadStudy(PredictionStudy(dir, 3000)), o);
  ASSERT_TRUE(r.tables_written);
  TrialStore store(dir + "/run/trials.sqlite");
  const CellSummary s = SummarizeCell(store, store.Cells().at(0));
  ASSERT_EQ(s.cell.predicted_validation.size(), 12u);
  for (int k = 0; k < 12; ++k) {
    // The empirical mean's own error (4 SE), the prediction's (4000 draws: ~1 %) and the
    // nominal-versus-truth linearisation (the predicted std is ~1-3 % off at these errors).
    const double predicted = s.cell.predicted_validation[k];
    EXPECT_NEAR(s.validation[k].mean, predicted, 4 * s.validation[k].mean_se + 0.04 * predicted)
        << ValidationColumnName(k);
  }
  const std::string csv = testing::ReadFile(dir + "/run/tables/validation.csv");
  EXPECT_THAT(csv, ::testing::HasSubstr(",mean_predicted\n"));
}

// selection.criterion: I minimises the predicted mean-square validation position error: its
// design has a smaller tr(W·(GᵀG)⁻¹) than the A design's, and a smaller predicted RMS position
// error, on the same pool.
TEST(TaskCriterion, ItsDesignPredictsALowerValidationPositionErrorThanA) {
  const std::string dir = testing::TempDir("task_criterion");
  std::list<Study> studies;  // a CellContext points into its study
  const auto cell = [&](const std::string& criterion) {
    const std::string path = dir + "/" + criterion + ".yaml";
    std::ofstream(path) << "name: task\nseed: 3\ntrials: 1\nrobot: "
                        << testing::SourcePath("studies/robots/paper.yaml")
                        << "\npool: {size: 60}\nvalidation: {size: 15}\n"
                           "selection: {count: 30, method: exchange, criterion: "
                        << criterion << "}\n";
    studies.push_back(LoadStudy(path));
    return PrepareCell(studies.back(), studies.back().cells[0]);
  };
  const auto a = cell("A"), task = cell("I");
  // The predicted mean square of the validation position errors, Σ over configurations and axes.
  const auto mean_square = [](const CellContext& c) {
    const int m = c.validation.size();
    Eigen::MatrixXd J(3 * m, c.model->num_parameters());
    const std::vector<Pose<double>> poses =
        ToolPoses(*c.robot, c.robot->nominal_values(), c.validation);
    Eigen::VectorXd e = Eigen::VectorXd::Zero(c.model->num_parameters());
    for (int k = 0; k < e.size(); ++k) {  // forward differences: an independent Jacobian
      e[k] = 1e-7;
      const PoseErrors p =
          ComparePoses(*c.robot, poses, c.model->LinkValues(e.data()), c.validation);
      e[k] = 0;
      for (int j = 0; j < m; ++j)
        for (int x = 0; x < 3; ++x) J(3 * j + x, k) = p.position(x, j) / 1e-7;
    }
    return (J * c.predicted_covariance * J.transpose()).trace();
  };
  EXPECT_LT(mean_square(*task), mean_square(*a));
  double rms_task = 0, rms_a = 0;
  for (int x = 0; x < 3; ++x) {
    rms_task += task->predicted_validation[x];
    rms_a += a->predicted_validation[x];
  }
  EXPECT_LT(rms_task, rms_a);
  EXPECT_EQ(task->cell->settings["selection"]["criterion"], "I");
}

}  // namespace
}  // namespace lrcal
