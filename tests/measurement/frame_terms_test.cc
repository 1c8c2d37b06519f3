// The base and tool transforms as estimated terms (parameter_set.h FrameTerms): their names and
// layout, their analytic Jacobian columns against Ceres autodiff through the reference
// kinematics and against central differences, and the batch kernel against the
// per-configuration path on every instruction-set variant.
#include <ceres/jet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/measurement/measurement_model.h"
#include "measurement/batch_evaluation.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Autodiff and the analytic formulas are both exact up to rounding: entries are O(1) m/rad.
constexpr double kAutodiffTolerance = 1e-11;
// Central differences, step 1e-6: truncation O(step²) ≈ 1e-12, rounding O(eps/step) ≈ 1e-10.
constexpr double kFiniteDifferenceTolerance = 1e-8;
// The batch kernel and the per-configuration path: the same formulas in another order.
constexpr double kBatchTolerance = 1e-13;
constexpr int kMaxParams = 48;
using Jet = ceres::Jet<double, kMaxParams>;

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

// The reading and its row at configuration i against autodiff and central differences of the
// templated reading (which moves the frames through the reference kinematics).
void ExpectRowMatches(const MeasurementModel& model, const ModelPoint& point,
                      const std::vector<double>& e, const ConfigurationSet& configs, int i) {
  const int n = model.num_parameters(), plane = configs.plane(i);
  const double* q = configs.q(i);
  double h = 0;
  std::vector<double> row(n);
  model.Evaluate(point, configs, i, &h, row.data());
  EXPECT_NEAR(h, model.Distance<double>(e.data(), q, plane), 1e-12);
  std::vector<Jet> ej(n);
  for (int k = 0; k < n; ++k) ej[k] = Jet(e[k], k);
  const Jet hj = model.Distance<Jet>(ej.data(), q, plane);
  constexpr double kStep = 1e-6;
  for (int k = 0; k < n; ++k) {
    const std::string& name = model.parameters().names[k];
    EXPECT_NEAR(row[k], hj.v[k], kAutodiffTolerance) << "dh/d" << name << " at configuration " << i;
    std::vector<double> ep = e, em = e;
    ep[k] += kStep;
    em[k] -= kStep;
    const double fd = (model.Distance<double>(ep.data(), q, plane) -
                       model.Distance<double>(em.data(), q, plane)) /
                      (2 * kStep);
    EXPECT_NEAR(row[k], fd, kFiniteDifferenceTolerance) << "dh/d" << name;
  }
}

// A tilted, shifted base and a ranger off the flange, every term estimated (25 link values,
// the plane's three, the ranger's two and both frames' twelve: 42), at the nominal estimate and
// away from it.
TEST(FrameTermsJacobian, AnalyticMatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const Plane plane = Plane::FromCoefficients(0.2, -0.3, 1.0, 0.8);
  const MeasurementModel model(robot, plane,
                               MakeParameterSet(robot, PlaneTerms{true, true}, {}, "--fix",
                                                RangerTerms{true, true}, All(), All()));
  const int n = model.num_parameters();
  ASSERT_EQ(n, 42);
  ASSERT_LE(n, kMaxParams);
  const ConfigurationSet configs = testing::ConfigurationsFacing(robot, plane, 25, 5);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> ue(-0.02, 0.02);
  for (int at = 0; at < 2; ++at) {
    std::vector<double> e(n, 0.0);
    if (at == 1)
      for (double& v : e) v = ue(rng);
    ModelPoint point;
    model.Prepare(e.data(), &point);
    for (int i = 0; i < configs.size(); ++i) ExpectRowMatches(model, point, e, configs, i);
  }
}

// The same on a robot whose nominal frames are the identity (the paper's arm), a subset of each
// frame's terms estimated.
TEST(FrameTermsJacobian, SubsetsOnTheIdentityFrames) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(
      robot, testing::PaperPlane(),
      MakeParameterSet(robot, PlaneTerms{}, {}, "--fix", RangerTerms{},
                       FrameTerms::Parse("y,roll,yaw", "b"), FrameTerms::Parse("x,z,pitch", "t")));
  const ConfigurationSet configs = testing::PaperHittingConfigurations(20, 4);
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> ue(-0.01, 0.01);
  std::vector<double> e(model.num_parameters());
  for (double& v : e) v = ue(rng);
  ModelPoint point;
  model.Prepare(e.data(), &point);
  for (int i = 0; i < configs.size(); ++i) ExpectRowMatches(model, point, e, configs, i);
}

// The moved frames are what the reference kinematics of a robot with those frames gives.
TEST(FrameTermsJacobian, MovedFramesAreTheRobotsOwnAtTheEstimate) {
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
  const ConfigurationSet configs = testing::ConfigurationsFacing(robot, testing::PaperPlane(), 5);
  for (int i = 0; i < configs.size(); ++i) {
    const Pose<double> pose =
        ForwardKinematics<double>(moved, robot.nominal_values().data(), configs.q(i));
    EXPECT_NEAR(model.Distance<double>(e.data(), configs.q(i)),
                LaserDistance<double>(pose.p_BT, pose.R_BT.col(2), testing::PaperPlane().normal,
                                      testing::PaperPlane().offset),
                1e-12);
  }
}

// The batch kernel computes the frame columns from its own arrays: the same numbers as the
// per-configuration path, on one plane and on three, on every instruction-set variant.
TEST(FrameTermsJacobian, BatchKernelMatchesPerConfigurationOnEveryVariant) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PlaneSet planes(
      {Plane::FromCoefficients(0.2, -0.3, 1.0, 0.8), Plane::FromCoefficients(1, 0.1, 0, 0.9),
       Plane::FromCoefficients(0, 1, 0.2, 0.9)},
      {});
  for (int num_planes : {1, 3}) {
    const PlaneSet used = num_planes == 1 ? PlaneSet({planes[0]}, {}) : planes;
    const MeasurementModel model(
        robot, used,
        MakeParameterSet(robot, std::vector<PlaneTerms>(num_planes, PlaneTerms{true, true}), {},
                         "--fix", RangerTerms{true, true}, All(),
                         FrameTerms::Parse("x,z,rpy", "t")));
    ConfigurationSet configs(robot.num_links());
    for (int p = 0; p < num_planes; ++p) {
      const ConfigurationSet facing = testing::ConfigurationsFacing(robot, used[p], 13, 3 + p);
      for (int i = 0; i < facing.size(); ++i) configs.Add(facing.q(i), p);
    }
    const int n = model.num_parameters(), m = configs.size();
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> ue(-0.01, 0.01);
    std::vector<double> e(n);
    for (double& v : e) v = ue(rng);
    ModelPoint point;
    model.Prepare(e.data(), &point);
    BatchEvaluator batch;
    batch.SetConfigurations(configs);
    std::vector<double> row(n);
    for (Isa isa : SupportedIsas()) {
      std::vector<double> h(m), J(static_cast<std::size_t>(m) * n);
      batch.Evaluate(model, point, h.data(), J.data(), isa);
      for (int i = 0; i < m; ++i) {
        double hi;
        model.Evaluate(point, configs, i, &hi, row.data());
        EXPECT_NEAR(h[i], hi, kBatchTolerance);
        for (int k = 0; k < n; ++k)
          EXPECT_NEAR(J[static_cast<std::size_t>(k) * m + i], row[k], kBatchTolerance)
              << model.parameters().names[k] << " at configuration " << i << ", " << num_planes
              << " plane(s), " << IsaName(isa);
      }
    }
  }
}

}  // namespace
}  // namespace lrcal
