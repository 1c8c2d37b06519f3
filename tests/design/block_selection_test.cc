// Selection of configurations with several values each (SelectBlocks): every method against an
// independent brute force over the subsets of a small pool, the exchange's end checked as a local
// optimum by trying every swap here, one value per configuration identical to
// SelectConfigurations, and bad requests.
#include "lrcal/design/block_selection.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <numeric>
#include <random>
#include <vector>

#include "lrcal/core/error.h"

namespace lrcal {
namespace {

using ::testing::ElementsAreArray;
using ::testing::HasSubstr;

constexpr int kBlockRows = 3;  // a tracker's point
constexpr double kScoreTolerance = 1e-12;

Eigen::MatrixXd RandomBlockMatrix(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;  // test data only
  Eigen::MatrixXd G(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) G(i, j) = normal(rng);
  return G;
}

// E-criterion score of the chosen blocks, computed here from the stacked rows themselves.
double StackedScore(const Eigen::MatrixXd& G, const std::vector<int>& chosen) {
  Eigen::MatrixXd S(static_cast<Eigen::Index>(chosen.size()) * kBlockRows, G.cols());
  for (std::size_t t = 0; t < chosen.size(); ++t)
    S.middleRows(static_cast<Eigen::Index>(t) * kBlockRows, kBlockRows) =
        G.middleRows(chosen[t] * kBlockRows, kBlockRows);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S.transpose() * S);
  return std::sqrt(eig.eigenvalues()[0]);
}

// The best E-score over every k-subset of N blocks (bit masks).
double BruteForceBest(const Eigen::MatrixXd& G, int N, int k) {
  double best = -1;
  for (unsigned mask = 0; mask < (1u << N); ++mask) {
    if (__builtin_popcount(mask) != k) continue;
    std::vector<int> chosen;
    for (int i = 0; i < N; ++i)
      if (mask & (1u << i)) chosen.push_back(i);
    best = std::max(best, StackedScore(G, chosen));
  }
  return best;
}

SelectionOptions BlockMethod(SelectionMethod method) {
  SelectionOptions o;
  o.criterion = DesignCriterion::kE;
  o.method = method;
  o.samples = 200;
  return o;
}

TEST(SelectBlocks, EveryMethodScoresItsChoiceAndNoneBeatsTheBruteForce) {
  constexpr int N = 12, n = 5, k = 4;
  const Eigen::MatrixXd G = RandomBlockMatrix(N * kBlockRows, n, 7);
  const double best = BruteForceBest(G, N, k);
  const RandomStream stream(3, 1, 0, RandomPurpose::kSelection);
  double backward = 0;
  for (SelectionMethod m :
       {SelectionMethod::kRandom, SelectionMethod::kSampled, SelectionMethod::kGreedy,
        SelectionMethod::kBackward, SelectionMethod::kExchange}) {
    SCOPED_TRACE(SelectionMethodName(m));
    const SelectionResult r = SelectBlocks(G, kBlockRows, k, BlockMethod(m), stream);
    ASSERT_EQ(r.indices.size(), static_cast<std::size_t>(k));
    EXPECT_TRUE(std::is_sorted(r.indices.begin(), r.indices.end()));
    EXPECT_NEAR(r.score, StackedScore(G, r.indices), kScoreTolerance);
    EXPECT_LE(r.score, best + kScoreTolerance);
    if (m == SelectionMethod::kBackward) backward = r.score;
    if (m == SelectionMethod::kExchange) {
      EXPECT_GE(r.score, backward - kScoreTolerance);
      EXPECT_NEAR(r.start_score, backward, kScoreTolerance);
    }
    if (m == SelectionMethod::kSampled) {
      EXPECT_GT(r.score, 0.8 * best);  // 200 of 495 subsets
    }
  }
}

// Backward elimination for E, written here as the definition: each step drops the block whose
// removal keeps the largest smallest eigenvalue (ties: the first in the design).
std::vector<int> PlainBackwardE(const Eigen::MatrixXd& G, int N, int k) {
  std::vector<int> design(static_cast<std::size_t>(N));
  std::iota(design.begin(), design.end(), 0);
  while (static_cast<int>(design.size()) > k) {
    double best = -1;
    std::size_t drop = 0;
    for (std::size_t p = 0; p < design.size(); ++p) {
      std::vector<int> rest = design;
      rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(p));
      const double score = StackedScore(G, rest);
      if (score > best) {
        best = score;
        drop = p;
      }
    }
    design.erase(design.begin() + static_cast<std::ptrdiff_t>(drop));
  }
  return design;
}

// lrcal's backward step for E skips candidates by an upper bound on what their removal keeps
// (block_selection.cc, BestEDrop): it must choose as the plain scan does, step by step. Pools of
// point (3 rows) and pose (6 rows) blocks, tall and nearly square.
TEST(SelectBlocks, BoundedBackwardChoosesAsThePlainScan) {
  for (const auto& [N, n, k, seed] :
       {std::array<int, 4>{40, 12, 8, 1}, {30, 25, 12, 2}, {60, 30, 20, 3}, {25, 6, 3, 4}}) {
    SCOPED_TRACE(seed);
    const Eigen::MatrixXd G = RandomBlockMatrix(N * kBlockRows, n, static_cast<unsigned>(seed));
    const SelectionResult r =
        SelectBlocks(G, kBlockRows, k, BlockMethod(SelectionMethod::kBackward),
                     RandomStream(1, 1, 0, RandomPurpose::kSelection));
    EXPECT_THAT(r.indices, ElementsAreArray(PlainBackwardE(G, N, k)));
  }
}

TEST(SelectBlocks, TheExchangesEndIsALocalOptimum) {
  constexpr int N = 14, n = 6, k = 5;
  const Eigen::MatrixXd G = RandomBlockMatrix(N * kBlockRows, n, 11);
  const SelectionResult r = SelectBlocks(G, kBlockRows, k, BlockMethod(SelectionMethod::kExchange),
                                         RandomStream(1, 1, 0, RandomPurpose::kSelection));
  for (int p = 0; p < k; ++p)
    for (int j = 0; j < N; ++j) {
      if (std::find(r.indices.begin(), r.indices.end(), j) != r.indices.end()) continue;
      std::vector<int> swapped = r.indices;
      swapped[static_cast<std::size_t>(p)] = j;
      EXPECT_LE(StackedScore(G, swapped), r.score * (1 + 1e-9)) << "swap " << p << " for " << j;
    }
}

TEST(SelectBlocks, GreedyReachesFullRankFromTooFewValuesPerBlock) {
  // Blocks of three values, six parameters: two blocks can be enough, the greedy must find a pair
  // that is (the ridge phase), then go on by the criterion.
  constexpr int N = 10, n = 6, k = 3;
  const Eigen::MatrixXd G = RandomBlockMatrix(N * kBlockRows, n, 5);
  const SelectionResult r = SelectBlocks(G, kBlockRows, k, BlockMethod(SelectionMethod::kGreedy),
                                         RandomStream(1, 1, 0, RandomPurpose::kSelection));
  EXPECT_GT(r.score, 0);
}

TEST(SelectBlocks, OneValuePerConfigurationIsTheRangersSelection) {
  const Eigen::MatrixXd G = RandomBlockMatrix(30, 5, 2);
  const RandomStream stream(9, 1, 0, RandomPurpose::kSelection);
  for (SelectionMethod m :
       {SelectionMethod::kBackward, SelectionMethod::kExchange, SelectionMethod::kSampled}) {
    const SelectionResult a = SelectBlocks(G, 1, 8, BlockMethod(m), stream);
    const SelectionResult b = SelectConfigurations(G, 8, BlockMethod(m), stream);
    EXPECT_THAT(a.indices, ElementsAreArray(b.indices));
    EXPECT_EQ(a.score, b.score);
  }
}

TEST(SelectBlocks, RefusesWhatItCannotChoose) {
  const Eigen::MatrixXd G = RandomBlockMatrix(12 * kBlockRows, 5, 1);
  const RandomStream stream(1, 1, 0, RandomPurpose::kSelection);
  const auto message = [&](int rows, int k, SelectionMethod m, const Eigen::MatrixXd& g) {
    try {
      SelectBlocks(g, rows, k, BlockMethod(m), stream);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message(kBlockRows, 4, SelectionMethod::kExhaustive, G),
              HasSubstr("for 3 values per configuration use backward"));
  EXPECT_THAT(message(kBlockRows, 13, SelectionMethod::kBackward, G),
              HasSubstr("cannot select 13"));
  EXPECT_THAT(message(kBlockRows, 1, SelectionMethod::kBackward, G),
              HasSubstr("need at least as many values as parameters"));
  EXPECT_THAT(message(5, 4, SelectionMethod::kBackward, G), HasSubstr("not whole configurations"));
  EXPECT_THAT(message(kBlockRows, 1, SelectionMethod::kBackward, Eigen::MatrixXd(0, 5)),
              HasSubstr("empty"));
}

}  // namespace
}  // namespace lrcal
