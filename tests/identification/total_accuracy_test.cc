// The total accuracy statement (total_accuracy.h): the estimate shift against re-identification
// with a perturbed truth, an exactly confounded ranger offset, the σ the statement uses, and — by
// Monte Carlo — that the stated total 95 % radius holds the true position error at its rate when
// every term (held ones included) is drawn from its prior, where the data-only radius does not.
#include "lrcal/identification/total_accuracy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "lrcal/kinematics/pose_errors.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;

constexpr double kTotalSigma = 0.1e-3;  // m, the noise of one reading in these tests

// Readings of the arm whose every term (robot, plane, ranger) deviates by e_all from nominal
// (laid out as the complete parameter set); noise-free when seed is 0.
MeasurementSet ReadingsOfTruth(const Eigen::VectorXd& e_all, const TargetedConfigurations& configs,
                               std::uint64_t seed, const Plane& plane = testing::PaperPlane()) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel complete(robot, plane, CompleteParameterSet(robot, 1));
  NoiseModel noise;
  noise.sigma = seed ? kTotalSigma : 0;
  noise.repetitions = 1;
  noise.ranger_offset = e_all[complete.parameters().ranger_offset_index];
  noise.ranger_scale = e_all[complete.parameters().ranger_scale_index];
  MeasurementSet data;
  // The truth's base and tool are moved by e_all's frame terms.
  SimulateReadings(complete.RobotAt(e_all.data()), complete.LinkValues(e_all.data()),
                   complete.PlanesAt(e_all.data()), testing::PaperRig().ranger, configs, noise,
                   RandomStream(seed, 0, 0, RandomPurpose::kNoise), &data);
  return data;
}

IdentificationOptions GivenSigma() {
  IdentificationOptions options;
  options.sigma = kTotalSigma;
  return options;
}

// S = ∂ê/∂u: re-identifying from noise-free readings of a truth whose held term is ±δ off
// (central differences) moves the estimate by S·δ.
TEST(UnestimatedTerms, EstimateShiftIsTheDerivativeOfTheEstimate) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(50, 4);
  const MeasurementModel model(robot, testing::PaperPlane(),
                               MakeParameterSet(robot, PlaneTerms{}, {"theta1", "a2"}));
  const int n_all = CompleteParameterSet(robot, 1).size();
  const IdentificationSummary nominal =
      Identify(model, ReadingsOfTruth(Eigen::VectorXd::Zero(n_all), configs, 0), GivenSigma());
  ASSERT_TRUE(nominal.IsSolutionUsable());
  const UnestimatedTerms held = FindUnestimatedTerms(
      SolvedModel(model, nominal), nominal,
      ReadingsOfTruth(Eigen::VectorXd::Zero(n_all), configs, 0), GivenSigma(), PriorSigmas{});
  ASSERT_THAT(held.names, ::testing::ElementsAre("theta1", "a2", "plane_u1", "plane_u2", "plane_f",
                                                 "ranger_offset", "ranger_scale"));
  const ParameterSet all = CompleteParameterSet(robot, 1);
  for (int c = 0; c < static_cast<int>(held.names.size()); ++c) {
    constexpr double delta = 1e-6;  // rad, m or (scale) dimensionless
    Eigen::VectorXd truth = Eigen::VectorXd::Zero(n_all);
    truth[all.Find(held.names[c])] = delta;
    const IdentificationSummary plus =
        Identify(model, ReadingsOfTruth(truth, configs, 0), GivenSigma());
    truth[all.Find(held.names[c])] = -delta;
    const IdentificationSummary minus =
        Identify(model, ReadingsOfTruth(truth, configs, 0), GivenSigma());
    ASSERT_TRUE(plus.IsSolutionUsable() && minus.IsSolutionUsable());
    const Eigen::VectorXd fd = (plus.delta - minus.delta) / (2 * delta);
    constexpr double kRelative = 1e-5;  // central differences of a converged LM: O(δ²) + tolerance
    EXPECT_THAT(fd, testing::EigenNear(held.estimate_shift.col(c),
                                       kRelative * held.estimate_shift.col(c).norm() + 1e-9))
        << held.names[c];
  }
}

// The paper's beam runs along z6: a ranger offset is exactly a change of d6, so d6 absorbs it
// and every pose moves by the offset along the beam — the source's RMS is its prior σ.
TEST(AccuracyPrediction, AConfoundedRangerOffsetMovesEveryPoseByItself) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(50, 4);
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const MeasurementSet data =
      ReadingsOfTruth(Eigen::VectorXd::Zero(CompleteParameterSet(robot, 1).size()), configs, 7);
  const IdentificationSummary s = Identify(model, data, GivenSigma());
  ASSERT_TRUE(s.IsSolutionUsable());
  const PriorSigmas known = PriorSigmas::Parse("ranger_offset=0.3mm,plane_u=0.2mrad,plane_f=0.1mm");
  const UnestimatedTerms held =
      FindUnestimatedTerms(SolvedModel(model, s), s, data, GivenSigma(), known);
  EXPECT_THAT(held.defaulted, ::testing::ElementsAre("ranger_scale"));
  const TargetedConfigurations poses = testing::PaperHittingConfigurations(40, 9);
  const AccuracyPrediction p =
      PredictTotalAccuracy(SolvedModel(model, s), s.delta.data(), s.covariance_given, held, poses);
  double shares = 0;
  for (const AccuracySource& src : p.sources) {
    shares += src.share;
    if (src.name != "ranger_offset") continue;
    EXPECT_EQ(src.absorbed_by, "d6");
    EXPECT_NEAR(src.position_rms, 0.3e-3, 1e-9);
    EXPECT_NEAR(src.prior_sigma, 0.3e-3, 1e-15);
    EXPECT_FALSE(src.defaulted);
  }
  EXPECT_NEAR(shares, 1.0, 1e-12);
  for (const PoseAccuracy& a : p.poses) {
    EXPECT_GE(a.position_radius_95_total, a.position_radius_95);
    EXPECT_GE(a.position_std_total.norm(), 0.3e-3 * (1 - 1e-9));
  }
  const std::string text = AccuracyPredictionText(p);
  EXPECT_THAT(text, HasSubstr("ranger_offset"));
  EXPECT_THAT(text, HasSubstr("warning: no tolerance known for 1 held terms"));
  EXPECT_THAT(text, HasSubstr("ranger_scale"));
}

// Without held terms the total is the data part, bit for bit.
TEST(AccuracyPrediction, WithNothingHeldTheTotalIsTheDataPart) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(50, 4);
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const IdentificationSummary s = Identify(
      model,
      ReadingsOfTruth(Eigen::VectorXd::Zero(CompleteParameterSet(robot, 1).size()), configs, 3),
      GivenSigma());
  ASSERT_TRUE(s.IsSolutionUsable());
  UnestimatedTerms none;
  none.estimate_shift.resize(s.delta.size(), 0);
  const TargetedConfigurations poses = testing::PaperHittingConfigurations(10, 9);
  const AccuracyPrediction p =
      PredictTotalAccuracy(SolvedModel(model, s), s.delta.data(), s.covariance_given, none, poses);
  const std::vector<PoseAccuracy> data_only =
      PredictPoseAccuracy(SolvedModel(model, s), s.delta.data(), s.covariance_given, poses);
  for (std::size_t j = 0; j < p.poses.size(); ++j) {
    EXPECT_EQ(p.poses[j].position_radius_95_total, data_only[j].position_radius_95);
    EXPECT_EQ(p.poses[j].position_std_total, data_only[j].position_std);
  }
  ASSERT_EQ(p.sources.size(), 1u);
  EXPECT_EQ(p.sources[0].share, 1.0);
}

// A fit the χ² check rejects (two configurations 3 mm off) is stated with σ̂, and says so.
TEST(ChooseSigma, UsesTheResidualsWhenTheGivenSigmaIsRejected) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(50, 4);
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  MeasurementSet data =
      ReadingsOfTruth(Eigen::VectorXd::Zero(CompleteParameterSet(robot, 1).size()), configs, 5);
  const IdentificationSummary good = Identify(model, data, GivenSigma());
  ASSERT_TRUE(good.fit.consistent);
  EXPECT_EQ(ChooseSigma(good, GivenSigma()).source, "given");
  EXPECT_EQ(ChooseSigma(good, GivenSigma()).sigma, kTotalSigma);
  data.mean_h[3] += 3e-3;
  data.mean_h[17] += 3e-3;
  const IdentificationSummary bad = Identify(model, data, GivenSigma());
  ASSERT_FALSE(bad.fit.consistent);
  const SigmaUsed used = ChooseSigma(bad, GivenSigma());
  EXPECT_EQ(used.source, "residual");
  EXPECT_EQ(used.sigma, bad.sigma_hat);
  EXPECT_GT(used.sigma, 5 * kTotalSigma);
  EXPECT_THAT(used.reason, HasSubstr("rejects the given sigma 0.1000 mm"));
  EXPECT_EQ(&CovarianceFor(bad, used), &bad.covariance_residual);
  EXPECT_EQ(ChooseSigma(bad, IdentificationOptions{}).source, "residual");
}

// Coverage, by Monte Carlo: every term — estimated, fixed (θ1, a1, d3, which a horizontal plane
// cannot see), the plane's offset, the ranger's terms and the base's and tool's transforms —
// drawn from its prior; the calibration
// estimates 22 robot terms and the plane's normal. At one pose per trial the true
// position error falls inside the stated total 95 % radius at 95 % within a 4-standard-error band
// of the binomial count, and inside the data-only radius below that band.
TEST(AccuracyPrediction, TotalRadiusCoversTruthsDrawnFromThePriors) {
  const RobotModel& robot = testing::PaperRobot();
  const Plane horizontal = Plane::FromCoefficients(0, 0, 1, 0.3);
  const TargetedConfigurations configs = testing::HittingConfigurations(horizontal, 60, 8);
  const TargetedConfigurations pool = testing::PaperHittingConfigurations(300, 21);
  const MeasurementModel model(
      robot, horizontal, MakeParameterSet(robot, PlaneTerms{true, false}, {"theta1", "a1", "d3"}));
  const PriorSigmas known = PriorSigmas::Parse(
      "theta=1mrad,alpha=1mrad,beta=1mrad,a=0.5mm,d=0.5mm,plane_u=0.5mrad,plane_f=0.3mm,"
      "ranger_offset=0.2mm,ranger_scale=100ppm,base_x=0.3mm,base_y=0.3mm,base_z=0.3mm,"
      "base_roll=0.3mrad,base_pitch=0.3mrad,base_yaw=0.3mrad,tool_x=0.2mm,tool_y=0.2mm,"
      "tool_z=0.2mm,tool_roll=0.5mrad,tool_pitch=0.5mrad,tool_yaw=0.5mrad");
  const ParameterSet all = CompleteParameterSet(robot, 1);
  const MeasurementModel complete(robot, horizontal, all);
  const Eigen::VectorXd prior = known.SigmasOf(all.names);
  ASSERT_TRUE((prior.array() > 0).all());
  const int trials = 300;
  int inside_total = 0, inside_data = 0;
  for (int t = 0; t < trials; ++t) {
    const RandomStream draws(91, 0, static_cast<std::uint64_t>(t), RandomPurpose::kTruth);
    Eigen::VectorXd truth(all.size());
    for (int k = 0; k < all.size(); ++k)
      truth[k] = prior[k] * draws.Normal(static_cast<std::uint64_t>(k));
    const MeasurementSet data = ReadingsOfTruth(truth, configs, 500 + t, horizontal);
    const IdentificationSummary s = Identify(model, data, GivenSigma());
    ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
    const MeasurementModel solved = SolvedModel(model, s);
    const UnestimatedTerms held = FindUnestimatedTerms(solved, s, data, GivenSigma(), known);
    ASSERT_TRUE(held.defaulted.empty());
    TargetedConfigurations pose(robot.num_links());
    pose.Add(pool.q(t));
    const AccuracyPrediction p = PredictTotalAccuracy(
        solved, s.delta.data(), CovarianceFor(s, ChooseSigma(s, GivenSigma())), held, pose);
    const std::vector<Pose<double>> true_pose =
        ToolPoses(complete.RobotAt(truth.data()), complete.LinkValues(truth.data()), pose);
    const double error = ComparePoses(robot, true_pose, solved.LinkValues(s.delta.data()), pose)
                             .position.col(0)
                             .norm();
    inside_total += error <= p.poses[0].position_radius_95_total;
    inside_data += error <= p.poses[0].position_radius_95;
  }
  const double expected = 0.95 * trials, se = std::sqrt(trials * 0.95 * 0.05);
  EXPECT_NEAR(inside_total, expected, 4 * se) << inside_total << " of " << trials << " inside";
  EXPECT_LT(inside_data, expected - 4 * se)
      << inside_data << " of " << trials << " inside (data only)";
  ::testing::Test::RecordProperty("inside_total_95", inside_total);
  ::testing::Test::RecordProperty("inside_data_95", inside_data);
}

}  // namespace
}  // namespace lrcal
