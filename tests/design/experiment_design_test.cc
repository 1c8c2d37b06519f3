// Selection of k of N configurations: criteria against hand-computed values, exhaustive against
// brute force, greedy and sampled determinism, and bad requests.
#include "lrcal/design/experiment_design.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <limits>
#include <numeric>
#include <random>
#include <tuple>

#include "lrcal/core/error.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

Eigen::MatrixXd RandomMatrix(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n;  // test data only
  Eigen::MatrixXd G(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) G(i, j) = n(rng);
  return G;
}

TEST(DesignCriteria, MatchHandComputedValuesOnADiagonalDesign) {
  // G = diag(3, 2) stacked with a zero row: σ = (3, 2), m = 3.
  Eigen::MatrixXd G(3, 2);
  G << 3, 0, 0, 2, 0, 0;
  Eigen::MatrixXd A = G.transpose() * G;
  EXPECT_NEAR(CriterionScore(A, 3, DesignCriterion::kE), 2.0, 1e-14);
  EXPECT_NEAR(CriterionScore(A, 3, DesignCriterion::kD), std::log(36.0), 1e-14);
  EXPECT_NEAR(CriterionScore(A, 3, DesignCriterion::kA), -(1.0 / 9 + 1.0 / 4), 1e-14);
  EXPECT_NEAR(CriterionScore(A, 3, DesignCriterion::kO1), std::sqrt(6.0) / std::sqrt(3.0), 1e-14);
  EXPECT_NEAR(CriterionScore(A, 3, DesignCriterion::kO2), 2.0 / 3.0, 1e-14);
  EXPECT_NEAR(CriterionScore(A, 3, DesignCriterion::kO4), 4.0 / 3.0, 1e-14);
  EXPECT_NEAR(CriterionScore(A, 3, DesignCriterion::kO5), 1.0 / (1.0 / 3 + 1.0 / 2), 1e-14);
}

TEST(DesignCriteria, EIsTheSmallestSingularValueOfG) {
  Eigen::MatrixXd G = RandomMatrix(30, 6, 1);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(G);
  EXPECT_NEAR(CriterionScore(G.transpose() * G, 30, DesignCriterion::kE),
              svd.singularValues().minCoeff(), 1e-12);
}

TEST(DesignCriteria, SeveralScoresFromOneDecompositionHaveEachScoresBits) {
  const Eigen::MatrixXd G = RandomMatrix(40, 7, 4);
  const Eigen::MatrixXd A = G.transpose() * G;
  const std::vector<DesignCriterion> criteria = {DesignCriterion::kE,  DesignCriterion::kD,
                                                 DesignCriterion::kA,  DesignCriterion::kO1,
                                                 DesignCriterion::kO4, DesignCriterion::kO5};
  const std::vector<double> scores = CriterionScores(A, 40, criteria);
  ASSERT_EQ(scores.size(), criteria.size());
  for (std::size_t c = 0; c < criteria.size(); ++c)
    EXPECT_EQ(scores[c], CriterionScore(A, 40, criteria[c])) << DesignCriterionName(criteria[c]);
}

TEST(Selection, ExhaustiveEqualsBruteForce) {
  const Eigen::MatrixXd G = RandomMatrix(10, 3, 2);
  RandomStream stream(1, 0, 0, RandomPurpose::kSelection);
  for (int k : {3, 5, 9}) {
    SelectionOptions o;
    o.method = SelectionMethod::kExhaustive;
    SelectionResult r = SelectConfigurations(G, k, o, stream);
    // Brute force over bit masks.
    double best = -1;
    for (int mask = 0; mask < (1 << 10); ++mask) {
      if (__builtin_popcount(mask) != k) continue;
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3, 3);
      for (int i = 0; i < 10; ++i)
        if (mask >> i & 1) A += G.row(i).transpose() * G.row(i);
      best = std::max(best, CriterionScore(A, k, DesignCriterion::kE));
    }
    EXPECT_NEAR(r.score, best, 1e-12) << "k = " << k;
    EXPECT_EQ(static_cast<int>(r.indices.size()), k);
  }
}

TEST(Selection, LeaveOneOutTakesNEvaluations) {
  const Eigen::MatrixXd G = RandomMatrix(101, 25, 3);
  SelectionOptions o;
  o.method = SelectionMethod::kExhaustive;
  SelectionResult r =
      SelectConfigurations(G, 100, o, RandomStream(1, 0, 0, RandomPurpose::kSelection));
  EXPECT_EQ(r.evaluations, 101);
  EXPECT_EQ(r.indices.size(), 100u);
}

TEST(Selection, GreedyBeatsRandomAndIsDeterministic) {
  const Eigen::MatrixXd G = RandomMatrix(60, 8, 4);
  RandomStream stream(7, 0, 0, RandomPurpose::kSelection);
  SelectionOptions greedy, random;
  random.method = SelectionMethod::kRandom;
  SelectionResult a = SelectConfigurations(G, 20, greedy, stream);
  SelectionResult b = SelectConfigurations(G, 20, greedy, stream);
  SelectionResult c = SelectConfigurations(G, 20, random, stream);
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_GT(a.score, c.score);
  SelectionOptions sampled;
  sampled.method = SelectionMethod::kSampled;
  sampled.samples = 200;
  SelectionResult d = SelectConfigurations(G, 20, sampled, stream);
  SelectionResult e = SelectConfigurations(G, 20, sampled, stream);
  EXPECT_EQ(d.indices, e.indices);
  EXPECT_GE(d.score, c.score);  // the first sample is the random subset
}

TEST(RankOneUpdate, SecularEigenvaluesMatchEigen) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::MatrixXd G = RandomMatrix(40, 8, trial + 100);
    Eigen::MatrixXd A = G.transpose() * G;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A);
    Eigen::VectorXd g(8);
    for (int k = 0; k < 8; ++k) g[k] = u(rng);
    for (double rho : {1.0, -1.0}) {
      if (rho < 0) g = G.row(trial % 40).transpose();  // a downdate must stay semi-definite
      Eigen::VectorXd z = eig.eigenvectors().transpose() * g;
      Eigen::VectorXd mu = RankOneUpdatedEigenvalues(eig.eigenvalues(), z, rho);
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ref(A + rho * g * g.transpose(),
                                                         Eigen::EigenvaluesOnly);
      EXPECT_LT((mu - ref.eigenvalues()).cwiseAbs().maxCoeff(),
                1e-10 * ref.eigenvalues().maxCoeff())
          << "rho " << rho;
    }
  }
}

// Backward elimination written the slow way (an eigendecomposition per candidate): the
// rank-one what-ifs of the library must make the same choices.
std::vector<int> BruteBackward(const Eigen::MatrixXd& G, int k, DesignCriterion c) {
  std::vector<int> kept(G.rows());
  std::iota(kept.begin(), kept.end(), 0);
  while (static_cast<int>(kept.size()) > k) {
    double best = -std::numeric_limits<double>::infinity();
    int best_pos = 0;
    for (int pos = 0; pos < static_cast<int>(kept.size()); ++pos) {
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(G.cols(), G.cols());
      for (int q = 0; q < static_cast<int>(kept.size()); ++q)
        if (q != pos) A += G.row(kept[q]).transpose() * G.row(kept[q]);
      const double score = CriterionScore(A, static_cast<int>(kept.size()) - 1, c);
      if (score > best) {
        best = score;
        best_pos = pos;
      }
    }
    kept.erase(kept.begin() + best_pos);
  }
  return kept;
}

TEST(Selection, BackwardWithRankOneUpdatesMatchesBruteForceForEveryCriterion) {
  const Eigen::MatrixXd G = RandomMatrix(30, 5, 21);
  RandomStream stream(1, 0, 0, RandomPurpose::kSelection);
  for (DesignCriterion c :
       {DesignCriterion::kE, DesignCriterion::kD, DesignCriterion::kA, DesignCriterion::kO1,
        DesignCriterion::kO2, DesignCriterion::kO4, DesignCriterion::kO5}) {
    SelectionOptions o;
    o.method = SelectionMethod::kBackward;
    o.criterion = c;
    EXPECT_EQ(SelectConfigurations(G, 12, o, stream).indices, BruteBackward(G, 12, c))
        << DesignCriterionName(c);
  }
}

// E-optimality prunes candidates by Rayleigh bounds and scores exactly only those that can win:
// the choices must still be those of scoring every candidate, on a paper-sized problem too.
TEST(Selection, BackwardEWithBoundsMatchesBruteForceOnLargerProblems) {
  RandomStream stream(1, 0, 0, RandomPurpose::kSelection);
  SelectionOptions o;
  o.method = SelectionMethod::kBackward;
  o.criterion = DesignCriterion::kE;
  const Eigen::MatrixXd small = RandomMatrix(60, 10, 22);
  EXPECT_EQ(SelectConfigurations(small, 20, o, stream).indices,
            BruteBackward(small, 20, DesignCriterion::kE));
  const Eigen::MatrixXd paper_sized = RandomMatrix(101, 25, 23);
  EXPECT_EQ(SelectConfigurations(paper_sized, 50, o, stream).indices,
            BruteBackward(paper_sized, 50, DesignCriterion::kE));
}

// The exchange scores swaps without a fresh decomposition (E: a rank-two eigenvalue count
// pruned by Rayleigh bounds; D and A: Fedorov's formulas): its end must still be a local
// optimum, no single swap raising the criterion by more than the acceptance margin (1e-10,
// relative), checked by a fresh eigendecomposition of every swap.
TEST(Selection, ExchangeEndsWhereNoSingleSwapImproves) {
  RandomStream stream(4, 0, 0, RandomPurpose::kSelection);
  for (DesignCriterion c : {DesignCriterion::kE, DesignCriterion::kD, DesignCriterion::kA}) {
    for (const auto& [rows, cols, k, seed] :
         {std::tuple{40, 6, 9, 51u}, std::tuple{60, 10, 14, 52u}, std::tuple{101, 25, 30, 53u}}) {
      const Eigen::MatrixXd G = RandomMatrix(rows, cols, seed);
      SelectionOptions o;
      o.method = SelectionMethod::kExchange;
      o.criterion = c;
      const SelectionResult r = SelectConfigurations(G, k, o, stream);
      std::vector<bool> in(rows, false);
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(cols, cols);
      for (int i : r.indices) {
        in[i] = true;
        A += G.row(i).transpose() * G.row(i);
      }
      const double current = CriterionScore(A, k, c);
      EXPECT_NEAR(current, r.score, 1e-12 * std::fabs(r.score));
      double best_swap = -std::numeric_limits<double>::infinity();
      for (int i : r.indices)
        for (int j = 0; j < rows; ++j) {
          if (in[j]) continue;
          const Eigen::MatrixXd B =
              A - G.row(i).transpose() * G.row(i) + G.row(j).transpose() * G.row(j);
          best_swap = std::max(best_swap, CriterionScore(B, k, c));
        }
      EXPECT_LE(best_swap, current + 1e-10 * std::fabs(current))
          << DesignCriterionName(c) << " " << rows << "x" << cols << " k " << k;
    }
  }
}

TEST(Selection, ExchangeMatchesExhaustiveOnSmallProblemsAndNeverEndsWorse) {
  RandomStream stream(3, 0, 0, RandomPurpose::kSelection);
  for (unsigned seed : {31u, 32u, 33u}) {
    const Eigen::MatrixXd G = RandomMatrix(12, 3, seed);
    for (DesignCriterion c : {DesignCriterion::kE, DesignCriterion::kD, DesignCriterion::kA}) {
      SelectionOptions ex, xc;
      ex.method = SelectionMethod::kExhaustive;
      ex.criterion = xc.criterion = c;
      xc.method = SelectionMethod::kExchange;
      xc.restarts = 6;
      const SelectionResult best = SelectConfigurations(G, 5, ex, stream);
      const SelectionResult got = SelectConfigurations(G, 5, xc, stream);
      EXPECT_NEAR(got.score, best.score, 1e-12 * std::fabs(best.score))
          << DesignCriterionName(c) << " seed " << seed;
      EXPECT_GE(got.score, got.start_score);
    }
  }
}

TEST(Selection, ExchangeImprovesOnBackwardGreedyForThePaperSizedProblem) {
  const Eigen::MatrixXd G = RandomMatrix(101, 25, 41);
  RandomStream stream(5, 0, 0, RandomPurpose::kSelection);
  SelectionOptions backward, exchange;
  backward.method = SelectionMethod::kBackward;
  exchange.method = SelectionMethod::kExchange;
  const SelectionResult b = SelectConfigurations(G, 50, backward, stream);
  const SelectionResult x = SelectConfigurations(G, 50, exchange, stream);
  EXPECT_GE(x.start_score, b.score);  // the backward design is one of the starts
  EXPECT_GE(x.score, b.score);
  EXPECT_EQ(x.indices, SelectConfigurations(G, 50, exchange, stream).indices);  // deterministic
}

TEST(Selection, ForwardGreedyIsDeterministicAndBeatsRandom) {
  const Eigen::MatrixXd G = RandomMatrix(60, 8, 6);
  RandomStream stream(2, 0, 0, RandomPurpose::kSelection);
  SelectionOptions forward, random;
  forward.method = SelectionMethod::kGreedy;
  random.method = SelectionMethod::kRandom;
  const SelectionResult a = SelectConfigurations(G, 20, forward, stream);
  EXPECT_EQ(a.indices, SelectConfigurations(G, 20, forward, stream).indices);
  EXPECT_EQ(a.indices.size(), 20u);
  EXPECT_GT(a.score, SelectConfigurations(G, 20, random, stream).score);
}

// Greedy forward written the slow way (a fresh eigendecomposition per candidate, D-optimal
// until the design has rank n): the library's Cholesky D steps and its E steps taken two per
// eigendecomposition (the second by the rank-two eigenvalue count) must make the same choices.
std::vector<int> BruteForward(const Eigen::MatrixXd& G, int k, DesignCriterion c) {
  const int n = static_cast<int>(G.cols());
  const double ridge = 1e-9 * G.squaredNorm() / n;
  Eigen::MatrixXd A = ridge * Eigen::MatrixXd::Identity(n, n);
  std::vector<bool> chosen(G.rows(), false);
  std::vector<int> out;
  while (static_cast<int>(out.size()) < k) {
    const DesignCriterion step = static_cast<int>(out.size()) < n ? DesignCriterion::kD : c;
    double best = -std::numeric_limits<double>::infinity();
    int best_j = -1;
    for (int j = 0; j < G.rows(); ++j) {
      if (chosen[j]) continue;
      const Eigen::MatrixXd B = A + G.row(j).transpose() * G.row(j);
      const double s = CriterionScore(B, static_cast<int>(out.size()) + 1, step);
      if (s > best || best_j < 0) {
        best = s;
        best_j = j;
      }
    }
    chosen[best_j] = true;
    out.push_back(best_j);
    A += G.row(best_j).transpose() * G.row(best_j);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Selection, ForwardMatchesBruteForceOnPaperSizedProblems) {
  RandomStream stream(1, 0, 0, RandomPurpose::kSelection);
  for (DesignCriterion c : {DesignCriterion::kE, DesignCriterion::kD, DesignCriterion::kA}) {
    SelectionOptions o;
    o.method = SelectionMethod::kGreedy;
    o.criterion = c;
    for (const auto& [rows, cols, k, seed] :
         {std::tuple{60, 10, 21, 61u}, std::tuple{101, 25, 50, 62u},
          std::tuple{101, 25, 27, 63u}}) {
      const Eigen::MatrixXd G = RandomMatrix(rows, cols, seed);
      EXPECT_EQ(SelectConfigurations(G, k, o, stream).indices, BruteForward(G, k, c))
          << DesignCriterionName(c) << " " << rows << "x" << cols << " k " << k;
    }
  }
}

TEST(Scaling, UnitColumnsAndExpectedErrors) {
  Eigen::MatrixXd G(3, 2);
  G << 3, 0, 4, 1, 0, 0;
  Eigen::MatrixXd U = ScaleColumns(G, DesignScaling::kUnitColumns);
  EXPECT_NEAR(U.col(0).norm(), 1.0, 1e-15);
  EXPECT_NEAR(U.col(1).norm(), 1.0, 1e-15);
  Eigen::MatrixXd E = ScaleColumns(G, DesignScaling::kExpectedErrors, Eigen::Vector2d(2, 0.5));
  EXPECT_DOUBLE_EQ(E(1, 0), 8.0);
  EXPECT_DOUBLE_EQ(E(1, 1), 0.5);
  EXPECT_TRUE(ScaleColumns(G, DesignScaling::kSI).isApprox(G));
  EXPECT_THROW(ScaleColumns(G, DesignScaling::kExpectedErrors, Eigen::Vector3d(1, 1, 1)),
               InputError);
}

TEST(Selection, BadRequestsAreClearErrors) {
  const Eigen::MatrixXd G = RandomMatrix(10, 4, 5);
  RandomStream stream(1, 0, 0, RandomPurpose::kSelection);
  SelectionOptions o;
  EXPECT_THROW(SelectConfigurations(G, 11, o, stream), InputError);
  EXPECT_THROW(SelectConfigurations(G, 3, o, stream), InputError);
  EXPECT_THROW(SelectConfigurations(Eigen::MatrixXd(0, 4), 1, o, stream), InputError);
  o.method = SelectionMethod::kExhaustive;
  EXPECT_THROW(SelectConfigurations(RandomMatrix(101, 25, 1), 50, o, stream), InputError);
}

TEST(DesignJacobian, ScalesTheIdentificationJacobianAsAsked) {
  const MeasurementModel model(testing::PaperRobot(), testing::PaperPlane(),
                               MakeParameterSet(testing::PaperRobot(), PlaneTerms{}));
  SamplingOptions sampling;
  const TargetedConfigurations pool =
      SampleConfigurations(testing::PaperRobot(), testing::PaperPlane(), 40,
                           RandomStream(3, 0, 0, RandomPurpose::kPool), sampling);
  const Eigen::MatrixXd G = IdentificationJacobian(model, pool);
  EXPECT_EQ(DesignJacobian(model, pool, DesignScaling::kSI, 2e-3, 5e-3), G);
  const Eigen::MatrixXd E = DesignJacobian(model, pool, DesignScaling::kExpectedErrors, 2e-3, 5e-3);
  const ParameterSet& ps = model.parameters();
  for (int k = 0; k < ps.size(); ++k)
    EXPECT_EQ(E.col(k), G.col(k) * (ps.IsAngular(k) ? 2e-3 : 5e-3)) << ps.names[k];
}

TEST(UsableCandidates, KeepsTheConfigurationsWhoseNominalBeamHitsAndSaysWhyOthersDoNot) {
  const RobotModel& robot = testing::PaperRobot();
  SamplingOptions anywhere;
  anywhere.require_beam_hit = false;
  const TargetedConfigurations pool =
      SampleConfigurations(robot, testing::PaperPlane(), 200,
                           RandomStream(5, 0, 0, RandomPurpose::kValidation), anywhere);
  const CandidatePool usable = UsableCandidates(robot, testing::PaperPlane(), RangerSpec{}, pool);
  std::vector<double> h;
  std::vector<BeamMiss> misses;
  ExactReadings(robot, robot.nominal_values(), testing::PaperPlane(), RangerSpec{}, pool, &h,
                &misses);
  std::vector<int> expected;
  for (int i = 0; i < pool.size(); ++i)
    if (misses[i] == BeamMiss::kNone) expected.push_back(i);
  ASSERT_GT(expected.size(), 0u);
  ASSERT_LT(expected.size(), 200u);  // the test needs both kinds
  EXPECT_EQ(usable.kept, expected);
  EXPECT_EQ(usable.misses, misses);
  EXPECT_EQ(usable.configs.size(), static_cast<int>(expected.size()));
  EXPECT_EQ(usable.configs.q(0)[3], pool.q(expected[0])[3]);
  EXPECT_EQ(usable.report.accepted, static_cast<int>(expected.size()));
  int rejected = 0;
  for (const auto& [why, n] : usable.report.rejected) rejected += n;
  EXPECT_EQ(rejected, 200 - usable.report.accepted);
}

}  // namespace
}  // namespace lrcal
