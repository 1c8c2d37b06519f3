// The kind-neutral simulation and Jacobian (measurement_kind.h), with the ranger behind them:
// the exact values are the ranger's own, misses are left out with their reasons, and the noise
// of a configuration does not depend on the others.
#include "lrcal/measurement/measurement_kind.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lrcal/core/error.h"
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
