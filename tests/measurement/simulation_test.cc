// A real rig's disturbances in SimulateReadings: joint-encoder noise, plane form error and
// outliers, each checked against its stated distribution (first-order propagation through the
// model's θ columns, the incidence factor, the binomial count) and against a reading recomputed
// from the forward kinematics at the disturbed joint angles.
#include "lrcal/measurement/simulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "lrcal/core/error.h"
#include "test_util.h"

namespace lrcal {
namespace {

// Readings of the true arm at `configs` over `trials` trial streams: (trial, configuration)
// errors of the mean reading against the exact one.
Eigen::MatrixXd MeanErrors(const TargetedConfigurations& configs, const NoiseModel& noise,
                           int trials) {
  const RobotModel& robot = testing::PaperRobot();
  std::vector<double> exact;
  std::vector<BeamMiss> misses;
  ExactReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                testing::PaperRig().ranger, configs, &exact, &misses);
  Eigen::MatrixXd err(trials, configs.size());
  for (int t = 0; t < trials; ++t) {
    MeasurementSet data;
    SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                     testing::PaperRig().ranger, configs, noise,
                     RandomStream(3, 0, t, RandomPurpose::kNoise), &data);
    EXPECT_EQ(data.size(), configs.size());
    for (int i = 0; i < configs.size(); ++i) err(t, i) = data.mean_h[i] - exact[i];
  }
  return err;
}

double Variance(const Eigen::VectorXd& x) {
  return (x.array() - x.mean()).square().sum() / (x.size() - 1);
}

TEST(Simulation, EncoderNoiseMovesTheBeamByTheJointJacobian) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(4, 2);
  // ∂h/∂q_j = ∂h/∂θ_j: the joint angle and its offset enter the chain as θ_j + q_j.
  MeasurementModel truth(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const std::vector<double> zero(truth.num_parameters(), 0.0);
  ModelPoint point;
  PrepareModelPoint(robot, testing::PaperTrueValues().data(), testing::PaperPlane(), &point);
  for (bool draw_mean : {false, true}) {
    NoiseModel noise{0.0, 4, draw_mean};
    noise.encoder_sigma = 0.1e-3;
    const Eigen::MatrixXd err = MeanErrors(configs, noise, 4000);
    for (int i = 0; i < configs.size(); ++i) {
      std::vector<double> row(truth.num_parameters());
      double h;
      truth.Evaluate(point, configs, i, &h, row.data());
      double g2 = 0;
      for (int j = 0; j < 6; ++j)
        g2 += std::pow(row[truth.parameters().Find("theta" + std::to_string(j + 1))], 2);
      const double predicted = noise.encoder_sigma * noise.encoder_sigma * g2 / 4;
      // 4000 draws: the variance's relative standard error is √(2/4000) ≈ 2.2 %.
      EXPECT_NEAR(Variance(err.col(i)) / predicted, 1.0, 0.1) << "draw_mean " << draw_mean;
    }
  }
  // One raw reading recomputed from the forward kinematics at the disturbed angles.
  NoiseModel noise{0.0, 1, false};
  noise.encoder_sigma = 1e-3;
  MeasurementSet data;
  const RandomStream stream(3, 0, 5, RandomPurpose::kNoise);
  SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                   testing::PaperRig().ranger, configs, noise, stream, &data);
  const RandomStream encoder = stream.WithPurpose(RandomPurpose::kEncoder);
  for (int i = 0; i < configs.size(); ++i) {
    double q[6];
    for (int j = 0; j < 6; ++j) q[j] = configs.q(i)[j] + 1e-3 * encoder.Normal(i * 6 + j);
    const Pose<double> pose =
        ForwardKinematics<double>(robot, testing::PaperTrueValues().data(), q);
    const Plane& plane = testing::PaperPlane();
    const double expected =
        LaserDistance<double>(pose.p_BT, pose.R_BT.col(2), plane.normal, plane.offset);
    EXPECT_NEAR(data.mean_h[i], expected, 1e-12);
    EXPECT_EQ(data.configs.q(i)[0], configs.q(i)[0]);  // the data records the encoder reading
  }
}

TEST(Simulation, PlaneFormErrorIsSharedByTheReadingsOfAConfiguration) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(3, 5);
  NoiseModel noise{0.0, 5, false};
  noise.form_sigma = 0.05e-3;
  std::vector<double> raw;
  MeasurementSet data;
  SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                   testing::PaperRig().ranger, configs, noise,
                   RandomStream(3, 0, 1, RandomPurpose::kNoise), &data, nullptr, &raw);
  for (int i = 0; i < configs.size(); ++i)
    for (int r = 1; r < 5; ++r) EXPECT_EQ(raw[i * 5 + r], raw[i * 5]);
  // The reading moves by ε/|n·b|: variance σ_form²/(n·b)².
  noise.draw_mean = true;
  const Eigen::MatrixXd err = MeanErrors(configs, noise, 4000);
  ModelPoint point;
  PrepareModelPoint(robot, testing::PaperTrueValues().data(), testing::PaperPlane(), &point);
  for (int i = 0; i < configs.size(); ++i) {
    const double nb = testing::PaperPlane().normal.dot(ToolPose(point, configs, i).R_BT.col(2));
    const double predicted = std::pow(noise.form_sigma / nb, 2);
    EXPECT_NEAR(Variance(err.col(i)) / predicted, 1.0, 0.1);
  }
}

TEST(Simulation, OutliersHitTheStatedShareOfReadingsAndAverageInTheMean) {
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(10, 6);
  NoiseModel noise{0.0, 1, false};
  noise.outlier_fraction = 0.1;
  noise.outlier_sigma = 5e-3;
  const Eigen::MatrixXd raw = MeanErrors(configs, noise, 2000);
  const double share = (raw.array().abs() > 1e-12).cast<double>().mean();
  // 20,000 readings: the share's standard error is 0.0021.
  EXPECT_NEAR(share, 0.1, 0.01);
  // The gross errors are N(0, σ_out²): as many negative as positive, mean 0, RMS σ_out (a
  // decision sharing its random word with the error once made every one of them positive, RMS
  // 6.9 mm for 5 mm). About 2000 of them: the mean's SE is 0.11 mm, the RMS's relative SE 1.6 %.
  std::vector<double> gross;
  for (Eigen::Index k = 0; k < raw.size(); ++k)
    if (std::fabs(raw.data()[k]) > 1e-12) gross.push_back(raw.data()[k]);
  double sum = 0, squares = 0, positive = 0;
  for (double g : gross) {
    sum += g;
    squares += g * g;
    positive += g > 0;
  }
  const double n = static_cast<double>(gross.size());
  EXPECT_NEAR(positive / n, 0.5, 4 * 0.5 / std::sqrt(n));
  EXPECT_NEAR(sum / n, 0.0, 4 * 5e-3 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(squares / n) / 5e-3, 1.0, 4 * std::sqrt(0.5 / n));
  // Means of R = 10: K ~ Binomial(10, p) gross errors add √K·σ_out·z/R, variance p·σ_out²/R.
  noise.repetitions = 10;
  noise.draw_mean = true;
  const Eigen::MatrixXd mean = MeanErrors(configs, noise, 2000);
  const Eigen::Map<const Eigen::VectorXd> all(mean.data(), mean.size());
  const double predicted = 0.1 * 25e-6 / 10;
  // Heavy-tailed (a mixture): the variance's relative SE is ≈ √((κ−1)/N) ≈ 3 % here.
  EXPECT_NEAR(Variance(all) / predicted, 1.0, 0.12);
  EXPECT_NEAR((all.array().abs() > 1e-12).cast<double>().mean(), 1 - std::pow(0.9, 10), 0.015);
}

// noise.average: a configuration's value is the median of exactly the readings written to `raw`,
// with its variance factor; draw_mean does not apply (every reading is drawn).
TEST(Simulation, AMedianIsTheMiddleOfTheWrittenReadingsWithItsVarianceFactor) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(8, 3);
  NoiseModel noise;
  noise.repetitions = 5;
  noise.outlier_fraction = 0.2;
  noise.average = Averaging::Parse("median");
  const RandomStream stream(5, 0, 0, RandomPurpose::kNoise);
  MeasurementSet data, drawn;
  std::vector<double> raw;
  SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                   testing::PaperRig().ranger, configs, noise, stream, &data, nullptr, &raw);
  ASSERT_EQ(data.size(), 8);
  ASSERT_EQ(raw.size(), 40u);
  for (int i = 0; i < data.size(); ++i) {
    std::vector<double> r(raw.begin() + 5 * i, raw.begin() + 5 * i + 5);
    std::sort(r.begin(), r.end());
    EXPECT_EQ(data.mean_h[i], r[2]) << i;
    EXPECT_EQ(data.Weight(i), 5 / noise.average.VarianceFactor(5));
  }
  noise.draw_mean = true;
  SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                   testing::PaperRig().ranger, configs, noise, stream, &drawn);
  EXPECT_EQ(drawn.mean_h, data.mean_h);
  // The mean keeps no factors: its weights are its counts.
  noise.average = Averaging{};
  SimulateReadings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                   testing::PaperRig().ranger, configs, noise, stream, &drawn);
  EXPECT_TRUE(drawn.variance_factor.empty());
  EXPECT_EQ(drawn.Weight(0), 5.0);
}

TEST(Simulation, DisturbancesAreValidated) {
  NoiseModel noise;
  noise.outlier_fraction = 1.5;
  EXPECT_THROW(noise.Validate(), InputError);
  noise = NoiseModel{};
  noise.encoder_sigma = -1;
  EXPECT_THROW(noise.Validate(), InputError);
  noise = NoiseModel{};
  noise.form_sigma = std::nan("");
  EXPECT_THROW(noise.Validate(), InputError);
}

}  // namespace
}  // namespace lrcal
