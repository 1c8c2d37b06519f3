// The random-design baseline: every index of the chosen design, the random designs' spread and
// where the choice falls among them, reproducibly from the seed.
#include "lrcal/design/random_baseline.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "lrcal/core/random.h"
#include "test_util.h"

namespace lrcal {
namespace {

Eigen::MatrixXd BaselineRandomMatrix(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n;  // test data only
  Eigen::MatrixXd G(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) G(i, j) = n(rng);
  return G;
}

TEST(RandomBaseline, ScoresTheChosenRowsAndDrawsTheRandomDesignsFromTheSeed) {
  const Eigen::MatrixXd G = BaselineRandomMatrix(40, 4, 7);
  SelectionOptions exchange;
  exchange.method = SelectionMethod::kExchange;
  const SelectionResult chosen =
      SelectConfigurations(G, 8, exchange, RandomStream(3, 1, 0, RandomPurpose::kSelection));
  const std::vector<BaselineIndex> b = CompareWithRandomDesigns(G, chosen.indices, 200, 3);
  ASSERT_EQ(b.size(), std::size(kBaselineCriteria));
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(4, 4);
  for (int r : chosen.indices) A += G.row(r).transpose() * G.row(r);
  // Random design 0 is draw 0 of selection stream 2.
  SelectionOptions random;
  random.method = SelectionMethod::kRandom;
  const SelectionResult first =
      SelectConfigurations(G, 8, random, RandomStream(3, 2, 0, RandomPurpose::kSelection));
  Eigen::MatrixXd A0 = Eigen::MatrixXd::Zero(4, 4);
  for (int r : first.indices) A0 += G.row(r).transpose() * G.row(r);
  for (const BaselineIndex& index : b) {
    EXPECT_DOUBLE_EQ(index.chosen, CriterionScore(A, 8, index.criterion));
    EXPECT_EQ(index.random.n, 200);
    EXPECT_LE(index.random.min, CriterionScore(A0, 8, index.criterion));
    EXPECT_GE(index.random.max, CriterionScore(A0, 8, index.criterion));
    EXPECT_THAT(index.percentile, ::testing::AllOf(::testing::Ge(0.0), ::testing::Le(100.0)));
  }
  // The exchange optimises E: its choice beats most random designs on E.
  EXPECT_GT(b[0].percentile, 90.0);
  const std::vector<BaselineIndex> again = CompareWithRandomDesigns(G, chosen.indices, 200, 3);
  EXPECT_EQ(again[1].random.mean, b[1].random.mean);
}

TEST(RandomBaseline, RefusesACountOutOfRangeNamingTheSetting) {
  const Eigen::MatrixXd G = BaselineRandomMatrix(10, 2, 1);
  try {
    CompareWithRandomDesigns(G, {0, 1, 2}, 0, 1);
    FAIL() << "no error";
  } catch (const SettingError& e) {
    EXPECT_THAT(e.Respelled(Frontend::kCommandLine).what(),
                ::testing::HasSubstr("--baseline: expected 1 to 1,000,000 random designs, got 0"));
  }
}

}  // namespace
}  // namespace lrcal
