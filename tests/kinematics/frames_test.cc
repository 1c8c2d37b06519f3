// Base and tool transforms around the D-H chain: roll-pitch-yaw conversions, and forward
// kinematics (reference and fast path) against an independent composition base · chain · tool.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/rigid_transform.h"
#include "test_util.h"

namespace lrcal {
namespace {

// Products of a few O(1) rotations and O(1 m) translations: rounding only.
constexpr double kTolerance = 1e-12;

TEST(RigidTransform, RpyRoundTripsIncludingGimbalLock) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-M_PI, M_PI), half(-M_PI / 2, M_PI / 2);
  std::vector<Eigen::Vector3d> rpys;
  for (int i = 0; i < 200; ++i) rpys.emplace_back(u(rng), half(rng), u(rng));
  // Gimbal lock: only roll ∓ yaw is defined; the rotation must still come back.
  rpys.emplace_back(0.3, M_PI / 2, -0.4);
  rpys.emplace_back(-1.1, -M_PI / 2, 2.0);
  for (const Eigen::Vector3d& rpy : rpys) {
    const RigidTransform t = RigidTransform::FromXyzRpy(Eigen::Vector3d(1, 2, 3), rpy);
    // Independent: URDF's fixed-axis convention as a product of elementary rotations.
    const Eigen::Matrix3d expected = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                         .toRotationMatrix();
    EXPECT_THAT(t.rotation, testing::EigenNear(expected, testing::tolerance::kRounding));
    const RigidTransform back = RigidTransform::FromXyzRpy(t.translation, t.Rpy());
    // Away from gimbal lock the angles' rounding grows as 1/cos(pitch); at it the branch is exact.
    const double cos_pitch = std::cos(rpy.y());
    const double tolerance = cos_pitch < 1e-12 ? 1e-15 : 1e-15 + 1e-15 / cos_pitch;
    EXPECT_LT((back.rotation - t.rotation).cwiseAbs().maxCoeff(), tolerance) << rpy.transpose();
  }
}

TEST(RigidTransform, InverseAndCompositionAndValidation) {
  const RigidTransform a =
      RigidTransform::FromXyzRpy(Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0.4, 0.5, -0.6));
  const RigidTransform identity = a * a.Inverse();
  EXPECT_THAT(identity.rotation,
              testing::EigenNear(Eigen::Matrix3d::Identity(), testing::tolerance::kRounding));
  EXPECT_LT(identity.translation.norm(), 1e-15);
  EXPECT_TRUE(RigidTransform().IsIdentity());
  EXPECT_FALSE(a.IsIdentity());
  RigidTransform sheared;
  sheared.rotation(0, 1) = 0.1;
  EXPECT_THROW(sheared.Validate("tool"), InputError);
  RigidTransform mirrored;
  mirrored.rotation(2, 2) = -1;
  EXPECT_THROW(mirrored.Validate("tool"), InputError);
}

Eigen::Isometry3d AsIsometry(const RigidTransform& t) {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.linear() = t.rotation;
  x.translation() = t.translation;
  return x;
}

TEST(RobotFrames, ForwardKinematicsIsBaseTimesChainTimesTool) {
  const RobotModel& framed = testing::PaperRobotWithFrames();
  const RobotModel& bare = testing::PaperRobot();
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-M_PI, M_PI), ue(-0.01, 0.01);
  for (int trial = 0; trial < 50; ++trial) {
    double q[6];
    for (double& v : q) v = u(rng);
    Eigen::VectorXd values = framed.nominal_values();
    if (trial % 2) values += Eigen::VectorXd::NullaryExpr(values.size(), [&] { return ue(rng); });
    const Pose<double> chain = ForwardKinematics<double>(bare, values.data(), q);
    Eigen::Isometry3d chain_x = Eigen::Isometry3d::Identity();
    chain_x.linear() = chain.R_BT;
    chain_x.translation() = chain.p_BT;
    const Eigen::Isometry3d expected =
        AsIsometry(framed.base()) * chain_x * AsIsometry(framed.tool());
    const Pose<double> ref = ForwardKinematics<double>(framed, values.data(), q);
    EXPECT_LT((ref.p_BT - expected.translation()).norm(), kTolerance);
    EXPECT_THAT(ref.R_BT, testing::EigenNear(expected.linear(), kTolerance));
    // The fast path.
    ChainPoint point;
    PrepareChainPoint(framed, values.data(), &point);
    ConfigurationSet one(6);
    one.Add(q);
    const Pose<double> fast = ToolPose(point, one, 0);
    EXPECT_LT((fast.p_BT - ref.p_BT).norm(), kTolerance);
    EXPECT_THAT(fast.R_BT, testing::EigenNear(ref.R_BT, kTolerance));
  }
}

// The same check as Kinematics.GeometricJacobianMatchesFiniteDifferences, on a rig with base
// and tool frames: the formulas hold unchanged with the tool pose including the tool transform.
TEST(RobotFrames, GeometricJacobianMatchesCentralDifferencesWithFrames) {
  const double q[6] = {0.3, -0.7, 1.1, 0.4, -0.9, 2.0};
  const auto [linear, angular] =
      testing::GeometricJacobianDeviation(testing::PaperRobotWithFrames(), q);
  EXPECT_LT(linear, 1e-8);
  EXPECT_LT(angular, 1e-6);
}

}  // namespace
}  // namespace lrcal
