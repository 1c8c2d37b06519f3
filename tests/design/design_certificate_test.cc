// The design certificate: the relaxation's bound is never below the best subset (checked by
// exhaustive search on small pools), it is tight enough to be useful, and on the paper's arm the
// E-optimal designs reach (almost) all of it.
#include "lrcal/design/design_certificate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "lrcal/design/configuration_sampling.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/measurement/measurement_model.h"
#include "test_util.h"

namespace lrcal {
namespace {

// The best score over every k-subset of G's rows.
double ExhaustiveBest(const Eigen::MatrixXd& G, int k, DesignCriterion criterion) {
  const int N = static_cast<int>(G.rows());
  std::vector<int> pick(k);
  for (int i = 0; i < k; ++i) pick[i] = i;
  double best = -std::numeric_limits<double>::infinity();
  while (true) {
    Eigen::MatrixXd Gs(k, G.cols());
    for (int i = 0; i < k; ++i) Gs.row(i) = G.row(pick[i]);
    best = std::max(best, CriterionScore(Gs.transpose() * Gs, k, criterion));
    int i = k - 1;
    while (i >= 0 && pick[i] == N - k + i) --i;
    if (i < 0) break;
    ++pick[i];
    for (int j = i + 1; j < k; ++j) pick[j] = pick[j - 1] + 1;
  }
  return best;
}

TEST(DesignCertificate, BoundIsNeverBelowTheExhaustiveOptimumAndIsTight) {
  std::mt19937_64 rng(21);  // test data only
  std::normal_distribution<double> z;
  for (int trial = 0; trial < 6; ++trial) {
    const int N = 14, n = 4, k = 5 + trial % 3;
    Eigen::MatrixXd G(N, n);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < n; ++j) G(i, j) = z(rng) * (1 + j);  // unequal column scales
    for (DesignCriterion c : {DesignCriterion::kE, DesignCriterion::kD, DesignCriterion::kA}) {
      SCOPED_TRACE(std::string(DesignCriterionName(c)) + " trial " + std::to_string(trial));
      const double best = ExhaustiveBest(G, k, c);
      const double bound = DesignUpperBound(G, k, c);
      EXPECT_GE(bound, best - 1e-12 * std::fabs(best));
      SelectionOptions o;
      o.method = SelectionMethod::kExhaustive;
      o.criterion = c;
      const SelectionResult r =
          SelectConfigurations(G, k, o, RandomStream(1, 0, 0, RandomPurpose::kSelection));
      EXPECT_NEAR(r.score, best, 1e-12 * std::fabs(best));
      const DesignCertificate cert = CertifyDesign(G, r.indices, c);
      ASSERT_TRUE(cert.available);
      EXPECT_LE(cert.efficiency, 1.0);
      EXPECT_GT(cert.efficiency, 0.8) << "bound " << cert.bound << " best " << best;
    }
  }
}

// The SI design Jacobian of a 101-candidate pool of the paper's arm (its plane, E sampling
// options as in studies), drawn with `seed`.
Eigen::MatrixXd PaperArmPoolJacobian(std::uint64_t seed) {
  const RobotFile& rig = testing::PaperRig();
  SamplingOptions so;
  so.ranger = rig.ranger;
  so.min_jacobian_singular_value = 0.05;
  const TargetedConfigurations pool = SampleConfigurations(
      rig.robot, (*rig.planes)[0], 101, RandomStream(seed, 7, 0, RandomPurpose::kPool), so);
  const MeasurementModel model(rig.robot, (*rig.planes)[0],
                               MakeParameterSet(rig.robot, PlaneTerms{}, {}, "fix"));
  return DesignJacobian(model, pool, DesignScaling::kSI, 1e-3, 1e-3);
}

TEST(DesignCertificate, PaperArmDesignsAndTheLimitsOfTheCertificate) {
  const Eigen::MatrixXd G = PaperArmPoolJacobian(2026);
  SelectionOptions o;  // backward elimination, E: the paper's case 1
  const SelectionResult r =
      SelectConfigurations(G, 50, o, RandomStream(1, 0, 0, RandomPurpose::kSelection));
  const DesignCertificate cert = CertifyDesign(G, r.indices, DesignCriterion::kE);
  ASSERT_TRUE(cert.available);
  EXPECT_GE(cert.bound, cert.achieved);
  EXPECT_GT(cert.efficiency, 0.99);  // independent computations: within 0.2 % at k = 50
  // Every random design is below the bound too.
  std::mt19937_64 rng(3);
  std::vector<int> all(101);
  for (int i = 0; i < 101; ++i) all[i] = i;
  for (int d = 0; d < 200; ++d) {
    std::shuffle(all.begin(), all.end(), rng);
    std::vector<int> pick(all.begin(), all.begin() + 50);
    EXPECT_LE(CertifyDesign(G, pick, DesignCriterion::kE, 1).achieved, cert.bound);
  }
  EXPECT_FALSE(CertifyDesign(G, r.indices, DesignCriterion::kO2).available);
  EXPECT_THAT(
      CertifyDesign(G, r.indices, DesignCriterion::kO2).ToString(DesignCriterion::kO2, 50, 101),
      ::testing::HasSubstr("no certificate"));
  std::cout << cert.ToString(DesignCriterion::kE, 50, 101) << "\n";
  std::cout << "bound with 300 iterations: " << DesignUpperBound(G, 50, DesignCriterion::kE, 300)
            << ", 1500: " << DesignUpperBound(G, 50, DesignCriterion::kE, 1500) << "\n";
}

// Exchange starts from backward and forward greedy designs and the relaxation's rounding: it is
// never worse than either greedy design, for E, D and A, near the number of parameters too
// (k = 26 of 25 parameters) and in between.
TEST(DesignCertificate, ExchangeIsAtLeastAsGoodAsGreedyEverywhere) {
  const Eigen::MatrixXd G = PaperArmPoolJacobian(11);
  const RandomStream stream(1, 0, 0, RandomPurpose::kSelection);
  for (DesignCriterion c : {DesignCriterion::kE, DesignCriterion::kD, DesignCriterion::kA})
    for (int k : {26, 40}) {
      SCOPED_TRACE(std::string(DesignCriterionName(c)) + " k " + std::to_string(k));
      SelectionOptions o;
      o.criterion = c;
      o.method = SelectionMethod::kExchange;
      const double exchange = SelectConfigurations(G, k, o, stream).score;
      o.method = SelectionMethod::kGreedy;
      const double forward = SelectConfigurations(G, k, o, stream).score;
      o.method = SelectionMethod::kBackward;
      const double backward = SelectConfigurations(G, k, o, stream).score;
      EXPECT_GE(exchange, forward);
      EXPECT_GE(exchange, backward);
      EXPECT_LE(exchange, DesignUpperBound(G, k, c, 300) * (1 + 1e-12) + 1e-12);
    }
}

}  // namespace
}  // namespace lrcal
