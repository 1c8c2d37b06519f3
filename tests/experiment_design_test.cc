// Selection of k of N configurations: criteria against hand-computed values, exhaustive against
// brute force, greedy and sampled determinism, and bad requests.
#include "lrcal/experiment_design.h"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <random>

#include "lrcal/error.h"

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
  SelectionResult r = SelectConfigurations(G, 100, o, RandomStream(1, 0, 0, RandomPurpose::kSelection));
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

}  // namespace
}  // namespace lrcal
