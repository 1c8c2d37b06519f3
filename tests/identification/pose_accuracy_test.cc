// The predicted accuracy of a calibrated arm against a Monte Carlo of the identification itself:
// simulate, identify and compare the identified tool poses with the true ones, 400 times.
#include "lrcal/identification/pose_accuracy.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "lrcal/core/error.h"
#include "lrcal/identification/identification.h"
#include "lrcal/kinematics/pose_errors.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

TEST(PoseAccuracy, PredictionMatchesAMonteCarloOfTheIdentification) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(60, 31);
  const TargetedConfigurations poses = testing::PaperHittingConfigurations(5, 32);
  const NoiseModel noise{0.2e-3, 10, true};
  IdentificationOptions o;
  o.sigma = noise.sigma;
  constexpr int kTrials = 400;
  std::vector<Eigen::Matrix3Xd> errors;
  std::vector<PoseAccuracy> predicted;
  for (int t = 0; t < kTrials; ++t) {
    MeasurementSet data;
    SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                     testing::PaperRig().ranger, configs, noise,
                     RandomStream(t, 0, 0, RandomPurpose::kNoise), &data);
    const IdentificationSummary s = Identify(model, data, o);
    ASSERT_TRUE(s.IsSolutionUsable());
    errors.push_back(
        ComparePoses(robot, testing::PaperTrueValues(), model.LinkValues(s.delta.data()), poses)
            .position);
    if (t == 0) predicted = PredictPoseAccuracy(model, s.delta.data(), s.covariance_given, poses);
  }
  for (int j = 0; j < poses.size(); ++j) {
    std::vector<double> radius;
    for (int a = 0; a < 3; ++a) {
      double ss = 0;
      for (const auto& e : errors) ss += e(a, j) * e(a, j);
      const double empirical = std::sqrt(ss / kTrials);  // mean error ~0: RMS = std
      // The std's relative standard error is 1/√(2·400) = 3.5 %; 4 of them, plus the first-order
      // prediction's own error (the covariance at one fit, not at the truth: ~2 %).
      EXPECT_NEAR(empirical / predicted[j].position_std[a], 1.0, 0.16)
          << "pose " << j << " axis " << a;
    }
    for (const auto& e : errors) radius.push_back(e.col(j).norm());
    std::sort(radius.begin(), radius.end());
    // The 95th percentile of 400 radii: its relative spread is about 7 %.
    EXPECT_NEAR(radius[379] / predicted[j].position_radius_95, 1.0, 0.2) << "pose " << j;
  }
  const PoseAccuracySummary summary = SummarizePoseAccuracy(predicted);
  EXPECT_GE(summary.worst, 0);
  EXPECT_GT(summary.rms_position, 0);
}

TEST(PoseAccuracy, RadiusOfAnIsotropicErrorIsTheChiQuantile) {
  // Σ = s²·I in 3-D: |x|/s is χ with 3 degrees of freedom, whose 0.95 quantile is 2.7955.
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const TargetedConfigurations pose = testing::PaperHittingConfigurations(1, 3);
  const Eigen::MatrixXd J = PoseJacobian(model, std::vector<double>(25, 0.0).data(), pose);
  // With C = s²·Jp⁺(Jp⁺)ᵀ, Jp·C·Jpᵀ = s²·I for the full-row-rank position Jacobian Jp.
  const Eigen::MatrixXd Jp = J.topRows(3);
  const Eigen::MatrixXd pinv = Jp.transpose() * (Jp * Jp.transpose()).inverse();
  const double s = 1e-4;
  const Eigen::MatrixXd C = s * s * pinv * pinv.transpose();
  const std::vector<PoseAccuracy> a =
      PredictPoseAccuracy(model, std::vector<double>(25, 0.0).data(), C, pose);
  EXPECT_NEAR(a[0].position_radius_95 / s, 2.7955, 0.03);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[0].position_std[k], s, 1e-9 * s + 1e-15);
  EXPECT_THROW(PredictPoseAccuracy(model, std::vector<double>(25, 0.0).data(),
                                   Eigen::MatrixXd::Identity(3, 3), pose),
               InputError);
}

}  // namespace
}  // namespace lrcal
