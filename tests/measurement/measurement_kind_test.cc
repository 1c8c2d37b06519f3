// The kind-neutral simulation and Jacobian (measurement_kind.h), with the ranger behind them:
// the exact values are the ranger's own, misses are left out with their reasons, and the noise
// of a configuration does not depend on the others.
#include "lrcal/measurement/measurement_kind.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lrcal/core/error.h"
#include "lrcal/measurement/pose_measurement.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

constexpr double kBatchAgreement = 1e-13;  // m: batch kernel against per-configuration readings

TEST(SimulateMeasurements, NoiseFreeValuesAreTheExactReadingsAndMissesAreLeftOut) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model, testing::PaperRig().ranger);
  TargetedConfigurations configs = testing::PaperHittingConfigurations(10, 3);
  configs.Add(std::vector<double>(6, 0.0));  // the arm stretched out: the beam misses
  NoiseModel exact;
  exact.sigma = 0;
  exact.repetitions = 3;
  MeasuredValues data;
  std::vector<std::string> reasons;
  const int missed = SimulateMeasurements(
      kind, configs, exact, RandomStream(1, 0, 0, RandomPurpose::kNoise), &data, &reasons);
  std::vector<double> h;
  std::vector<BeamMiss> misses;
  ExactReadings(robot, robot.nominal_values(), testing::PaperPlane(), testing::PaperRig().ranger,
                configs, &h, &misses);
  ASSERT_NE(misses.back(), BeamMiss::kNone);
  int expected_missed = 0, j = 0;
  for (int i = 0; i < configs.size(); ++i) {
    EXPECT_EQ(reasons[i], BeamMissName(misses[i]));
    if (misses[i] != BeamMiss::kNone) {
      ++expected_missed;
      continue;
    }
    EXPECT_NEAR(data.y[j], h[i], kBatchAgreement) << i;
    EXPECT_EQ(data.repetitions[j], 3);
    ++j;
  }
  EXPECT_EQ(missed, expected_missed);
  EXPECT_EQ(data.size(), configs.size() - missed);
}

TEST(SimulateMeasurements, AConfigurationsNoiseDoesNotDependOnTheOthers) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model, testing::PaperRig().ranger);
  const TargetedConfigurations all = testing::PaperHittingConfigurations(12, 5);
  const TargetedConfigurations first = all.Subset({0, 1, 2, 3});
  NoiseModel noise;
  const RandomStream stream(9, 0, 0, RandomPurpose::kNoise);
  MeasuredValues a, b;
  SimulateMeasurements(kind, all, noise, stream, &a);
  SimulateMeasurements(kind, first, noise, stream, &b);
  ASSERT_EQ(b.size(), 4);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(a.y[i], b.y[i]) << i;
}

// AddMeasurementNoise on exact values computed once (a study's fixed truth) gives the values
// SimulateMeasurements computes from the truth each time, bit for bit: with a pose's angle rows
// and their weights, with the mean drawn directly and with every reading drawn.
TEST(SimulateMeasurements, NoiseOnCachedExactValuesIsTheSameBits) {
  const RobotModel& robot = testing::PaperRobot();
  PointSetup setup;
  setup.instrument =
      RigidTransform::FromXyzRpy(Eigen::Vector3d(2.5, 0.3, 0.2), Eigen::Vector3d(0, 0, 3));
  const PoseMeasurement kind(robot, setup);
  const TargetedConfigurations configs(testing::PaperHittingConfigurations(7, 2));
  const std::vector<double> zero(static_cast<std::size_t>(kind.num_parameters()), 0.0);
  std::vector<double> exact(static_cast<std::size_t>(configs.size()) * 6);
  kind.Bind(configs)->Predict(zero.data(), exact.data(), nullptr);
  const std::vector<std::string> reasons = kind.MissReasons(configs, zero.data());
  for (bool draw_mean : {true, false}) {
    NoiseModel noise;
    noise.repetitions = 3;
    noise.sigma_angle = 0.3e-3;
    noise.draw_mean = draw_mean;
    const RandomStream stream(4, 0, 1, RandomPurpose::kNoise);
    MeasuredValues simulated, cached;
    SimulateMeasurements(kind, configs, noise, stream, &simulated);
    AddMeasurementNoise(kind, exact, reasons, configs, noise, stream, &cached);
    EXPECT_EQ(simulated.y, cached.y) << draw_mean;
    EXPECT_EQ(simulated.weights, cached.weights);
    EXPECT_EQ(simulated.repetitions, cached.repetitions);
  }
  MeasuredValues unused;
  EXPECT_THROW(AddMeasurementNoise(kind, std::vector<double>(exact.begin(), exact.end() - 1),
                                   reasons, configs, NoiseModel{},
                                   RandomStream(4, 0, 1, RandomPurpose::kNoise), &unused),
               std::invalid_argument);
}

TEST(SimulateMeasurements, OutOfRangeNoiseIsRefused) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model, testing::PaperRig().ranger);
  NoiseModel noise;
  noise.sigma = -1e-3;
  MeasuredValues data;
  EXPECT_THROW(SimulateMeasurements(kind, testing::PaperHittingConfigurations(3, 1), noise,
                                    RandomStream(1, 0, 0, RandomPurpose::kNoise), &data),
               InputError);
}

}  // namespace
}  // namespace lrcal
