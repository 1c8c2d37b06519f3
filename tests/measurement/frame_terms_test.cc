// The base and tool transforms as estimated terms (parameter_set.h FrameTerms): their names and
// layout, and the moved frames the model reads with. Their Jacobian columns are checked in
// measurement_model_test.cc (autodiff, central differences) and batch_evaluation_test.cc.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/measurement/measurement_model.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

FrameTerms All() {
  FrameTerms t;
  t.estimated.fill(true);
  return t;
}

TEST(FrameTerms, ParseAndTextRoundTrip) {
  EXPECT_EQ(FrameTerms::Parse("none", "--estimate-base").ToString(), "none");
  EXPECT_EQ(FrameTerms::Parse("all", "--estimate-base").ToString(), "all");
  EXPECT_EQ(FrameTerms::Parse("x,y,z", "--estimate-base").ToString(), "xyz");
  EXPECT_EQ(FrameTerms::Parse("rpy", "--estimate-base").ToString(), "rpy");
  EXPECT_EQ(FrameTerms::Parse("xyz,rpy", "--estimate-base").ToString(), "all");
  EXPECT_EQ(FrameTerms::Parse("z,yaw", "--estimate-base").ToString(), "z,yaw");
  EXPECT_EQ(FrameTerms::Parse("xyz,yaw", "--estimate-tool").ToString(), "xyz,yaw");
  for (const std::string text : {"none", "all", "xyz", "rpy", "x,pitch", "xyz,roll,yaw"})
    EXPECT_EQ(FrameTerms::Parse(FrameTerms::Parse(text, "t").ToString(), "t").estimated,
              FrameTerms::Parse(text, "t").estimated)
        << text;
  try {
    FrameTerms::Parse("x,twist", "--estimate-tool");
    FAIL() << "an unknown frame term was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "--estimate-tool");
    EXPECT_THAT(e.what(), HasSubstr("unknown frame term 'twist'"));
  }
}

TEST(FrameTerms, ComeLastInTheEstimateAndCanBeFixedByName) {
  const RobotModel& robot = testing::PaperRobot();
  const ParameterSet ps =
      MakeParameterSet(robot, PlaneTerms{false, true}, {"tool_yaw", "base_y"}, "--fix",
                       RangerTerms{true, false}, FrameTerms::Parse("xyz", "b"), All());
  const int robot_terms = static_cast<int>(robot.parameter_indices().size());
  std::vector<std::string> tail(ps.names.begin() + robot_terms, ps.names.end());
  EXPECT_THAT(tail, ElementsAre("plane_f", "ranger_offset", "base_x", "base_z", "tool_x", "tool_y",
                                "tool_z", "tool_roll", "tool_pitch"));
  EXPECT_TRUE(ps.EstimatesFrames());
  EXPECT_EQ(ps.frame_columns[0][1], -1);  // base_y fixed
  EXPECT_EQ(ps.frame_columns[1][5], -1);  // tool_yaw fixed
  EXPECT_EQ(ps.names[ps.frame_columns[1][3]], "tool_roll");
  EXPECT_TRUE(ps.IsAngular(ps.Find("tool_pitch")));
  EXPECT_FALSE(ps.IsAngular(ps.Find("base_z")));
  // WithoutParameters keeps the frames asked for and the ones fixed before.
  const ParameterSet fewer = WithoutParameters(robot, ps, {"tool_x"});
  EXPECT_EQ(fewer.Find("tool_x"), -1);
  EXPECT_EQ(fewer.Find("tool_yaw"), -1);
  EXPECT_EQ(fewer.Find("base_y"), -1);
  EXPECT_GE(fewer.Find("tool_y"), 0);
  EXPECT_EQ(fewer.size(), ps.size() - 1);
  EXPECT_FALSE(MakeParameterSet(robot, PlaneTerms{}).EstimatesFrames());
}

// The moved frames are what the reference kinematics of a robot with those frames gives.
TEST(FrameTerms, MovedFramesAreTheRobotsOwnAtTheEstimate) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const MeasurementModel model(
      robot, testing::PaperPlane(),
      MakeParameterSet(robot, PlaneTerms{}, {}, "--fix", RangerTerms{}, All(), All()));
  std::vector<double> e(model.num_parameters(), 0.0);
  const int base = model.parameters().frame_columns[0][0];
  const int tool = model.parameters().frame_columns[1][0];
  const double moves[6] = {1e-3, -2e-3, 3e-3, 4e-3, -5e-3, 6e-3};
  for (int k = 0; k < 6; ++k) {
    e[base + k] = moves[k];
    e[tool + k] = -moves[k];
  }
  const RobotModel moved = model.RobotAt(e.data());
  // Translation: p0 + d; rotation: R0·Rz(yaw)·Ry(pitch)·Rx(roll).
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(moves[5], Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(moves[4], Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(moves[3], Eigen::Vector3d::UnitX()))
                                   .toRotationMatrix();
  EXPECT_THAT(moved.base().rotation, testing::EigenNear(robot.base().rotation * turn, 1e-15));
  EXPECT_THAT(
      moved.base().translation,
      testing::EigenNear(robot.base().translation + Eigen::Vector3d(1e-3, -2e-3, 3e-3), 1e-15));
  EXPECT_THAT(
      moved.tool().translation,
      testing::EigenNear(robot.tool().translation - Eigen::Vector3d(1e-3, -2e-3, 3e-3), 1e-15));
  // The reading of the moved robot's reference kinematics is the model's at e.
  const TargetedConfigurations configs =
      testing::ConfigurationsFacing(robot, testing::PaperPlane(), 5);
  for (int i = 0; i < configs.size(); ++i) {
    const Pose<double> pose =
        ForwardKinematics<double>(moved, robot.nominal_values().data(), configs.q(i));
    EXPECT_NEAR(model.Distance<double>(e.data(), configs.q(i)),
                LaserDistance<double>(pose.p_BT, pose.R_BT.col(2), testing::PaperPlane().normal,
                                      testing::PaperPlane().offset),
                1e-12);
  }
}

}  // namespace
}  // namespace lrcal
