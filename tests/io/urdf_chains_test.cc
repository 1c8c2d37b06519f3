// Issue 30: a tree's chains in one calibration. The dual-arm robot of examples/urdf (a three-joint
// torso, two six-joint arms) read as two chains sharing the torso: forward kinematics of each
// against the URDF composed independently at the whole robot's configurations; a tracker on each
// tool, the true robot a URDF whose every joint origin is moved (a physical tree, not the model's
// own parametrisation), calibrated noise-free through the union; the union's identifiable count
// against the chains' own.
#include <ceres/jet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/urdf.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/measurement/chain_measurement.h"
#include "lrcal/measurement/contact_measurement.h"
#include "lrcal/measurement/mixed_measurement.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/measurement/pose_measurement.h"
#include "lrcal/measurement/tree_measurement.h"
#include "test_util.h"
#include "tracker_fixtures.h"
#include "urdf_kinematics.h"

namespace lrcal {
namespace {

const std::vector<std::string> kArms = {"left_tool", "right_tool"};

std::string DualArm() { return testing::SourcePath("examples/urdf/dual_arm_torso.urdf"); }

// The whole robot's configurations: every joint uniform in its range (its first chain's).
TargetedConfigurations RobotConfigurations(const UrdfChains& tree, int count, unsigned seed) {
  std::vector<std::pair<double, double>> range(tree.joint_names.size());
  for (std::size_t c = 0; c < tree.chains.size(); ++c)
    for (std::size_t k = 0; k < tree.placements[c].joints.size(); ++k) {
      const Link& link = tree.chains[c].robot.links()[k];
      range[static_cast<std::size_t>(tree.placements[c].joints[k])] = {link.q_min, link.q_max};
    }
  std::mt19937 rng(seed);
  TargetedConfigurations configs(static_cast<int>(range.size()));
  for (int i = 0; i < count; ++i) {
    std::vector<double> q;
    for (const auto& [lo, hi] : range)
      q.push_back(std::uniform_real_distribution<double>(lo, hi)(rng));
    configs.Add(q);
  }
  return configs;
}

TEST(UrdfChains, TwoArmsOnATorsoShareItsJointsAndLinks) {
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArms);
  ASSERT_EQ(tree.joint_names.size(), 15u);
  EXPECT_THAT(
      std::vector<std::string>(tree.joint_names.begin(), tree.joint_names.begin() + 4),
      ::testing::ElementsAre("torso_yaw", "torso_pitch_1", "torso_pitch_2", "left_shoulder_pitch"));
  EXPECT_EQ(tree.joint_names[9], "right_shoulder_pitch");
  EXPECT_THAT(tree.placements[1].joints, ::testing::ElementsAre(0, 1, 2, 9, 10, 11, 12, 13, 14));
  // The torso's two links between its joints are every chain's; the link from the last torso
  // joint to the shoulder is each arm's own.
  EXPECT_THAT(tree.placements[0].link_labels,
              ::testing::ElementsAre("", "", "left_tool", "left_tool", "left_tool", "left_tool",
                                     "left_tool", "left_tool", "left_tool"));
  EXPECT_EQ(tree.placements[1].link_labels[2], "right_tool");
  // Each chain's kinematics at the whole robot's configurations, against the URDF's.
  const TargetedConfigurations configs = RobotConfigurations(tree, 100, 5);
  for (std::size_t c = 0; c < kArms.size(); ++c) {
    const RobotModel& robot = tree.chains[c].robot;
    for (int i = 0; i < configs.size(); ++i) {
      std::map<std::string, double> by_name;
      for (std::size_t j = 0; j < tree.joint_names.size(); ++j)
        by_name[tree.joint_names[j]] = configs.q(i)[j];
      std::vector<double> q;
      for (int j : tree.placements[c].joints) q.push_back(configs.q(i)[j]);
      const Pose<double> pose =
          ForwardKinematics<double>(robot, robot.nominal_values().data(), q.data());
      const Eigen::Isometry3d expected =
          testing::UrdfPoseBetween(DualArm(), "base_link", kArms[c], by_name);
      EXPECT_LT((pose.p_BT - expected.translation()).norm(), testing::tolerance::kUrdf);
      EXPECT_THAT(pose.R_BT, testing::EigenNear(expected.linear(), testing::tolerance::kUrdf));
    }
  }
}

PointSetup OneTarget() {
  PointSetup setup = testing::TrackerSetup();
  setup.targets = {Eigen::Vector3d(0.02, -0.01, 0.05)};
  return setup;
}

MixedMeasurement TrackedArms(const UrdfChains& tree) {
  std::vector<MixedPart> parts;
  for (std::size_t c = 0; c < tree.chains.size(); ++c)
    parts.push_back({std::make_shared<ChainMeasurement>(
                         std::make_shared<PointMeasurement>(tree.chains[c].robot, OneTarget()),
                         tree.placements[c]),
                     tree.placements[c].label, true});
  return MixedMeasurement(parts);
}

MeasuredValues Simulated(const MixedMeasurement& truth, const TargetedConfigurations& configs) {
  std::vector<MeasuredValues> values;
  NoiseModel exact;
  exact.sigma = 0;
  for (int p = 0; p < truth.num_parts(); ++p) {
    MeasuredValues v;
    SimulateMeasurements(*truth.part(p).kind, configs, exact,
                         RandomStream(1, 0, 0, RandomPurpose::kNoise), &v);
    values.push_back(v);
  }
  return truth.Combine(values);
}

TEST(UrdfChains, TwoTrackedArmsSharingATorsoCalibrateToAPhysicalTree) {
  const UrdfChains nominal = LoadUrdfChains(DualArm(), kArms);
  const UrdfChains truth =
      LoadUrdfChains(testing::UrdfWithMovedOrigins(
                         DualArm(), 11, testing::TempDir("urdf_chains") + "/true_dual_arm.urdf"),
                     kArms);
  const MixedMeasurement full = TrackedArms(nominal);
  const MixedMeasurement true_kind = TrackedArms(truth);
  // Shared by name: the torso's first two links and the tracker's frame (one instrument sees both
  // tools); each arm's links and target are its own.
  EXPECT_THAT(full.parameter_names(), ::testing::Contains("theta1"));
  EXPECT_THAT(full.parameter_names(), ::testing::Contains("instrument_x"));
  EXPECT_THAT(full.parameter_names(), ::testing::Contains("left_tool.theta3"));
  EXPECT_THAT(full.parameter_names(), ::testing::Contains("right_tool.target_x"));
  const TargetedConfigurations configs = RobotConfigurations(nominal, 60, 7);
  const MeasuredValues data = Simulated(true_kind, configs);
  const IdentifiabilityReport report = AnalyzeIdentifiability(full, data.configs);
  const std::unique_ptr<MeasurementKind> reduced = full.Without(report.suggested_fixed);
  for (auto solver : {IdentificationOptions::Solver::kLevenbergMarquardt,
                      IdentificationOptions::Solver::kCeres}) {
    IdentificationOptions options;
    options.solver = solver;
    const IdentificationSummary s = Identify(*reduced, data, options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.message;
    // The union's model holds the physical tree exactly: no residual, and at configurations it
    // was not fitted on, every tool point where the true robot puts it.
    EXPECT_LT(s.residual_rms, 1e-12) << s.solver;
    const TargetedConfigurations validation = RobotConfigurations(nominal, 30, 8);
    const MeasuredValues expected = Simulated(true_kind, validation);
    std::vector<double> y(expected.y.size()), nominal_y(expected.y.size());
    reduced->Bind(expected.configs)->Predict(s.delta.data(), y.data(), nullptr);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(reduced->num_parameters());
    reduced->Bind(expected.configs)->Predict(zero.data(), nominal_y.data(), nullptr);
    double nominal_error = 0;
    for (std::size_t r = 0; r < y.size(); ++r) {
      EXPECT_NEAR(y[r], expected.y[r], testing::tolerance::kRoundTrip) << "value " << r;
      nominal_error = std::max(nominal_error, std::abs(nominal_y[r] - expected.y[r]));
    }
    EXPECT_GT(nominal_error, 5e-3) << "the moved origins move the tools by millimetres";
  }
}

// The covariance a joint fit of two arms states holds: over many noisy campaigns of a tracker on
// each tool (0.05 mm), the mean of δᵀΣ⁻¹δ is the number of terms within 4 standard errors.
TEST(UrdfChains, TheJointFitsStatedCovarianceHoldsOverManyCampaigns) {
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArms);
  const MixedMeasurement full = TrackedArms(tree);
  const TargetedConfigurations configs = RobotConfigurations(tree, 40, 31);
  const IdentifiabilityReport report =
      AnalyzeIdentifiability(full, Simulated(full, configs).configs);
  const std::unique_ptr<MeasurementKind> reduced = full.Without(report.suggested_fixed);
  const auto& kind = dynamic_cast<const MixedMeasurement&>(*reduced);
  const int n = kind.num_parameters();
  NoiseModel noise;
  noise.sigma = 5e-5;
  constexpr int kCampaigns = 150;
  double sum = 0;
  for (int r = 0; r < kCampaigns; ++r) {
    std::vector<MeasuredValues> values(2);
    for (int p = 0; p < 2; ++p)
      SimulateMeasurements(
          *kind.part(p).kind, configs, noise,
          RandomStream(4, static_cast<std::uint64_t>(2 * r + p), 0, RandomPurpose::kNoise),
          &values[static_cast<std::size_t>(p)]);
    IdentificationOptions options;
    options.sigma = noise.sigma;
    const IdentificationSummary s = Identify(kind, kind.Combine(values), options);
    ASSERT_TRUE(s.IsSolutionUsable()) << s.message;
    sum += s.delta.dot(s.covariance_given.ldlt().solve(s.delta));
  }
  const double mean = sum / kCampaigns, se = std::sqrt(2.0 * n / kCampaigns);
  EXPECT_NEAR(mean, n, 4 * se);
}

TEST(UrdfChains, TheUnionSeesWhatTheArmsShareOnce) {
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArms);
  const MixedMeasurement both = TrackedArms(tree);
  const TargetedConfigurations configs = RobotConfigurations(tree, 60, 9);
  const MeasuredValues data = Simulated(both, configs);
  const int union_rank = AnalyzeIdentifiability(both, data.configs).rank;
  // Each arm alone, and each arm with the shared terms held: what the arm sees of the torso.
  std::vector<std::string> shared;
  for (const std::string& name : both.parameter_names())
    if (name.find('.') == std::string::npos) shared.push_back(name);
  ASSERT_FALSE(shared.empty());
  int sum = 0, shared_seen = -1;
  for (int p = 0; p < 2; ++p) {
    const MixedMeasurement alone({both.part(p)});
    const MeasuredValues own = Simulated(alone, configs);
    const int rank = AnalyzeIdentifiability(alone, own.configs).rank;
    const int without_shared = AnalyzeIdentifiability(*alone.Without(shared), own.configs).rank;
    sum += rank;
    if (shared_seen >= 0) {
      EXPECT_EQ(rank - without_shared, shared_seen);
    }
    shared_seen = rank - without_shared;
  }
  EXPECT_GT(shared_seen, 0);
  EXPECT_EQ(union_rank, sum - shared_seen);
}

// Design's view of a tree: both arms measured at each whole-robot configuration, each chain's
// values as its own kind gives them, bit for bit, in chain order; the terms are the joint fit's.
TEST(UrdfChains, ChainsMeasuredTogetherAreEachChainsValuesInTurn) {
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArms);
  std::vector<std::shared_ptr<const ChainMeasurement>> chains;
  for (std::size_t c = 0; c < tree.chains.size(); ++c)
    chains.push_back(std::make_shared<ChainMeasurement>(
        std::make_shared<PointMeasurement>(tree.chains[c].robot, OneTarget()), tree.placements[c]));
  const TreeMeasurement together(chains);
  EXPECT_STREQ(together.name(), "point");
  EXPECT_EQ(together.rows_per_configuration(), 6);
  EXPECT_EQ(together.parameter_names(), TrackedArms(tree).parameter_names());
  const TargetedConfigurations configs = RobotConfigurations(tree, 12, 13);
  const Eigen::VectorXd e = testing::SomeTruth(together, 3);
  const Eigen::MatrixXd J = MeasurementJacobian(together, configs, e.data());
  std::vector<double> y(static_cast<std::size_t>(J.rows()));
  together.Bind(configs)->Predict(e.data(), y.data(), nullptr);
  for (std::size_t c = 0; c < chains.size(); ++c) {
    // The chain's own estimate: its terms' columns of the joint one.
    Eigen::VectorXd own(chains[c]->num_parameters());
    std::vector<int> columns;
    for (int k = 0; k < own.size(); ++k) {
      const auto& names = together.parameter_names();
      const auto it = std::find(names.begin(), names.end(), chains[c]->parameter_names()[k]);
      ASSERT_NE(it, names.end());
      columns.push_back(static_cast<int>(it - names.begin()));
      own[k] = e[columns.back()];
    }
    const Eigen::MatrixXd Jc = MeasurementJacobian(*chains[c], configs, own.data());
    std::vector<double> yc(static_cast<std::size_t>(Jc.rows()));
    chains[c]->Bind(configs)->Predict(own.data(), yc.data(), nullptr);
    for (int i = 0; i < configs.size(); ++i)
      for (int r = 0; r < 3; ++r) {
        const int row = i * 6 + 3 * static_cast<int>(c) + r;
        EXPECT_EQ(y[static_cast<std::size_t>(row)], yc[static_cast<std::size_t>(i * 3 + r)]);
        for (int k = 0; k < own.size(); ++k)
          EXPECT_EQ(J(row, columns[static_cast<std::size_t>(k)]), Jc(i * 3 + r, k));
      }
  }
  // Held terms keep the layout; contacts, seated chain by chain, are refused by name.
  EXPECT_EQ(together.Without({"left_tool.theta9"})->rows_per_configuration(), 6);
  ContactSetup table;
  table.planes = PlaneSet(Plane::FromCoefficients(0, 0, 1, -0.2));
  const auto contact = std::make_shared<ChainMeasurement>(
      std::make_shared<ContactMeasurement>(tree.chains[0].robot, table), tree.placements[0]);
  EXPECT_THAT([&] { TreeMeasurement({contact}); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(
                  "chain 'left_tool': contact data seat each chain at configurations of its own")));
}

// A mimic joint on a chain: the dual-arm robot's head tilts with the last torso joint (multiplier
// -1). The head's chain has the tilt as a coupled link that follows torso_pitch_2, which is not a
// joint of its own in the robot's vector.
const std::vector<std::string> kArmsAndHead = {"left_tool", "right_tool", "head"};

TEST(UrdfChains, AMimicJointIsACoupledLinkFollowingItsJoint) {
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArmsAndHead);
  EXPECT_EQ(tree.joint_names.size(), 15u);  // head_tilt follows torso_pitch_2
  EXPECT_THAT(tree.placements[2].joints, ::testing::ElementsAre(0, 1, 2, 2));
  ASSERT_EQ(tree.placements[2].couplings.size(), 1u);
  const JointCoupling& tilt = tree.placements[2].couplings[0];
  EXPECT_EQ(tilt.link, 3);
  EXPECT_EQ(tilt.joint, 2);
  EXPECT_EQ(tilt.multiplier, -1.0);
  // The head's pose is the URDF's with the tilt at -q(torso_pitch_2).
  const ChainMeasurement head(std::make_shared<PointMeasurement>(tree.chains[2].robot, OneTarget()),
                              tree.placements[2]);
  const TargetedConfigurations configs = RobotConfigurations(tree, 40, 17);
  const TargetedConfigurations chain = head.ChainConfigurations(configs);
  const RobotModel& robot = tree.chains[2].robot;
  for (int i = 0; i < configs.size(); ++i) {
    std::map<std::string, double> by_name;
    for (std::size_t j = 0; j < tree.joint_names.size(); ++j)
      by_name[tree.joint_names[j]] = configs.q(i)[j];
    by_name["head_tilt"] = -by_name["torso_pitch_2"];
    const Pose<double> pose =
        ForwardKinematics<double>(robot, robot.nominal_values().data(), chain.q(i));
    const Eigen::Isometry3d expected =
        testing::UrdfPoseBetween(DualArm(), "base_link", "head", by_name);
    EXPECT_LT((pose.p_BT - expected.translation()).norm(), testing::tolerance::kUrdf);
  }
  // Its gain is a term of the head's own (the tilt's link is no other chain's), in ppm.
  EXPECT_THAT(head.parameter_names(), ::testing::Contains("head.coupling4_gain"));
  EXPECT_STREQ(DisplayUnitOf("head.coupling4_gain").unit, "ppm");
  EXPECT_THAT(head.Without({"head.coupling4_gain"})->parameter_names(),
              ::testing::Not(::testing::Contains("head.coupling4_gain")));
  // Holding the tilt's offset (a last link's θ0 depends on its target's offset) keeps the gain:
  // the offset's column is kept, hidden, for the gain's.
  const std::unique_ptr<MeasurementKind> held = head.Without({"head.theta4", "head.target_x"});
  EXPECT_THAT(held->parameter_names(), ::testing::Contains("head.coupling4_gain"));
  EXPECT_THAT(held->parameter_names(), ::testing::Not(::testing::Contains("head.theta4")));
  EXPECT_EQ(held->num_parameters(), head.num_parameters() - 2);
  EXPECT_EQ(held->NominalValues().size(), held->num_parameters());
}

// The gain's column against autodiff of the chain's forward kinematics through the coupled joint
// value (m + δm)·q_j + o, and against central differences of the whole evaluator (which rebinds
// the kind at each gain).
TEST(UrdfChains, ACouplingsGainColumnMatchesAutodiffAndCentralDifferences) {
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArmsAndHead);
  const PointSetup setup = OneTarget();
  const ChainMeasurement head(std::make_shared<PointMeasurement>(tree.chains[2].robot, setup),
                              tree.placements[2]);
  const TargetedConfigurations configs = RobotConfigurations(tree, 20, 19);
  const int n = head.num_parameters();
  const int gain = n - 1;
  ASSERT_EQ(head.parameter_names()[static_cast<std::size_t>(gain)], "head.coupling4_gain");
  std::vector<double> e(static_cast<std::size_t>(n), 0.0);
  e[static_cast<std::size_t>(gain)] = 0.003;
  std::unique_ptr<MeasurementEvaluator> evaluator = head.Bind(configs);
  const int m = evaluator->num_rows();
  std::vector<double> y(static_cast<std::size_t>(m));
  Eigen::MatrixXd J(m, n);
  ASSERT_TRUE(evaluator->Predict(e.data(), y.data(), J.data()));
  using Jet = ceres::Jet<double, 1>;
  const RobotModel& robot = tree.chains[2].robot;
  std::vector<Jet> values;
  for (int k = 0; k < robot.num_values(); ++k) values.emplace_back(robot.nominal_values()[k]);
  const JointCoupling& tilt = tree.placements[2].couplings[0];
  for (int i = 0; i < configs.size(); ++i) {
    // FK takes joint values as numbers: the coupled joint's value, a Jet in the gain, goes into
    // its link's θ (θ = θ0 + q) with q = 0 there.
    std::vector<double> q;
    for (int j : tree.placements[2].joints) q.push_back(configs.q(i)[j]);
    q[3] = 0;
    std::vector<Jet> with_tilt = values;
    with_tilt[3 * kValuesPerLink + kTheta] +=
        (Jet(tilt.multiplier) + Jet(0.003, 0)) * configs.q(i)[tilt.joint] + tilt.offset;
    const Pose<Jet> pose = ForwardKinematics<Jet>(robot, with_tilt.data(), q.data());
    const Eigen::Matrix<Jet, 3, 1> p = setup.instrument.rotation.cast<Jet>().transpose() *
                                       (pose.p_BT + pose.R_BT * setup.targets[0].cast<Jet>() -
                                        setup.instrument.translation.cast<Jet>());
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(y[static_cast<std::size_t>(3 * i + c)], p[c].a, testing::tolerance::kUrdf);
      EXPECT_NEAR(J(3 * i + c, gain), p[c].v[0], testing::tolerance::kAutodiff);
    }
  }
  EXPECT_THAT(J, testing::EigenNear(testing::CentralDifferences(*evaluator, e),
                                    testing::tolerance::kCentralDifference));
}

TEST(UrdfChains, ACoupledPoseChainsJacobianMatchesCentralDifferencesAwayFromNominal) {
  // A 6-D probe on the head: every column, the gain's with the orientation rows too, at an
  // estimate away from nominal (each term 1e-3, the gain 3e-3). The orientation rows stay in the
  // charts of the nominal multiplier's configurations as the gain moves the coupled joint (they
  // followed it once, and the fit of a probe's orientations did not converge).
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArmsAndHead);
  const ChainMeasurement head(std::make_shared<PoseMeasurement>(tree.chains[2].robot, OneTarget()),
                              tree.placements[2]);
  const TargetedConfigurations configs = RobotConfigurations(tree, 20, 23);
  const int n = head.num_parameters();
  ASSERT_EQ(head.parameter_names().back(), "head.coupling4_gain");
  std::vector<double> e(static_cast<std::size_t>(n), 1e-3);
  e.back() = 3e-3;
  std::unique_ptr<MeasurementEvaluator> evaluator = head.Bind(configs);
  std::vector<double> y(static_cast<std::size_t>(evaluator->num_rows()));
  Eigen::MatrixXd J(evaluator->num_rows(), n);
  ASSERT_TRUE(evaluator->Predict(e.data(), y.data(), J.data()));
  EXPECT_THAT(J, testing::EigenNear(testing::CentralDifferences(*evaluator, e),
                                    testing::tolerance::kCentralDifference));
}

// Three chains, the head's tilt coupled to the torso: the true robot's origins moved and its
// tilt's multiplier off by 3e-3. The joint fit returns the gain and every tool point to 1e-9.
TEST(UrdfChains, ACoupledJointsGainIsCalibratedNoiseFree) {
  const UrdfChains nominal = LoadUrdfChains(DualArm(), kArmsAndHead);
  const std::string moved = testing::UrdfWithMovedOrigins(
      DualArm(), 21, testing::TempDir("urdf_chains") + "/true_coupled.urdf");
  {
    std::ifstream in(moved);
    std::stringstream text;
    text << in.rdbuf();
    std::string urdf = text.str();
    const std::string mimic = "multiplier=\"-1.0\"";
    ASSERT_NE(urdf.find(mimic), std::string::npos);
    urdf.replace(urdf.find(mimic), mimic.size(), "multiplier=\"-1.003\"");
    std::ofstream(moved) << urdf;
  }
  const UrdfChains truth = LoadUrdfChains(moved, kArmsAndHead);
  const MixedMeasurement full = TrackedArms(nominal);
  const MixedMeasurement true_kind = TrackedArms(truth);
  const TargetedConfigurations configs = RobotConfigurations(nominal, 60, 23);
  const MeasuredValues data = Simulated(true_kind, configs);
  const IdentifiabilityReport report = AnalyzeIdentifiability(full, data.configs);
  EXPECT_THAT(report.suggested_fixed, ::testing::Not(::testing::Contains("head.coupling4_gain")));
  const std::unique_ptr<MeasurementKind> reduced = full.Without(report.suggested_fixed);
  IdentificationOptions options;
  const IdentificationSummary s = Identify(*reduced, data, options);
  ASSERT_TRUE(s.IsSolutionUsable()) << s.message;
  EXPECT_LT(s.residual_rms, 1e-12);
  const auto& names = reduced->parameter_names();
  const auto gain = std::find(names.begin(), names.end(), "head.coupling4_gain");
  ASSERT_NE(gain, names.end());
  EXPECT_NEAR(s.delta[gain - names.begin()], -3e-3, testing::tolerance::kRoundTrip);
  const MeasuredValues expected = Simulated(true_kind, RobotConfigurations(nominal, 30, 29));
  std::vector<double> y(expected.y.size());
  reduced->Bind(expected.configs)->Predict(s.delta.data(), y.data(), nullptr);
  for (std::size_t r = 0; r < y.size(); ++r)
    EXPECT_NEAR(y[r], expected.y[r], testing::tolerance::kRoundTrip) << "value " << r;
}

// A robot YAML file's couple: (examples/robots/parallelogram_arm.yaml, q3 = -q2) is a tree of one
// chain: five joints, link 3 following joint 2. Its points are the arm's forward kinematics with
// q3 = -q2 composed in the test, to 1e-12; its Jacobian, the gain's column on a 6-D probe's
// orientation rows too, matches central differences away from nominal.
TEST(UrdfChains, ARobotFilesCoupledLinkIsAChainOfOneTree) {
  const UrdfChains tree =
      LoadRobotChains(testing::SourcePath("examples/robots/parallelogram_arm.yaml"), {});
  EXPECT_EQ(tree.joint_names, (std::vector<std::string>{"q1", "q2", "q4", "q5", "q6"}));
  const ChainOfTree& chain = tree.placements.at(0);
  EXPECT_EQ(chain.joints, (std::vector<int>{0, 1, 1, 2, 3, 4}));
  ASSERT_EQ(chain.couplings.size(), 1u);
  EXPECT_EQ(chain.couplings[0].link, 2);
  EXPECT_EQ(chain.couplings[0].joint, 1);
  EXPECT_EQ(chain.couplings[0].multiplier, -1.0);
  const RobotModel& robot = tree.chains[0].robot;
  const PointSetup setup = OneTarget();
  const ChainMeasurement points(std::make_shared<PointMeasurement>(robot, setup), chain);
  const TargetedConfigurations configs = RobotConfigurations(tree, 20, 31);
  std::vector<double> y(static_cast<std::size_t>(3 * configs.size()));
  const std::vector<double> zero(static_cast<std::size_t>(points.num_parameters()), 0.0);
  ASSERT_TRUE(points.Bind(configs)->Predict(zero.data(), y.data(), nullptr));
  for (int i = 0; i < configs.size(); ++i) {
    const double* q = configs.q(i);
    const std::vector<double> full = {q[0], q[1], -q[1], q[2], q[3], q[4]};
    const Pose<double> pose =
        ForwardKinematics<double>(robot, robot.nominal_values().data(), full.data());
    const Eigen::Vector3d p =
        setup.instrument.rotation.transpose() *
        (pose.p_BT + pose.R_BT * setup.targets[0] - setup.instrument.translation);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(y[static_cast<std::size_t>(3 * i + c)], p[c], testing::tolerance::kUrdf);
  }
  const ChainMeasurement probe(std::make_shared<PoseMeasurement>(robot, setup), chain);
  ASSERT_EQ(probe.parameter_names().back(), "coupling3_gain");
  std::vector<double> e(static_cast<std::size_t>(probe.num_parameters()), 1e-3);
  e.back() = 3e-3;
  std::unique_ptr<MeasurementEvaluator> evaluator = probe.Bind(configs);
  Eigen::MatrixXd J(evaluator->num_rows(), probe.num_parameters());
  std::vector<double> values(static_cast<std::size_t>(evaluator->num_rows()));
  ASSERT_TRUE(evaluator->Predict(e.data(), values.data(), J.data()));
  EXPECT_THAT(J, testing::EigenNear(testing::CentralDifferences(*evaluator, e),
                                    testing::tolerance::kCentralDifference));
}

TEST(UrdfChains, BadCouplingsAreNamedByFileLineAndKey) {
  const std::string dir = testing::TempDir("urdf_chains_couplings");
  const auto message = [&](const std::string& name, const std::string& couple,
                           const std::string& link2 = "") {
    const std::string path = dir + "/" + name + ".yaml";
    std::ofstream(path) << "name: c\nlinks:\n"
                           "  - {theta: 0, alpha: 0, a: 0.3, d: 0, parameters: [theta]}\n"
                           "  - {theta: 0, alpha: 0, a: 0.3, d: 0, parameters: [theta]"
                        << link2
                        << "}\n"
                           "  - {theta: 0, alpha: 0, a: 0.3, d: 0, parameters: [theta], couple: "
                        << couple << "}\n";
    try {
      LoadRobotChains(path, {});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  using ::testing::AllOf;
  using ::testing::HasSubstr;
  EXPECT_THAT(message("itself", "{joint: 3}"),
              AllOf(HasSubstr("itself.yaml:5 key 'links[2].couple.joint'"),
                    HasSubstr("expected the number (1 to 3) of another link")));
  EXPECT_THAT(message("outside", "{joint: 4}"), HasSubstr("of another link"));
  EXPECT_THAT(message("fraction", "{joint: 1.5}"), HasSubstr("of another link"));
  EXPECT_THAT(
      message("chained", "{joint: 2}", ", couple: {joint: 1}"),
      AllOf(HasSubstr("key 'links[2].couple.joint'"), HasSubstr("link 2 is itself coupled")));
  EXPECT_THAT(message("scalar", "2"), HasSubstr("expected {joint: j, multiplier: m, offset: o}"));
  EXPECT_THAT(message("key", "{joint: 1, ratio: 2}"), HasSubstr("ratio"));
  EXPECT_THAT(message("missing", "{multiplier: 2}"),
              AllOf(HasSubstr("key 'links[2].couple.joint'"), HasSubstr("missing")));
  EXPECT_EQ(message("good", "{joint: 1, multiplier: 0.5, offset: pi/4}"), "no error");
  // The commands that read one uncoupled arm refuse it at its line.
  try {
    LoadRobotFile(dir + "/good.yaml");
    ADD_FAILURE() << "a coupled robot file was read as an uncoupled arm";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("good.yaml:5 key 'links[2].couple'"),
                                HasSubstr("a coupled link is calibrated as a tree of one chain")));
  }
}

// A tree's files: a whole-robot file names every joint; a chain's log may leave out a coupled
// joint only when it holds the joint that one follows; values out of the URDF's limits are named.
TEST(UrdfChains, BadTreeFilesAreNamedByFileLineAndJoint) {
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArmsAndHead);
  const std::string dir = testing::TempDir("urdf_chains_files");
  const auto message = [](const auto& read) {
    try {
      read();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::ofstream(dir + "/short.csv") << "torso_yaw,torso_pitch_1\n0,0\n";
  EXPECT_THAT(message([&] { ReadTreeConfigurations(dir + "/short.csv", tree); }),
              ::testing::HasSubstr("short.csv:1 column 'torso_pitch_2': missing"));
  std::string header, row;
  for (std::size_t j = 0; j < tree.joint_names.size(); ++j) {
    header += (j ? "," : "") + tree.joint_names[j];
    row += std::string(j ? "," : "") + (j == 3 ? "90" : "0");
  }
  std::ofstream(dir + "/degrees.csv") << header << "\n" << row << "\n";
  EXPECT_THAT(message([&] { ReadTreeConfigurations(dir + "/degrees.csv", tree); }),
              ::testing::HasSubstr("degrees.csv:2 column 'left_shoulder_pitch': 90 is outside "
                                   "the joint's range"));
  std::ofstream(dir + "/head.csv") << "torso_yaw,torso_pitch_1,x\n0,0,1\n";
  EXPECT_THAT(message([&] { ReadChainCsv(dir + "/head.csv", tree, 2); }),
              ::testing::HasSubstr("column 'torso_pitch_2': missing"));
  std::ofstream(dir + "/head_no_tilt.csv") << "torso_yaw,torso_pitch_1,torso_pitch_2\n0,0,0.25\n";
  const CsvTable filled = ReadChainCsv(dir + "/head_no_tilt.csv", tree, 2);
  ASSERT_GE(filled.Column("head_tilt"), 0);
  EXPECT_EQ(filled.Number(0, filled.Column("head_tilt")), -0.25);
}

TEST(UrdfChains, BadChainListsAreNamed) {
  EXPECT_THAT(
      [] {
        LoadUrdfChains(DualArm(), {"left_tool", "left_tool"});
      },
      ::testing::ThrowsMessage<InputError>(
          ::testing::HasSubstr("the tool link 'left_tool' is named twice")));
  EXPECT_THAT([] { LoadUrdfChains(DualArm(), {}); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("at least one tool link")));
  // A chain's configurations must be the whole robot's.
  const UrdfChains tree = LoadUrdfChains(DualArm(), kArms);
  const ChainMeasurement left(std::make_shared<PointMeasurement>(tree.chains[0].robot, OneTarget()),
                              tree.placements[0]);
  TargetedConfigurations chain_only(9);
  chain_only.Add(std::vector<double>(9, 0.0));
  EXPECT_THAT([&] { left.Bind(chain_only); }, ::testing::ThrowsMessage<InputError>(
                                                  ::testing::HasSubstr("expected the robot's 15")));
}

}  // namespace
}  // namespace lrcal
