// Errors in variables (IdentificationOptions::encoder_sigma): the weights against the analytic
// identification Jacobian (a revolute joint's value enters like its θ), and — by Monte Carlo with
// noisy recorded joint values — that the χ² check and the covariance hold with them and not
// without them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>

#include "lrcal/identification/identification.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

constexpr double kEivSigma = 0.05e-3;   // m, one reading
constexpr double kJointSigma = 0.1e-3;  // rad, each recorded joint value

// ∂h/∂q_j is ∂h/∂θ_j for a revolute joint (θ = θ0 + q): the weights follow from the analytic
// Jacobian's θ columns, computed here independently of the central differences they use.
TEST(ErrorsInVariables, WeightsFollowTheJointGradientOfEachReading) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(30, 2);
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model);
  MeasuredValues data;
  data.configs = configs;
  data.y.assign(configs.size(), 0.0);
  data.repetitions.assign(configs.size(), 4);
  const std::vector<double> w = ErrorsInVariablesWeights(kind, data, kEivSigma, kJointSigma);
  const Eigen::MatrixXd G = MeasurementJacobian(kind, configs);
  for (int i = 0; i < configs.size(); ++i) {
    double g2 = 0;
    for (int j = 1; j <= robot.num_links(); ++j) {
      const double g = G(i, model.parameters().Find("theta" + std::to_string(j)));
      g2 += g * g;
    }
    const double variance = kEivSigma * kEivSigma / 4 + kJointSigma * kJointSigma * g2;
    constexpr double kRelative = 1e-7;  // central differences, step 1e-6 rad
    EXPECT_NEAR(w[i], kEivSigma * kEivSigma / variance, kRelative * w[i]) << "configuration " << i;
    EXPECT_LT(w[i], 4.0);
  }
}

// Recorded joint values off by N(0, (0.1 mrad)²) per configuration, readings of 0.05 mm: with
// errors in variables the χ² statistic averages its degrees of freedom and the estimate's error
// falls inside the stated covariance's 95 % ellipsoid at its rate (4-standard-error bands);
// without them the χ² check rejects nearly every calibration.
TEST(ErrorsInVariables, ChiSquaredAndCovarianceHoldWithNoisyJointValues) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(60, 3);
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  IdentificationOptions eiv;
  eiv.sigma = kEivSigma;
  eiv.encoder_sigma = kJointSigma;
  IdentificationOptions plain;
  plain.sigma = kEivSigma;
  NoiseModel noise;
  noise.sigma = kEivSigma;
  noise.repetitions = 1;  // one joint error per configuration, as the weights assume
  noise.encoder_sigma = kJointSigma;
  const Eigen::VectorXd truth = testing::PaperTrueErrors();
  const int n = model.num_parameters(), trials = 200;
  const double limit =
      boost::math::quantile(boost::math::chi_squared_distribution<double>(n), 0.95);
  int inside = 0, rejected_plain = 0, rejected_eiv = 0;
  double chi2_sum = 0;
  int dof = 0;
  for (int t = 0; t < trials; ++t) {
    MeasurementSet data;
    SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                     testing::PaperRig().ranger, configs, noise,
                     RandomStream(300 + t, 0, 0, RandomPurpose::kNoise), &data);
    const IdentificationSummary s = Identify(model, data, eiv);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
    Eigen::VectorXd error(n);
    for (int k = 0; k < n; ++k) error[k] = s.delta[k] - truth[model.parameters().robot_values[k]];
    inside += error.dot(s.covariance_given.ldlt().solve(error)) <= limit;
    chi2_sum += s.fit.chi2;
    dof = s.fit.dof;
    rejected_eiv += !s.fit.consistent;
    rejected_plain += !Identify(model, data, plain).fit.consistent;
  }
  const double expected = 0.95 * trials, se = std::sqrt(trials * 0.95 * 0.05);
  EXPECT_NEAR(inside, expected, 4 * se) << inside << " of " << trials << " inside";
  // The mean of χ²_dof over the trials: dof ± 4·√(2·dof/trials).
  EXPECT_NEAR(chi2_sum / trials, dof, 4 * std::sqrt(2.0 * dof / trials));
  EXPECT_LE(rejected_eiv, 3);  // p < 0.001 each: 0.2 expected
  EXPECT_GT(rejected_plain, trials * 9 / 10);
  ::testing::Test::RecordProperty("inside_95", inside);
  ::testing::Test::RecordProperty("rejected_without", rejected_plain);
}

// A median's values carry weights R/c of their own (averaging.h): errors in variables add the
// joint term to those, as they do to the repetitions of a mean (the joint term was once dropped
// when the values had weights: a median fit then ignored encoder_sigma).
TEST(ErrorsInVariables, ApplyOnTopOfAMediansWeights) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(40, 4);
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model);
  MeasuredValues median;
  median.configs = configs;
  median.repetitions.assign(configs.size(), 5);
  median.weights.assign(configs.size(), 5 / 1.5);  // R/c
  median.y.resize(configs.size());
  kind.Bind(configs)->Predict(std::vector<double>(model.num_parameters(), 0.0).data(),
                              median.y.data(), nullptr);
  IdentificationOptions eiv;
  eiv.sigma = kEivSigma;
  eiv.encoder_sigma = kJointSigma;
  IdentificationOptions plain;
  plain.sigma = kEivSigma;
  MeasuredValues weighted = median;
  weighted.weights = ErrorsInVariablesWeights(kind, median, kEivSigma, kJointSigma);
  for (int i = 0; i < configs.size(); ++i) {
    EXPECT_GT(weighted.weights[i], 0.0);
    EXPECT_LT(weighted.weights[i], median.weights[i]);
  }
  const IdentificationSummary with = Identify(kind, median, eiv);
  const IdentificationSummary reference = Identify(kind, weighted, plain);
  const IdentificationSummary without = Identify(kind, median, plain);
  ASSERT_TRUE(with.IsSolutionUsable()) << with.FullReport();
  constexpr double kSameSolve = 1e-12;  // the same weights, the same normal equations
  EXPECT_THAT(with.std_given, testing::EigenNear(reference.std_given, kSameSolve * 1e-3));
  EXPECT_GT((with.std_given - without.std_given).minCoeff(), 0.0);
}

TEST(ErrorsInVariables, NeedTheReadingNoise) {
  IdentificationOptions options;
  options.encoder_sigma = 1e-4;
  EXPECT_THROW(options.Validate(), SettingError);
  options.sigma = 1e-4;
  EXPECT_NO_THROW(options.Validate());
  options.encoder_sigma = -1;
  EXPECT_THROW(options.Validate(), SettingError);
}

}  // namespace
}  // namespace lrcal
