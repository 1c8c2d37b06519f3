// Truth: the simulated arm's link errors and the true ranger's errors, kept out of RobotModel.
#include "lrcal/measurement/truth.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lrcal/core/error.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;

TEST(Truth, LinkValuesAreTheNominalOnesPlusTheErrors) {
  const RobotModel& robot = testing::PaperRobot();
  Truth truth;
  EXPECT_EQ(truth.LinkValues(robot), robot.nominal_values());  // no errors: the nominal arm
  EXPECT_EQ(truth.LinkErrors(robot), Eigen::VectorXd::Zero(robot.num_values()));
  truth.link_errors = Eigen::VectorXd::Zero(robot.num_values());
  truth.link_errors[robot.FindValue("d6")] = 0.85e-3;
  const Eigen::VectorXd values = truth.LinkValues(robot);
  EXPECT_EQ(values[robot.FindValue("d6")], robot.nominal_values()[robot.FindValue("d6")] + 0.85e-3);
  EXPECT_EQ(values[robot.FindValue("a2")], robot.nominal_values()[robot.FindValue("a2")]);
  // The paper's robot file: its true_errors section, read into the file's Truth.
  EXPECT_EQ(testing::PaperTrueValues(),
            robot.nominal_values() + testing::PaperRig().truth.link_errors);
}

TEST(Truth, ErrorsOfAnotherLengthOrOfFixedValuesAreRefused) {
  const RobotModel& robot = testing::PaperRobot();
  Truth truth;
  truth.link_errors = Eigen::VectorXd::Zero(robot.num_values() - 1);
  EXPECT_THAT([&] { truth.LinkValues(robot); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("expected 30 link value errors")));
  truth.link_errors = Eigen::VectorXd::Zero(robot.num_values());
  truth.link_errors[robot.FindValue("d2")] = 1e-3;  // d2 is fixed on the paper's arm (β2)
  EXPECT_THAT([&] { truth.LinkErrors(robot); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("'d2', which is fixed")));
}

}  // namespace
}  // namespace lrcal
