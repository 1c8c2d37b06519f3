// The ranger behind the measurement interface (ranger_measurement.h): the batch kernel's
// predictions and Jacobian are MeasurementModel's, its misses are ExactReadings', and fixing
// terms is WithoutParameters'.
#include "lrcal/measurement/ranger_measurement.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lrcal/core/error.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

using testing::EigenNear;
// The batch kernel against the per-configuration path: the same formulas in another order.
constexpr double kRangerBatchAgreement = 1e-13;

TEST(RangerMeasurement, PredictionsAndJacobianAreTheMeasurementModels) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(),
                               MakeParameterSet(robot, PlaneTerms{true, true}, {"theta1", "d1"},
                                                "fix", RangerTerms{true, true}));
  const RangerMeasurement kind(model, testing::PaperRig().ranger);
  EXPECT_STREQ(kind.name(), "ranger");
  EXPECT_EQ(kind.rows_per_configuration(), 1);
  EXPECT_EQ(kind.parameter_names(), model.parameters().names);
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(30, 4);
  std::vector<double> e(kind.num_parameters());
  for (int k = 0; k < kind.num_parameters(); ++k) e[k] = (k % 2 ? 1e-3 : -2e-3);
  const Eigen::MatrixXd G = MeasurementJacobian(kind, configs, e.data());
  EXPECT_THAT(G,
              EigenNear(IdentificationJacobian(model, configs, e.data()), kRangerBatchAgreement));
  std::vector<double> y(configs.size());
  kind.Bind(configs)->Predict(e.data(), y.data(), nullptr);
  ModelPoint point;
  model.Prepare(e.data(), &point);
  for (int i = 0; i < configs.size(); ++i) {
    double h;
    model.Evaluate(point, configs, i, &h, nullptr);
    EXPECT_NEAR(y[i], h, kRangerBatchAgreement) << i;
  }
  // Nominal values: link values, the plane's offset, zero for chart and ranger terms.
  const Eigen::VectorXd nominal = kind.NominalValues();
  EXPECT_EQ(nominal[model.parameters().Find("plane_f")], testing::PaperPlane().offset);
  EXPECT_EQ(nominal[model.parameters().Find("ranger_scale")], 0.0);
  EXPECT_EQ(nominal[model.parameters().Find("a2")], robot.nominal_values()[robot.FindValue("a2")]);
}

TEST(RangerMeasurement, MissesAreTheSimulationsAndFixingIsWithoutParameters) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model, testing::PaperRig().ranger);
  // Random configurations: many beams miss the plane, for several reasons.
  TargetedConfigurations configs = testing::PaperHittingConfigurations(20, 2);
  for (int i = 0; i < 20; ++i) {
    std::vector<double> q(6, 0.3 * i - 3.0);
    configs.Add(q);
  }
  std::vector<double> h;
  std::vector<BeamMiss> misses;
  ExactReadings(robot, robot.nominal_values(), testing::PaperPlane(), testing::PaperRig().ranger,
                configs, &h, &misses);
  const std::vector<std::string> reasons = kind.MissReasons(configs, nullptr);
  ASSERT_EQ(reasons.size(), misses.size());
  int missed = 0;
  for (std::size_t i = 0; i < misses.size(); ++i) {
    EXPECT_EQ(reasons[i], BeamMissName(misses[i])) << i;
    missed += misses[i] != BeamMiss::kNone;
  }
  EXPECT_GT(missed, 0);

  const std::unique_ptr<MeasurementKind> reduced = kind.Without({"theta1", "d6"});
  EXPECT_EQ(reduced->parameter_names(),
            WithoutParameters(robot, model.parameters(), {"theta1", "d6"}).names);
  EXPECT_THROW(kind.Without({"plane7_u1"}), InputError);
}

TEST(RangerMeasurement, ConfigurationsThatDoNotFitAreRefused) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model, testing::PaperRig().ranger);
  TargetedConfigurations second_plane(6);
  second_plane.Add(std::vector<double>(6, 0.1), 1);
  EXPECT_THROW(kind.Bind(second_plane), InputError);
  TargetedConfigurations five_joints(5);
  five_joints.Add(std::vector<double>(5, 0.1));
  try {
    kind.Bind(five_joints);
    ADD_FAILURE() << "a 5-joint configuration was accepted for a 6-joint arm";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("the ranger's robot has 6 joints, the "
                                               "configurations 5"));
  }
}

}  // namespace
}  // namespace lrcal
