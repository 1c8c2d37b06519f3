// The analytic identification Jacobian against Ceres autodiff (through the independent
// reference kinematics) and against central differences, for every choice of plane terms.
#include "lrcal/measurement/measurement_model.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>

#include "lrcal/core/error.h"
#include "test_util.h"

namespace lrcal {
namespace {

// Autodiff and the analytic formulas are both exact up to rounding: entries are O(1) m/rad.
constexpr double kAutodiffTolerance = 1e-11;
// Central differences with step 1e-6 have truncation error O(step²·h''') ≈ 1e-12 and rounding
// error O(eps·h/step) ≈ 1e-10.
constexpr double kFiniteDifferenceTolerance = 1e-8;
constexpr int kMaxParams = 30;
using Jet = ceres::Jet<double, kMaxParams>;
// Every link value, plane and ranger term and both frames' twelve terms (42) fit in 48.
using WideJet = ceres::Jet<double, 48>;

struct Case {
  PlaneTerms terms;
  std::vector<std::string> fixed;
  RangerTerms ranger = {};
};
// Short, stable test names in ctest (not the struct's bytes).
void PrintTo(const Case& c, std::ostream* os) {
  *os << c.terms.ToString() << " ranger " << c.ranger.ToString();
  for (const auto& f : c.fixed) *os << " -" << f;
}

class JacobianTest : public ::testing::TestWithParam<Case> {};

// Row i of the analytic Jacobian at estimate `e` (prepared as `point`) against Ceres jets of type
// JetT through the reference kinematics and against central differences (step 1e-6); the
// reading against the reference too. Returns the row.
template <typename JetT>
std::vector<double> ExpectRowMatches(const MeasurementModel& model, const ModelPoint& point,
                                     const std::vector<double>& e,
                                     const TargetedConfigurations& configs, int i) {
  const int n = model.num_parameters(), plane = configs.target(i);
  const double* q = configs.q(i);
  double h = 0;
  std::vector<double> row(n);
  model.Evaluate(point, configs, i, &h, row.data());
  EXPECT_NEAR(h, model.Distance<double>(e.data(), q, plane), 1e-12);
  std::vector<JetT> ej(n);
  for (int k = 0; k < n; ++k) ej[k] = JetT(e[k], k);
  const JetT hj = model.Distance<JetT>(ej.data(), q, plane);
  EXPECT_NEAR(hj.a, h, 1e-12);
  const double step = 1e-6;
  for (int k = 0; k < n; ++k) {
    const std::string& name = model.parameters().names[k];
    EXPECT_NEAR(row[k], hj.v[k], kAutodiffTolerance)
        << "d h / d " << name << " at configuration " << i;
    std::vector<double> ep = e, em = e;
    ep[k] += step;
    em[k] -= step;
    const double fd = (model.Distance<double>(ep.data(), q, plane) -
                       model.Distance<double>(em.data(), q, plane)) /
                      (2 * step);
    EXPECT_NEAR(row[k], fd, kFiniteDifferenceTolerance) << "d h / d " << name;
  }
  return row;
}

TEST_P(JacobianTest, AnalyticMatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobot();
  MeasurementModel model(
      robot, testing::PaperPlane(),
      MakeParameterSet(robot, GetParam().terms, GetParam().fixed, "--fix", GetParam().ranger));
  const int n = model.num_parameters();
  ASSERT_LE(n, kMaxParams);
  TargetedConfigurations configs = testing::PaperHittingConfigurations(30, 3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ue(-0.01, 0.01);
  for (int point_index = 0; point_index < 3; ++point_index) {
    std::vector<double> e(n, 0.0);
    if (point_index > 0)
      for (double& v : e) v = ue(rng);  // away from nominal too
    ModelPoint point;
    model.Prepare(e.data(), &point);
    for (int i = 0; i < configs.size(); ++i) ExpectRowMatches<Jet>(model, point, e, configs, i);
  }
}

INSTANTIATE_TEST_SUITE_P(
    PlaneTerms, JacobianTest,
    ::testing::Values(Case{PlaneTerms{false, false}, {}}, Case{PlaneTerms{true, false}, {}},
                      Case{PlaneTerms{false, true}, {}}, Case{PlaneTerms{true, true}, {}},
                      Case{PlaneTerms{true, true}, {"plane_u1", "d1"}},
                      Case{PlaneTerms{false, false}, {}, RangerTerms{true, false}},
                      Case{PlaneTerms{false, false}, {}, RangerTerms{false, true}},
                      Case{PlaneTerms{true, true}, {}, RangerTerms{true, true}}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string name = info.param.terms.normal ? "Normal" : "";
      name += info.param.terms.offset ? "Offset" : "";
      if (name.empty()) name = "PlaneKnown";
      if (!info.param.fixed.empty()) name += "SomeFixed";
      if (info.param.ranger.offset) name += "RangerOffset";
      if (info.param.ranger.scale) name += "RangerScale";
      return name;
    });

// A tilted, shifted base and a ranger mounted off the flange: the analytic Jacobian (fast path,
// frames in the base frame) against autodiff through the reference kinematics and against
// central differences, every plane term and both ranger terms estimated.
TEST(JacobianWithFrames, AnalyticMatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const Plane plane = Plane::FromCoefficients(0.2, -0.3, 1.0, 0.8);
  MeasurementModel model(
      robot, plane,
      MakeParameterSet(robot, PlaneTerms{true, true}, {}, "--fix", RangerTerms{true, true}));
  const int n = model.num_parameters();
  ASSERT_LE(n, kMaxParams);
  const TargetedConfigurations configs = testing::ConfigurationsFacing(robot, plane, 30, 7);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> ue(-0.01, 0.01);
  std::vector<double> e(n);
  for (double& v : e) v = ue(rng);
  ModelPoint point;
  model.Prepare(e.data(), &point);
  for (int i = 0; i < configs.size(); ++i) ExpectRowMatches<Jet>(model, point, e, configs, i);
}

// A tilted, shifted base and a ranger off the flange, every term estimated (25 link values,
// the plane's three, the ranger's two and both frames' twelve: 42), at the nominal estimate and
// away from it.
TEST(JacobianWithFrameTerms, AnalyticMatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const Plane plane = Plane::FromCoefficients(0.2, -0.3, 1.0, 0.8);
  const MeasurementModel model(
      robot, plane,
      MakeParameterSet(robot, PlaneTerms{true, true}, {}, "--fix", RangerTerms{true, true},
                       FrameTerms::Parse("all", "b"), FrameTerms::Parse("all", "t")));
  const int n = model.num_parameters();
  ASSERT_EQ(n, 42);
  ASSERT_LE(n, 48);
  const TargetedConfigurations configs = testing::ConfigurationsFacing(robot, plane, 25, 5);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> ue(-0.02, 0.02);
  for (int at = 0; at < 2; ++at) {
    std::vector<double> e(n, 0.0);
    if (at == 1)
      for (double& v : e) v = ue(rng);
    ModelPoint point;
    model.Prepare(e.data(), &point);
    for (int i = 0; i < configs.size(); ++i) ExpectRowMatches<WideJet>(model, point, e, configs, i);
  }
}

// The same on a robot whose nominal frames are the identity (the paper's arm), a subset of each
// frame's terms estimated.
TEST(JacobianWithFrameTerms, SubsetsOnTheIdentityFrames) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(
      robot, testing::PaperPlane(),
      MakeParameterSet(robot, PlaneTerms{}, {}, "--fix", RangerTerms{},
                       FrameTerms::Parse("y,roll,yaw", "b"), FrameTerms::Parse("x,z,pitch", "t")));
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(20, 4);
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> ue(-0.01, 0.01);
  std::vector<double> e(model.num_parameters());
  for (double& v : e) v = ue(rng);
  ModelPoint point;
  model.Prepare(e.data(), &point);
  for (int i = 0; i < configs.size(); ++i) ExpectRowMatches<WideJet>(model, point, e, configs, i);
}

// Three planes, every plane term and both ranger terms estimated (36 parameters): each row's
// Jacobian has its own plane's columns and zeros in the other planes' columns, and matches
// autodiff and central differences. Rows alternate between planes.
TEST(JacobianSeveralPlanes, AnalyticMatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobot();
  const PlaneSet planes({testing::PaperPlane(), Plane::FromCoefficients(1, 0, 0, 0.9),
                         Plane::FromCoefficients(0, 1, 0, 0.9)},
                        {});
  MeasurementModel model(robot, planes,
                         MakeParameterSet(robot, std::vector<PlaneTerms>(3, PlaneTerms{true, true}),
                                          {}, "--fix", RangerTerms{true, true}));
  constexpr int kParams = 36;
  using BigJet = ceres::Jet<double, kParams>;
  ASSERT_EQ(model.num_parameters(), kParams);
  TargetedConfigurations configs(6);
  for (int k = 0; k < 8; ++k)
    for (int p = 0; p < 3; ++p)
      configs.Add(testing::HittingConfigurations(planes[p], 8, 5 + p).q(k), p);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> ue(-0.01, 0.01);
  std::vector<double> e(kParams);
  for (double& v : e) v = ue(rng);
  ModelPoint point;
  model.Prepare(e.data(), &point);
  const ParameterSet& ps = model.parameters();
  for (int i = 0; i < configs.size(); ++i) {
    const int plane = configs.target(i);
    const std::vector<double> row = ExpectRowMatches<BigJet>(model, point, e, configs, i);
    for (int p = 0; p < 3; ++p) {
      const PlaneColumns& c = ps.plane_columns[p];
      for (int k : {c.u[0], c.u[1], c.f}) {
        if (p == plane) {
          EXPECT_NE(row[k], 0.0) << ps.names[k] << " at configuration " << i;
        } else {
          EXPECT_EQ(row[k], 0.0) << ps.names[k] << " at configuration " << i;
        }
      }
    }
  }
}

// A measurement model needs one set of plane terms per plane.
TEST(JacobianSeveralPlanes, PlaneTermsMustMatchThePlanes) {
  const RobotModel& robot = testing::PaperRobot();
  const PlaneSet planes({testing::PaperPlane(), Plane::FromCoefficients(1, 0, 0, 0.9)}, {});
  EXPECT_ANY_THROW(MeasurementModel(robot, planes, MakeParameterSet(robot, PlaneTerms{})));
}

TEST(NormalChart, RegularAtThePapersPlaneAndEverywhere) {
  // The paper's plane has n_x = 0; the chart's Jacobian must still have full rank 2 there and
  // at the coordinate axes, and n(u) must be a unit vector.
  for (Eigen::Vector3d n0 : {Eigen::Vector3d(0, 1, 4.6).normalized(), Eigen::Vector3d(1, 0, 0),
                             Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(1, 1, 1).normalized()}) {
    NormalChart chart(n0);
    Eigen::Vector3d n;
    Eigen::Matrix<double, 3, 2> J;
    chart.NormalAndJacobian(0, 0, &n, &J);
    EXPECT_LT((n - n0).norm(), 1e-15);
    EXPECT_NEAR(J.col(0).norm(), 1.0, 1e-15);
    EXPECT_NEAR(J.col(1).norm(), 1.0, 1e-15);
    EXPECT_NEAR(J.col(0).dot(J.col(1)), 0.0, 1e-15);
    EXPECT_NEAR(J.col(0).dot(n0), 0.0, 1e-15);
    chart.NormalAndJacobian(0.3, -0.2, &n, &J);
    EXPECT_NEAR(n.norm(), 1.0, 1e-15);
  }
}

TEST(Plane, HugeOrTinyCoefficientsNormaliseInsteadOfVanishing) {
  // |n|² of (1e200, 0, 0) overflows: the normal used to become 0 and every beam "parallel".
  const Plane big = Plane::FromCoefficients(1e200, 0, 0, -0.5e200);
  EXPECT_EQ(big.normal, Eigen::Vector3d(1, 0, 0));
  EXPECT_DOUBLE_EQ(big.offset, -0.5);
  const Plane tiny = Plane::FromCoefficients(0, 3e-200, 4e-200, 5e-200);
  EXPECT_NEAR(tiny.normal.y(), 0.6, 1e-15);
  EXPECT_NEAR(tiny.normal.z(), 0.8, 1e-15);
  EXPECT_NEAR(tiny.offset, 1.0, 1e-15);
  // Ordinary planes keep their bits (the paper's plane, normalised as ever).
  const Plane paper = Plane::FromCoefficients(0, 1, 4.6, -0.69);
  const Eigen::Vector3d n(0, 1, 4.6);
  EXPECT_EQ(paper.normal, n / n.norm());
  EXPECT_THROW(Plane::FromCoefficients(0, 0, 0, 1), InputError);
  EXPECT_THROW(Plane::FromCoefficients(1e-300, 0, 0, 1e300), InputError);  // |f|/|n| overflows
}

TEST(ClassifyReading, ReportsEveryMissReason) {
  RangerSpec ranger;  // 0.05 .. 3 m, 70°
  EXPECT_EQ(ClassifyReading(1.0, -0.9, ranger), BeamMiss::kNone);
  EXPECT_EQ(ClassifyReading(1.0, 0.0, ranger), BeamMiss::kParallel);
  EXPECT_EQ(ClassifyReading(-1.0, 0.9, ranger), BeamMiss::kBehind);
  EXPECT_EQ(ClassifyReading(5.0, 0.9, ranger), BeamMiss::kOutOfRange);
  EXPECT_EQ(ClassifyReading(0.01, 0.9, ranger), BeamMiss::kOutOfRange);
  EXPECT_EQ(ClassifyReading(1.0, 0.2, ranger), BeamMiss::kGrazing);
}

}  // namespace
}  // namespace lrcal
