// The contact measurement (contact_measurement.h): its analytic Jacobian against Ceres autodiff
// through the reference kinematics and the constraint written out here, and against central
// differences, for point and flush contacts with the planes' terms; seating and its play;
// identifiability; a noise-free round trip through both solvers; located errors.
#include "lrcal/measurement/contact_measurement.h"

#include <ceres/jet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

constexpr int kMaxContactTerms = 40;
using ContactJet = ceres::Jet<double, kMaxContactTerms>;

// Two planes within the paper arm's reach, a tilted floor and a wall, both estimated.
ContactSetup TwoPlanes(bool flush) {
  ContactSetup setup;
  setup.planes = PlaneSet(
      {Plane::FromCoefficients(0.1, 0.2, 1.0, -0.3), Plane::FromCoefficients(1.0, 0.0, 0.2, -0.9)},
      {}, "test");
  setup.plane_terms = {PlaneTerms{true, true}, PlaneTerms{true, true}};
  setup.tool_point = Eigen::Vector3d(0.01, -0.02, 0.1);
  setup.flush = flush;
  return setup;
}

// Random starts (joints uniform in ±2.5 rad), configuration i on plane i mod 2.
TargetedConfigurations Starts(int count, unsigned seed) {
  return testing::RandomTrackerConfigurations(6, count, 2, seed);
}

// The rows written out independently: the reference kinematics, the plane's chart n(u) as
// plane.h defines it, the tool z axis's gnomonic coordinates in that chart minus u.
template <typename T>
std::vector<T> ReferenceRows(const ContactMeasurement& kind, const std::vector<T>& all,
                             const double* q, int plane) {
  using V = Eigen::Matrix<T, 3, 1>;
  const RobotModel& robot = kind.robot();
  const std::vector<std::string> names = kind.AllTermNames();
  const auto term = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? T(0) : all[static_cast<std::size_t>(it - names.begin())];
  };
  std::vector<T> values(robot.num_values());
  for (int k = 0; k < robot.num_values(); ++k)
    values[k] = T(robot.nominal_values()[k]) + term(robot.ValueName(k));
  const Pose<T> pose = ForwardKinematics<T>(robot, values.data(), q);
  const V t =
      kind.setup().tool_point.cast<T>() + V(term("target_x"), term("target_y"), term("target_z"));
  const int np = kind.setup().planes.size();
  const T u1 = term(PlaneTermName(plane, np, "u1")), u2 = term(PlaneTermName(plane, np, "u2"));
  const NormalChart chart(kind.setup().planes[plane].normal);
  const V n = chart.Normal(u1, u2);
  const T f = T(kind.setup().planes[plane].offset) + term(PlaneTermName(plane, np, "f"));
  std::vector<T> rows = {n.dot(pose.p_BT + pose.R_BT * t) + f};
  if (!kind.setup().flush) return rows;
  const V z = pose.R_BT.col(2);
  const T zn = z.dot(chart.n0.cast<T>());
  rows.push_back(z.dot(chart.t1.cast<T>()) / zn - u1);
  rows.push_back(z.dot(chart.t2.cast<T>()) / zn - u2);
  return rows;
}

class ContactJacobianTest
    : public ::testing::TestWithParam<std::pair<bool, std::vector<std::string>>> {};

TEST_P(ContactJacobianTest, MatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const ContactMeasurement kind(robot, TwoPlanes(GetParam().first), GetParam().second);
  // Flush rows divide by z·n0: at the seated postures of a flush contact (z near ±n0) as data
  // have them; a point contact at any posture.
  const TargetedConfigurations configs =
      GetParam().first ? kind.LinearisationConfigurations(Starts(12, 5)) : Starts(12, 5);
  const int n = kind.num_parameters(), k = kind.rows_per_configuration(), m = k * configs.size();
  ASSERT_LE(n, kMaxContactTerms);
  std::vector<double> e(static_cast<std::size_t>(n));
  for (int c = 0; c < n; ++c) e[c] = (c % 2 ? 1 : -1) * (0.002 + 0.0003 * c);
  std::unique_ptr<MeasurementEvaluator> evaluator = kind.Bind(configs);
  std::vector<double> y(m);
  Eigen::MatrixXd J(m, n);
  ASSERT_TRUE(evaluator->Predict(e.data(), y.data(), J.data()));

  std::vector<ContactJet> ej(n);
  for (int c = 0; c < n; ++c) ej[c] = ContactJet(e[c], c);
  const std::vector<ContactJet> all = testing::AllTrackerTerms(kind, ej);
  Eigen::MatrixXd autodiff(m, n);
  Eigen::VectorXd reference(m);
  for (int i = 0; i < configs.size(); ++i) {
    const std::vector<ContactJet> rows = ReferenceRows(kind, all, configs.q(i), configs.target(i));
    for (int r = 0; r < k; ++r) {
      reference[k * i + r] = rows[r].a;
      for (int c = 0; c < n; ++c) autodiff(k * i + r, c) = rows[r].v[c];
    }
  }
  EXPECT_THAT(Eigen::Map<Eigen::VectorXd>(y.data(), m), EigenNear(reference, tolerance::kUrdf));
  EXPECT_THAT(J, EigenNear(autodiff, tolerance::kAutodiff));
  EXPECT_THAT(J,
              EigenNear(testing::CentralDifferences(*evaluator, e), tolerance::kCentralDifference));
}

INSTANTIATE_TEST_SUITE_P(Terms, ContactJacobianTest,
                         ::testing::Values(std::make_pair(false, std::vector<std::string>{}),
                                           std::make_pair(true, std::vector<std::string>{}),
                                           std::make_pair(true, std::vector<std::string>{
                                                                    "plane2_u1", "plane1_f",
                                                                    "target_y", "theta2"})));

TEST(ContactMeasurement, ConfigurationsOnPlanesItDoesNotHaveAreRefused) {
  const ContactMeasurement kind(testing::PaperRobot(), TwoPlanes(false));
  TargetedConfigurations third_plane(6);
  third_plane.Add(std::vector<double>(6, 0.1), 2);
  EXPECT_THAT([&] { kind.Bind(third_plane); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("a configuration touches plane 3 but the set-up has 2 plane(s)")));
}

TEST(ContactMeasurement, SeatingPutsTheToolPointOnItsPlaneWithTheStatedPlay) {
  const RobotModel& robot = testing::PaperRobot();
  const ContactMeasurement kind(robot, TwoPlanes(false));
  NoiseModel noise;
  noise.sigma = 2e-4;
  noise.repetitions = 4;
  MeasuredValues data;
  std::vector<std::string> misses;
  const TargetedConfigurations starts = Starts(1200, 3);
  const int missed = SimulateContactMeasurements(
      kind, starts, noise, RandomStream(2, 0, 0, RandomPurpose::kNoise), &data, &misses);
  EXPECT_LT(missed, starts.size() / 4);
  ASSERT_EQ(data.size() + missed, starts.size());
  std::vector<double> y(data.size());
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
}

TEST(ContactMeasurement, FlushContactsSeeTheToolsTiltAndTheirRowsAreAngles) {
  const RobotModel& robot = testing::PaperRobot();
  const ContactMeasurement point(robot, TwoPlanes(false)), flush(robot, TwoPlanes(true));
  EXPECT_EQ(point.rows_per_configuration(), 1);
  EXPECT_EQ(flush.rows_per_configuration(), 3);
  EXPECT_FALSE(flush.RowIsAngle(0));
  EXPECT_TRUE(flush.RowIsAngle(1));
  NoiseModel exact;
  exact.sigma = 0;
  exact.sigma_angle = 0;
  MeasuredValues data;
  SimulateContactMeasurements(flush, Starts(90, 4), exact,
                              RandomStream(1, 0, 0, RandomPurpose::kNoise), &data);
  ASSERT_GT(data.size(), 40);
  // Flush contacts also see the tool's orientation: more identifiable combinations.
  const IdentifiabilityReport a = AnalyzeIdentifiability(point, data.configs);
  const IdentifiabilityReport b = AnalyzeIdentifiability(flush, data.configs);
  EXPECT_EQ(a.num_params(), b.num_params());
  EXPECT_GT(b.rank, a.rank) << a.ToString() << b.ToString();
}

TEST(ContactMeasurement, NoiseFreeIdentificationRecoversTheTruth) {
  for (bool flush : {false, true}) {
    SCOPED_TRACE(flush ? "flush" : "point contact");
    const RobotModel& robot = testing::PaperRobotWithFrames();
    const ContactMeasurement full(robot, TwoPlanes(flush));
    NoiseModel exact;
    exact.sigma = 0;
    exact.sigma_angle = 0;
    MeasuredValues nominal_data;
    SimulateContactMeasurements(full, Starts(160, 8), exact,
                                RandomStream(1, 0, 0, RandomPurpose::kNoise), &nominal_data);
    const IdentifiabilityReport report = AnalyzeIdentifiability(full, nominal_data.configs);
    const std::unique_ptr<MeasurementKind> reduced = full.Without(report.suggested_fixed);
    const auto& kind = dynamic_cast<const ContactMeasurement&>(*reduced);
    const Eigen::VectorXd truth = testing::SomeTruth(kind, 6);
    RobotModel true_robot;
    const std::unique_ptr<ContactMeasurement> true_kind =
        testing::TrueContactKind(kind, truth, &true_robot);
    MeasuredValues data;
    SimulateContactMeasurements(*true_kind, Starts(160, 8), exact,
                                RandomStream(1, 0, 0, RandomPurpose::kNoise), &data);
    ASSERT_GT(data.size(), kind.num_parameters());
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
}

// The stated covariance holds: over many noisy contacts the estimate's Mahalanobis distance from
// the truth, δᵀ·Σ⁻¹·δ with Σ the covariance at the given σ, averages n (a χ²(n) law) within 4 of
// its standard errors √(2n/realisations) — for flush contacts too, whose tilt rows (σ_angle) are
// weighed against the distances (σ) as the simulation weighs them. The linearisation check (on
// every 20th fit) agrees that it holds.
TEST(ContactMeasurement, StatedCovarianceHoldsOverManyRealisations) {
  constexpr int kRealisations = 200, kCheckEvery = 20;
  for (bool flush : {false, true}) {
    SCOPED_TRACE(flush ? "flush" : "point contact");
    const RobotModel& robot = testing::PaperRobot();
    const ContactMeasurement full(robot, TwoPlanes(flush));
    const TargetedConfigurations starts = Starts(80, 5);
    NoiseModel noise;
    noise.sigma = 0.1e-3;
    noise.sigma_angle = 0.5e-3;
    noise.repetitions = 1;
    MeasuredValues nominal_data;
    NoiseModel exact = noise;
    exact.sigma = exact.sigma_angle = 0;
    SimulateContactMeasurements(full, starts, exact, RandomStream(1, 0, 0, RandomPurpose::kNoise),
                                &nominal_data);
    const std::unique_ptr<MeasurementKind> reduced =
        full.Without(AnalyzeIdentifiability(full, nominal_data.configs).suggested_fixed);
    const auto& kind = dynamic_cast<const ContactMeasurement&>(*reduced);
    IdentificationOptions options;
    options.sigma = noise.sigma;
    const int n = kind.num_parameters();
    double sum = 0;
    int holding = 0;
    for (int seed = 0; seed < kRealisations; ++seed) {
      MeasuredValues data;
      SimulateContactMeasurements(
          kind, starts, noise,
          RandomStream(static_cast<std::uint64_t>(seed), 0, 0, RandomPurpose::kNoise), &data);
      options.check_linearisation = seed % kCheckEvery == 0;  // its cost: ~2n² predictions
      const IdentificationSummary s = Identify(kind, data, options);
      ASSERT_TRUE(s.IsSolutionUsable()) << s.message;
      sum += s.delta.dot(s.covariance_given.ldlt().solve(s.delta));  // the truth is nominal
      holding += s.linearisation.Holds();
    }
    EXPECT_EQ(holding, kRealisations / kCheckEvery);
    EXPECT_NEAR(sum / kRealisations, n, 4 * std::sqrt(2.0 * n / kRealisations));
  }
}

TEST(ContactMeasurement, BadSetUpsAndTermsAreNamed) {
  const RobotModel& robot = testing::PaperRobot();
  ContactSetup bad = TwoPlanes(false);
  bad.plane_terms.resize(1);
  EXPECT_THAT([&] { bad.Validate(); }, ::testing::ThrowsMessage<InputError>(HasSubstr(
                                           "contact.plane_terms: expected none or one per plane")));
  EXPECT_THAT([&] { ContactMeasurement(robot, TwoPlanes(false), {"plane3_u1"}, "--fix"); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("--fix: 'plane3_u1' is not a term of the contact measurement")));
  const ContactMeasurement kind(robot, TwoPlanes(false));
  TargetedConfigurations third(6);
  third.Add(std::vector<double>(6, 0.1), 2);
  EXPECT_THAT([&] { kind.Bind(third); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("touches plane 3")));
}

}  // namespace
}  // namespace lrcal
