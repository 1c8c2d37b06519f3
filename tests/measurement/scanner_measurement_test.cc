// The scanner measurement (scanner_measurement.h): its analytic Jacobian against Ceres autodiff
// through the reference kinematics and the beams written out here, and against central
// differences; a one-beam scanner along the tool's z axis against the ranger's own model; the
// noise-free round trip through both solvers; what a fan adds to a single beam; its errors.
#include "lrcal/measurement/scanner_measurement.h"

#include <ceres/jet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <functional>

#include "lrcal/core/error.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/truth.h"
#include "test_util.h"
#include "tracker_fixtures.h"

namespace lrcal {
namespace {

using testing::EigenNear;
using ::testing::HasSubstr;
namespace tolerance = testing::tolerance;

constexpr int kMaxScannerTerms = 48;
using ScannerJet = ceres::Jet<double, kMaxScannerTerms>;
constexpr double kSameModel = 1e-12;  // m, and per unit: two computations of one reading

// A five-beam fan of ±0.2 rad, 3 cm off the tool axis and turned, aimed at the paper's plane
// (its terms estimated).
ScannerSetup FanSetup(int beams = 5) {
  ScannerSetup setup;
  setup.planes = PlaneSet({testing::PaperPlane()}, {}, "test");
  setup.plane_terms = {PlaneTerms{true, true}};
  setup.origin = Eigen::Vector3d(0.03, -0.01, 0.02);
  setup.orientation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).matrix();
  setup.beam_angles = ScannerSetup::Fan(beams, 0.2);
  return setup;
}

// R_TS = R0·Rz(yaw)·Ry(pitch)·Rx(roll), written out with Jets.
template <typename T>
Eigen::Matrix<T, 3, 3> RollPitchYaw(const T& roll, const T& pitch, const T& yaw) {
  using std::cos;
  using std::sin;
  Eigen::Matrix<T, 3, 3> Rx, Ry, Rz;
  Rx << T(1), T(0), T(0), T(0), cos(roll), -sin(roll), T(0), sin(roll), cos(roll);
  Ry << cos(pitch), T(0), sin(pitch), T(0), T(1), T(0), -sin(pitch), T(0), cos(pitch);
  Rz << cos(yaw), -sin(yaw), T(0), sin(yaw), cos(yaw), T(0), T(0), T(0), T(1);
  return Rz * Ry * Rx;
}

// The readings of one configuration written out independently: the reference kinematics, the
// plane's chart as plane.h defines it, each beam intersected with the plane.
template <typename T>
std::vector<T> ReferenceReadings(const ScannerMeasurement& kind, const std::vector<T>& all,
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
  const V origin =
      kind.setup().origin.cast<T>() + V(term("target_x"), term("target_y"), term("target_z"));
  const Eigen::Matrix<T, 3, 3> R_TS =
      kind.setup().orientation.cast<T>() *
      RollPitchYaw(term("scanner_roll"), term("scanner_pitch"), term("scanner_yaw"));
  const int np = kind.setup().planes.size();
  const NormalChart chart(kind.setup().planes[plane].normal);
  const V n =
      chart.Normal(term(PlaneTermName(plane, np, "u1")), term(PlaneTermName(plane, np, "u2")));
  const T f = T(kind.setup().planes[plane].offset) + term(PlaneTermName(plane, np, "f"));
  const V O = pose.p_BT + pose.R_BT * origin;
  std::vector<T> readings;
  for (double angle : kind.setup().beam_angles) {
    const V D = pose.R_BT * R_TS * V(T(std::sin(angle)), T(0), T(std::cos(angle)));
    readings.push_back(-(n.dot(O) + f) / n.dot(D));
  }
  return readings;
}

class ScannerJacobianTest : public ::testing::TestWithParam<std::vector<std::string>> {};

TEST_P(ScannerJacobianTest, MatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const ScannerMeasurement kind(robot, FanSetup(), GetParam());
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(10, 5);
  const int n = kind.num_parameters(), k = kind.rows_per_configuration(), m = k * configs.size();
  ASSERT_LE(n, kMaxScannerTerms);
  std::vector<double> e(static_cast<std::size_t>(n));
  for (int c = 0; c < n; ++c) e[c] = (c % 2 ? 1 : -1) * (0.002 + 0.0003 * c);
  std::unique_ptr<MeasurementEvaluator> evaluator = kind.Bind(configs);
  std::vector<double> y(m);
  Eigen::MatrixXd J(m, n);
  ASSERT_TRUE(evaluator->Predict(e.data(), y.data(), J.data()));

  std::vector<ScannerJet> ej(n);
  for (int c = 0; c < n; ++c) ej[c] = ScannerJet(e[c], c);
  const std::vector<ScannerJet> all = testing::AllTrackerTerms(kind, ej);
  Eigen::MatrixXd autodiff(m, n);
  Eigen::VectorXd reference(m);
  for (int i = 0; i < configs.size(); ++i) {
    const std::vector<ScannerJet> rows =
        ReferenceReadings(kind, all, configs.q(i), configs.target(i));
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

INSTANTIATE_TEST_SUITE_P(Terms, ScannerJacobianTest,
                         ::testing::Values(std::vector<std::string>{},
                                           std::vector<std::string>{"scanner_pitch", "plane_f",
                                                                    "target_y", "theta2"}));

// One beam from the tool origin along the tool's z axis is the paper's ranger (no offset, no
// scale error): the same readings and the same Jacobian columns for the link values and the
// plane, computed by the ranger's own model (measurement_model.h).
TEST(ScannerMeasurement, OneBeamAlongTheToolAxisIsTheRanger) {
  const RobotModel& robot = testing::PaperRobot();
  ScannerSetup setup;
  setup.planes = PlaneSet({testing::PaperPlane()}, {}, "test");
  setup.plane_terms = {PlaneTerms{true, true}};
  const ScannerMeasurement scanner(
      robot, setup,
      {"target_x", "target_y", "target_z", "scanner_roll", "scanner_pitch", "scanner_yaw"});
  const RangerMeasurement ranger(MeasurementModel(robot, testing::PaperPlane(),
                                                  MakeParameterSet(robot, PlaneTerms{true, true})));
  ASSERT_EQ(scanner.parameter_names(), ranger.parameter_names());
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(25, 2);
  std::vector<double> e(static_cast<std::size_t>(scanner.num_parameters()));
  for (std::size_t c = 0; c < e.size(); ++c) e[c] = (c % 2 ? 1 : -1) * 1e-3;
  const Eigen::MatrixXd Js = MeasurementJacobian(scanner, configs, e.data());
  const Eigen::MatrixXd Jr = MeasurementJacobian(ranger, configs, e.data());
  EXPECT_THAT(Js, EigenNear(Jr, kSameModel));
  std::vector<double> ys(configs.size()), yr(configs.size());
  scanner.Bind(configs)->Predict(e.data(), ys.data(), nullptr);
  ranger.Bind(configs)->Predict(e.data(), yr.data(), nullptr);
  EXPECT_THAT(Eigen::Map<Eigen::VectorXd>(ys.data(), configs.size()),
              EigenNear(Eigen::Map<Eigen::VectorXd>(yr.data(), configs.size()), kSameModel));
}

// The kind a campaign reads from when `kind`'s terms are off nominal by `truth`.
std::unique_ptr<ScannerMeasurement> TrueScannerKind(const ScannerMeasurement& kind,
                                                    const Eigen::VectorXd& truth,
                                                    RobotModel* true_robot) {
  const RobotModel& robot = kind.robot();
  Truth errors;
  errors.link_errors = Eigen::VectorXd::Zero(robot.num_values());
  for (std::size_t c = 0; c < kind.arm().robot_values().size(); ++c)
    errors.link_errors[kind.arm().robot_values()[c]] = truth[static_cast<Eigen::Index>(c)];
  *true_robot = errors.TrueRobot(robot);
  PointMeasurement::State arm;
  kind.arm().StateAt(truth.data(), &arm);
  ScannerSetup setup = kind.setup();
  setup.origin = arm.targets[0];
  setup.orientation = kind.OrientationAt(truth.data(), nullptr);
  for (int p = 0; p < setup.planes.size(); ++p) {
    const EstimatedPlanes::State plane = kind.PlaneAt(truth.data(), p);
    setup.planes[p].normal = plane.normal;
    setup.planes[p].offset = plane.offset;
  }
  return std::make_unique<ScannerMeasurement>(*true_robot, setup, kind.fixed());
}

TEST(ScannerMeasurement, NoiseFreeIdentificationRecoversTheTruth) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const ScannerMeasurement full(robot, FanSetup());
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(90, 8);
  const IdentifiabilityReport report = AnalyzeIdentifiability(full, configs);
  ASSERT_FALSE(report.full_rank());
  const std::unique_ptr<MeasurementKind> reduced = full.Without(report.suggested_fixed);
  const auto& kind = dynamic_cast<const ScannerMeasurement&>(*reduced);
  const Eigen::VectorXd truth = testing::SomeTruth(kind, 6);
  RobotModel true_robot;
  const std::unique_ptr<ScannerMeasurement> true_kind = TrueScannerKind(kind, truth, &true_robot);
  NoiseModel exact;
  exact.sigma = 0;
  exact.repetitions = 1;
  MeasuredValues data;
  SimulateMeasurements(*true_kind, configs, exact, RandomStream(1, 0, 0, RandomPurpose::kNoise),
                       &data);
  ASSERT_GT(data.size(), 50);  // the others: a beam out of range or grazing
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

// A fan sees the plane along several directions from each posture: at the same postures it
// identifies more than one beam, and its simulated noise is the readings' own.
TEST(ScannerMeasurement, AFanIdentifiesMoreThanOneBeam) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(40, 3);
  const ScannerMeasurement fan(robot, FanSetup(5)), beam(robot, FanSetup(1));
  const IdentifiabilityReport a = AnalyzeIdentifiability(beam, configs);
  const IdentifiabilityReport b = AnalyzeIdentifiability(fan, configs);
  EXPECT_EQ(a.num_params(), b.num_params());
  EXPECT_GT(b.rank, a.rank) << a.ToString() << b.ToString();

  NoiseModel noise;
  noise.sigma = 0.2e-3;
  noise.repetitions = 4;
  MeasuredValues data;
  std::vector<std::string> misses;
  const int missed = SimulateMeasurements(
      fan, configs, noise, RandomStream(5, 0, 0, RandomPurpose::kNoise), &data, &misses);
  EXPECT_EQ(data.size() + missed, configs.size());
  EXPECT_LT(missed, configs.size() / 2);
  for (const std::string& reason : misses)
    EXPECT_THAT(reason, ::testing::AnyOf("ok", HasSubstr("out of range"), HasSubstr("grazing")));
  std::vector<double> exact(data.y.size());
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(fan.num_parameters());
  fan.Bind(data.configs)->Predict(zero.data(), exact.data(), nullptr);
  double sum2 = 0;
  for (std::size_t r = 0; r < exact.size(); ++r) sum2 += std::pow(data.y[r] - exact[r], 2);
  const double count = static_cast<double>(exact.size()), sd = noise.sigma / 2;
  EXPECT_NEAR(sum2 / count / (sd * sd), 1.0, 4 * std::sqrt(2 / count));
}

TEST(ScannerMeasurement, MissesAndBadSetUpsAreNamed) {
  const RobotModel& robot = testing::PaperRobot();
  ScannerSetup setup = FanSetup();
  setup.beam_angles = {0.1, 2.0};
  EXPECT_THAT([&] { setup.Validate(); },
              ::testing::ThrowsMessage<InputError>(HasSubstr(
                  "scanner.beam_angles[1]: expected a finite angle within (-pi/2, pi/2)")));
  setup = FanSetup();
  setup.orientation(0, 0) = 2;
  EXPECT_THAT([&] { setup.Validate(); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("scanner.orientation")));
  setup = FanSetup();
  setup.beam_angles.clear();
  EXPECT_THAT([&] { setup.Validate(); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("expected 1 to 256 beams")));
  EXPECT_THAT([&] { ScannerMeasurement(robot, FanSetup(), {"scanner_twist"}, "--fix"); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("--fix: 'scanner_twist' is not a term of the scanner measurement")));
  EXPECT_EQ(DisplayUnitOf("scanner_yaw").unit, std::string("mrad"));

  // The tool turned away from the plane: the plane is behind every beam.
  const ScannerMeasurement kind(robot, FanSetup());
  TargetedConfigurations configs = testing::PaperHittingConfigurations(3, 2);
  TargetedConfigurations away(6);
  std::vector<double> q(configs.q(0), configs.q(0) + 6);
  away.Add(q, 0);
  q[4] += M_PI;  // the wrist flipped
  away.Add(q, 0);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(kind.num_parameters());
  const std::vector<std::string> reasons = kind.MissReasons(away, zero.data());
  ASSERT_EQ(reasons.size(), 2u);
  EXPECT_EQ(reasons[0], "ok");
  EXPECT_THAT(reasons[1], HasSubstr("plane 1 behind beam 1"));
}

TEST(ScannerMeasurement, ConfigurationsItCannotMeasureAreRefusedByBindAndMissReasons) {
  const ScannerMeasurement kind(testing::PaperRobot(), FanSetup());  // one plane
  TargetedConfigurations second_plane(6), five_joints(5);
  second_plane.Add(std::vector<double>(6, 0.1), 1);
  five_joints.Add(std::vector<double>(5, 0.1), 0);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(kind.num_parameters());
  for (const auto& call : std::vector<std::function<void(const TargetedConfigurations&)>>{
           [&](const TargetedConfigurations& c) { kind.Bind(c); },
           [&](const TargetedConfigurations& c) { kind.MissReasons(c, zero.data()); }}) {
    EXPECT_THAT([&] { call(second_plane); },
                ::testing::ThrowsMessage<InputError>(HasSubstr(
                    "a configuration is aimed at plane 2 but the set-up has 1 plane(s)")));
    EXPECT_THAT([&] { call(five_joints); }, ::testing::ThrowsMessage<InputError>(HasSubstr(
                                                "the robot has 6 joints, the configurations 5")));
  }
}

}  // namespace
}  // namespace lrcal
