// The 6-D pose measurement (pose_measurement.h): its analytic Jacobian against Ceres autodiff
// through the reference kinematics and Ceres' own rotation-to-angle-axis, and against central
// differences; the rotation vector's log and J_r⁻¹ on their own; Everett's count of identifiable
// terms from the rank analysis against an independent rank; a noise-free round trip through both
// solvers; the simulated orientation noise and its weights.
#include "lrcal/measurement/pose_measurement.h"

#include <ceres/jet.h>
#include <ceres/rotation.h>
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

constexpr int kMaxPoseTerms = 48;  // the point test's Jet: one instantiation in a unity build
using PoseJet = ceres::Jet<double, kMaxPoseTerms>;

// Two 6-D probes seen by a tracker in front of the arm (tracker_fixtures.h).
PointSetup ProbeSetup() { return testing::TrackerSetup(true); }

TargetedConfigurations ProbeConfigurations(const RobotModel& robot, int count, int targets,
                                           unsigned seed) {
  return testing::RandomTrackerConfigurations(robot.num_links(), count, targets, seed);
}

template <typename T>
using Matrix3 = Eigen::Matrix<T, 3, 3>;
template <typename T>
using Vector3 = Eigen::Matrix<T, 3, 1>;

// R0·Rz(yaw)·Ry(pitch)·Rx(roll) from Eigen's angle-axis rotations.
template <typename T>
Matrix3<T> Turned(const Eigen::Matrix3d& R0, const T& roll, const T& pitch, const T& yaw) {
  return R0.cast<T>() * Eigen::AngleAxis<T>(yaw, Vector3<T>::UnitZ()).toRotationMatrix() *
         Eigen::AngleAxis<T>(pitch, Vector3<T>::UnitY()).toRotationMatrix() *
         Eigen::AngleAxis<T>(roll, Vector3<T>::UnitX()).toRotationMatrix();
}

// The six rows written out independently of the library from every term (AllTermNames order):
// the reference kinematics for the tool, Ceres' RotationMatrixToAngleAxis for the log.
template <typename T>
Eigen::Matrix<T, 6, 1> ReferencePose(const PoseMeasurement& kind, const std::vector<T>& all,
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
  const Matrix3<T> R_BI = Turned<T>(kind.setup().instrument.rotation, inst[3], inst[4], inst[5]);
  const Vector3<T> p_BI =
      kind.setup().instrument.translation.cast<T>() + Vector3<T>(inst[0], inst[1], inst[2]);
  const T* t = &all[column + 6 + 6 * target];
  const Vector3<T> offset = kind.setup().targets[target].cast<T>() + Vector3<T>(t[0], t[1], t[2]);
  const Matrix3<T> R_TM = Turned<T>(kind.setup().TargetOrientation(target), t[3], t[4], t[5]);
  Eigen::Matrix<T, 6, 1> rows;
  rows.template head<3>() = R_BI.transpose() * (pose.p_BT + pose.R_BT * offset - p_BI);
  Matrix3<T> M =
      kind.ChartCentre(q, target).cast<T>().transpose() * R_BI.transpose() * pose.R_BT * R_TM;
  T aa[3];
  ceres::RotationMatrixToAngleAxis(ceres::ColumnMajorAdapter3x3(static_cast<const T*>(M.data())),
                                   aa);
  rows.template tail<3>() = Vector3<T>(aa[0], aa[1], aa[2]);
  return rows;
}

class PoseJacobianTest : public ::testing::TestWithParam<std::vector<std::string>> {};

TEST_P(PoseJacobianTest, MatchesAutodiffAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const PoseMeasurement kind(robot, ProbeSetup(), GetParam());
  const TargetedConfigurations configs = ProbeConfigurations(robot, 12, 2, 7);
  const int n = kind.num_parameters(), m = 6 * configs.size();
  ASSERT_LE(n, kMaxPoseTerms);
  // Away from nominal, so that φ ≠ 0, where the log's autodiff is defined.
  const std::vector<double> e = testing::OffNominalEstimate(kind);
  std::unique_ptr<MeasurementEvaluator> evaluator = kind.Bind(configs);
  std::vector<double> y(m);
  Eigen::MatrixXd J(m, n);
  ASSERT_TRUE(evaluator->Predict(e.data(), y.data(), J.data()));

  std::vector<PoseJet> ej(n);
  for (int k = 0; k < n; ++k) ej[k] = PoseJet(e[k], k);
  const std::vector<PoseJet> all_jets = testing::AllTrackerTerms(kind, ej);
  Eigen::MatrixXd autodiff(m, n);
  Eigen::VectorXd reference(m);
  for (int i = 0; i < configs.size(); ++i) {
    const Eigen::Matrix<PoseJet, 6, 1> p =
        ReferencePose(kind, all_jets, configs.q(i), configs.target(i));
    for (int c = 0; c < 6; ++c) {
      reference[6 * i + c] = p[c].a;
      for (int k = 0; k < n; ++k) autodiff(6 * i + c, k) = p[c].v[k];
    }
  }
  const Eigen::MatrixXd central = testing::CentralDifferences(*evaluator, e);
  EXPECT_THAT(Eigen::Map<Eigen::VectorXd>(y.data(), m), EigenNear(reference, tolerance::kUrdf));
  EXPECT_THAT(J, EigenNear(autodiff, tolerance::kAutodiff));
  EXPECT_THAT(J, EigenNear(central, tolerance::kCentralDifference));
}

INSTANTIATE_TEST_SUITE_P(Terms, PoseJacobianTest,
                         ::testing::Values(std::vector<std::string>{},
                                           std::vector<std::string>{"instrument_roll", "target2_y",
                                                                    "target1_pitch", "theta1"},
                                           std::vector<std::string>{"instrument_yaw",
                                                                    "target2_roll", "alpha3"}));

TEST(RotationLog, InvertsTheExponentialAndItsInverseJacobianIsTheLogsDerivative) {
  constexpr double kStep = 1e-6;
  for (const Eigen::Vector3d& phi :
       {Eigen::Vector3d(0.3, -0.2, 0.5), Eigen::Vector3d(1e-6, 2e-6, -1e-6),
        Eigen::Vector3d(2.0, 1.5, -0.8), Eigen::Vector3d(0, 0, 0)}) {
    const double theta = phi.norm();
    const Eigen::Matrix3d R = theta > 0 ? Eigen::AngleAxisd(theta, phi / theta).toRotationMatrix()
                                        : Eigen::Matrix3d::Identity();
    EXPECT_THAT(RotationLog(R), EigenNear(phi, tolerance::kUrdf));
    // log(R·exp(εe_k)) by central differences: column k of J_r⁻¹(φ).
    Eigen::Matrix3d numeric;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Matrix3d step =
          Eigen::AngleAxisd(kStep, Eigen::Vector3d::Unit(k)).toRotationMatrix();
      numeric.col(k) = (RotationLog(R * step) - RotationLog(R * step.transpose())) / (2 * kStep);
    }
    EXPECT_THAT(InverseRightJacobian(phi), EigenNear(numeric, tolerance::kCentralDifference))
        << phi.transpose();
  }
}

TEST(PoseMeasurement, NoiseFreeIdentificationRecoversTheTruth) {
  const RobotModel& robot = testing::PaperRobot();
  const PoseMeasurement full(robot, ProbeSetup());
  const TargetedConfigurations configs = ProbeConfigurations(robot, 60, 2, 11);
  const IdentifiabilityReport report = AnalyzeIdentifiability(full, configs);
  ASSERT_FALSE(report.full_rank());
  const std::unique_ptr<MeasurementKind> kind = full.Without(report.suggested_fixed);
  const auto& pose_kind = dynamic_cast<const PoseMeasurement&>(*kind);
  const Eigen::VectorXd truth = testing::SomeTruth(*kind, 5);
  const MeasuredValues data = testing::ExpectNoiseFreeRoundTrip(pose_kind, configs, truth);
  // The orientation rows are the true orientation in the nominal kind's chart.
  RobotModel true_robot;
  testing::TrueTrackerKind(pose_kind, truth, &true_robot);
  PointMeasurement::State state;
  pose_kind.StateAt(truth.data(), &state);
  const Pose<double> pose0 =
      ForwardKinematics<double>(true_robot, true_robot.nominal_values().data(), configs.q(0));
  const Eigen::Matrix3d R_IM0 = state.R_BI.transpose() * pose0.R_BT * state.R_TM[0];
  EXPECT_THAT(Eigen::Map<const Eigen::Vector3d>(&data.y[3]),
              EigenNear(pose_kind.OrientationValue(configs.q(0), 0, R_IM0), tolerance::kUrdf));
}

// The rank of central differences of the reference rows, columns scaled to unit norm.
int IndependentRank(const PoseMeasurement& kind, const TargetedConfigurations& configs, int rows) {
  const int n = kind.num_parameters(), m = rows * configs.size();
  Eigen::MatrixXd G(m, n);
  constexpr double kStep = 1e-6;
  // About a point off nominal by 1 mrad / 1 mm, where Ceres' log is smooth.
  std::vector<double> e0(n);
  for (int k = 0; k < n; ++k) e0[k] = 1e-3 * (k % 3 - 1);
  for (int k = 0; k < n; ++k) {
    std::vector<double> ep = e0, em = e0;
    ep[k] += kStep;
    em[k] -= kStep;
    const std::vector<double> ap = testing::AllTrackerTerms(kind, ep),
                              am = testing::AllTrackerTerms(kind, em);
    for (int i = 0; i < configs.size(); ++i) {
      const Eigen::Matrix<double, 6, 1> d =
          (ReferencePose(kind, ap, configs.q(i), configs.target(i)) -
           ReferencePose(kind, am, configs.q(i), configs.target(i))) /
          (2 * kStep);
      G.block(static_cast<Eigen::Index>(rows) * i, k, rows, 1) = d.head(rows);
    }
  }
  for (int k = 0; k < n; ++k)
    if (G.col(k).norm() > 1e-9) G.col(k).normalize();
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(G).singularValues();
  int rank = 0;
  for (int k = 0; k < sv.size(); ++k) rank += sv[k] > 1e-6 * sv[0];
  return rank;
}

// Everett's C = 4R + 2P + 6 = 30 for the paper's six revolute joints with a full-pose
// measurement, the instrument's frame and the probe's estimated; three fewer (27) when only the
// probe's position is read, its orientation then unseen.
TEST(PoseMeasurement, IdentifiableTermsAreEverettsCount) {
  const RobotModel& robot = testing::PaperRobot();
  PointSetup one = ProbeSetup();
  one.targets.resize(1);
  one.target_orientations.resize(1);
  const PoseMeasurement kind(robot, one);
  const TargetedConfigurations configs = ProbeConfigurations(robot, 40, 1, 3);
  const IdentifiabilityReport report = AnalyzeIdentifiability(kind, configs);
  EXPECT_EQ(report.num_params(), 25 + 6 + 6);
  EXPECT_EQ(report.rank, 30) << report.ToString();
  EXPECT_EQ(report.rank, IndependentRank(kind, configs, 6));
  const PointMeasurement point(robot, one);
  const IdentifiabilityReport point_report = AnalyzeIdentifiability(point, configs);
  EXPECT_EQ(point_report.rank, 27) << point_report.ToString();
  EXPECT_EQ(point_report.rank, IndependentRank(kind, configs, 3) - 0);
}

TEST(PoseMeasurement, SimulatedOrientationNoiseHasItsOwnSigmaAndWeight) {
  const RobotModel& robot = testing::PaperRobot();
  const PoseMeasurement kind(robot, ProbeSetup());
  const TargetedConfigurations configs = ProbeConfigurations(robot, 1500, 2, 9);
  NoiseModel noise;
  noise.sigma = 1e-3;
  noise.sigma_angle = 4e-3;
  noise.repetitions = 4;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(kind.num_parameters());
  std::vector<double> exact(6 * configs.size());
  kind.Bind(configs)->Predict(zero.data(), exact.data(), nullptr);
  for (bool draw_mean : {false, true}) {
    noise.draw_mean = draw_mean;
    MeasuredValues data;
    ASSERT_EQ(SimulateMeasurements(kind, configs, noise,
                                   RandomStream(3, 0, 0, RandomPurpose::kNoise), &data),
              0);
    ASSERT_EQ(data.weights.size(), exact.size());
    double sum2[2] = {0, 0};
    for (std::size_t r = 0; r < exact.size(); ++r) {
      const double error = data.y[r] - exact[r];
      sum2[r % 6 >= 3] += error * error;
      // Four readings; an angle's weight is (σ/σ_angle)² = 1/16 of a length's per reading.
      EXPECT_EQ(data.weights[r], r % 6 >= 3 ? 4.0 / 16 : 4.0) << r;
    }
    const double count = 3.0 * configs.size();
    const double sd[2] = {noise.sigma / 2, noise.sigma_angle / 2};  // σ/√R
    for (int angle : {0, 1})
      EXPECT_NEAR(sum2[angle] / count / (sd[angle] * sd[angle]), 1.0, 4 * std::sqrt(2 / count))
          << draw_mean << " " << angle;
  }
}

// The stated covariance holds: over many noisy realisations the estimate's Mahalanobis distance
// from the truth, δᵀ·Σ⁻¹·δ with Σ the covariance at the given σ, averages n (a χ²(n) law), the
// positions and orientations of different σ weighed against each other by the simulation's
// weights. A wrong weight for the orientations would make it far from n.
TEST(PoseMeasurement, StatedCovarianceHoldsOverManyRealisations) {
  const RobotModel& robot = testing::PaperRobot();
  PointSetup one = ProbeSetup();
  one.targets.resize(1);
  one.target_orientations.resize(1);
  const PoseMeasurement full(robot, one);
  const TargetedConfigurations configs = ProbeConfigurations(robot, 30, 1, 21);
  const std::unique_ptr<MeasurementKind> kind =
      full.Without(AnalyzeIdentifiability(full, configs).suggested_fixed);
  NoiseModel noise;
  noise.sigma = 0.1e-3;
  noise.sigma_angle = 0.5e-3;
  noise.repetitions = 2;
  IdentificationOptions options;
  options.sigma = noise.sigma;
  constexpr int kRealisations = 200;
  const int n = kind->num_parameters();
  double sum = 0;
  for (int seed = 0; seed < kRealisations; ++seed) {
    MeasuredValues data;
    SimulateMeasurements(
        *kind, configs, noise,
        RandomStream(static_cast<std::uint64_t>(seed), 0, 0, RandomPurpose::kNoise), &data);
    const IdentificationSummary s = Identify(*kind, data, options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.message;
    // The truth is the nominal model here: δ is the estimate's error.
    sum += s.delta.dot(s.covariance_given.ldlt().solve(s.delta));
  }
  // The mean of χ²(n) within 4 of its standard errors, √(2n/realisations).
  EXPECT_NEAR(sum / kRealisations, n, 4 * std::sqrt(2.0 * n / kRealisations));
}

TEST(PoseMeasurement, BadOrientationsAndTermsAreNamed) {
  const RobotModel& robot = testing::PaperRobot();
  PointSetup bad = ProbeSetup();
  bad.target_orientations.resize(1);
  EXPECT_THAT([&] { PoseMeasurement(robot, bad); },
              ::testing::ThrowsMessage<InputError>(HasSubstr(
                  "point.target_orientations: expected none or one per target (2), got 1")));
  bad = ProbeSetup();
  bad.target_orientations[1](0, 0) = 2;
  EXPECT_THAT([&] { PoseMeasurement(robot, bad); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("point.target_orientations[1]")));
  EXPECT_THAT([&] { PoseMeasurement(robot, ProbeSetup(), {"target_roll"}, "--fix"); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("'target_roll' is not a term of the pose measurement")));
  // The point kind has no orientation terms.
  EXPECT_THAT([&] { PointMeasurement(robot, ProbeSetup(), {"target1_roll"}, "--fix"); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("'target1_roll' is not a term of the point measurement")));
  const PoseMeasurement kind(robot, ProbeSetup());
  EXPECT_EQ(kind.name(), std::string("pose"));
  EXPECT_EQ(kind.rows_per_configuration(), 6);
  EXPECT_TRUE(kind.RowIsAngle(4));
  EXPECT_FALSE(kind.RowIsAngle(2));
  EXPECT_THAT(kind.parameter_names(), ::testing::Contains("target2_yaw"));
  EXPECT_EQ(DisplayUnitOf("target2_yaw").unit, std::string("mrad"));
}

}  // namespace
}  // namespace lrcal
