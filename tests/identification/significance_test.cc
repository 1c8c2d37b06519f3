// Significance filtering (significance.h): which corrections are held, their tolerance, and — by
// Monte Carlo — that the filtered model's stated total 95 % radius, with the held terms'
// tolerance √(δ² + sd²) from the full fit, still holds the true position error at least at its
// rate when the truth is drawn from priors that make some terms too small for the data to see.
#include "lrcal/identification/significance.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "lrcal/identification/total_accuracy.h"
#include "lrcal/kinematics/pose_errors.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

constexpr double kSignificanceSigma = 0.1e-3;  // m, one reading's noise

TEST(InsignificantCorrections, HoldsWhatIsWithinKStandardDeviations) {
  IdentificationSummary s;
  s.names = {"theta1", "a2", "d3"};
  s.delta = Eigen::Vector3d(1e-3, -0.5e-4, 2e-5);
  s.covariance_given = Eigen::Vector3d(1e-8, 1e-8, 1e-8).asDiagonal();  // sd 1e-4
  IdentificationOptions options;
  options.sigma = 1e-4;
  const InsignificantCorrections c = FindInsignificantCorrections(s, options, 2.0);
  EXPECT_THAT(c.Names(), ::testing::ElementsAre("a2", "d3"));
  EXPECT_NEAR(c.Tolerances().SigmaOf("a2"), std::hypot(0.5e-4, 1e-4), 1e-18);
  EXPECT_EQ(c.Tolerances().SigmaOf("theta1"), 0);
  EXPECT_THROW(FindInsignificantCorrections(s, options, 0), std::invalid_argument);
}

// The arm's every term drawn from its prior, the α's and β's a hundred times smaller than the
// rest (near zero for the data); a horizontal plane, 22 robot terms and the plane's normal
// estimated; the fit filtered at K = 2 and refitted; one pose per trial.
TEST(InsignificantCorrections, FilteredModelsTotalRadiusStillCoversTheTruth) {
  const RobotModel& robot = testing::PaperRobot();
  const Plane horizontal = Plane::FromCoefficients(0, 0, 1, 0.3);
  const TargetedConfigurations configs = testing::HittingConfigurations(horizontal, 60, 8);
  const TargetedConfigurations pool = testing::PaperHittingConfigurations(300, 21);
  const MeasurementModel model(
      robot, horizontal, MakeParameterSet(robot, PlaneTerms{true, false}, {"theta1", "a1", "d3"}));
  const PriorSigmas known = PriorSigmas::Parse(
      "theta=1mrad,alpha=0.01mrad,beta=0.01mrad,a=0.5mm,d=0.5mm,plane_u=0.5mrad,plane_f=0.3mm,"
      "ranger_offset=0.2mm,ranger_scale=100ppm,base_x=0.3mm,base_y=0.3mm,base_z=0.3mm,"
      "base_roll=0.3mrad,base_pitch=0.3mrad,base_yaw=0.3mrad,tool_x=0.2mm,tool_y=0.2mm,"
      "tool_z=0.2mm,tool_roll=0.5mrad,tool_pitch=0.5mrad,tool_yaw=0.5mrad");
  const ParameterSet all = CompleteParameterSet(robot, 1);
  const MeasurementModel complete(robot, horizontal, all);
  const Eigen::VectorXd prior = known.SigmasOf(all.names);
  IdentificationOptions options;
  options.sigma = kSignificanceSigma;
  const int trials = 300;
  int inside = 0, filtered = 0;
  for (int t = 0; t < trials; ++t) {
    const RandomStream draws(93, 0, static_cast<std::uint64_t>(t), RandomPurpose::kTruth);
    Eigen::VectorXd truth(all.size());
    for (int k = 0; k < all.size(); ++k)
      truth[k] = prior[k] * draws.Normal(static_cast<std::uint64_t>(k));
    NoiseModel noise;
    noise.sigma = kSignificanceSigma;
    noise.repetitions = 1;
    noise.ranger_offset = truth[complete.parameters().ranger_offset_index];
    noise.ranger_scale = truth[complete.parameters().ranger_scale_index];
    MeasurementSet data;
    SimulateReadings(complete.RobotAt(truth.data()), complete.LinkValues(truth.data()),
                     complete.PlanesAt(truth.data()), testing::PaperRig().ranger, configs, noise,
                     RandomStream(700 + t, 0, 0, RandomPurpose::kNoise), &data);
    const IdentificationSummary full = Identify(model, data, options);
    ASSERT_TRUE(full.IsSolutionUsable()) << full.FullReport();
    const InsignificantCorrections held = FindInsignificantCorrections(full, options, 2.0);
    filtered += !held.terms.empty();
    const MeasurementModel reduced(robot, horizontal,
                                   WithoutParameters(robot, model.parameters(), held.Names()));
    const IdentificationSummary s = Identify(reduced, data, options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
    const MeasurementModel solved = SolvedModel(reduced, s);
    const UnestimatedTerms unestimated =
        FindUnestimatedTerms(solved, s, data, options, known.OverriddenBy(held.Tolerances()));
    TargetedConfigurations pose(robot.num_links());
    pose.Add(pool.q(t));
    const AccuracyPrediction p = PredictTotalAccuracy(
        solved, s.delta.data(), CovarianceFor(s, ChooseSigma(s, options)), unestimated, pose);
    const std::vector<Pose<double>> true_pose =
        ToolPoses(complete.RobotAt(truth.data()), complete.LinkValues(truth.data()), pose);
    const double error = ComparePoses(robot, true_pose, solved.LinkValues(s.delta.data()), pose)
                             .position.col(0)
                             .norm();
    inside += error <= p.poses[0].position_radius_95_total;
  }
  EXPECT_GT(filtered, trials / 2);  // the small α's and β's are held in most trials
  const double expected = 0.95 * trials, se = std::sqrt(trials * 0.95 * 0.05);
  EXPECT_GE(inside, expected - 4 * se) << inside << " of " << trials << " inside";
  ::testing::Test::RecordProperty("inside_filtered_95", inside);
}

}  // namespace
}  // namespace lrcal
