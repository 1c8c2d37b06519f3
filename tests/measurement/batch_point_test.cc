// The point and pose kinds' structure-of-arrays kernel (batch_point.h): with the probes'
// orientation terms fixed a pose kind has the point kind's terms, and rows 6i…6i+2 of its values
// and Jacobian are the point's rows 3i…3i+2 bit for bit (the kernel's two row strides agree);
// every instruction-set variant gives the same bits, for either kind; a kind without the charts
// it needs is refused. point_measurement_test.cc and pose_measurement_test.cc check the kernel
// (through Bind) against autodiff and central differences.
#include "measurement/batch_point.h"

#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>
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
      EXPECT_TRUE(SameBits(y[3 * i + c], y6[6 * i + c])) << "value " << c << " at " << i;
      for (int k = 0; k < n; ++k)
        EXPECT_TRUE(SameBits(J[static_cast<std::size_t>(k) * 3 * m + 3 * i + c],
                             J6[static_cast<std::size_t>(k) * 6 * m + 6 * i + c]))
            << point.parameter_names()[k] << ", row " << c << " of configuration " << i;
    }
  }
}

TEST(BatchPointEvaluator, ThePointsRowsAreThePosesPositionRows) {
  const PointSetup setup = testing::TrackerSetup();
  ExpectThePoseKindsPositionRows(testing::PaperRobotWithFrames(), setup, {}, 2);
  ExpectThePoseKindsPositionRows(testing::PaperRobot(), setup, {"instrument_y", "target2_z"}, 2);
  PointSetup one = setup;
  one.targets.resize(1);
  ExpectThePoseKindsPositionRows(testing::PaperRobot(), one, {"instrument_roll", "theta1"}, 1);
}

TEST(BatchPointEvaluator, ThePointsRowsAreThePosesPositionRowsWithAPrismaticJoint) {
  std::vector<Link> links(3);
  links[0].nominal = {0.1, -1.2, 0.3, 0.5, 0.0};
  links[1].joint = JointType::kPrismatic;
  links[1].nominal = {0.4, 0.7, 0.2, 0.1, 0.05};
  links[2].nominal = {-0.3, 0.0, 0.4, 0.2, 0.02};
  for (auto& l : links) l.is_parameter = {true, true, true, true, true};
  const RobotModel robot("three", links);
  ExpectThePoseKindsPositionRows(robot, testing::TrackerSetup(), {}, 2);
}

// The rows as the per-configuration Eigen code the kernel replaced computed them (ToolPose's
// frames, Eigen's 3 × 3 products; a zero-filled Jacobian): the kernel's values and Jacobian must
// have their bits, which keeps every table made before it. Without a tool transform (the batch
// chain applies one with its own sums, as the ranger's kernel always has).
void PerConfigurationRows(const PointMeasurement& kind, const TargetedConfigurations& configs,
                          const std::vector<Eigen::Matrix3d>& charts, const double* e,
                          std::vector<double>* y, std::vector<double>* J) {
  const int k = kind.rows_per_configuration(), m = k * configs.size();
  y->assign(static_cast<std::size_t>(m), 0.0);
  J->assign(static_cast<std::size_t>(m) * kind.num_parameters(), 0.0);
  PointMeasurement::State st;
  kind.StateAt(e, &st);
  ChainPoint chain;
  PrepareChainPoint(kind.robot(), st.link_values.data(), &chain);
  const auto put = [&](int column, int row, const Eigen::Vector3d& v) {
    if (column < 0) return;
    for (int c = 0; c < 3; ++c) (*J)[static_cast<std::size_t>(column) * m + row + c] = v[c];
  };
  const std::vector<int>& values = kind.robot_values();
  for (int i = 0; i < configs.size(); ++i) {
    ChainFrames frames;
    const Pose<double> pose = ToolPose(chain, configs, i, &frames);
    const int t = configs.target(i), row = k * i;
    const Eigen::Vector3d P = pose.p_BT + pose.R_BT * st.targets[t];
    const Eigen::Vector3d value = st.R_BI.transpose() * (P - st.p_BI);
    for (int c = 0; c < 3; ++c) (*y)[row + c] = value[c];
    const Eigen::Matrix3d Rt = st.R_BI.transpose();
    for (int v = 0; v < static_cast<int>(values.size()); ++v)
      put(v, row, Rt * LinkValuePointMotion(frames, values[v], P));
    for (int c = 0; c < 3; ++c) put(kind.instrument_column(c), row, -Rt.col(c));
    const Eigen::Vector3d u2 = st.Rz.transpose() * (st.R_BI0.transpose() * (P - st.p_BI));
    const Eigen::Vector3d u1 = st.Ry.transpose() * u2;
    put(kind.instrument_column(3), row, -Eigen::Vector3d::UnitX().cross(st.Rx.transpose() * u1));
    put(kind.instrument_column(4), row, -(st.Rx.transpose() * Eigen::Vector3d::UnitY().cross(u1)));
    put(kind.instrument_column(5), row,
        -(st.Rx.transpose() * (st.Ry.transpose() * Eigen::Vector3d::UnitZ().cross(u2))));
    const Eigen::Matrix3d dy_dt = Rt * pose.R_BT;
    for (int c = 0; c < 3; ++c) put(kind.target_column(t, c), row, dy_dt.col(c));
    if (k == 3) continue;
    const Eigen::Matrix3d R_BM = pose.R_BT * st.R_TM[t];
    const Eigen::Matrix3d R_IM = st.R_BI.transpose() * R_BM;
    const Eigen::Vector3d phi = RotationLog(charts[i].transpose() * R_IM);
    for (int c = 0; c < 3; ++c) (*y)[row + 3 + c] = phi[c];
    const Eigen::Matrix3d Jinv = InverseRightJacobian(phi);
    const Eigen::Matrix3d to_body = Jinv * R_BM.transpose();
    for (int v = 0; v < static_cast<int>(values.size()); ++v)
      put(v, row + 3, to_body * LinkValueRotation(frames, values[v]));
    const Eigen::Matrix3d from_instrument = -Jinv * R_IM.transpose();
    put(kind.instrument_column(3), row + 3, from_instrument * Eigen::Vector3d::UnitX());
    put(kind.instrument_column(4), row + 3,
        from_instrument * (st.Rx.transpose() * Eigen::Vector3d::UnitY()));
    put(kind.instrument_column(5), row + 3,
        from_instrument * (st.Rx.transpose() * (st.Ry.transpose() * Eigen::Vector3d::UnitZ())));
    const Eigen::Matrix3d& Rx = st.target_Rx[t];
    const Eigen::Matrix3d& Ry = st.target_Ry[t];
    put(kind.target_rotation_column(t, 0), row + 3, Jinv * Eigen::Vector3d::UnitX());
    put(kind.target_rotation_column(t, 1), row + 3,
        Jinv * (Rx.transpose() * Eigen::Vector3d::UnitY()));
    put(kind.target_rotation_column(t, 2), row + 3,
        Jinv * (Rx.transpose() * (Ry.transpose() * Eigen::Vector3d::UnitZ())));
  }
}

void ExpectThePerConfigurationBits(const PointMeasurement& kind,
                                   const std::vector<Eigen::Matrix3d>& charts,
                                   const TargetedConfigurations& configs) {
  const std::vector<double> e = testing::OffNominalEstimate(kind);
  std::vector<double> y0, J0;
  PerConfigurationRows(kind, configs, charts, e.data(), &y0, &J0);
  std::vector<double> y(y0.size()), J(J0.size());
  // Bind's evaluator: the pose kind's charts are its own nominal predictions, as `charts` are.
  ASSERT_TRUE(kind.Bind(configs)->Predict(e.data(), y.data(), J.data()));
  const int m = static_cast<int>(y.size());
  for (int r = 0; r < m; ++r) EXPECT_TRUE(SameBits(y[r], y0[r])) << kind.name() << " value " << r;
  for (std::size_t x = 0; x < J.size(); ++x)
    EXPECT_TRUE(SameBits(J[x], J0[x]))
        << kind.name() << " " << kind.parameter_names()[x / static_cast<std::size_t>(m)] << ", row "
        << x % static_cast<std::size_t>(m) << ": " << J[x] << " vs " << J0[x];
}

TEST(BatchPointEvaluator, HasTheBitsOfThePerConfigurationEigenCodeItReplaced) {
#if defined(__AVX__)
  GTEST_SKIP() << "with AVX (LRCAL_NATIVE) Eigen pairs a 3 x 3 product's sums otherwise";
#endif
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs =
      testing::RandomTrackerConfigurations(robot.num_links(), 29, 2, 13);
  PointSetup setup = testing::TrackerSetup(true);
  setup.targets[0] = Eigen::Vector3d(0.05, -0.02, 0.10);  // no zero offset: every sum matters
  ExpectThePerConfigurationBits(PointMeasurement(robot, setup), {}, configs);
  ExpectThePerConfigurationBits(PointMeasurement(robot, setup, {"instrument_y", "target2_x"}), {},
                                configs);
  const PoseMeasurement pose(robot, setup);
  std::vector<Eigen::Matrix3d> charts;
  for (int i = 0; i < configs.size(); ++i)
    charts.push_back(pose.ChartCentre(configs.q(i), configs.target(i)));
  ExpectThePerConfigurationBits(pose, charts, configs);
  ExpectThePerConfigurationBits(PoseMeasurement(robot, setup, {"target2_yaw", "instrument_roll"}),
                                charts, configs);
}

// Every variant gives the default's bits, for the point kind and the pose kind (two probes, one
// turned against the tool's axes).
void ExpectEveryInstructionSetsBits(const PointMeasurement& kind,
                                    const std::vector<Eigen::Matrix3d>& charts) {
  const RobotModel& robot = kind.robot();
  const TargetedConfigurations configs =
      testing::RandomTrackerConfigurations(robot.num_links(), 37, 2, 5);
  const std::vector<double> e = testing::OffNominalEstimate(kind);
  PointMeasurement::State state;
  kind.StateAt(e.data(), &state);
  ChainPoint chain;
  PrepareChainPoint(robot, state.link_values.data(), &chain);
  BatchPointEvaluator batch;
  batch.SetConfigurations(configs);
  const Eigen::Matrix3d* centres = charts.empty() ? nullptr : charts.data();
  const int m = kind.rows_per_configuration() * configs.size(), n = kind.num_parameters();
  std::vector<double> y0(m), J0(static_cast<std::size_t>(m) * n);
  batch.Evaluate(kind, state, chain, centres, y0.data(), J0.data(), Isa::kDefault);
  for (Isa isa : SupportedIsas()) {
    std::vector<double> y(m), J(J0.size()), y_only(m);
    batch.Evaluate(kind, state, chain, centres, y.data(), J.data(), isa);
    batch.Evaluate(kind, state, chain, centres, y_only.data(), nullptr, isa);
    for (int r = 0; r < m; ++r) {
      EXPECT_TRUE(SameBits(y[r], y0[r])) << IsaName(isa) << " value " << r;
      EXPECT_TRUE(SameBits(y_only[r], y0[r])) << IsaName(isa) << " value only " << r;
    }
    for (std::size_t k = 0; k < J.size(); ++k)
      EXPECT_TRUE(SameBits(J[k], J0[k])) << IsaName(isa) << " Jacobian entry " << k;
  }
}

TEST(BatchPointEvaluator, EveryInstructionSetGivesTheSameBits) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  ExpectEveryInstructionSetsBits(PointMeasurement(robot, testing::TrackerSetup()), {});
  const PoseMeasurement pose(robot, testing::TrackerSetup(true));
  const TargetedConfigurations configs =
      testing::RandomTrackerConfigurations(robot.num_links(), 37, 2, 5);
  std::vector<Eigen::Matrix3d> charts;
  for (int i = 0; i < configs.size(); ++i)
    charts.push_back(pose.ChartCentre(configs.q(i), configs.target(i)));
  ExpectEveryInstructionSetsBits(pose, charts);
}

TEST(BatchPointEvaluator, APoseKindNeedsItsChartsAndAPointKindNone) {
  const RobotModel& robot = testing::PaperRobot();
  const PoseMeasurement pose(robot, testing::TrackerSetup(true));
  PointMeasurement::State state;
  const std::vector<double> e(static_cast<std::size_t>(pose.num_parameters()), 0.0);
  pose.StateAt(e.data(), &state);
  ChainPoint chain;
  PrepareChainPoint(robot, state.link_values.data(), &chain);
  BatchPointEvaluator batch;
  batch.SetConfigurations(testing::RandomTrackerConfigurations(robot.num_links(), 3, 2, 5));
  std::vector<double> y(18);
  EXPECT_THROW(batch.Evaluate(pose, state, chain, nullptr, y.data(), nullptr),
               std::invalid_argument);
  const Eigen::Matrix3d charts[3] = {Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(),
                                     Eigen::Matrix3d::Identity()};
  const PointMeasurement point(robot, testing::TrackerSetup());
  EXPECT_THROW(batch.Evaluate(point, state, chain, charts, y.data(), nullptr),
               std::invalid_argument);
}

}  // namespace
}  // namespace lrcal
