// The point kind's structure-of-arrays kernel (batch_point.h) against the per-configuration
// evaluation it replaces, which the pose kind still runs for its position rows: with the probes'
// orientation terms fixed, a pose kind has the point kind's terms, and rows 6i…6i+2 of its
// values and Jacobian are the point's rows 3i…3i+2 (to rounding); and every instruction-set
// variant gives the same bits. point_measurement_test.cc checks the kernel (through
// PointMeasurement::Bind) against autodiff and central differences.
#include "measurement/batch_point.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "lrcal/kinematics/chain.h"
#include "lrcal/measurement/pose_measurement.h"
#include "test_util.h"
#include "tracker_fixtures.h"

namespace lrcal {
namespace {

// Bit equality, so that -0 and +0 differ and NaN equals NaN.
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The same formulas summed in another order (Eigen sums a 3×3 product's third row as
// a₀b₀ + (a₁b₁ + a₂b₂), the kernel every row as (a₀b₀ + a₁b₁) + a₂b₂): a few ulps of O(1) values.
constexpr double kTolerance = 1e-14;

std::vector<std::string> OrientationTerms(int targets) {
  std::vector<std::string> names;
  for (int t = 0; t < targets; ++t)
    for (const char* axis : {"roll", "pitch", "yaw"})
      names.push_back(TargetTermName(t, targets, axis));
  return names;
}

// The point kind's values and Jacobian (3 rows a configuration) through Bind: the kernel.
void PointRows(const PointMeasurement& kind, const TargetedConfigurations& configs,
               const std::vector<double>& e, std::vector<double>* y, std::vector<double>* J) {
  const int m = 3 * configs.size();
  y->assign(static_cast<std::size_t>(m), 0.0);
  J->assign(static_cast<std::size_t>(m) * kind.num_parameters(), 0.0);
  ASSERT_TRUE(kind.Bind(configs)->Predict(e.data(), y->data(), J->data()));
}

void ExpectThePoseKindsPositionRows(const RobotModel& robot, const PointSetup& setup,
                                    const std::vector<std::string>& fixed, int targets) {
  const PointMeasurement point(robot, setup, fixed);
  std::vector<std::string> pose_fixed = fixed;
  for (const std::string& name : OrientationTerms(targets)) pose_fixed.push_back(name);
  const PoseMeasurement pose(robot, setup, pose_fixed);
  ASSERT_EQ(point.parameter_names(), pose.parameter_names());
  const TargetedConfigurations configs =
      testing::RandomTrackerConfigurations(robot.num_links(), 23, targets, 11);
  const std::vector<double> e = testing::OffNominalEstimate(point);
  const int n = point.num_parameters(), m = configs.size();
  std::vector<double> y, J;
  PointRows(point, configs, e, &y, &J);
  std::vector<double> y6(6 * static_cast<std::size_t>(m)), J6(y6.size() * n);
  ASSERT_TRUE(pose.Bind(configs)->Predict(e.data(), y6.data(), J6.data()));
  for (int i = 0; i < m; ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(y[3 * i + c], y6[6 * i + c], kTolerance) << "value " << c << " at " << i;
      for (int k = 0; k < n; ++k)
        EXPECT_NEAR(J[static_cast<std::size_t>(k) * 3 * m + 3 * i + c],
                    J6[static_cast<std::size_t>(k) * 6 * m + 6 * i + c], kTolerance)
            << point.parameter_names()[k] << ", row " << c << " of configuration " << i;
    }
  }
}

TEST(BatchPointEvaluator, AgreesWithThePerConfigurationRows) {
  const PointSetup setup = testing::TrackerSetup();
  ExpectThePoseKindsPositionRows(testing::PaperRobotWithFrames(), setup, {}, 2);
  ExpectThePoseKindsPositionRows(testing::PaperRobot(), setup, {"instrument_y", "target2_z"}, 2);
  PointSetup one = setup;
  one.targets.resize(1);
  ExpectThePoseKindsPositionRows(testing::PaperRobot(), one, {"instrument_roll", "theta1"}, 1);
}

TEST(BatchPointEvaluator, AgreesWithThePerConfigurationRowsWithAPrismaticJoint) {
  std::vector<Link> links(3);
  links[0].nominal = {0.1, -1.2, 0.3, 0.5, 0.0};
  links[1].joint = JointType::kPrismatic;
  links[1].nominal = {0.4, 0.7, 0.2, 0.1, 0.05};
  links[2].nominal = {-0.3, 0.0, 0.4, 0.2, 0.02};
  for (auto& l : links) l.is_parameter = {true, true, true, true, true};
  const RobotModel robot("three", links);
  ExpectThePoseKindsPositionRows(robot, testing::TrackerSetup(), {}, 2);
}

TEST(BatchPointEvaluator, EveryInstructionSetGivesTheSameBits) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PointMeasurement kind(robot, testing::TrackerSetup());
  const TargetedConfigurations configs =
      testing::RandomTrackerConfigurations(robot.num_links(), 37, 2, 5);
  const std::vector<double> e = testing::OffNominalEstimate(kind);
  PointMeasurement::State state;
  kind.StateAt(e.data(), &state);
  ChainPoint chain;
  PrepareChainPoint(robot, state.link_values.data(), &chain);
  BatchPointEvaluator batch;
  batch.SetConfigurations(configs);
  const int m = 3 * configs.size(), n = kind.num_parameters();
  std::vector<double> y0(m), J0(static_cast<std::size_t>(m) * n);
  batch.Evaluate(kind, state, chain, y0.data(), J0.data(), Isa::kDefault);
  for (Isa isa : SupportedIsas()) {
    std::vector<double> y(m), J(J0.size()), y_only(m);
    batch.Evaluate(kind, state, chain, y.data(), J.data(), isa);
    batch.Evaluate(kind, state, chain, y_only.data(), nullptr, isa);
    for (int r = 0; r < m; ++r) {
      EXPECT_TRUE(SameBits(y[r], y0[r])) << IsaName(isa) << " value " << r;
      EXPECT_TRUE(SameBits(y_only[r], y0[r])) << IsaName(isa) << " value only " << r;
    }
    for (std::size_t k = 0; k < J.size(); ++k)
      EXPECT_TRUE(SameBits(J[k], J0[k])) << IsaName(isa) << " Jacobian entry " << k;
  }
}

}  // namespace
}  // namespace lrcal
