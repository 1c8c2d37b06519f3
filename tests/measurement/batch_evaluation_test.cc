// The structure-of-arrays kernel against the per-configuration evaluation, for every choice of
// plane terms and for a prismatic joint.
#include "measurement/batch_evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "lrcal/core/hash.h"
#include "test_util.h"

namespace lrcal {
namespace {

// Same formulas, different order of operations: agreement to a few ulps of O(1) values.
constexpr double kTolerance = 1e-13;

void ExpectSame(const MeasurementModel& model, const TargetedConfigurations& configs,
                Isa isa = ActiveIsa()) {
  const int n = model.num_parameters(), m = configs.size();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ue(-0.01, 0.01);
  std::vector<double> e(n);
  for (double& v : e) v = ue(rng);
  ModelPoint point;
  model.Prepare(e.data(), &point);
  BatchEvaluator batch;
  batch.SetConfigurations(configs);
  std::vector<double> h(m), J(static_cast<std::size_t>(m) * n), h_only(m);
  batch.Evaluate(model, point, h.data(), J.data(), isa);
  batch.Evaluate(model, point, h_only.data(), nullptr, isa);
  std::vector<double> row(n);
  for (int i = 0; i < m; ++i) {
    double hi;
    model.Evaluate(point, configs, i, &hi, row.data());
    EXPECT_NEAR(h[i], hi, kTolerance);
    EXPECT_EQ(h[i], h_only[i]);
    for (int k = 0; k < n; ++k)
      EXPECT_NEAR(J[static_cast<std::size_t>(k) * m + i], row[k], kTolerance)
          << model.parameters().names[k] << " at configuration " << i << ", " << IsaName(isa);
  }
}

TEST(BatchEvaluator, MatchesPerConfigurationEvaluationForEveryPlaneTerm) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(37);
  for (PlaneTerms terms : {PlaneTerms{false, false}, PlaneTerms{true, false},
                           PlaneTerms{false, true}, PlaneTerms{true, true}}) {
    MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, terms));
    ExpectSame(model, configs);
    for (RangerTerms ranger :
         {RangerTerms{true, false}, RangerTerms{false, true}, RangerTerms{true, true}}) {
      MeasurementModel with_ranger(robot, testing::PaperPlane(),
                                   MakeParameterSet(robot, terms, {}, "--fix", ranger));
      ExpectSame(with_ranger, configs);
    }
  }
}

// Several planes: rows on different planes in one batch (the kernel's per-row plane path), with
// each plane's terms estimated or not, and with only one of three planes referenced (the
// one-plane path with another plane's columns present).
TEST(BatchEvaluator, MatchesPerConfigurationEvaluationWithSeveralPlanes) {
  const RobotModel& robot = testing::PaperRobot();
  const PlaneSet planes({testing::PaperPlane(), Plane::FromCoefficients(1, 0, 0, 0.9),
                         Plane::FromCoefficients(0, 1, 0, 0.9)},
                        {});
  TargetedConfigurations mixed(6), second_only(6);
  for (int k = 0; k < 13; ++k)
    for (int p = 0; p < 3; ++p) {
      const TargetedConfigurations c = testing::HittingConfigurations(planes[p], 13, 2 + p);
      mixed.Add(c.q(k), p);
      if (p == 1) second_only.Add(c.q(k), 1);
    }
  const std::vector<PlaneTerms> all(3, PlaneTerms{true, true});
  const std::vector<PlaneTerms> some{PlaneTerms{true, false}, PlaneTerms{},
                                     PlaneTerms{false, true}};
  for (const auto& terms : {all, some}) {
    MeasurementModel model(robot, planes,
                           MakeParameterSet(robot, terms, {}, "--fix", RangerTerms{true, true}));
    ExpectSame(model, mixed);
    ExpectSame(model, second_only);
  }
  // A row on a plane the model lacks is refused, not read out of bounds.
  MeasurementModel one(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  BatchEvaluator batch;
  batch.SetConfigurations(mixed);
  ModelPoint point;
  std::vector<double> e(one.num_parameters(), 0.0);
  one.Prepare(e.data(), &point);
  std::vector<double> h(mixed.size());
  EXPECT_THROW(batch.Evaluate(one, point, h.data(), nullptr), std::invalid_argument);
}

// Three links, the middle one prismatic, every link value estimated, and its model on one plane.
const RobotModel& PrismaticRobot() {
  static const RobotModel robot = [] {
    std::vector<Link> links(3);
    links[0].nominal = {0.1, -1.2, 0.3, 0.5, 0.0};
    links[1].joint = JointType::kPrismatic;
    links[1].nominal = {0.4, 0.7, 0.2, 0.1, 0.05};
    links[1].q_min = 0;
    links[1].q_max = 1;
    links[2].nominal = {-0.3, 0.0, 0.4, 0.2, 0.02};
    for (auto& l : links) l.is_parameter = {true, true, true, true, true};
    return RobotModel("three", links);
  }();
  return robot;
}

MeasurementModel PrismaticModel(const RobotModel& robot) {
  return MeasurementModel(robot, Plane::FromCoefficients(0.1, 0.2, 1.0, 2.0),
                          MakeParameterSet(robot, PlaneTerms{true, true}));
}

TEST(BatchEvaluator, MatchesWithAPrismaticJoint) {
  const RobotModel& robot = PrismaticRobot();
  const MeasurementModel model = PrismaticModel(robot);
  TargetedConfigurations configs(3);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 20; ++i) configs.Add(std::vector<double>{u(rng), 0.5 + 0.4 * u(rng), u(rng)});
  ExpectSame(model, configs);
}

TEST(BatchEvaluator, MatchesWithBaseAndToolTransforms) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const Plane plane = Plane::FromCoefficients(0.2, -0.3, 1.0, 0.8);
  MeasurementModel model(robot, plane, MakeParameterSet(robot, PlaneTerms{true, true}));
  ExpectSame(model, testing::ConfigurationsFacing(robot, plane, 40, 4));
}

// Three planes around the paper's arm, and 13 configurations facing each (tagged with its plane).
PlaneSet ThreePlanes() {
  return PlaneSet(
      {Plane::FromCoefficients(0.2, -0.3, 1.0, 0.8), Plane::FromCoefficients(1, 0.1, 0, 0.9),
       Plane::FromCoefficients(0, 1, 0.2, 0.9)},
      {});
}

TargetedConfigurations FacingEachPlane(const RobotModel& robot, const PlaneSet& planes) {
  TargetedConfigurations mixed(robot.num_links());
  for (int p = 0; p < planes.size(); ++p) {
    const TargetedConfigurations facing =
        testing::ConfigurationsFacing(robot, planes[p], 13, 3 + p);
    for (int i = 0; i < facing.size(); ++i) mixed.Add(facing.q(i), p);
  }
  return mixed;
}

// A model on those planes with every plane term, the ranger's terms, the base's x, z and
// rotations and all of the tool's terms estimated.
MeasurementModel ThreePlaneModel(const RobotModel& robot, const PlaneSet& planes) {
  return MeasurementModel(
      robot, planes,
      MakeParameterSet(robot, std::vector<PlaneTerms>(3, PlaneTerms{true, true}), {}, "--fix",
                       RangerTerms{true, true}, FrameTerms::Parse("x,z,rpy", "t"),
                       FrameTerms::Parse("all", "base")));
}

// The base's and the tool's terms estimated (parameter_set.h FrameTerms): the kernel computes
// their columns from its own arrays, on one plane and on three, on every instruction set.
TEST(BatchEvaluator, MatchesWithEstimatedBaseAndToolTermsOnEveryVariant) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PlaneSet planes = ThreePlanes();
  const TargetedConfigurations mixed = FacingEachPlane(robot, planes);
  const FrameTerms all = FrameTerms::Parse("all", "base"), some = FrameTerms::Parse("x,z,rpy", "t");
  const MeasurementModel one(robot, PlaneSet({planes[0]}, {}),
                             MakeParameterSet(robot, PlaneTerms{true, true}, {}, "--fix",
                                              RangerTerms{true, true}, all, some));
  const MeasurementModel three = ThreePlaneModel(robot, planes);
  for (Isa isa : SupportedIsas()) {
    ExpectSame(one, testing::ConfigurationsFacing(robot, planes[0], 30, 3), isa);
    ExpectSame(three, mixed, isa);
  }
}

// The bits themselves: a fingerprint (core/hash.h's FNV-1a of the bytes) of the readings and the
// Jacobian of three models, equal to that of the structure-of-arrays kernel this one replaced
// (lrcal 3d70741).
// Study tables are reproducible across versions only while these hold; a change of the
// kernel's arithmetic, even by an ulp, changes them (and then the golden tables).
std::uint64_t Fingerprint(const MeasurementModel& model, const TargetedConfigurations& configs,
                          Isa isa) {
  const int n = model.num_parameters(), m = configs.size();
  std::vector<double> e(n);
  for (int k = 0; k < n; ++k) e[k] = 1e-3 * std::sin(1.0 + k);
  ModelPoint point;
  model.Prepare(e.data(), &point);
  BatchEvaluator batch;
  batch.SetConfigurations(configs);
  std::vector<double> values(m + static_cast<std::size_t>(m) * n);
  batch.Evaluate(model, point, values.data(), values.data() + m, isa);
  return Fnv1a(
      std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double)));
}

TEST(BatchEvaluator, KeepsTheBitsOfEarlierVersions) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PlaneSet planes = ThreePlanes();
  const TargetedConfigurations mixed = FacingEachPlane(robot, planes);
  const MeasurementModel three = ThreePlaneModel(robot, planes);
  const MeasurementModel paper(testing::PaperRobot(), testing::PaperPlane(),
                               MakeParameterSet(testing::PaperRobot(), PlaneTerms{true, true}));
  const MeasurementModel prismatic = PrismaticModel(PrismaticRobot());
  TargetedConfigurations prismatic_configs(3);
  for (int i = 0; i < 21; ++i)
    prismatic_configs.Add(
        std::vector<double>{std::sin(0.3 * i), 0.5 + 0.4 * std::cos(0.7 * i), std::sin(1.1 * i)});
  for (Isa isa : SupportedIsas()) {
    EXPECT_EQ(Fingerprint(three, mixed, isa), 14358357692654284885ull) << IsaName(isa);
    EXPECT_EQ(Fingerprint(paper, testing::PaperHittingConfigurations(101), isa),
              1945727211899323826ull)
        << IsaName(isa);
    EXPECT_EQ(Fingerprint(prismatic, prismatic_configs, isa), 16567870222553167440ull)
        << IsaName(isa);
  }
}

// Rebinding keeps the arrays only for the configurations already taken: another set of the
// same size, one joint of one configuration changed (to 0, to −0, by one ulp) or one target
// alone, evaluates as a fresh evaluator bound to it does (dropping either comparison of
// SetConfigurations fails this test).
TEST(BatchEvaluator, RebindingTakesEveryChangeOfTheConfigurations) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PlaneSet planes = ThreePlanes();
  const MeasurementModel three = ThreePlaneModel(robot, planes);
  const TargetedConfigurations mixed = FacingEachPlane(robot, planes);
  const auto with = [&](int changed, double q_value, int target) {
    TargetedConfigurations out(robot.num_links());
    for (int i = 0; i < mixed.size(); ++i) {
      std::vector<double> q(mixed.q(i), mixed.q(i) + robot.num_links());
      if (i == changed && q_value == q_value) q[2] = q_value;
      out.Add(q, i == changed && target >= 0 ? target : mixed.target(i));
    }
    return out;
  };
  const std::vector<TargetedConfigurations> sets = {mixed,
                                                    with(5, 0.0, -1),
                                                    with(5, -0.0, -1),  // the sign of zero alone
                                                    with(5, -0.0, 2),   // the target alone
                                                    with(5, std::nextafter(0.0, 1), 2),  // one ulp
                                                    mixed};
  std::vector<double> e(three.num_parameters(), 1e-3);
  ModelPoint point;
  three.Prepare(e.data(), &point);
  const int m = mixed.size(), n = three.num_parameters();
  BatchEvaluator reused;
  for (std::size_t k = 0; k < sets.size(); ++k) {
    BatchEvaluator fresh;
    fresh.SetConfigurations(sets[k]);
    reused.SetConfigurations(sets[k]);
    std::vector<double> a(m + static_cast<std::size_t>(m) * n), b(a.size());
    fresh.Evaluate(three, point, a.data(), a.data() + m);
    reused.Evaluate(three, point, b.data(), b.data() + m);
    EXPECT_EQ(Fnv1a(std::string(reinterpret_cast<const char*>(a.data()), a.size() * 8)),
              Fnv1a(std::string(reinterpret_cast<const char*>(b.data()), b.size() * 8)))
        << "set " << k;
  }
}

// Weighted rows (the solver's √w): J(i, k) · w[i] bit for bit as a separate pass gives it, for a
// model whose J the kernel finishes (weighted as it stores) and for one whose ranger terms
// change J after the kernel (weighted in a pass of its own), on every variant, with a number of
// configurations that leaves a partial block.
TEST(BatchEvaluator, WeightsRowsAsASeparatePassWould) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PlaneSet planes = ThreePlanes();
  const TargetedConfigurations mixed = FacingEachPlane(robot, planes);  // 39: 8·4 + 7
  const MeasurementModel with_ranger = ThreePlaneModel(robot, planes);
  const MeasurementModel without_ranger(
      robot, planes,
      MakeParameterSet(robot, std::vector<PlaneTerms>(3, PlaneTerms{true, true}), {}, "--fix",
                       RangerTerms{}, FrameTerms::Parse("x,z,rpy", "t"),
                       FrameTerms::Parse("all", "base")));
  ASSERT_GE(with_ranger.parameters().ranger_scale_index, 0);
  ASSERT_LT(without_ranger.parameters().ranger_offset_index, 0);
  ASSERT_LT(without_ranger.parameters().ranger_scale_index, 0);
  const int m = mixed.size();
  std::vector<double> w(m);
  for (int i = 0; i < m; ++i) w[i] = std::sqrt(1.0 + 0.37 * i);
  for (const MeasurementModel* model : {&with_ranger, &without_ranger}) {
    const int n = model->num_parameters();
    std::vector<double> e(n);
    for (int k = 0; k < n; ++k) e[k] = 1e-3 * std::cos(2.0 + k);
    ModelPoint point;
    model->Prepare(e.data(), &point);
    BatchEvaluator batch;
    batch.SetConfigurations(mixed);
    for (Isa isa : SupportedIsas()) {
      std::vector<double> h(m), J(static_cast<std::size_t>(m) * n), hw(m), Jw(J.size());
      batch.Evaluate(*model, point, h.data(), J.data(), isa);
      batch.Evaluate(*model, point, hw.data(), Jw.data(), isa, w.data());
      for (int k = 0; k < n; ++k)
        for (int i = 0; i < m; ++i) J[static_cast<std::size_t>(k) * m + i] *= w[i];
      EXPECT_EQ(std::memcmp(h.data(), hw.data(), m * sizeof(double)), 0) << IsaName(isa);
      for (std::size_t at = 0; at < J.size(); ++at)
        ASSERT_EQ(std::memcmp(&J[at], &Jw[at], sizeof(double)), 0)
            << model->parameters().names[at / m] << " at configuration " << at % m << ", "
            << IsaName(isa) << ": " << J[at] << " against " << Jw[at];
    }
  }
}

}  // namespace
}  // namespace lrcal
