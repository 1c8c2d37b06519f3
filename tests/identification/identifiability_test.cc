// Identifiability: the paper's remark on a plane z + f = 0, the 25-parameter set, and the
// dependencies that estimating the plane introduces, each against a closed form.
#include "lrcal/identification/identifiability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "test_util.h"

namespace lrcal {
namespace {

using testing::PaperRobot;

std::vector<std::string> Sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

TargetedConfigurations HittingConfigurations(const Plane& plane, int count) {
  return testing::HittingConfigurations(plane, count, 5);
}

TEST(Identifiability, PapersTwentyFiveParametersAreIdentifiableOnThePapersPlane) {
  const RobotModel& robot = PaperRobot();
  MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  auto report = AnalyzeIdentifiability(model, testing::PaperHittingConfigurations(101));
  EXPECT_EQ(report.num_params(), 25);
  EXPECT_EQ(report.rank, 25);
  EXPECT_TRUE(report.unidentifiable.empty());
  EXPECT_TRUE(report.dependencies.empty());
  EXPECT_TRUE(std::isfinite(report.condition_number));
}

TEST(Identifiability, HorizontalPlaneMakesTheta1A1D3Unidentifiable) {
  // The paper: "if the measured plane is z + f = 0 ... θ1, a1, d3 will make no difference".
  // Those three columns are zero in exact arithmetic (d3 only up to cos(π/2) rounding); they must
  // be reported as unidentifiable, not scaled into a dependence.
  const RobotModel& robot = PaperRobot();
  Plane horizontal = Plane::FromCoefficients(0, 0, 1, 0.3);
  MeasurementModel model(robot, horizontal, MakeParameterSet(robot, PlaneTerms{}));
  auto report = AnalyzeIdentifiability(model, HittingConfigurations(horizontal, 101));
  EXPECT_EQ(Sorted(report.unidentifiable), Sorted({"theta1", "a1", "d3"}));
  EXPECT_TRUE(report.dependencies.empty()) << report.ToString();
  EXPECT_EQ(report.rank, 22);
  EXPECT_EQ(Sorted(report.suggested_fixed), Sorted({"theta1", "a1", "d3"}));
}

TEST(Identifiability, PapersOwnDeltaEWithPlaneNormalConfoundsTheta1WithPlaneTilt) {
  // Turning the whole arm about z0 by t is the same, for every reading, as turning the plane
  // about z0 by -t. The plane's chart direction t1 is the base x axis here (n_x = 0) and
  // d n = t·(ez × n) = -t·n_y·ex, so the unobservable direction is (theta1: 1, plane_u1: -n_y).
  const RobotModel& robot = PaperRobot();
  const Plane& plane = testing::PaperPlane();
  MeasurementModel model(robot, plane, MakeParameterSet(robot, PlaneTerms{true, false}));
  auto report = AnalyzeIdentifiability(model, testing::PaperHittingConfigurations(101));
  EXPECT_EQ(report.num_params(), 27);
  EXPECT_EQ(report.rank, 26);
  EXPECT_TRUE(report.unidentifiable.empty());
  ASSERT_EQ(report.dependencies.size(), 1u) << report.ToString();
  const auto& terms = report.dependencies[0].terms;
  ASSERT_EQ(terms.size(), 2u) << report.ToString();
  std::map<std::string, double> c(terms.begin(), terms.end());
  ASSERT_TRUE(c.count("theta1") && c.count("plane_u1")) << report.ToString();
  EXPECT_NEAR(c["plane_u1"] / c["theta1"], -plane.normal.y(), 1e-9);
  EXPECT_EQ(report.suggested_fixed.size(), 1u);
}

TEST(Identifiability, EstimatingThePlaneOffsetConfoundsD1) {
  // Lifting the arm along z0 by t equals lowering the plane: (d1: 1, plane_f: -n_z).
  const RobotModel& robot = PaperRobot();
  const Plane& plane = testing::PaperPlane();
  MeasurementModel model(robot, plane, MakeParameterSet(robot, PlaneTerms{true, true}));
  auto report = AnalyzeIdentifiability(model, testing::PaperHittingConfigurations(101));
  EXPECT_EQ(report.rank, 26);
  ASSERT_EQ(report.dependencies.size(), 2u) << report.ToString();
  bool found = false;
  for (const auto& dep : report.dependencies) {
    std::map<std::string, double> c(dep.terms.begin(), dep.terms.end());
    if (c.count("d1") && c.count("plane_f")) {
      EXPECT_EQ(c.size(), 2u);
      EXPECT_NEAR(c["plane_f"] / c["d1"], -plane.normal.z(), 1e-9);
      found = true;
    }
  }
  EXPECT_TRUE(found) << report.ToString();
}

TEST(Identifiability, EveryDependenceIsANullDirectionOfG) {
  const RobotModel& robot = PaperRobot();
  MeasurementModel model(robot, testing::PaperPlane(),
                         MakeParameterSet(robot, PlaneTerms{true, true}));
  TargetedConfigurations configs = testing::PaperHittingConfigurations(80);
  auto report = AnalyzeIdentifiability(model, configs);
  Eigen::MatrixXd G = IdentificationJacobian(model, configs);
  for (const auto& dep : report.dependencies) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(model.num_parameters());
    for (const auto& [name, coef] : dep.terms) v[model.parameters().Find(name)] = coef;
    EXPECT_LT((G * v).norm(), 1e-9 * G.norm() * v.norm()) << dep.ToString();
  }
}

TEST(Identifiability, TooFewConfigurationsIsRankDeficient) {
  const RobotModel& robot = PaperRobot();
  MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  auto report = AnalyzeIdentifiability(model, testing::PaperHittingConfigurations(20));
  EXPECT_EQ(report.rank, 20);
  EXPECT_FALSE(report.full_rank());
  EXPECT_EQ(report.suggested_fixed.size(), 5u);
}

}  // namespace
}  // namespace lrcal
