// The non-geometric model (environment_measurement.h): its analytic Jacobian against Ceres
// autodiff through an independent reference (the reference kinematics with grown lengths and
// deflected joints, the one LaserDistance formula) and against central differences; the
// identifiability's words for what gravity and temperature cannot excite; noise-free round trips
// of compliance, thermal growth and geometry together; and a geometric-only fit of a compliant or
// warm arm flagged by the fit check.
#include "lrcal/measurement/environment_measurement.h"

#include <ceres/jet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>

#include "lrcal/core/error.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/truth.h"
#include "test_util.h"

namespace lrcal {
namespace {

using testing::EigenNear;
using ::testing::HasSubstr;
namespace tolerance = testing::tolerance;

constexpr int kMaxTerms = 40;
using TermJet = ceres::Jet<double, kMaxTerms>;
// Autodiff and the analytic chain rule compute the same derivatives in another order.
constexpr double kAutodiffAgreement = 1e-9;
// Central differences (step 1e-7 scaled per term) of readings of ~1 m.
constexpr double kDifferenceAgreement = 1e-5;

MassModel ArmMasses() {
  MassModel m;
  m.masses = {{2, 20.0, {-0.5, 0.02, 0.0}},
              {3, 5.0, {0.0, 0.0, 0.1}},
              {4, 12.0, {0.0, 0.4, 0.0}},
              {6, 3.0, {0.01, 0.0, -0.1}},
              {7, 4.0, {0.0, 0.05, 0.1}}};
  return m;
}

NonGeometricModel NominalModel() {
  NonGeometricModel m;
  m.masses = ArmMasses();
  m.thermal.reference_c = 20;
  m.thermal.links = 23e-6;  // aluminium
  m.thermal.ranger = 0;
  return m;
}

// Configurations hitting the paper's plane, spread over `temperatures` and `gravities` in turn.
TargetedConfigurations Spread(int count, const std::vector<double>& temperatures,
                              const std::vector<Eigen::Vector3d>& gravities, unsigned seed = 3) {
  TargetedConfigurations configs = testing::PaperHittingConfigurations(count, seed);
  for (int i = 0; i < configs.size(); ++i) {
    Environment e;
    e.temperature_c = temperatures[static_cast<std::size_t>(i) % temperatures.size()];
    e.gravity = gravities[static_cast<std::size_t>(i) % gravities.size()];
    configs.SetEnvironment(i, e);
  }
  return configs;
}

std::shared_ptr<const MeasurementKind> FullRanger(const RobotModel& robot) {
  return std::make_shared<RangerMeasurement>(
      MeasurementModel(robot, testing::PaperPlane(),
                       MakeParameterSet(robot, PlaneTerms{}, {}, "fix", RangerTerms{true, true})),
      testing::PaperRig().ranger);
}

// The reading written out independently: link values nominal + their terms, lengths grown by
// (1 + α ΔT), each joint turned by c_j τ_j (added to θ_j: the reference kinematics takes q in
// double), the beam read on the plane with the scale grown by α_r ΔT.
template <typename T>
T ReferenceReading(const EnvironmentMeasurement& kind, const RobotModel& robot,
                   const std::vector<T>& e, const TargetedConfigurations& configs, int i) {
  const NonGeometricModel& m = kind.model();
  const std::vector<std::string>& names = kind.parameter_names();
  std::vector<T> values(static_cast<std::size_t>(robot.num_values()));
  for (int v = 0; v < robot.num_values(); ++v) values[v] = T(robot.nominal_values()[v]);
  T offset(0), scale(0), dalpha(0), alpha_r(m.thermal.ranger);
  std::vector<T> c(6);
  for (int j = 0; j < 6; ++j) c[j] = T(m.Compliance(j));
  for (std::size_t k = 0; k < names.size(); ++k) {
    const int v = robot.FindValue(names[k]);
    if (v >= 0) values[v] += e[k];
    if (names[k] == "ranger_offset") offset += e[k];
    if (names[k] == "ranger_scale") scale += e[k];
    if (ComplianceTermJoint(names[k]) >= 0) c[ComplianceTermJoint(names[k])] += e[k];
    if (names[k] == kThermalLinksTerm) dalpha += e[k];
    if (names[k] == kThermalRangerTerm) alpha_r += e[k];
  }
  const Environment env = kind.EnvironmentOf(configs, i);
  const double dt = env.temperature_c - m.thermal.reference_c;
  for (int v : robot.parameter_indices())
    if (v % kValuesPerLink == kA || v % kValuesPerLink == kD)
      values[v] *= T(1.0) + (T(m.thermal.Link(v / kValuesPerLink)) + dalpha) * dt;
  const Eigen::VectorXd tau =
      GravityTorques(robot, robot.nominal_values().data(), m.masses, configs.q(i), env.gravity);
  for (int j = 0; j < 6; ++j) values[j * kValuesPerLink + kTheta] += c[j] * tau[j];
  const Pose<T> pose = ForwardKinematics<T>(robot, values.data(), configs.q(i));
  const Plane& plane = testing::PaperPlane();
  const Eigen::Matrix<T, 3, 1> b = pose.R_BT.col(2);
  const T h = LaserDistance<T>(pose.p_BT, b, plane.normal.cast<T>(), T(plane.offset));
  return (T(1.0) + scale + alpha_r * dt) * h + offset;
}

NonGeometricTerms AllTerms() {
  NonGeometricTerms t;
  t.compliance_joints = {0, 1, 2, 3, 4, 5};
  t.thermal_links = t.thermal_ranger = true;
  return t;
}

TEST(EnvironmentMeasurement, JacobianIsAutodiffsAndCentralDifferences) {
  const RobotModel& robot = testing::PaperRobot();
  NonGeometricModel model = NominalModel();
  model.compliance = Eigen::VectorXd::Constant(6, 2e-5);
  // A material per link: aluminium links 1-3, carbon fibre 4-6, on a common part.
  model.thermal.links = 1e-6;
  model.thermal.per_link.resize(6);
  model.thermal.per_link << 22e-6, 22e-6, 22e-6, 0.5e-6, 0.5e-6, 0.5e-6;
  const EnvironmentMeasurement kind(FullRanger(robot), robot, model, AllTerms(), {"d6"});
  ASSERT_LE(kind.num_parameters(), kMaxTerms);
  EXPECT_THAT(kind.parameter_names(), ::testing::Contains("c3"));
  EXPECT_EQ(kind.parameter_names().back(), kThermalRangerTerm);
  const TargetedConfigurations configs =
      Spread(24, {-40, 20, 80}, {Eigen::Vector3d(0, 0, -9.81), Eigen::Vector3d(4, -3, -8)});
  const int n = kind.num_parameters();
  std::vector<double> e(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) e[k] = (k % 2 ? 4e-4 : -3e-4) * (k % 3 + 1);
  // The non-geometric terms at their own scale.
  for (int k = 0; k < n; ++k) {
    const std::string& name = kind.parameter_names()[static_cast<std::size_t>(k)];
    if (ComplianceTermJoint(name) >= 0) e[k] = 3e-6 * (k % 3 - 1);
    if (name == kThermalLinksTerm || name == kThermalRangerTerm) e[k] = 5e-6;
  }
  const Eigen::MatrixXd J = MeasurementJacobian(kind, configs, e.data());
  ASSERT_EQ(J.rows(), configs.size());
  std::vector<double> y(static_cast<std::size_t>(configs.size()));
  kind.Bind(configs)->Predict(e.data(), y.data(), nullptr);

  std::vector<TermJet> ej(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) ej[k] = TermJet(e[k], k);
  Eigen::MatrixXd autodiff(configs.size(), n), differences(configs.size(), n);
  for (int i = 0; i < configs.size(); ++i) {
    const TermJet r = ReferenceReading<TermJet>(kind, robot, ej, configs, i);
    EXPECT_NEAR(r.a, y[i], 1e-12) << i;
    autodiff.row(i) = r.v.head(n).transpose();
  }
  for (int k = 0; k < n; ++k) {
    const std::string& name = kind.parameter_names()[static_cast<std::size_t>(k)];
    const double step = ComplianceTermJoint(name) >= 0                              ? 1e-9
                        : (name == kThermalLinksTerm || name == kThermalRangerTerm) ? 1e-8
                                                                                    : 1e-7;
    std::vector<double> plus = e, minus = e;
    plus[k] += step;
    minus[k] -= step;
    std::vector<double> yp(y.size()), ym(y.size());
    kind.Bind(configs)->Predict(plus.data(), yp.data(), nullptr);
    kind.Bind(configs)->Predict(minus.data(), ym.data(), nullptr);
    for (int i = 0; i < configs.size(); ++i) differences(i, k) = (yp[i] - ym[i]) / (2 * step);
  }
  // Compared column by column, each relative to its own size (compliance columns are ~1e2 m per
  // rad/(N·m), thermal ~1e2 m·K, link columns ~1).
  for (int k = 0; k < n; ++k) {
    const double size = std::max(1.0, autodiff.col(k).cwiseAbs().maxCoeff());
    EXPECT_THAT(Eigen::MatrixXd(J.col(k) / size),
                EigenNear(Eigen::MatrixXd(autodiff.col(k) / size), kAutodiffAgreement))
        << kind.parameter_names()[static_cast<std::size_t>(k)];
    EXPECT_THAT(Eigen::MatrixXd(J.col(k) / size),
                EigenNear(Eigen::MatrixXd(differences.col(k) / size), kDifferenceAgreement))
        << kind.parameter_names()[static_cast<std::size_t>(k)];
  }
}

// Noise-free readings of an arm with geometric errors, compliant joints and a thermal coefficient
// other than the nominal, at `configs`: the truth is the same model on the true arm, nothing
// estimated (τ on the nominal geometry, as the model defines it).
MeasuredValues TrueReadings(const RobotModel& robot, const NonGeometricModel& truth,
                            const TargetedConfigurations& configs) {
  static const RobotModel true_arm = Truth{testing::PaperTrueErrors()}.TrueRobot(robot);
  const EnvironmentMeasurement kind(FullRanger(true_arm), robot, truth, NonGeometricTerms{});
  MeasuredValues data;
  data.configs = configs;
  data.y.resize(static_cast<std::size_t>(configs.size()));
  const std::vector<double> zero(static_cast<std::size_t>(kind.num_parameters()), 0.0);
  EXPECT_TRUE(kind.Bind(configs)->Predict(zero.data(), data.y.data(), nullptr));
  data.repetitions.assign(static_cast<std::size_t>(configs.size()), 1);
  return data;
}

NonGeometricModel TrueModel() {
  NonGeometricModel m = NominalModel();
  m.compliance.resize(6);
  m.compliance << 1.5e-5, 2.5e-5, 3.0e-5, 4.0e-5, 5.0e-5, 6.0e-5;
  m.thermal.links = 24.5e-6;  // the nominal 23e-6 is off by 1.5 ppm/K
  m.thermal.ranger = 2e-6;
  return m;
}

TEST(EnvironmentMeasurement, RecoversGeometryComplianceAndThermalGrowthFromExactReadings) {
  const RobotModel& robot = testing::PaperRobot();
  // A tilted mount as well as an upright one: joint 1 then carries gravity torque too.
  const TargetedConfigurations configs =
      Spread(160, {-10, 20, 60}, {Eigen::Vector3d(0, 0, -9.81), Eigen::Vector3d(0, 6.0, -7.8)});
  const MeasuredValues data = TrueReadings(robot, TrueModel(), configs);
  NonGeometricTerms terms = AllTerms();
  terms.thermal_ranger = false;  // the ranger's terms: offset and scale, no thermal (below)
  NonGeometricModel nominal = NominalModel();
  nominal.thermal.ranger = 2e-6;  // known
  const EnvironmentMeasurement kind(FullRanger(robot), robot, nominal, terms);
  const IdentifiabilityReport rank = AnalyzeIdentifiability(kind, configs);
  ASSERT_TRUE(rank.full_rank()) << rank.ToString();
  const IdentificationSummary s = Identify(kind, data);
  ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
  const Eigen::VectorXd& truth_errors = testing::PaperTrueErrors();
  for (int k = 0; k < kind.num_parameters(); ++k) {
    const std::string& name = s.names[static_cast<std::size_t>(k)];
    double expected = 0;
    if (robot.FindValue(name) >= 0) expected = truth_errors[robot.FindValue(name)];
    if (ComplianceTermJoint(name) >= 0)
      expected = TrueModel().Compliance(ComplianceTermJoint(name));
    if (name == kThermalLinksTerm) expected = 1.5e-6;
    EXPECT_NEAR(s.delta[k], expected, tolerance::kRoundTrip) << name;
  }
  EXPECT_LT(s.residual_rms, 1e-12);
}

// A material per link: the links' coefficients differ (aluminium and carbon fibre), the truth's
// common part is off by 1.5 ppm/K; exact readings recover it and the geometry to 1e-9.
TEST(EnvironmentMeasurement, RecoversACommonCorrectionOfPerLinkCoefficients) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = Spread(120, {-20, 20, 60}, {Eigen::Vector3d(0, 0, -9.81)});
  NonGeometricModel nominal = NominalModel();
  nominal.thermal.links = 0;
  nominal.thermal.per_link.resize(6);
  nominal.thermal.per_link << 23e-6, 23e-6, 23e-6, 1e-6, 1e-6, 1e-6;
  NonGeometricModel truth = nominal;
  truth.thermal.links = 1.5e-6;
  const MeasuredValues data = TrueReadings(robot, truth, configs);
  NonGeometricTerms terms;
  terms.thermal_links = true;
  const EnvironmentMeasurement kind(FullRanger(robot), robot, nominal, terms,
                                    {"ranger_offset", "ranger_scale"});
  const IdentificationSummary s = Identify(kind, data);
  ASSERT_TRUE(s.IsSolutionUsable()) << s.FullReport();
  for (int k = 0; k < kind.num_parameters(); ++k) {
    const std::string& name = s.names[static_cast<std::size_t>(k)];
    const int v = robot.FindValue(name);
    const double expected = name == kThermalLinksTerm ? 1.5e-6
                            : v >= 0                  ? testing::PaperTrueErrors()[v]
                                                      : 0.0;
    EXPECT_NEAR(s.delta[k], expected, tolerance::kRoundTrip) << name;
  }
  // The poses follow each link's own material: the true arm's poses at 60 °C against its
  // link values grown link by link.
  const RobotModel true_arm = Truth{testing::PaperTrueErrors()}.TrueRobot(robot);
  TargetedConfigurations warm = configs.Subset({0});
  Environment hot;
  hot.temperature_c = 60;
  hot.gravity = Eigen::Vector3d::Zero();
  warm.SetEnvironment(0, hot);
  const Pose<double> pose =
      EnvironmentToolPoses(robot, true_arm.nominal_values(), truth, warm).front();
  Eigen::VectorXd grown = true_arm.nominal_values();
  for (int v : robot.parameter_indices())
    if (v % kValuesPerLink == kA || v % kValuesPerLink == kD)
      grown[v] *= 1 + truth.thermal.Link(v / kValuesPerLink) * 40;
  const Pose<double> expected = ForwardKinematics<double>(robot, grown.data(), warm.q(0));
  EXPECT_THAT(pose.p_BT, EigenNear(expected.p_BT, 1e-15));
}

TEST(EnvironmentMeasurement, IdentifiabilitySaysWhatGravityAndTemperatureCannotExcite) {
  const RobotModel& robot = testing::PaperRobot();
  // Upright, one temperature: joint 1 carries no torque, thermal growth is a length change.
  const TargetedConfigurations configs = Spread(80, {20}, {Eigen::Vector3d(0, 0, -9.81)});
  NonGeometricTerms terms;
  terms.compliance_joints = {0, 1, 2};
  terms.thermal_links = true;
  const EnvironmentMeasurement kind(FullRanger(robot), robot, NominalModel(), terms);
  const IdentifiabilityReport rep = AnalyzeIdentifiability(kind, configs);
  EXPECT_FALSE(rep.full_rank());
  EXPECT_THAT(rep.unidentifiable, ::testing::Contains("c1"));
  EXPECT_THAT(rep.explanations,
              ::testing::Contains(HasSubstr("c1: joint 1 carries no gravity torque")));
  EXPECT_THAT(rep.explanations,
              ::testing::Contains(HasSubstr("thermal_links: every measurement at 20 °C")));
  EXPECT_THAT(rep.ToString(), HasSubstr("lost: c1: joint 1"));
  // On orbit no joint carries any load: every compliance is unidentifiable.
  const TargetedConfigurations orbit = Spread(80, {-40, 80}, {Eigen::Vector3d::Zero()});
  const IdentifiabilityReport free = AnalyzeIdentifiability(kind, orbit);
  EXPECT_THAT(free.unidentifiable, ::testing::IsSupersetOf({"c1", "c2", "c3"}));
  EXPECT_THAT(free.unidentifiable, ::testing::Not(::testing::Contains(kThermalLinksTerm)));
}

// The equivalence an independent computation found: on one plane a uniform growth of the arm
// reads as the ranger's gain and a shift of the plane, so with the plane's offset and the ranger's
// scale estimated the links' and the ranger's thermal coefficients are not separable, even at
// two temperatures; the analysis finds the dependence and says it in words.
TEST(EnvironmentMeasurement, OnePlaneCannotSeparateTheArmsGrowthFromTheRangersGain) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = Spread(80, {0, 40}, {Eigen::Vector3d(0, 0, -9.81)});
  const auto ranger = std::make_shared<RangerMeasurement>(
      MeasurementModel(
          robot, testing::PaperPlane(),
          MakeParameterSet(robot, PlaneTerms{false, true}, {}, "fix", RangerTerms{true, true})),
      testing::PaperRig().ranger);
  NonGeometricTerms thermal;
  thermal.thermal_links = thermal.thermal_ranger = true;
  const EnvironmentMeasurement kind(ranger, robot, NominalModel(), thermal);
  const IdentifiabilityReport rep = AnalyzeIdentifiability(kind, configs);
  EXPECT_FALSE(rep.full_rank());
  bool thermal_in_dependence = false;
  for (const Dependency& d : rep.dependencies)
    for (const auto& term : d.terms) thermal_in_dependence |= term.first == kThermalLinksTerm;
  EXPECT_TRUE(thermal_in_dependence) << rep.ToString();
  EXPECT_THAT(rep.explanations,
              ::testing::Contains(HasSubstr("a uniform growth of the arm reads, on these planes, "
                                            "as the ranger's gain and a shift of the planes")));
  // Holding the ranger's coefficient leaves the links' identifiable.
  thermal.thermal_ranger = false;
  const EnvironmentMeasurement links_only(ranger, robot, NominalModel(), thermal);
  const IdentifiabilityReport held = AnalyzeIdentifiability(links_only, configs);
  EXPECT_THAT(held.names, ::testing::Contains(kThermalLinksTerm));
  EXPECT_THAT(held.suggested_fixed, ::testing::Not(::testing::Contains(kThermalLinksTerm)));
}

TEST(EnvironmentMeasurement, AGeometricFitOfACompliantOrWarmArmFailsTheFitCheck) {
  const RobotModel& robot = testing::PaperRobot();
  const TargetedConfigurations configs = Spread(120, {-20, 20, 60}, {Eigen::Vector3d(0, 0, -9.81)});
  IdentificationOptions options;
  options.sigma = 20e-6;  // m: a ranger of 20 µm
  const MeasurementModel geometric_model(robot, testing::PaperPlane(),
                                         MakeParameterSet(robot, PlaneTerms{}));
  const RangerMeasurement geometric(geometric_model, testing::PaperRig().ranger);
  NonGeometricModel compliant = NominalModel();
  compliant.thermal.links = 0;
  compliant.compliance = TrueModel().compliance;
  NonGeometricModel warm = NominalModel();
  for (const NonGeometricModel& truth : {compliant, warm}) {
    const MeasuredValues data = TrueReadings(robot, truth, configs);
    const IdentificationSummary plain = Identify(geometric, data, options);
    ASSERT_TRUE(plain.IsSolutionUsable());
    EXPECT_FALSE(plain.fit.consistent) << plain.fit.Explain();
    // The model that has the term fits to rounding.
    NonGeometricTerms terms;
    if (truth.compliance.size())
      terms.compliance_joints = {1, 2, 3, 4, 5};
    else
      terms.thermal_links = true;
    NonGeometricModel model = NominalModel();
    model.thermal.links = 0;  // nominal: no growth known
    const EnvironmentMeasurement kind(FullRanger(robot), robot, model, terms,
                                      {"ranger_offset", "ranger_scale"});
    const IdentificationSummary fitted = Identify(kind, data, options);
    ASSERT_TRUE(fitted.IsSolutionUsable()) << fitted.FullReport();
    EXPECT_TRUE(fitted.fit.consistent);
    EXPECT_LT(fitted.residual_rms, 1e-11);
  }
}

TEST(EnvironmentMeasurement, RefusesTermsItCannotMoveAndNamesThem) {
  const RobotModel& robot = testing::PaperRobot();
  const auto without_lengths = std::make_shared<RangerMeasurement>(
      MeasurementModel(robot, testing::PaperPlane(),
                       MakeParameterSet(robot, PlaneTerms{}, {"a2"}, "fix")),
      testing::PaperRig().ranger);
  NonGeometricTerms thermal;
  thermal.thermal_links = true;
  try {
    EnvironmentMeasurement kind(without_lengths, robot, NominalModel(), thermal);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("a2"));
  }
  EXPECT_THROW(NonGeometricTerms::ParseCompliance("j7", 6, "--estimate-compliance"), InputError);
  EXPECT_EQ(NonGeometricTerms::ParseCompliance("j1,3,c2", 6, "x"), (std::vector<int>{0, 1, 2}));
  NonGeometricTerms t;
  EXPECT_THROW(t.ParseThermal("link", "--estimate-thermal"), InputError);
  t.ParseThermal("all", "--estimate-thermal");
  EXPECT_TRUE(t.thermal_links && t.thermal_ranger);
  const EnvironmentMeasurement kind(FullRanger(robot), robot, NominalModel(), AllTerms());
  const std::unique_ptr<MeasurementKind> fewer = kind.Without({"c1", "thermal_ranger", "d6"});
  EXPECT_THAT(fewer->parameter_names(), ::testing::Not(::testing::Contains("c1")));
  EXPECT_THAT(fewer->parameter_names(), ::testing::Not(::testing::Contains("d6")));
  EXPECT_THAT(fewer->parameter_names(), ::testing::Contains("c2"));
  EXPECT_THROW(kind.Without({"c9"}), InputError);
}

}  // namespace
}  // namespace lrcal
