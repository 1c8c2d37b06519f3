// Several kinds in one calibration (mixed_measurement.h): the union of terms (shared by name,
// clashing own terms prefixed), the layout Combine builds and Bind checks, the Jacobian against
// the parts' own and central differences, a noise-free round trip of a tracker with flush plane
// contacts through both solvers, a one-part mix that is the kind itself, identifiability of the
// union, the stated covariance over many noisy campaigns, located errors.
#include "lrcal/measurement/mixed_measurement.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lrcal/core/error.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/measurement/contact_measurement.h"
#include "lrcal/measurement/pose_measurement.h"
#include "test_util.h"
#include "tracker_fixtures.h"

namespace lrcal {
namespace {

using testing::EigenNear;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
namespace tolerance = testing::tolerance;

// A floor and a wall within the paper arm's reach, both estimated; the probe's tip on the tool.
ContactSetup MixPlanes(bool flush) {
  ContactSetup setup;
  setup.planes = PlaneSet(
      {Plane::FromCoefficients(0.1, 0.2, 1.0, -0.3), Plane::FromCoefficients(1.0, 0.0, 0.2, -0.9)},
      {}, "test");
  setup.plane_terms = {PlaneTerms{true, true}, PlaneTerms{true, true}};
  setup.tool_point = Eigen::Vector3d(0.01, -0.02, 0.1);
  setup.flush = flush;
  return setup;
}

// A tracker seeing one reflector (its terms "target_x", … clash with the probe tip's).
PointSetup OneReflector() {
  PointSetup setup = testing::TrackerSetup();
  setup.targets.resize(1);
  return setup;
}

// The value of `names`' terms of part p taken from a mixed estimate.
Eigen::VectorXd PartEstimate(const MixedMeasurement& mixed, int p, const Eigen::VectorXd& e) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(mixed.columns(p).size()));
  for (Eigen::Index t = 0; t < out.size(); ++t) out[t] = e[mixed.columns(p)[t]];
  return out;
}

TEST(MixedMeasurement, SharesTheArmAndPlanesAndPrefixesClashingOwnTerms) {
  const RobotModel& robot = testing::PaperRobot();
  const auto point = std::make_shared<PointMeasurement>(robot, OneReflector());
  const auto contact = std::make_shared<ContactMeasurement>(robot, MixPlanes(false));
  const MixedMeasurement mixed({{point}, {contact}});
  const std::vector<std::string>& names = mixed.parameter_names();
  const auto count = [&](const std::string& name) {
    return std::count(names.begin(), names.end(), name);
  };
  EXPECT_EQ(count("theta2"), 1);
  EXPECT_EQ(count("plane2_f"), 1);
  EXPECT_EQ(count("instrument_yaw"), 1);
  EXPECT_EQ(count("target_x"), 0);
  EXPECT_EQ(count("point.target_x"), 1);
  EXPECT_EQ(count("contact.target_x"), 1);
  // The arm's terms once, each kind's own terms once.
  const int arm = static_cast<int>(robot.parameter_indices().size());
  EXPECT_EQ(mixed.num_parameters(), point->num_parameters() + contact->num_parameters() - arm);
  // Nominal values follow the names: the probe tip's offset is the contact's.
  const auto at = [&](const std::string& name) {
    return mixed.NominalValues()[std::find(names.begin(), names.end(), name) - names.begin()];
  };
  EXPECT_EQ(at("contact.target_z"), 0.1);
  EXPECT_EQ(at("point.target_z"), 0.10);
  EXPECT_TRUE(MixedMeasurement::IsSharedTerm("beta2"));
  EXPECT_TRUE(MixedMeasurement::IsSharedTerm("tool_yaw"));
  EXPECT_FALSE(MixedMeasurement::IsSharedTerm("ranger_offset"));
  EXPECT_FALSE(MixedMeasurement::IsSharedTerm("socket1_x"));
}

TEST(MixedMeasurement, TagsRoundTripAndCombineLaysEveryValueOut) {
  const RobotModel& robot = testing::PaperRobot();
  const auto pose = std::make_shared<PoseMeasurement>(robot, testing::TrackerSetup(true));
  const auto contact = std::make_shared<ContactMeasurement>(robot, MixPlanes(true));
  const MixedMeasurement mixed({{pose}, {contact}});
  for (int p = 0; p < 2; ++p)
    for (int t = 0; t < 5; ++t)
      for (int c = 0; c < 6; ++c) {
        const MixedMeasurement::Entry e = mixed.Decode(mixed.Tag(p, t, c));
        EXPECT_EQ(e.part, p);
        EXPECT_EQ(e.target, t);
        EXPECT_EQ(e.component, c);
      }
  MeasuredValues a{testing::RandomTrackerConfigurations(6, 4, 2, 1), {}, {}};
  a.y.assign(24, 0.5);
  a.repetitions = {1, 2, 3, 4};
  MeasuredValues b{testing::RandomTrackerConfigurations(6, 3, 2, 2), {}, {}};
  b.y.assign(9, -0.5);
  b.repetitions = {5, 6, 7};
  b.weights = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  const MeasuredValues both = mixed.Combine({a, b});
  ASSERT_EQ(both.size(), 24 + 9);
  EXPECT_EQ(both.weights[5], 1);  // pose configuration 1's sixth value: its repetitions
  EXPECT_EQ(both.weights[6], 2);
  EXPECT_EQ(both.weights[24], 1);  // the contact's given weights
  EXPECT_EQ(both.weights[32], 9);
  EXPECT_EQ(mixed.Decode(both.configs.target(24 + 4)).component, 1);
  EXPECT_THAT(mixed.ConfigurationsPerPart(both.configs), ElementsAre(4, 3));
  EXPECT_EQ(mixed.Bind(both.configs)->num_rows(), 33);
}

TEST(MixedMeasurement, JacobianIsThePartsColumnsAndMatchesCentralDifferences) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const auto point = std::make_shared<PointMeasurement>(robot, OneReflector());
  const auto pose = std::make_shared<PoseMeasurement>(robot, testing::TrackerSetup(true));
  const auto contact = std::make_shared<ContactMeasurement>(robot, MixPlanes(true));
  const MixedMeasurement mixed({{point}, {pose, "probe"}, {contact}});
  std::vector<MeasuredValues> parts;
  for (int p = 0; p < 3; ++p) {
    const int k = mixed.part(p).kind->rows_per_configuration();
    MeasuredValues v{testing::RandomTrackerConfigurations(6, 5, p == 0 ? 1 : 2, 10 + p), {}, {}};
    v.y.assign(static_cast<std::size_t>(5 * k), 0.0);
    v.repetitions.assign(5, 1);
    parts.push_back(v);
  }
  const MeasuredValues data = mixed.Combine(parts);
  const std::vector<double> e = testing::OffNominalEstimate(mixed);
  std::unique_ptr<MeasurementEvaluator> evaluator = mixed.Bind(data.configs);
  Eigen::MatrixXd J(evaluator->num_rows(), evaluator->num_parameters());
  std::vector<double> y(static_cast<std::size_t>(evaluator->num_rows()));
  ASSERT_TRUE(evaluator->Predict(e.data(), y.data(), J.data()));
  // Relative to each row's size: a flush contact's tilt row near a grazing tool grows large.
  const Eigen::VectorXd row_size = J.cwiseAbs().rowwise().maxCoeff().cwiseMax(1.0);
  const Eigen::MatrixXd central = testing::CentralDifferences(*evaluator, e);
  EXPECT_THAT(Eigen::MatrixXd(row_size.cwiseInverse().asDiagonal() * J),
              EigenNear(Eigen::MatrixXd(row_size.cwiseInverse().asDiagonal() * central),
                        tolerance::kCentralDifference));
  // Every part's rows and columns are the part's own Jacobian, bit for bit; the rest is 0.
  const Eigen::Map<const Eigen::VectorXd> e_all(e.data(), static_cast<Eigen::Index>(e.size()));
  int row = 0;
  for (int p = 0; p < 3; ++p) {
    const MeasurementKind& kind = *mixed.part(p).kind;
    const Eigen::VectorXd ep = PartEstimate(mixed, p, e_all);
    const Eigen::MatrixXd Jp =
        MeasurementJacobian(kind, parts[static_cast<std::size_t>(p)].configs, ep.data());
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(Jp.rows(), mixed.num_parameters());
    for (int t = 0; t < kind.num_parameters(); ++t) expected.col(mixed.columns(p)[t]) = Jp.col(t);
    EXPECT_THAT(J.middleRows(row, Jp.rows()), EigenNear(expected, 0.0)) << mixed.part(p).label;
    row += static_cast<int>(Jp.rows());
  }
}

// Noise-free campaigns of a tracker and flush contacts on one true arm, each simulated by its
// own kind on the truth: the mixed fit recovers the truth through both solvers.
TEST(MixedMeasurement, NoiseFreeTrackerAndContactsRecoverTheTruth) {
  const RobotModel& robot = testing::PaperRobot();
  const auto point_full = std::make_shared<PointMeasurement>(robot, OneReflector());
  const auto contact_full = std::make_shared<ContactMeasurement>(robot, MixPlanes(true));
  const MixedMeasurement full({{point_full}, {contact_full}});
  const TargetedConfigurations tracker_configs = testing::RandomTrackerConfigurations(6, 40, 1, 3);
  const TargetedConfigurations starts = testing::RandomTrackerConfigurations(6, 80, 2, 4);
  NoiseModel exact;
  exact.sigma = 0;
  exact.sigma_angle = 0;
  const RandomStream stream(1, 0, 0, RandomPurpose::kNoise);
  // The rank analysis at the nominal campaign names what the union cannot see.
  MeasuredValues nominal_point, nominal_contact;
  SimulateMeasurements(*point_full, tracker_configs, exact, stream, &nominal_point);
  SimulateContactMeasurements(*contact_full, starts, exact, stream, &nominal_contact);
  const IdentifiabilityReport report =
      AnalyzeIdentifiability(full, full.Combine({nominal_point, nominal_contact}).configs);
  const IdentifiabilityReport point_alone =
      AnalyzeIdentifiability(*point_full, nominal_point.configs);
  const IdentifiabilityReport contact_alone =
      AnalyzeIdentifiability(*contact_full, nominal_contact.configs);
  EXPECT_GT(report.rank, point_alone.rank);
  EXPECT_GT(report.rank, contact_alone.rank);
  const std::unique_ptr<MeasurementKind> reduced = full.Without(report.suggested_fixed);
  const auto& mixed = dynamic_cast<const MixedMeasurement&>(*reduced);
  EXPECT_EQ(mixed.num_parameters(), report.rank);

  const Eigen::VectorXd truth = testing::SomeTruth(mixed, 7);
  const auto& point = dynamic_cast<const PointMeasurement&>(*mixed.part(0).kind);
  const auto& contact = dynamic_cast<const ContactMeasurement&>(*mixed.part(1).kind);
  RobotModel true_arm_point, true_arm_contact;
  const auto true_point =
      testing::TrueTrackerKind(point, PartEstimate(mixed, 0, truth), &true_arm_point);
  const auto true_contact =
      testing::TrueContactKind(contact, PartEstimate(mixed, 1, truth), &true_arm_contact);
  MeasuredValues point_data, contact_data;
  EXPECT_EQ(SimulateMeasurements(*true_point, tracker_configs, exact, stream, &point_data), 0);
  SimulateContactMeasurements(*true_contact, starts, exact, stream, &contact_data);
  ASSERT_GT(contact_data.size(), 40);
  const MeasuredValues data = mixed.Combine({point_data, contact_data});
  for (auto solver : {IdentificationOptions::Solver::kLevenbergMarquardt,
                      IdentificationOptions::Solver::kCeres}) {
    IdentificationOptions options;
    options.solver = solver;
    const IdentificationSummary s = Identify(mixed, data, options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.message;
    EXPECT_THAT(s.delta, EigenNear(truth, tolerance::kRoundTrip)) << s.solver;
    EXPECT_LT(s.residual_rms, 1e-12);
  }
}

TEST(MixedMeasurement, OnePartIsTheKindItself) {
  const RobotModel& robot = testing::PaperRobot();
  const auto point = std::make_shared<PointMeasurement>(robot, testing::TrackerSetup());
  const MixedMeasurement mixed({{point}});
  EXPECT_EQ(mixed.parameter_names(), point->parameter_names());
  const TargetedConfigurations configs = testing::RandomTrackerConfigurations(6, 30, 2, 5);
  NoiseModel noise;
  noise.sigma = 1e-4;
  MeasuredValues data;
  SimulateMeasurements(*point, configs, noise, RandomStream(3, 0, 0, RandomPurpose::kNoise), &data);
  IdentificationOptions options;
  options.sigma = noise.sigma;
  options.fix_dependent_parameters = true;
  const IdentificationSummary alone = Identify(*point, data, options);
  const IdentificationSummary mix = Identify(mixed, mixed.Combine({data}), options);
  ASSERT_TRUE(alone.IsSolutionUsable()) << alone.message;
  ASSERT_TRUE(mix.IsSolutionUsable()) << mix.message;
  EXPECT_EQ(mix.names, alone.names);
  EXPECT_EQ(mix.fixed, alone.fixed);
  EXPECT_THAT(mix.delta, EigenNear(alone.delta, 1e-12));
  EXPECT_THAT(mix.covariance_given, EigenNear(alone.covariance_given, 1e-18));
  EXPECT_NEAR(mix.fit.chi2, alone.fit.chi2, 1e-9 * alone.fit.chi2);
}

// The covariance Identify states for a mixed fit holds: over many noisy campaigns (the tracker's
// points with σ, the flush contacts' play σ and tilt σ_angle, each simulated by its kind) the
// estimate's Mahalanobis distance δᵀΣ⁻¹δ averages the number of terms within 4 standard errors.
TEST(MixedMeasurement, StatedCovarianceHoldsOverManyCampaigns) {
  const RobotModel& robot = testing::PaperRobot();
  const auto point_full = std::make_shared<PointMeasurement>(robot, OneReflector());
  const auto contact_full = std::make_shared<ContactMeasurement>(robot, MixPlanes(true));
  const MixedMeasurement full({{point_full}, {contact_full}});
  const TargetedConfigurations tracker_configs = testing::RandomTrackerConfigurations(6, 30, 1, 8);
  const TargetedConfigurations starts = testing::RandomTrackerConfigurations(6, 60, 2, 9);
  NoiseModel noise;
  noise.sigma = 5e-5;
  noise.sigma_angle = 2e-4;
  MeasuredValues point_data, contact_data;
  const RandomStream first(1, 0, 0, RandomPurpose::kNoise);
  SimulateMeasurements(*point_full, tracker_configs, noise, first, &point_data);
  SimulateContactMeasurements(*contact_full, starts, noise, first, &contact_data);
  const IdentifiabilityReport report =
      AnalyzeIdentifiability(full, full.Combine({point_data, contact_data}).configs);
  const std::unique_ptr<MeasurementKind> mixed = full.Without(report.suggested_fixed);
  const auto& kind = dynamic_cast<const MixedMeasurement&>(*mixed);
  const int n = kind.num_parameters();
  constexpr int kCampaigns = 150;
  double sum = 0;
  for (int r = 0; r < kCampaigns; ++r) {
    const RandomStream stream(1, static_cast<std::uint64_t>(r), 0, RandomPurpose::kNoise);
    SimulateMeasurements(*kind.part(0).kind, tracker_configs, noise, stream, &point_data);
    const RandomStream play(2, static_cast<std::uint64_t>(r), 0, RandomPurpose::kNoise);
    SimulateContactMeasurements(dynamic_cast<const ContactMeasurement&>(*kind.part(1).kind), starts,
                                noise, play, &contact_data);
    IdentificationOptions options;
    options.sigma = noise.sigma;
    const IdentificationSummary s =
        Identify(kind, kind.Combine({point_data, contact_data}), options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.message;
    sum += s.delta.dot(s.covariance_given.ldlt().solve(s.delta));
  }
  const double mean = sum / kCampaigns, se = std::sqrt(2.0 * n / kCampaigns);
  EXPECT_NEAR(mean, n, 4 * se);
}

TEST(MixedMeasurement, BadMixesAndLayoutsAreNamed) {
  const RobotModel& robot = testing::PaperRobot();
  const auto point = std::make_shared<PointMeasurement>(robot, OneReflector());
  const auto contact = std::make_shared<ContactMeasurement>(robot, MixPlanes(true));
  EXPECT_THAT([] { MixedMeasurement({}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("needs at least one kind")));
  EXPECT_THAT(
      [&] {
        MixedMeasurement({{point}, {point}});
      },
      ::testing::ThrowsMessage<InputError>(HasSubstr("labelled 'point'")));
  ContactSetup moved = MixPlanes(true);
  moved.planes[1].offset += 0.01;
  const auto other_planes = std::make_shared<ContactMeasurement>(robot, moved);
  EXPECT_THAT(
      [&] {
        MixedMeasurement({{contact}, {other_planes, "other"}});
      },
      ::testing::ThrowsMessage<InputError>(
          HasSubstr("the contact and other measurements disagree on plane2_f")));
  const MixedMeasurement mixed({{point}, {contact}});
  // A flush contact's three values must follow each other at one configuration.
  TargetedConfigurations torn(6);
  const std::vector<double> q(6, 0.2);
  torn.Add(q, mixed.Tag(1, 0, 0));
  torn.Add(q, mixed.Tag(1, 0, 2));
  EXPECT_THAT([&] { mixed.Bind(torn); },
              ::testing::ThrowsMessage<InputError>(HasSubstr(
                  "mixed measurement entry 2: expected value 2 of the contact configuration")));
  EXPECT_THAT([&] { mixed.Without({"no_such_term"}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("'no_such_term' is not a term")));
  // Holding one of two clashing terms keeps the other's prefixed name.
  const std::unique_ptr<MeasurementKind> held = mixed.Without({"contact.target_x", "theta1"});
  const std::vector<std::string>& names = held->parameter_names();
  EXPECT_EQ(std::count(names.begin(), names.end(), "point.target_x"), 1);
  EXPECT_EQ(std::count(names.begin(), names.end(), "theta1"), 0);
  EXPECT_EQ(held->num_parameters(), mixed.num_parameters() - 2);
}

}  // namespace
}  // namespace lrcal
