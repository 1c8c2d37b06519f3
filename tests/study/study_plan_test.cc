// The dry run: every cell prepared and timed, the estimate the sum of the cells', in text and JSON.
#include "lrcal/study/study_plan.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "test_util.h"

namespace lrcal {
namespace {

TEST(StudyPlan, PreparesEveryCellAndAddsTheirEstimates) {
  const std::string dir = testing::TempDir("study_plan");
  const std::string path = dir + "/s.yaml";
  std::ofstream(path) << "name: planned\nseed: 3\ntrials: 50\nrobot: "
                      << testing::SourcePath("studies/robots/paper.yaml")
                      << "\npool: {size: 60}\nvalidation: {size: 5}\n"
                         "sweep:\n  axes:\n    - key: selection.count\n      values: [30, 59]\n";
  const Study study = LoadStudy(path);
  const StudyPlan plan = PlanStudy(study, 3);
  ASSERT_EQ(plan.cells.size(), 2u);
  EXPECT_EQ(plan.threads, 3);
  EXPECT_EQ(plan.total_trials, 100);
  double sum = 0;
  for (std::size_t k = 0; k < plan.cells.size(); ++k) {
    const CellPlan& c = plan.cells[k];
    EXPECT_EQ(c.id, study.cells[k].id);
    EXPECT_GT(c.seconds_per_trial, 0);
    EXPECT_DOUBLE_EQ(c.estimate_seconds, c.prepare_seconds + c.seconds_per_trial * 50 / 3);
    sum += c.estimate_seconds;
  }
  EXPECT_DOUBLE_EQ(plan.estimate_seconds, sum);
  const ResultJson j = plan.ToJson();
  EXPECT_EQ(j["study"], "planned");
  EXPECT_EQ(j["cells"].size(), 2u);
  EXPECT_EQ(j["cells"][1]["settings"]["selection"]["count"], 59);
  EXPECT_THAT(plan.ToText(), ::testing::HasSubstr("total: 2 cells, 100 trials, about"));
  EXPECT_GE(PlanStudy(study, 0).threads, 1);
}

}  // namespace
}  // namespace lrcal
