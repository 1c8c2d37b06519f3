// Base and tool transforms identified with the arm (parameter_set.h FrameTerms): identifiability
// finds and names their dependences on the first and last links' parameters, the reduced set
// recovers a truth from noise-free readings to the round-trip tolerance with both solvers, and
// the calibrated model's poses carry the estimated frames.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;

constexpr double kFrameRecoveryTolerance = testing::tolerance::kRoundTrip;  // SI (m or rad)

FrameTerms All() {
  FrameTerms t;
  t.estimated.fill(true);
  return t;
}

// Three planes around the paper's arm on its tilted base, a ranger off the flange.
PlaneSet TiltedThreePlanes() {
  return PlaneSet(
      {Plane::FromCoefficients(0.2, -0.3, 1.0, 0.8), Plane::FromCoefficients(1, 0.1, 0, 0.9),
       Plane::FromCoefficients(0, 1, 0.2, 0.9)},
      {});
}

TargetedConfigurations FacingAll(const RobotModel& robot, const PlaneSet& planes, int per_plane) {
  TargetedConfigurations configs(robot.num_links());
  for (int p = 0; p < planes.size(); ++p) {
    const TargetedConfigurations facing =
        testing::ConfigurationsFacing(robot, planes[p], per_plane, 7 + p);
    for (int i = 0; i < facing.size(); ++i) configs.Add(facing.q(i), p);
  }
  return configs;
}

// Noise-free readings of `robot` (its own base and tool) at link values `values`: the reference
// kinematics, independent of the measurement model's frame terms.
MeasurementSet Exact(const RobotModel& robot, const Eigen::VectorXd& values, const PlaneSet& planes,
                     const TargetedConfigurations& configs) {
  MeasurementSet data;
  data.configs = configs;
  for (int i = 0; i < configs.size(); ++i) {
    const Pose<double> pose = ForwardKinematics<double>(robot, values.data(), configs.q(i));
    const Plane& plane = planes[configs.target(i)];
    data.mean_h.push_back(
        LaserDistance<double>(pose.p_BT, pose.R_BT.col(2), plane.normal, plane.offset));
  }
  data.repetitions.assign(configs.size(), 1);
  return data;
}

bool Mentions(const Dependency& d, const std::string& name) {
  return std::any_of(d.terms.begin(), d.terms.end(),
                     [&](const auto& term) { return term.first == name; });
}

// Every link value, both frames' twelve terms: identifiability says which cannot be told apart
// and from what. A rotation about the beam moves no reading (tool_yaw: zero column), the base's
// yaw turns the arm about joint 1's axis exactly as θ1 does.
TEST(FrameTermsIdentifiability, NamesTheDependencesOnTheEndLinks) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PlaneSet planes = TiltedThreePlanes();
  const MeasurementModel model(robot, planes,
                               MakeParameterSet(robot, std::vector<PlaneTerms>(3), {}, "--fix",
                                                RangerTerms{}, All(), All()));
  const IdentifiabilityReport report = AnalyzeIdentifiability(model, FacingAll(robot, planes, 40));
  EXPECT_THAT(report.unidentifiable, Contains("tool_yaw"));
  EXPECT_FALSE(report.full_rank());
  bool base_yaw_with_theta1 = false;
  for (const Dependency& d : report.dependencies)
    if (Mentions(d, "base_yaw") && Mentions(d, "theta1")) base_yaw_with_theta1 = true;
  EXPECT_TRUE(base_yaw_with_theta1) << report.ToString();
  // Every dependence that involves a frame term also involves a parameter of link 1 or link 6.
  for (const Dependency& d : report.dependencies) {
    bool frame = false, end_link = false;
    for (const auto& term : d.terms) {
      const std::string& name = term.first;
      const bool is_frame = IsFrameTermName(name);
      frame |= is_frame;
      end_link |= !is_frame && (name.back() == '1' || name.back() == '6');
    }
    if (frame) {
      EXPECT_TRUE(end_link) << d.ToString();
    }
  }
  EXPECT_THAT(report.ToString(), HasSubstr("tool_yaw"));
}

// The reduced set (what --auto-fix keeps) recovers a truth that moves every kept term, from the
// readings of a robot whose base and tool are really moved, with either solver.
TEST(FrameTermsRecovery, RecoversLinksBaseAndToolFromNoiseFreeReadings) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PlaneSet planes = TiltedThreePlanes();
  const TargetedConfigurations configs = FacingAll(robot, planes, 40);
  const ParameterSet asked =
      MakeParameterSet(robot, std::vector<PlaneTerms>(3), {}, "--fix", RangerTerms{}, All(), All());
  const IdentifiabilityReport report =
      AnalyzeIdentifiability(MeasurementModel(robot, planes, asked), configs);
  const MeasurementModel model(robot, planes,
                               WithoutParameters(robot, asked, report.suggested_fixed));
  const ParameterSet& ps = model.parameters();
  ASSERT_TRUE(ps.EstimatesFrames());
  // The truth: every kept term moved by up to 2 mm / 2 mrad.
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-2e-3, 2e-3);
  std::vector<double> e_true(ps.size());
  for (double& v : e_true) v = u(rng);
  const RobotModel truth = model.RobotAt(e_true.data());
  const MeasurementSet data = Exact(truth, model.LinkValues(e_true.data()), planes, configs);
  int frame_terms = 0;
  for (int k = 0; k < ps.size(); ++k) frame_terms += IsFrameTermName(ps.names[k]);
  EXPECT_GE(frame_terms, 4) << "the reduced set keeps few frame terms";
  for (const auto solver : {IdentificationOptions::Solver::kLevenbergMarquardt,
                            IdentificationOptions::Solver::kCeres}) {
    IdentificationOptions options;
    options.solver = solver;
    const IdentificationSummary s = Identify(model, data, options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
    for (int k = 0; k < ps.size(); ++k)
      EXPECT_NEAR(s.delta[k], e_true[k], kFrameRecoveryTolerance)
          << s.names[k] << (solver == IdentificationOptions::Solver::kCeres ? " (Ceres)" : "");
    EXPECT_LT(s.residual_rms, 1e-12);
  }
}

// The pose Jacobian moves the tool with the frames: a base shift moves every pose by itself, a
// tool shift by the tool's rotation of it.
TEST(FrameTermsPoses, PoseJacobianColumnsOfTheFrames) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const MeasurementModel model(
      robot, testing::PaperPlane(),
      MakeParameterSet(robot, PlaneTerms{}, {}, "--fix", RangerTerms{}, All(), All()));
  const TargetedConfigurations configs =
      testing::ConfigurationsFacing(robot, testing::PaperPlane(), 4);
  const std::vector<double> e(model.num_parameters(), 0.0);
  const Eigen::MatrixXd J = PoseJacobian(model, e.data(), configs);
  const ParameterSet& ps = model.parameters();
  for (int j = 0; j < configs.size(); ++j) {
    const Pose<double> pose =
        ForwardKinematics<double>(robot, robot.nominal_values().data(), configs.q(j));
    const Eigen::Matrix3d R_BN = pose.R_BT * robot.tool().rotation.transpose();
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d base_shift = J.block(6 * j, ps.frame_columns[0][c], 3, 1);
      const Eigen::Vector3d tool_shift = J.block(6 * j, ps.frame_columns[1][c], 3, 1);
      EXPECT_THAT(base_shift, testing::EigenNear(Eigen::Vector3d::Unit(c), 1e-8));
      EXPECT_THAT(tool_shift, testing::EigenNear(R_BN.col(c), 1e-8));
    }
  }
}

}  // namespace
}  // namespace lrcal
