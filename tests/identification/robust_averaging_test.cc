// Robust averaging (noise.average) by Monte Carlo: with a median of each configuration's
// readings the identification's weights carry the median's variance factor, so that the χ² check
// and the covariance hold (and would not with the mean's weights); against gross errors the
// median calibrates far better than the mean.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>

#include "lrcal/identification/identification.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

constexpr double kAveragingSigma = 0.05e-3;  // m, one reading
constexpr int kReadings = 5;                 // per configuration

struct Outcome {
  int inside = 0;            // parameter errors inside the 95 % ellipsoid
  double chi2_sum = 0;       // with the median's weights
  double chi2_as_mean = 0;   // the same data weighed as if they were means
  double squared_error = 0;  // Σ over trials of |δ − δ_true|² in SI (m, rad mixed)
  int dof = 0;
};

Outcome Calibrate(const NoiseModel& noise, int trials, std::uint64_t seed) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(60, 3);
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  IdentificationOptions options;
  options.sigma = kAveragingSigma;
  const Eigen::VectorXd truth = testing::PaperTrueErrors();
  const int n = model.num_parameters();
  const double limit =
      boost::math::quantile(boost::math::chi_squared_distribution<double>(n), 0.95);
  Outcome out;
  for (int t = 0; t < trials; ++t) {
    MeasurementSet data;
    SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                     testing::PaperRig().ranger, configs, noise,
                     RandomStream(seed + t, 0, 0, RandomPurpose::kNoise), &data);
    const IdentificationSummary s = Identify(model, data, options);
    EXPECT_TRUE(s.IsSolutionUsable()) << s.FullReport();
    Eigen::VectorXd error(n);
    for (int k = 0; k < n; ++k) error[k] = s.delta[k] - truth[model.parameters().robot_values[k]];
    out.inside += error.dot(s.covariance_given.ldlt().solve(error)) <= limit;
    out.chi2_sum += s.fit.chi2;
    out.squared_error += error.squaredNorm();
    out.dof = s.fit.dof;
    data.variance_factor.clear();
    out.chi2_as_mean += Identify(model, data, options).fit.chi2;
  }
  return out;
}

TEST(RobustAveraging, TheMediansWeightsKeepTheChiSquaredAndTheCovarianceHonest) {
  NoiseModel noise;
  noise.sigma = kAveragingSigma;
  noise.repetitions = kReadings;
  noise.average = Averaging::Parse("median");
  const int trials = 200;
  const Outcome o = Calibrate(noise, trials, 700);
  const double expected = 0.95 * trials, se = std::sqrt(trials * 0.95 * 0.05);
  EXPECT_NEAR(o.inside, expected, 4 * se) << o.inside << " of " << trials << " inside";
  // The mean of χ²_dof over the trials: dof ± 4·√(2·dof/trials).
  const double chi2_se = std::sqrt(2.0 * o.dof / trials);
  EXPECT_NEAR(o.chi2_sum / trials, o.dof, 4 * chi2_se);
  // Weighed as means, the medians' χ² is about VarianceFactor(5) ≈ 1.43 times too large.
  EXPECT_NEAR(o.chi2_as_mean / trials / o.dof, noise.average.VarianceFactor(kReadings),
              4 * chi2_se / o.dof * noise.average.VarianceFactor(kReadings));
  ::testing::Test::RecordProperty("inside_95", o.inside);
}

TEST(RobustAveraging, AMedianResistsGrossErrorsThatPullAMean) {
  NoiseModel noise;
  noise.sigma = kAveragingSigma;
  noise.repetitions = kReadings;
  noise.outlier_fraction = 0.05;  // about one configuration in four has a gross reading
  noise.outlier_sigma = 5e-3;
  const int trials = 40;
  const Outcome mean = Calibrate(noise, trials, 900);
  noise.average = Averaging::Parse("median");
  const Outcome median = Calibrate(noise, trials, 900);  // the same readings
  // A gross error of 5 mm moves a mean of 5 by 1 mm, 20 σ: the mean's calibration is off by
  // far more than the median's, which only loses the median's efficiency (about 1.4 in variance).
  EXPECT_GT(mean.squared_error, 20 * median.squared_error);
  ::testing::Test::RecordProperty("error_ratio", mean.squared_error / median.squared_error);
}

}  // namespace
}  // namespace lrcal
