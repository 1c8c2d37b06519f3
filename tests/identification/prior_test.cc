// Priors (prior.h): their parsing, the maximum a-posteriori estimate against its optimality
// conditions computed independently, rank deficiency resolved by priors, the two solvers'
// agreement, and — by Monte Carlo — the coverage of the stated posterior covariance.
#include "lrcal/identification/prior.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

using testing::EigenNear;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr double kPriorTestSigma = 0.2e-3;  // m, the noise of one reading in these tests

TEST(PriorSigmas, ParsesNamesAndClassesWithTheirUnits) {
  const PriorSigmas p =
      PriorSigmas::Parse("theta=1mrad,a=0.5mm,d6=0.2mm,ranger_scale=200ppm,plane_u=2deg");
  EXPECT_DOUBLE_EQ(p.SigmaOf("theta4"), 1e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("a2"), 0.5e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("d6"), 0.2e-3);  // a name
  EXPECT_EQ(p.SigmaOf("d5"), 0.0);            // no class entry for d
  EXPECT_DOUBLE_EQ(p.SigmaOf("ranger_scale"), 200e-6);
  EXPECT_DOUBLE_EQ(p.SigmaOf("plane2_u1"), 2 * M_PI / 180);
  // A name's own entry wins over its class, whatever the order.
  EXPECT_DOUBLE_EQ(PriorSigmas::Parse("d3=1um,d=1mm").SigmaOf("d3"), 1e-6);
  EXPECT_EQ(TermClass("plane2_u1"), "plane_u");
  EXPECT_EQ(TermClass("target2_x"), "target_x");
  EXPECT_EQ(p.ToString(),
            "theta=1 mrad, a=0.5 mm, d6=0.2 mm, ranger_scale=200 ppm, plane_u=34.9066 mrad");
}

TEST(PriorSigmas, BadItemsAreNamed) {
  const auto message = [](const std::string& text) {
    try {
      PriorSigmas::Parse(text);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(message("thta=1mrad"), HasSubstr("--prior-sigma: 'thta=1mrad': 'thta' is neither"));
  EXPECT_THAT(message("theta=1mm"), HasSubstr("'theta' is an angle (rad, mrad, urad or deg)"));
  EXPECT_THAT(message("a=1"), HasSubstr("'a' is a length (m, mm or um): give its unit"));
  EXPECT_THAT(message("a=-1mm"), HasSubstr("expected a finite value > 0"));
  EXPECT_THAT(message("a=1mm,a=2mm"), HasSubstr("'a' is given twice"));
  EXPECT_THAT(message("a"), HasSubstr("expected NAME=VALUE UNIT"));
}

MeasurementSet Readings(const RobotModel& robot, const Eigen::VectorXd& values, const Plane& plane,
                        const TargetedConfigurations& configs, std::uint64_t seed) {
  MeasurementSet data;
  NoiseModel noise;
  noise.sigma = kPriorTestSigma;
  noise.repetitions = 4;
  noise.draw_mean = true;
  SimulateReadings(robot, values, plane, testing::PaperRig().ranger, configs, noise,
                   RandomStream(seed, 0, 0, RandomPurpose::kNoise), &data);
  return data;
}

IdentificationOptions WithPriors(const std::string& priors) {
  IdentificationOptions options;
  options.sigma = kPriorTestSigma;
  options.priors = PriorSigmas::Parse(priors);
  return options;
}

TEST(Priors, MapEstimateSatisfiesItsNormalEquationsAndStatesTheirCovariance) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const MeasurementSet data = Readings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                                       testing::PaperHittingConfigurations(40, 3), 11);
  const IdentificationOptions options =
      WithPriors("theta=1mrad,alpha=1mrad,beta=1mrad,a=1mm,d=1mm");
  const IdentificationSummary s = Identify(model, data, options);
  ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
  // Independently: the Jacobian and readings at the estimate, per configuration.
  const Eigen::MatrixXd G = IdentificationJacobian(model, data.configs, s.delta.data());
  ModelPoint point;
  model.Prepare(s.delta.data(), &point);
  Eigen::VectorXd r(data.size()), w(data.size());
  for (int i = 0; i < data.size(); ++i) {
    double h;
    model.Evaluate(point, data.configs, i, &h, nullptr);
    r[i] = data.mean_h[i] - h;
    w[i] = data.repetitions[i];
  }
  const Eigen::VectorXd prior = options.priors.SigmasOf(s.names);
  const Eigen::VectorXd lambda =
      (kPriorTestSigma * kPriorTestSigma) * prior.array().square().inverse().matrix();
  // Stationarity of Σw r² + Σ λ_k e_k²: Gᵀ W r = Λ e (relative to the terms' size).
  const Eigen::VectorXd gradient =
      G.transpose() * w.asDiagonal() * r - lambda.asDiagonal() * s.delta;
  EXPECT_LT(gradient.cwiseAbs().maxCoeff(),
            1e-9 * (G.transpose() * w.asDiagonal() * r).cwiseAbs().maxCoeff() + 1e-18);
  const Eigen::MatrixXd A =
      G.transpose() * w.asDiagonal() * G + Eigen::MatrixXd(lambda.asDiagonal());
  const Eigen::MatrixXd covariance = kPriorTestSigma * kPriorTestSigma * A.inverse();
  EXPECT_THAT(s.covariance_given, EigenNear(covariance, 1e-6 * covariance.cwiseAbs().maxCoeff()));
  EXPECT_THAT(
      s.posterior_to_prior,
      EigenNear(Eigen::VectorXd(covariance.diagonal().cwiseSqrt().cwiseQuotient(prior)), 1e-6));
  EXPECT_EQ(s.loss, "least squares with priors");
  EXPECT_THAT(s.FullReport(), HasSubstr("posterior/prior"));
  // lrcal's LM and Ceres reach the same maximum a-posteriori estimate.
  IdentificationOptions ceres = options;
  ceres.solver = IdentificationOptions::Solver::kCeres;
  const IdentificationSummary c = Identify(model, data, ceres);
  ASSERT_TRUE(c.IsSolutionUsable()) << c.FullReport();
  EXPECT_THAT(c.delta, EigenNear(s.delta, 1e-9 * s.delta.cwiseAbs().maxCoeff()));
}

// The check on the paper's data: with 1 mm / 1 mrad priors the estimate is the least
// squares one within its standard error where the readings inform a term; on a horizontal plane
// the terms the plane cannot see are set by their prior.
TEST(Priors, DataDecideWhereTheyCanAndPriorsWhereTheyCannot) {
  const RobotModel& robot = testing::PaperRobot();
  const std::string priors = "theta=1mrad,alpha=1mrad,beta=1mrad,a=1mm,d=1mm";
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const MeasurementSet data = Readings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                                       testing::PaperHittingConfigurations(100, 5), 3);
  IdentificationOptions least_squares;
  least_squares.sigma = kPriorTestSigma;
  const IdentificationSummary ls = Identify(model, data, least_squares);
  const IdentificationSummary map = Identify(model, data, WithPriors(priors));
  ASSERT_TRUE(ls.IsSolutionUsable() && map.IsSolutionUsable());
  for (int k = 0; k < model.num_parameters(); ++k) {
    if (map.posterior_to_prior[k] > 0.5) continue;  // the prior has a say: not a data term
    EXPECT_LT(std::fabs(map.delta[k] - ls.delta[k]), ls.std_given[k]) << ls.names[k];
  }
  EXPECT_TRUE(map.SetByPrior().empty()) << map.FullReport();

  const Plane horizontal = Plane::FromCoefficients(0, 0, 1, 0.3);
  const TargetedConfigurations configs = testing::HittingConfigurations(horizontal, 100, 6);
  const MeasurementModel flat(robot, horizontal, MakeParameterSet(robot, PlaneTerms{}));
  const MeasurementSet flat_data =
      Readings(robot, testing::PaperTrueValues(), horizontal, configs, 4);
  const IdentifiabilityReport report = AnalyzeIdentifiability(flat, configs);
  ASSERT_FALSE(report.full_rank());
  EXPECT_EQ(Identify(flat, flat_data, least_squares).termination, Termination::kRankDeficient);
  const IdentificationSummary flat_map = Identify(flat, flat_data, WithPriors(priors));
  ASSERT_TRUE(flat_map.IsSolutionUsable()) << flat_map.FullReport();
  // Every term the analysis says to fix is one the priors set; nothing else is.
  EXPECT_EQ(flat_map.SetByPrior().size(), report.suggested_fixed.size()) << flat_map.FullReport();
  for (const std::string& name : report.suggested_fixed)
    EXPECT_THAT(flat_map.SetByPrior(), ::testing::Contains(name)) << flat_map.FullReport();
}

TEST(Priors, NeedTheReadingNoise) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  IdentificationOptions options = WithPriors("d=1mm");
  options.sigma = 0;
  EXPECT_THAT(Identify(model,
                       Readings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                                testing::PaperHittingConfigurations(40, 3), 1),
                       options)
                  .message,
              HasSubstr("identification.priors: priors are weighed against the readings' noise"));
}

TEST(PriorRowsEvaluator, AppendsOneRowPerPriorTerm) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model);
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(5, 2);
  std::unique_ptr<MeasurementEvaluator> readings = kind.Bind(configs);
  PriorRowsEvaluator evaluator(*readings, {1, 4});
  const int n = kind.num_parameters();
  ASSERT_EQ(evaluator.num_rows(), 7);
  std::vector<double> e(n, 0.0), y(7), J(7 * n), y0(5), J0(5 * n);
  e[1] = 2e-3;
  e[4] = -3e-3;
  ASSERT_TRUE(evaluator.Predict(e.data(), y.data(), J.data()));
  readings->Predict(e.data(), y0.data(), J0.data());
  EXPECT_THAT(std::vector<double>(y.begin(), y.begin() + 5), ::testing::ContainerEq(y0));
  EXPECT_THAT(std::vector<double>(y.begin() + 5, y.end()), ElementsAre(2e-3, -3e-3));
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < 5; ++i) EXPECT_EQ(J[k * 7 + i], J0[k * 5 + i]);
    EXPECT_EQ(J[k * 7 + 5], k == 1 ? 1.0 : 0.0);
    EXPECT_EQ(J[k * 7 + 6], k == 4 ? 1.0 : 0.0);
  }
}

// The stated posterior covariance holds: truths drawn from the priors, readings with the stated
// noise; the estimate's error falls inside the covariance's 95 % ellipsoid at the stated rate
// (within a 4-standard-error band of the binomial count), on a plane where some terms are set by
// their priors alone.
TEST(Priors, PosteriorCovarianceCoversTruthsDrawnFromThePriors) {
  const RobotModel& robot = testing::PaperRobot();
  const Plane horizontal = Plane::FromCoefficients(0, 0, 1, 0.3);
  const TargetedConfigurations configs = testing::HittingConfigurations(horizontal, 60, 8);
  const MeasurementModel model(robot, horizontal, MakeParameterSet(robot, PlaneTerms{}));
  const IdentificationOptions options =
      WithPriors("theta=1mrad,alpha=1mrad,beta=1mrad,a=1mm,d=1mm");
  const Eigen::VectorXd prior = options.priors.SigmasOf(model.parameters().names);
  const int n = model.num_parameters(), trials = 300;
  const double limit =
      boost::math::quantile(boost::math::chi_squared_distribution<double>(n), 0.95);
  int inside = 0;
  for (int t = 0; t < trials; ++t) {
    const RandomStream draws(77, 0, static_cast<std::uint64_t>(t), RandomPurpose::kTruth);
    Eigen::VectorXd truth(n), values = robot.nominal_values();
    for (int k = 0; k < n; ++k) {
      truth[k] = prior[k] * draws.Normal(static_cast<std::uint64_t>(k));
      values[model.parameters().robot_values[k]] += truth[k];
    }
    const MeasurementSet data = Readings(robot, values, horizontal, configs, 1000 + t);
    const IdentificationSummary s = Identify(model, data, options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
    const Eigen::VectorXd error = s.delta - truth;
    inside += error.dot(s.covariance_given.ldlt().solve(error)) <= limit;
  }
  const double expected = 0.95 * trials, se = std::sqrt(trials * 0.95 * 0.05);
  EXPECT_NEAR(inside, expected, 4 * se) << inside << " of " << trials << " inside";
  ::testing::Test::RecordProperty("inside_95", inside);
}

}  // namespace
}  // namespace lrcal

namespace lrcal {
namespace {

// Before any reading: the posterior of readings at the configurations against the priors is the
// inverse of GᵀWG/σ² + diag(1/σ_k²), computed here independently; the horizontal plane's
// unseen terms are set by their priors, and a term with neither readings nor a prior leaves
// the posterior undefined.
TEST(PriorInformation, IsThePosteriorOfReadingsAtTheConfigurations) {
  const RobotModel& robot = testing::PaperRobot();
  const Plane horizontal = Plane::FromCoefficients(0, 0, 1, 0.3);
  const TargetedConfigurations configs = testing::HittingConfigurations(horizontal, 60, 8);
  const MeasurementModel model(robot, horizontal, MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement kind(model);
  NoiseModel noise;
  noise.sigma = kPriorTestSigma;
  noise.repetitions = 10;
  const PriorSigmas priors = PriorSigmas::Parse("theta=5mrad,alpha=5mrad,beta=5mrad,a=5mm,d=5mm");
  const PriorInformation info = InformationFromPriors(kind, configs, noise, priors);
  ASSERT_TRUE(info.defined);
  const Eigen::MatrixXd G = IdentificationJacobian(model, configs);
  const Eigen::VectorXd prior = priors.SigmasOf(model.parameters().names);
  const Eigen::MatrixXd A = 10 * G.transpose() * G / (kPriorTestSigma * kPriorTestSigma) +
                            Eigen::MatrixXd(prior.array().square().inverse().matrix().asDiagonal());
  const Eigen::VectorXd posterior = A.inverse().diagonal().cwiseSqrt();
  EXPECT_THAT(info.posterior_sigma, EigenNear(posterior, 1e-6 * posterior.maxCoeff()));
  EXPECT_THAT(info.SetByPrior(), ElementsAre("theta1", "a1", "d3"));
  EXPECT_THAT(info.ToString(), HasSubstr("set by the prior (posterior/prior std above 0.9): "
                                         "theta1 a1 d3"));

  const PriorInformation partial =
      InformationFromPriors(kind, configs, noise, PriorSigmas::Parse("theta=5mrad"));
  EXPECT_FALSE(partial.defined);
  EXPECT_TRUE(partial.SetByPrior().empty());
  EXPECT_THAT(partial.ToString(), HasSubstr("leave a direction unbounded"));
  noise.sigma = 0;
  EXPECT_THAT([&] { InformationFromPriors(kind, configs, noise, priors); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("noise.sigma")));
}

}  // namespace
}  // namespace lrcal

namespace lrcal {
namespace {

// With a prior on every term, fewer configurations than terms still give an estimate: the
// posterior is proper, and the data-only refusal names what is missing.
TEST(Priors, FewerReadingsThanTermsAreEnoughWithPriorsOnEveryTerm) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const MeasurementSet data = Readings(robot, testing::PaperTrueValues(), testing::PaperPlane(),
                                       testing::PaperHittingConfigurations(12, 2), 5);
  const IdentificationSummary s =
      Identify(model, data, WithPriors("theta=5mrad,alpha=5mrad,beta=5mrad,a=5mm,d=5mm"));
  ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
  EXPECT_EQ(s.fit.dof, 12);  // 12 readings + 25 priors − 25 terms
  const IdentificationSummary partial = Identify(model, data, WithPriors("theta=5mrad"));
  EXPECT_EQ(partial.termination, Termination::kInvalidInput);
  EXPECT_THAT(partial.message, HasSubstr("need at least as many measured values and priors"));
}

}  // namespace
}  // namespace lrcal
