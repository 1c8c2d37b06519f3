// The memos of a cell's preparation (src/study/preparation_memo.h): cells that differ only in the
// noise share their robot, configurations, design and first-order draws; anything else that a
// step reads (another pool size, an edited robot file) is computed again.
#include "study/preparation_memo.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <list>
#include <stdexcept>
#include <string>

#include "lrcal/study/study.h"
#include "study/trial_pipeline.h"
#include "test_util.h"

namespace lrcal {
namespace {

TEST(PreparationMemo, ReturnsTheStoredValueForAnEqualKeyAndComputesOtherwise) {
  PreparationMemo<int, std::string, 2> memo;
  int computed = 0;
  const auto get = [&](int key) {
    return memo.Get(key, [&] {
      ++computed;
      return "value " + std::to_string(key);
    });
  };
  EXPECT_EQ(get(1), "value 1");
  EXPECT_EQ(get(1), "value 1");
  EXPECT_EQ(computed, 1);
  EXPECT_EQ(get(2), "value 2");
  EXPECT_EQ(get(3), "value 3");  // evicts 1 (two entries)
  EXPECT_EQ(computed, 3);
  EXPECT_EQ(get(1), "value 1");
  EXPECT_EQ(computed, 4);
  // A step that throws stores nothing: the next call computes (and meets the error) again.
  for (int attempt = 0; attempt < 2; ++attempt)
    EXPECT_THROW(memo.Get(7, []() -> std::string { throw std::runtime_error("bad"); }),
                 std::runtime_error);
}

TEST(PreparationMemo, ClearPreparationMemosEmptiesEveryMemo) {
  PreparationMemo<int, int> a, b;
  int computed = 0;
  const auto twice = [&](int key) { return ++computed, 2 * key; };
  a.Get(1, [&] { return twice(1); });
  b.Get(1, [&] { return twice(1); });
  a.Get(1, [&] { return twice(1); });
  EXPECT_EQ(computed, 2);
  ClearPreparationMemos();
  EXPECT_EQ(a.Get(1, [&] { return twice(1); }), 2);
  EXPECT_EQ(b.Get(1, [&] { return twice(1); }), 2);
  EXPECT_EQ(computed, 4);
}

TEST(SameMatrix, ComparesSizesBeforeValues) {
  EXPECT_TRUE(SameMatrix(Eigen::MatrixXd::Ones(2, 3), Eigen::MatrixXd::Ones(2, 3)));
  EXPECT_FALSE(SameMatrix(Eigen::MatrixXd::Ones(2, 3), Eigen::MatrixXd::Ones(3, 2)));
  Eigen::MatrixXd b = Eigen::MatrixXd::Ones(2, 3);
  b(1, 2) = std::nextafter(1.0, 2.0);
  EXPECT_FALSE(SameMatrix(Eigen::MatrixXd::Ones(2, 3), b));
}

class NoiseSweep : public ::testing::Test {
 protected:
  // A sweep over σ of a study of `robot` with a pool of `pool`, prepared cell by cell.
  std::vector<std::unique_ptr<CellContext>> Prepare(const std::string& robot, int pool = 60) {
    const std::string path = dir_ + "/sweep" + std::to_string(studies_.size()) + ".yaml";
    std::ofstream(path)
        << "name: sweep\nseed: 5\ntrials: 1\nrobot: " << robot << "\npool: {size: " << pool
        << "}\nselection: {count: 30, method: backward}\n"
           "validation: {size: 12}\n"
        << "sweep:\n  axes:\n    - {key: noise.sigma_mm, values: [0.05, 0.2, 0.45]}\n";
    studies_.push_back(LoadStudy(path));
    std::vector<std::unique_ptr<CellContext>> cells;
    for (const Cell& cell : studies_.back().cells)
      cells.push_back(PrepareCell(studies_.back(), cell));
    return cells;
  }
  std::string dir_ = testing::TempDir("preparation_memo");
  std::list<Study> studies_;  // a CellContext points into its study
};

// The cells of a noise sweep share the pool, the validation poses, the design and the unit
// covariance; their predictions scale with σ (to rounding: each is σ times the shared draws).
TEST_F(NoiseSweep, CellsShareTheirDesignAndTheirPredictionsScaleWithSigma) {
  const auto cells = Prepare(testing::SourcePath("studies/robots/paper.yaml"));
  ASSERT_EQ(cells.size(), 3u);
  const double sigmas[] = {0.05e-3, 0.2e-3, 0.45e-3};
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const CellContext& c = *cells[i];
    EXPECT_EQ(c.robot, cells[0]->robot);  // one model per robot file
    EXPECT_EQ(c.design.slots, cells[0]->design.slots);
    EXPECT_TRUE(SameMatrix(c.unit_covariance, cells[0]->unit_covariance));
    EXPECT_DOUBLE_EQ(c.covariance_scale, sigmas[i]);
    EXPECT_EQ(c.predicted_covariance,
              (c.covariance_scale * c.covariance_scale) * c.unit_covariance);
    for (int k = 0; k < 12; ++k)
      EXPECT_NEAR(c.predicted_validation[k] / cells[0]->predicted_validation[k],
                  sigmas[i] / sigmas[0], 1e-12)
          << k;
  }
}

// What a step reads decides whether it is shared: another pool size draws another pool, and a
// robot file edited between two preparations is read again.
TEST_F(NoiseSweep, AnotherPoolOrAnEditedRobotFileIsPreparedAgain) {
  const std::string robot = dir_ + "/arm.yaml";
  std::ofstream(robot) << testing::ReadFile(testing::SourcePath("studies/robots/paper.yaml"));
  const auto before = Prepare(robot);
  const auto other_pool = Prepare(robot, 61);
  EXPECT_EQ(other_pool[0]->robot, before[0]->robot);
  EXPECT_NE(other_pool[0]->pool.size(), before[0]->pool.size());

  std::string text = testing::ReadFile(robot);
  const std::string link6 = "a: -0.12, d: 0.4";
  ASSERT_NE(text.find(link6), std::string::npos);
  text.replace(text.find(link6), link6.size(), "a: -0.13, d: 0.4");
  std::ofstream(robot) << text;
  const auto edited = Prepare(robot);
  EXPECT_NE(edited[0]->robot, before[0]->robot);
  const Eigen::VectorXd change =
      edited[0]->robot->nominal_values() - before[0]->robot->nominal_values();
  EXPECT_NEAR(change.cwiseAbs().sum(), 0.01, 1e-15);  // a6 alone, by -10 mm
  EXPECT_NEAR(change.sum(), -0.01, 1e-15);
}

}  // namespace
}  // namespace lrcal
