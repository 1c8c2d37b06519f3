// Candidates where a kind measures (measurable_pool.h): a scanner's pool has every beam of its fan
// on its plane, checked here by each beam's own ray–plane intersection; a socket pool has the
// nominal ball in its sockets in turn, within the joint ranges; seated contacts touch their plane
// and a plane out of reach seats none; the draws are a function of their seed; a fan too wide
// for its plane is refused by name.
#include "lrcal/design/measurable_pool.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/joint_constraints.h"
#include "lrcal/measurement/contact_measurement.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;

constexpr double kSeated = 1e-9;  // m: the seatings' own tolerance is 1e-12

// The nominal tool pose at q, from the reference kinematics.
Pose<double> ToolAt(const RobotModel& robot, const double* q) {
  const Eigen::VectorXd values = robot.nominal_values();
  return ForwardKinematics<double>(robot, values.data(), q);
}

ScannerSetup FanOnThePaperPlane(double half_angle_deg) {
  ScannerSetup setup;
  setup.planes = PlaneSet(testing::PaperPlane());
  setup.beam_angles = ScannerSetup::FanOf(5, half_angle_deg, "beams", "fan");
  setup.range = RangerSpec{};
  return setup;
}

TEST(MeasurablePool, EveryBeamOfAScannersFanMeetsItsPlane) {
  const RobotModel& robot = testing::PaperRobot();
  const ScannerSetup setup = FanOnThePaperPlane(10);
  const ScannerMeasurement scanner(robot, setup);
  SamplingReport report;
  const TargetedConfigurations pool =
      SampleScannerConfigurations(scanner, {40}, 7, 3, SamplingOptions{}, &report);
  ASSERT_EQ(pool.size(), 40);
  EXPECT_EQ(report.accepted, 40);
  EXPECT_GE(report.attempts, 40);
  const Plane& plane = setup.planes[0];
  for (int i = 0; i < pool.size(); ++i) {
    // Each beam from the tool origin along R·(sin φ, 0, cos φ) meets the plane ahead, within the
    // ranger's range, computed here from the tool pose alone.
    const Pose<double> tool = ToolAt(robot, pool.q(i));
    for (double phi : setup.beam_angles) {
      const Eigen::Vector3d d = tool.R_BT * Eigen::Vector3d(std::sin(phi), 0, std::cos(phi));
      const double h = -(plane.normal.dot(tool.p_BT) + plane.offset) / plane.normal.dot(d);
      EXPECT_GT(h, setup.range.min_range) << "configuration " << i;
      EXPECT_LT(h, setup.range.max_range) << "configuration " << i;
    }
  }
  const TargetedConfigurations again = SampleScannerConfigurations(scanner, {40}, 7, 3, {});
  const TargetedConfigurations other = SampleScannerConfigurations(scanner, {40}, 8, 3, {});
  EXPECT_EQ(again.q(39)[2], pool.q(39)[2]);
  EXPECT_NE(other.q(0)[2], pool.q(0)[2]);
}

TEST(MeasurablePool, AGivenPoolKeepsTheConfigurationsWhereEveryBeamMeetsItsPlane) {
  // Aimed draws (the ranger's beam on the plane) of which a ±30° fan misses on some: exactly the
  // rows MissReasons calls "ok" are kept, in order, with the others counted by reason.
  const ScannerMeasurement scanner(testing::PaperRobot(), FanOnThePaperPlane(30));
  SamplingOptions aimed;
  aimed.require_beam_hit = true;
  const TargetedConfigurations drawn =
      SampleConfigurations(testing::PaperRobot(), scanner.setup().planes, {60},
                           RandomStream(4, 0, 0, RandomPurpose::kPool), aimed);
  SamplingReport report;
  std::vector<std::string> reasons;
  const TargetedConfigurations kept = MeasurableConfigurations(scanner, drawn, &report, &reasons);
  ASSERT_EQ(reasons.size(), 60u);
  int k = 0;
  for (int i = 0; i < drawn.size(); ++i) {
    if (reasons[static_cast<std::size_t>(i)] != "ok") continue;
    ASSERT_LT(k, kept.size());
    EXPECT_EQ(kept.q(k)[0], drawn.q(i)[0]);
    ++k;
  }
  EXPECT_EQ(k, kept.size());
  EXPECT_LT(kept.size(), 60);  // the fan is wide enough to miss on some
  EXPECT_EQ(report.accepted, kept.size());
  int rejected = 0;
  for (const auto& [why, n] : report.rejected) rejected += n;
  EXPECT_EQ(rejected, 60 - kept.size());
}

TEST(MeasurablePool, AFanTooWideForItsPlaneIsRefused) {
  // At 89° a beam runs along the tool's x axis: it meets a plane the tool faces only far away,
  // grazing, so no configuration has all five on the plane.
  const ScannerMeasurement scanner(testing::PaperRobot(), FanOnThePaperPlane(89));
  try {
    SampleScannerConfigurations(scanner, {20}, 1, 0, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("a beam of the fan off its plane"));
  }
}

TEST(MeasurablePool, ASocketPoolSeatsTheBallInEachSocketInTurn) {
  const RobotModel& robot = testing::PaperRobot();
  SocketSetup setup;
  setup.ids = {0, 1, 2};
  setup.positions = {{1.0, 0.5, 0.3}, {1.0, 0.55, 0.3}, {0.8, -0.6, 0.4}};
  setup.tool_point = {0, 0, 0.05};
  const SocketMeasurement socket(robot, setup);
  SamplingOptions options;
  options.min_jacobian_singular_value = 0.05;
  const TargetedConfigurations pool = SampleSocketConfigurations(socket, 30, 5, 0, options);
  ASSERT_EQ(pool.size(), 30);
  for (int i = 0; i < pool.size(); ++i) {
    EXPECT_EQ(pool.target(i), i % 3);
    const Pose<double> tool = ToolAt(robot, pool.q(i));
    const Eigen::Vector3d ball = tool.p_BT + tool.R_BT * setup.tool_point;
    EXPECT_LT((ball - setup.positions[static_cast<std::size_t>(i % 3)]).norm(), kSeated) << i;
    std::vector<double> q(pool.q(i), pool.q(i) + pool.num_joints());
    const std::vector<double> before = q;
    EXPECT_TRUE(WrapIntoJointRanges(robot, q.data()));
    EXPECT_EQ(q, before) << "configuration " << i << " is not in the joint ranges";
    EXPECT_TRUE(IsWellConditioned(robot, pool.q(i), options.min_jacobian_singular_value));
  }
  setup.positions[2] = {5, 0, 0};  // beyond the arm's 2.3 m reach
  try {
    SampleSocketConfigurations(SocketMeasurement(robot, setup), 30, 5, 0, options);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not seated in its socket"));
  }
}

TEST(MeasurablePool, SeatedContactsTouchTheirPlaneAndAPlaneOutOfReachSeatsNone) {
  const RobotModel& robot = testing::PaperRobot();
  ContactSetup setup;
  setup.planes = PlaneSet(testing::PaperPlane());
  setup.tool_point = {0, 0, 0.05};
  SamplingOptions aimed;
  aimed.require_beam_hit = true;
  const TargetedConfigurations starts = SampleConfigurations(
      robot, setup.planes, {30}, RandomStream(2, 0, 0, RandomPurpose::kPool), aimed);
  SamplingReport report;
  std::vector<std::string> reasons;
  const TargetedConfigurations seated =
      SeatedConfigurations(robot, ContactMeasurement(robot, setup), starts, &report, &reasons);
  EXPECT_GT(seated.size(), 20);
  EXPECT_EQ(std::count(reasons.begin(), reasons.end(), "ok"), seated.size());
  EXPECT_EQ(report.accepted, seated.size());
  EXPECT_EQ(report.attempts, 30);
  const Plane& plane = setup.planes[0];
  for (int i = 0; i < seated.size(); ++i) {
    const Pose<double> tool = ToolAt(robot, seated.q(i));
    EXPECT_LT(std::abs(plane.normal.dot(tool.p_BT + tool.R_BT * setup.tool_point) + plane.offset),
              kSeated);
  }
  setup.planes = PlaneSet(Plane{Eigen::Vector3d(0, 0, 1), -10});  // z = 10 m
  const TargetedConfigurations none =
      SeatedConfigurations(robot, ContactMeasurement(robot, setup), starts, &report);
  EXPECT_EQ(none.size(), 0);
  EXPECT_EQ(report.rejected["not seated"], 30);
}

}  // namespace
}  // namespace lrcal
