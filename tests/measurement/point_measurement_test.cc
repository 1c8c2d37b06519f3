// The tracker's point measurement (point_measurement.h): its analytic Jacobian against Ceres
// autodiff through the independent reference kinematics and against central differences, its
// simulation's noise, its identifiability against an independent rank, and a noise-free round
// trip through the identification (identification_test.cc has the ranger's).
#include "lrcal/measurement/point_measurement.h"

#include <ceres/jet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <random>

#include "lrcal/core/error.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "test_util.h"
#include "tracker_fixtures.h"

namespace lrcal {
namespace {

using testing::EigenNear;
using ::testing::HasSubstr;
namespace tolerance = testing::tolerance;

constexpr int kMaxTerms = 48;
using TermJet = ceres::Jet<double, kMaxTerms>;

using testing::AllTrackerTerms;
using testing::TrackerSetup;

TargetedConfigurations RandomConfigurations(const RobotModel& robot, int count, int targets,
                                            unsigned seed) {
  return testing::RandomTrackerConfigurations(robot.num_links(), count, targets, seed);
}

// The point in the instrument's frame written out independently of the library: the reference
// kinematics, the instrument's orientation as R_BI0·Rz(yaw)·Ry(pitch)·Rx(roll) from Eigen's
// angle-axis rotations, with every term (estimated or not) taken from `all` (AllTermNames order).
template <typename T>
Eigen::Matrix<T, 3, 1> ReferencePoint(const PointMeasurement& kind, const std::vector<T>& all,
                                      const double* q, int target) {
  const RobotModel& robot = kind.robot();
  std::vector<T> values(robot.num_values());
  for (int k = 0; k < robot.num_values(); ++k) values[k] = T(robot.nominal_values()[k]);
  const std::vector<std::string> names = kind.AllTermNames();
  int column = 0;
  for (; column < static_cast<int>(names.size()); ++column) {
    const int index = robot.FindValue(names[column]);
    if (index < 0) break;
    values[index] += all[column];
  }
  const Pose<T> pose = ForwardKinematics<T>(robot, values.data(), q);
  const T* inst = &all[column];
  using V = Eigen::Matrix<T, 3, 1>;
  const Eigen::Matrix<T, 3, 3> R_BI = kind.setup().instrument.rotation.cast<T>() *
                                      Eigen::AngleAxis<T>(inst[5], V::UnitZ()).toRotationMatrix() *
                                      Eigen::AngleAxis<T>(inst[4], V::UnitY()).toRotationMatrix() *
                                      Eigen::AngleAxis<T>(inst[3], V::UnitX()).toRotationMatrix();
  const V p_BI = kind.setup().instrument.translation.cast<T>() + V(inst[0], inst[1], inst[2]);
  const T* t = &all[column + 6 + 3 * target];
  const V offset = kind.setup().targets[target].cast<T>() + V(t[0], t[1], t[2]);
  return R_BI.transpose() * (pose.p_BT + pose.R_BT * offset - p_BI);
}

class PointJacobianTest : public ::testing::TestWithParam<std::vector<std::string>> {};

TEST_P(PointJacobianTest, MatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PointMeasurement kind(robot, TrackerSetup(), GetParam());
  const TargetedConfigurations configs = RandomConfigurations(robot, 12, 2, 7);
  const int n = kind.num_parameters(), m = 3 * configs.size();
  ASSERT_LE(n, kMaxTerms);
  const std::vector<double> e = testing::OffNominalEstimate(kind);
  std::unique_ptr<MeasurementEvaluator> evaluator = kind.Bind(configs);
  std::vector<double> y(m);
  Eigen::MatrixXd J(m, n);
  ASSERT_TRUE(evaluator->Predict(e.data(), y.data(), J.data()));

  std::vector<TermJet> ej(n);
  for (int k = 0; k < n; ++k) ej[k] = TermJet(e[k], k);
  const std::vector<TermJet> all_jets = AllTrackerTerms(kind, ej);
  Eigen::MatrixXd autodiff(m, n);
  Eigen::VectorXd reference(m);
  for (int i = 0; i < configs.size(); ++i) {
    const Eigen::Matrix<TermJet, 3, 1> p =
        ReferencePoint(kind, all_jets, configs.q(i), configs.target(i));
    for (int c = 0; c < 3; ++c) {
      reference[3 * i + c] = p[c].a;
      for (int k = 0; k < n; ++k) autodiff(3 * i + c, k) = p[c].v[k];
    }
  }
  const Eigen::MatrixXd central = testing::CentralDifferences(*evaluator, e);
  EXPECT_THAT(Eigen::Map<Eigen::VectorXd>(y.data(), m), EigenNear(reference, tolerance::kUrdf));
  EXPECT_THAT(J, EigenNear(autodiff, tolerance::kAutodiff));
  EXPECT_THAT(J, EigenNear(central, tolerance::kCentralDifference));
}

INSTANTIATE_TEST_SUITE_P(Terms, PointJacobianTest,
                         ::testing::Values(std::vector<std::string>{},
                                           std::vector<std::string>{"instrument_roll", "target2_y",
                                                                    "theta1", "d6"},
                                           std::vector<std::string>{"instrument_x", "instrument_y",
                                                                    "instrument_z", "target1_x"}));

TEST(PointMeasurement, NoiseFreeIdentificationRecoversTheTruth) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PointMeasurement full(robot, TrackerSetup());
  const TargetedConfigurations configs = RandomConfigurations(robot, 60, 2, 11);
  // The terms a point cannot see (found by the analysis) are held at nominal in the truth too.
  const IdentifiabilityReport report = AnalyzeIdentifiability(full, configs);
  ASSERT_FALSE(report.full_rank());
  const std::unique_ptr<MeasurementKind> kind = full.Without(report.suggested_fixed);
  const auto& point_kind = dynamic_cast<const PointMeasurement&>(*kind);
  // Truth: every identifiable term off nominal by 1–3 mm or 1–3 mrad.
  testing::ExpectNoiseFreeRoundTrip(point_kind, configs, testing::SomeTruth(*kind, 5));
}

TEST(PointMeasurement, IdentifiabilityRankMatchesAnIndependentJacobian) {
  const RobotModel& robot = testing::PaperRobot();
  const PointMeasurement kind(robot, TrackerSetup());
  const TargetedConfigurations configs = RandomConfigurations(robot, 40, 2, 3);
  const IdentifiabilityReport report = AnalyzeIdentifiability(kind, configs);
  // The rank of central differences of the reference point, columns scaled to unit norm.
  const int n = kind.num_parameters(), m = 3 * configs.size();
  Eigen::MatrixXd G(m, n);
  constexpr double kStep = 1e-6;
  for (int k = 0; k < n; ++k) {
    std::vector<double> ep(n, 0.0), em(n, 0.0);
    ep[k] = kStep;
    em[k] = -kStep;
    const std::vector<double> ap = AllTrackerTerms(kind, ep), am = AllTrackerTerms(kind, em);
    for (int i = 0; i < configs.size(); ++i) {
      const Eigen::Vector3d d = (ReferencePoint(kind, ap, configs.q(i), configs.target(i)) -
                                 ReferencePoint(kind, am, configs.q(i), configs.target(i))) /
                                (2 * kStep);
      G.block<3, 1>(3 * i, k) = d;
    }
  }
  for (int k = 0; k < n; ++k)
    if (G.col(k).norm() > 1e-9) G.col(k).normalize();
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(G).singularValues();
  int rank = 0;
  for (int k = 0; k < sv.size(); ++k) rank += sv[k] > 1e-6 * sv[0];
  EXPECT_EQ(report.rank, rank) << report.ToString();
  EXPECT_EQ(report.num_params(), static_cast<int>(report.suggested_fixed.size()) + report.rank);
  // A shift of the instrument along z and of the first joint's d move every point alike.
  EXPECT_THAT(report.suggested_fixed, ::testing::Contains(::testing::AnyOf("d1", "instrument_z")));
}

TEST(PointMeasurement, SimulatedNoiseHasTheStatedLaw) {
  const RobotModel& robot = testing::PaperRobot();
  const PointMeasurement kind(robot, TrackerSetup());
  const TargetedConfigurations configs = RandomConfigurations(robot, 2000, 2, 9);
  NoiseModel noise;
  noise.sigma = 1e-3;
  noise.repetitions = 4;
  const RandomStream stream(3, 0, 0, RandomPurpose::kNoise);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(kind.num_parameters());
  std::vector<double> exact(3 * configs.size());
  kind.Bind(configs)->Predict(zero.data(), exact.data(), nullptr);
  for (bool draw_mean : {false, true}) {
    noise.draw_mean = draw_mean;
    MeasuredValues data;
    ASSERT_EQ(SimulateMeasurements(kind, configs, noise, stream, &data), 0);
    ASSERT_EQ(data.y.size(), exact.size());
    double sum = 0, sum2 = 0;
    for (std::size_t r = 0; r < exact.size(); ++r) {
      const double error = data.y[r] - exact[r];
      sum += error;
      sum2 += error * error;
    }
    const double count = static_cast<double>(exact.size());
    const double expected_sd = noise.sigma / 2;  // σ/√R
    // The mean within 4 standard errors; the variance within 4 of its standard errors
    // (√(2/count) relative for a normal sample).
    EXPECT_NEAR(sum / count, 0.0, 4 * expected_sd / std::sqrt(count)) << draw_mean;
    EXPECT_NEAR(sum2 / count / (expected_sd * expected_sd), 1.0, 4 * std::sqrt(2 / count))
        << draw_mean;
  }
  noise.outlier_fraction = 0.1;
  MeasuredValues data;
  try {
    SimulateMeasurements(kind, configs, noise, stream, &data);
    ADD_FAILURE() << "outliers were accepted for the point measurement";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("outliers is simulated for the ranger only"));
  }
}

TEST(PointMeasurement, BadTermsAndTargetsAreNamed) {
  const RobotModel& robot = testing::PaperRobot();
  try {
    PointMeasurement(robot, TrackerSetup(), {"instrument_w"}, "--fix");
    ADD_FAILURE() << "an unknown term was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--fix"));
    EXPECT_THAT(e.what(), HasSubstr("'instrument_w' is not a term of the point measurement: "
                                    "expected a robot parameter, instrument_x … instrument_yaw, "
                                    "or target1_x … target2_z"));
  }
  PointSetup none = TrackerSetup();
  none.targets.clear();
  EXPECT_THAT([&] { PointMeasurement(robot, none); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("point.targets: expected 1 to 16 targets, got 0")));
  PointSetup far = TrackerSetup();
  far.targets[1].x() = std::nan("");
  EXPECT_THAT([&] { far.Validate(); }, ::testing::ThrowsMessage<InputError>(HasSubstr(
                                           "point.targets[1]: expected a finite offset")));
  PointSetup one = TrackerSetup();
  one.targets.resize(1);
  const PointMeasurement kind(robot, one);
  EXPECT_THAT(kind.parameter_names(), ::testing::Contains("target_x"));
  EXPECT_EQ(DisplayUnitOf("instrument_yaw").unit, std::string("mrad"));
  const TargetedConfigurations configs = RandomConfigurations(robot, 4, 2, 1);  // target index 1
  try {
    kind.Bind(configs);
    ADD_FAILURE() << "a configuration naming a missing target was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("names target 2 but the set-up has 1 target(s)"));
  }
}

}  // namespace
}  // namespace lrcal
