// The socket measurement (socket_measurement.h): its analytic Jacobian against Ceres autodiff
// through the reference kinematics and the sockets written out here, and against central
// differences; seating and its simulated play; identifiability with and without a length
// reference; a noise-free round trip through both solvers; and its located errors.
#include "lrcal/measurement/socket_measurement.h"

#include <ceres/jet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "lrcal/core/error.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/measurement/truth.h"
#include "test_util.h"
#include "tracker_fixtures.h"

namespace lrcal {
namespace {

using testing::EigenNear;
using ::testing::HasSubstr;
namespace tolerance = testing::tolerance;

constexpr int kMaxSocketTerms = 48;
using SocketJet = ceres::Jet<double, kMaxSocketTerms>;

// Two postures of the paper's arm whose tool points are the sockets.
const double kPostureA[6] = {0.3, -0.6, 1.1, 0.4, 0.9, -0.5};
const double kPostureB[6] = {-0.5, -0.4, 0.9, -0.6, 1.2, 0.7};

// Three sockets: 0 and 1 at the postures' tool points, 7 beside 0; socket 1 placed from 0 by a
// known distance (`with_distance`), the others free.
SocketSetup ThreeSockets(const RobotModel& robot, bool with_distance) {
  SocketSetup setup;
  setup.tool_point = Eigen::Vector3d(0.02, -0.01, 0.08);
  const auto point = [&](const double* q) {
    const Pose<double> pose = ForwardKinematics<double>(robot, robot.nominal_values().data(), q);
    return Eigen::Vector3d(pose.p_BT + pose.R_BT * setup.tool_point);
  };
  setup.ids = {0, 1, 7};
  setup.positions = {point(kPostureA), point(kPostureB),
                     point(kPostureA) + Eigen::Vector3d(0.04, -0.03, 0.01)};
  if (with_distance) setup.distances = {{0, 1, (setup.positions[1] - setup.positions[0]).norm()}};
  return setup;
}

// Starts near the postures (joints ±`spread` rad about them), configuration i in socket i mod 3.
TargetedConfigurations SocketStarts(int count, unsigned seed, double spread = 0.35) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> wiggle(-spread, spread);
  TargetedConfigurations starts(6);
  for (int i = 0; i < count; ++i) {
    const double* base = i % 3 == 1 ? kPostureB : kPostureA;
    std::vector<double> q(6);
    for (int j = 0; j < 6; ++j) q[j] = base[j] + wiggle(rng);
    starts.Add(q, i % 3);
  }
  return starts;
}

// The constraint y = p_BT + R_BT·t − s_k written out independently: the reference kinematics,
// socket 1 at D·v/|v| from socket 0 with its chart as the header states it.
template <typename T>
Eigen::Matrix<T, 3, 1> ReferenceResidual(const SocketMeasurement& kind, const std::vector<T>& all,
                                         const double* q, int socket) {
  using V = Eigen::Matrix<T, 3, 1>;
  const RobotModel& robot = kind.robot();
  const SocketSetup& setup = kind.setup();
  std::vector<T> values(robot.num_values());
  for (int k = 0; k < robot.num_values(); ++k) values[k] = T(robot.nominal_values()[k]);
  const std::vector<std::string> names = kind.AllTermNames();
  const auto term = [&](const std::string& name) {
    return all[static_cast<std::size_t>(std::find(names.begin(), names.end(), name) -
                                        names.begin())];
  };
  for (std::size_t c = 0; c < names.size(); ++c) {
    const int index = robot.FindValue(names[c]);
    if (index >= 0) values[index] += all[c];
  }
  const Pose<T> pose = ForwardKinematics<T>(robot, values.data(), q);
  const V t = setup.tool_point.cast<T>() + V(term("target_x"), term("target_y"), term("target_z"));
  const auto free_socket = [&](int k) {
    const int id = setup.ids[k];
    return V(setup.positions[k].cast<T>() + V(term(SocketTermName(id, "x")),
                                              term(SocketTermName(id, "y")),
                                              term(SocketTermName(id, "z"))));
  };
  V s;
  if (socket == 1 && !setup.distances.empty()) {
    const Eigen::Vector3d u0 = (setup.positions[1] - setup.positions[0]).normalized();
    Eigen::Index smallest;
    u0.cwiseAbs().minCoeff(&smallest);
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(smallest);
    const Eigen::Vector3d t1 = (axis - axis.dot(u0) * u0).normalized(), t2 = u0.cross(t1);
    const V v =
        u0.cast<T>() + term("socket1_u1") * t1.cast<T>() + term("socket1_u2") * t2.cast<T>();
    s = free_socket(0) + T(setup.distances[0].metres) * v / v.norm();
  } else {
    s = free_socket(socket);
  }
  return pose.p_BT + pose.R_BT * t - s;
}

class SocketJacobianTest
    : public ::testing::TestWithParam<std::pair<bool, std::vector<std::string>>> {};

TEST_P(SocketJacobianTest, MatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const SocketMeasurement kind(robot, ThreeSockets(robot, GetParam().first), GetParam().second);
  const TargetedConfigurations configs = SocketStarts(12, 5);
  const int n = kind.num_parameters(), m = 3 * configs.size();
  ASSERT_LE(n, kMaxSocketTerms);
  std::vector<double> e(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) e[k] = (k % 2 ? 1 : -1) * (0.002 + 0.0003 * k);
  std::unique_ptr<MeasurementEvaluator> evaluator = kind.Bind(configs);
  std::vector<double> y(m);
  Eigen::MatrixXd J(m, n);
  ASSERT_TRUE(evaluator->Predict(e.data(), y.data(), J.data()));

  std::vector<SocketJet> ej(n);
  for (int k = 0; k < n; ++k) ej[k] = SocketJet(e[k], k);
  const std::vector<SocketJet> all = testing::AllTrackerTerms(kind, ej);
  Eigen::MatrixXd autodiff(m, n);
  Eigen::VectorXd reference(m);
  for (int i = 0; i < configs.size(); ++i) {
    const Eigen::Matrix<SocketJet, 3, 1> r =
        ReferenceResidual(kind, all, configs.q(i), configs.target(i));
    for (int c = 0; c < 3; ++c) {
      reference[3 * i + c] = r[c].a;
      for (int k = 0; k < n; ++k) autodiff(3 * i + c, k) = r[c].v[k];
    }
  }
  EXPECT_THAT(Eigen::Map<Eigen::VectorXd>(y.data(), m), EigenNear(reference, tolerance::kUrdf));
  EXPECT_THAT(J, EigenNear(autodiff, tolerance::kAutodiff));
  EXPECT_THAT(J,
              EigenNear(testing::CentralDifferences(*evaluator, e), tolerance::kCentralDifference));
}

INSTANTIATE_TEST_SUITE_P(Terms, SocketJacobianTest,
                         ::testing::Values(std::make_pair(false, std::vector<std::string>{}),
                                           std::make_pair(true, std::vector<std::string>{}),
                                           std::make_pair(true, std::vector<std::string>{
                                                                    "socket1_u2", "socket0_y",
                                                                    "target_z", "theta1"})));

// The kind a campaign reads from when `kind`'s terms are off nominal by `truth`: the true arm
// (`*true_robot`, which must outlive it), tool point and sockets.
std::unique_ptr<SocketMeasurement> TrueSocketKind(const SocketMeasurement& kind,
                                                  const Eigen::VectorXd& truth,
                                                  RobotModel* true_robot) {
  const RobotModel& robot = kind.robot();
  Truth errors;
  errors.link_errors = Eigen::VectorXd::Zero(robot.num_values());
  for (std::size_t k = 0; k < kind.arm().robot_values().size(); ++k)
    errors.link_errors[kind.arm().robot_values()[k]] = truth[static_cast<Eigen::Index>(k)];
  *true_robot = errors.TrueRobot(robot);
  PointMeasurement::State arm;
  kind.arm().StateAt(truth.data(), &arm);
  SocketSetup setup = kind.setup();
  setup.tool_point = arm.targets[0];
  kind.SocketsAt(truth.data(), &setup.positions);
  return std::make_unique<SocketMeasurement>(*true_robot, setup, kind.fixed());
}

TEST(SocketMeasurement, SeatingPutsTheToolPointInItsSocketWithTheStatedPlay) {
  const RobotModel& robot = testing::PaperRobot();
  const SocketMeasurement kind(robot, ThreeSockets(robot, true));
  const TargetedConfigurations starts = SocketStarts(900, 3);
  NoiseModel noise;
  noise.sigma = 2e-4;
  noise.repetitions = 4;
  MeasuredValues data;
  std::vector<std::string> misses;
  const int missed = SimulateSocketMeasurements(
      kind, starts, noise, RandomStream(2, 0, 0, RandomPurpose::kNoise), &data, &misses);
  EXPECT_LT(missed, starts.size() / 20);
  ASSERT_EQ(data.size() + missed, starts.size());
  EXPECT_THAT(data.y, ::testing::Each(0.0));
  // The residuals at the true model are the play: mean 0, σ/√R per axis, within 4 standard
  // errors.
  const Eigen::MatrixXd J = MeasurementJacobian(kind, data.configs);  // binds, checks tags
  std::vector<double> y(3 * data.size());
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(kind.num_parameters());
  kind.Bind(data.configs)->Predict(zero.data(), y.data(), nullptr);
  double sum = 0, sum2 = 0;
  for (double r : y) {
    sum += r;
    sum2 += r * r;
  }
  const double count = static_cast<double>(y.size()), sd = noise.sigma / 2;
  EXPECT_NEAR(sum / count, 0.0, 4 * sd / std::sqrt(count));
  EXPECT_NEAR(sum2 / count / (sd * sd), 1.0, 4 * std::sqrt(2 / count));
  EXPECT_EQ(J.rows(), static_cast<Eigen::Index>(y.size()));
}

TEST(SocketMeasurement, ALengthReferenceMakesTheScaleIdentifiable) {
  const RobotModel& robot = testing::PaperRobot();
  NoiseModel exact;
  exact.sigma = 0;
  MeasuredValues data;
  SimulateSocketMeasurements(SocketMeasurement(robot, ThreeSockets(robot, true)),
                             SocketStarts(90, 4), exact,
                             RandomStream(1, 0, 0, RandomPurpose::kNoise), &data);
  const IdentifiabilityReport without =
      AnalyzeIdentifiability(SocketMeasurement(robot, ThreeSockets(robot, false)), data.configs);
  const IdentifiabilityReport with =
      AnalyzeIdentifiability(SocketMeasurement(robot, ThreeSockets(robot, true)), data.configs);
  // The distance takes one term away (socket 1 has two, not three) and no direction: the
  // scale the free sockets leave undetermined is what it fixes.
  EXPECT_EQ(with.num_params(), without.num_params() - 1);
  EXPECT_EQ(with.rank, without.rank) << without.ToString() << with.ToString();
  EXPECT_EQ(without.suggested_fixed.size(), with.suggested_fixed.size() + 1);
}

TEST(SocketMeasurement, NoiseFreeIdentificationRecoversTheTruth) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const SocketMeasurement full(robot, ThreeSockets(robot, true));
  NoiseModel exact;
  exact.sigma = 0;
  MeasuredValues nominal_data;
  SimulateSocketMeasurements(full, SocketStarts(120, 8), exact,
                             RandomStream(1, 0, 0, RandomPurpose::kNoise), &nominal_data);
  const IdentifiabilityReport report = AnalyzeIdentifiability(full, nominal_data.configs);
  ASSERT_FALSE(report.full_rank());
  const std::unique_ptr<MeasurementKind> reduced = full.Without(report.suggested_fixed);
  const auto& kind = dynamic_cast<const SocketMeasurement&>(*reduced);
  const Eigen::VectorXd truth = testing::SomeTruth(kind, 6);
  RobotModel true_robot;
  const std::unique_ptr<SocketMeasurement> true_kind = TrueSocketKind(kind, truth, &true_robot);
  MeasuredValues data;
  ASSERT_EQ(SimulateSocketMeasurements(*true_kind, SocketStarts(120, 8), exact,
                                       RandomStream(1, 0, 0, RandomPurpose::kNoise), &data),
            0);
  for (auto solver : {IdentificationOptions::Solver::kLevenbergMarquardt,
                      IdentificationOptions::Solver::kCeres}) {
    IdentificationOptions options;
    options.solver = solver;
    const IdentificationSummary s = Identify(kind, data, options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.message;
    EXPECT_THAT(s.delta, EigenNear(truth, tolerance::kRoundTrip)) << s.solver;
    EXPECT_LT(s.residual_rms, 1e-12);
  }
}

// Monte Carlo over noisy seatings at fixed starts: the mean of the estimate's Mahalanobis
// distance from the truth, δᵀ·Σ⁻¹·δ with Σ the covariance at the given σ (a χ²(n) law where the
// linearisation holds), its standard error, and the mean excess the linearisation check predicts
// (on every tenth realisation, `checks` of them).
struct Coverage {
  int n = 0;
  double mean = 0, standard_error = 0, predicted_excess = 0;
  int checks = 0, checks_holding = 0;
};

Coverage SocketCoverage(double wiggle, double sigma, int realisations) {
  const RobotModel& robot = testing::PaperRobot();
  const SocketMeasurement full(robot, ThreeSockets(robot, true));
  const TargetedConfigurations starts = SocketStarts(60, 12, wiggle);
  NoiseModel exact;
  exact.sigma = 0;
  MeasuredValues nominal_data;
  SimulateSocketMeasurements(full, starts, exact, RandomStream(1, 0, 0, RandomPurpose::kNoise),
                             &nominal_data);
  const std::unique_ptr<MeasurementKind> reduced =
      full.Without(AnalyzeIdentifiability(full, nominal_data.configs).suggested_fixed);
  const auto& kind = dynamic_cast<const SocketMeasurement&>(*reduced);
  NoiseModel noise;
  noise.sigma = sigma;
  noise.repetitions = 1;
  IdentificationOptions options;
  options.sigma = sigma;
  constexpr int kCheckEvery = 10;  // the check's cost: ~2n² predictions per fit
  Coverage c;
  c.n = kind.num_parameters();
  double sum2 = 0;
  for (int seed = 0; seed < realisations; ++seed) {
    MeasuredValues data;
    SimulateSocketMeasurements(
        kind, starts, noise,
        RandomStream(static_cast<std::uint64_t>(seed), 0, 0, RandomPurpose::kNoise), &data);
    options.check_linearisation = seed % kCheckEvery == 0;
    const IdentificationSummary s = Identify(kind, data, options);
    if (!s.IsSolutionUsable() || (options.check_linearisation && !s.linearisation.computed)) {
      ADD_FAILURE() << s.message << " " << s.linearisation.message;
      return c;
    }
    // The truth is the nominal model here: δ is the estimate's error.
    const double distance = s.delta.dot(s.covariance_given.ldlt().solve(s.delta));
    c.mean += distance / realisations;
    sum2 += distance * distance / realisations;
    if (!options.check_linearisation) continue;
    c.predicted_excess += s.linearisation.excess / (realisations / kCheckEvery);
    c.checks_holding += s.linearisation.Holds();
    ++c.checks;
  }
  c.standard_error = std::sqrt((sum2 - c.mean * c.mean) / (realisations - 1));
  return c;
}

// Configurations spread ±0.9 rad about the postures: the linearisation check says the covariance
// holds, and it does — δᵀΣ⁻¹δ averages n within 4 of its standard errors √(2n/realisations).
TEST(SocketMeasurement, StatedCovarianceHoldsWhereTheLinearisationCheckSaysSo) {
  constexpr int kRealisations = 200;
  const Coverage c = SocketCoverage(0.9, 0.1e-3, kRealisations);
  EXPECT_EQ(c.checks_holding, c.checks);
  EXPECT_EQ(c.checks, kRealisations / 10);
  EXPECT_NEAR(c.mean, c.n, 4 * std::sqrt(2.0 * c.n / kRealisations));
}

// Configurations within ±0.6 rad, play 0.3 mm: the weakest terms are uncertain enough for the
// model's curvature to bend the best-determined combinations, δᵀΣ⁻¹δ averages about a third more
// than n, and the check both flags it and predicts the excess (within 4 Monte-Carlo standard
// errors of the observed one).
TEST(SocketMeasurement, LinearisationCheckPredictsTheCovariancesOptimism) {
  constexpr int kRealisations = 200;
  const Coverage c = SocketCoverage(0.6, 0.3e-3, kRealisations);
  const double observed_excess = c.mean - c.n;
  EXPECT_EQ(c.checks_holding, 0);
  EXPECT_EQ(c.checks, kRealisations / 10);
  EXPECT_GT(observed_excess, 2 * c.standard_error);  // the optimism is real, not noise
  EXPECT_NEAR(observed_excess, c.predicted_excess, 4 * c.standard_error);
}

TEST(SocketMeasurement, BadDistancesAndTermsAreNamed) {
  const RobotModel& robot = testing::PaperRobot();
  EXPECT_THAT([] { SocketDistance::Parse("0,1", "--socket-distance"); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("--socket-distance: '0,1': expected A,B=METRES")));
  EXPECT_THAT([] { SocketDistance::Parse("1,1=0.05", "--socket-distance"); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("two distinct socket ids")));
  EXPECT_THAT([] { SocketDistance::Parse("0,1=-2", "--socket-distance"); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("finite and > 0")));
  const SocketDistance d = SocketDistance::Parse("0,7=0.05", "--socket-distance");
  EXPECT_EQ(d.a, 0);
  EXPECT_EQ(d.b, 7);
  EXPECT_DOUBLE_EQ(d.metres, 0.05);

  SocketSetup cycle = ThreeSockets(robot, true);
  cycle.distances.push_back({1, 7, 0.1});
  cycle.distances.push_back({7, 0, 0.1});
  EXPECT_THAT([&] { cycle.Validate(); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("socket.distances[2]: the known distances between sockets 7 and 0 "
                            "close a cycle")));
  SocketSetup twice = ThreeSockets(robot, true);
  twice.distances.push_back({7, 1, 0.1});
  EXPECT_THAT([&] { twice.Validate(); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("socket 1 is already placed")));
  SocketSetup unknown = ThreeSockets(robot, false);
  unknown.distances.push_back({0, 3, 0.1});
  EXPECT_THAT([&] { unknown.Validate(); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("socket 3 has no configuration")));
  EXPECT_THAT([&] { SocketMeasurement(robot, ThreeSockets(robot, true), {"socket1_x"}, "--fix"); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("--fix: 'socket1_x' is not a term of the socket measurement")));
  EXPECT_EQ(DisplayUnitOf("socket1_u2").unit, std::string("mrad"));
  EXPECT_EQ(DisplayUnitOf("socket1_x").unit, std::string("mm"));

  const SocketMeasurement kind(robot, ThreeSockets(robot, false));
  TargetedConfigurations four(6);
  four.Add(std::vector<double>(kPostureA, kPostureA + 6), 3);
  EXPECT_THAT([&] { kind.Bind(four); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("socket index 3")));
  TargetedConfigurations only_first(6);
  only_first.Add(std::vector<double>(kPostureA, kPostureA + 6), 0);
  EXPECT_THAT([&] { SocketPositionsFromData(robot, Eigen::Vector3d::Zero(), only_first, 2); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("socket index 1 has no "
                                                             "configuration")));
}

}  // namespace
}  // namespace lrcal
