// validation.coverage: how often the 95 % radius a cell's calibration states holds the true
// position error, by Monte Carlo over the trials of a study (trial.cc: StateCoverageRadii,
// RecordCoverage), and how a run records and tables it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <string>

#include "lrcal/core/error.h"
#include "lrcal/report/run_tables.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial_store.h"
#include "run_summaries.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// Runs `body` on the paper's arm with validation.coverage and returns each cell's summary.
std::vector<CellSummary> RunCoverage(const std::string& dir, const std::string& body, int trials) {
  std::ofstream(dir + "/s.yaml") << "name: coverage\nseed: 7\ntrials: " << trials
                                 << "\npool: {size: 80}\nselection: {count: 40}\n"
                                    "validation: {size: 20, coverage: true}\n"
                                    "noise: {sigma_mm: 0.1}\n"
                                 << body;
  EXPECT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  return testing::SummarizeRun(dir + "/run");
}

// The paper's case: every term with a true error is estimated (the plane is known exactly), so
// the data part's radius covers at its stated 95 % (4 standard errors of the Monte-Carlo mean,
// and 2 points for the first-order prediction at the nominal model). With d6 fixed at nominal
// (its true error 0.85 mm) the data part covers far less, and the total, which gives d6 lrcal's
// default tolerance of 1 mm, covers at least its 95 %.
TEST(Coverage, TheStatedRadiusHoldsAtItsRateAndTheTotalCoversAFixedTerm) {
  const std::string dir = testing::TempDir("coverage_paper");
  const std::vector<CellSummary> cells =
      RunCoverage(dir,
                  "sweep:\n  axes:\n"
                  "    - {key: identification.fix, values: [[], [d6]], labels: [all, d6 fixed]}\n",
                  300);
  ASSERT_EQ(cells.size(), 2u);
  const CellSummary &all = cells[0], &fixed = cells[1];
  ASSERT_EQ(all.coverage.n, 300);
  std::cout << "coverage, data part: all estimated " << all.coverage.mean << " ± "
            << all.coverage.mean_se << ", d6 fixed " << fixed.coverage.mean << " ± "
            << fixed.coverage.mean_se << "; total, d6 fixed " << fixed.coverage_total.mean << " ± "
            << fixed.coverage_total.mean_se << "\n";
  EXPECT_NEAR(all.coverage.mean, 0.95, 4 * all.coverage.mean_se + 0.02);
  EXPECT_GE(all.coverage_total.mean, all.coverage.mean);
  EXPECT_LT(fixed.coverage.mean, 0.5);
  EXPECT_GT(fixed.coverage_total.mean, 0.95 - 4 * fixed.coverage_total.mean_se);
}

// The run records it: trial store columns, validation.csv rows, summary.md's section and
// summary.json; a study without it has no such rows and keeps its cells' names.
TEST(Coverage, RunsRecordAndTableIt) {
  const std::string dir = testing::TempDir("coverage_tables");
  std::ofstream(dir + "/s.yaml") << "name: c\nseed: 3\ntrials: 12\npool: {size: 60}\n"
                                    "selection: {count: 40}\nvalidation: {size: 10, coverage: "
                                    "true}\nnoise: {sigma_mm: 0.1}\n";
  RunOptions o;
  o.out_dir = dir + "/run";
  o.threads = 2;
  o.progress = false;
  ASSERT_TRUE(RunStudyAndWriteTables(LoadStudy(dir + "/s.yaml"), o).tables_written);
  TrialStore store(dir + "/run/trials.sqlite");
  int recorded = 0;
  store.ForEachTrial(store.Cells().at(0).id, [&](const TrialRecord& r) {
    EXPECT_GE(r.coverage, 0.0);
    EXPECT_LE(r.coverage, r.coverage_total);  // the total radius is never the smaller
    recorded += r.coverage >= 0;
  });
  EXPECT_EQ(recorded, 12);
  const std::string csv = testing::ReadFile(dir + "/run/tables/validation.csv");
  EXPECT_THAT(csv, AllOf(HasSubstr(",identified,coverage,all,%,12,"),
                         HasSubstr(",identified,coverage_total,all,%,12,")));
  EXPECT_THAT(testing::ReadFile(dir + "/run/tables/summary.md"),
              HasSubstr("Coverage of the stated 95 % radius"));
  EXPECT_THAT(testing::ReadFile(dir + "/run/tables/summary.json"), HasSubstr("\"coverage_total\""));

  // Without it: nothing of the above, and the cell's name is the one it had before the key.
  std::ofstream(dir + "/t.yaml") << "name: c\nseed: 3\ntrials: 12\npool: {size: 60}\n"
                                    "selection: {count: 40}\nvalidation: {size: 10}\n"
                                    "noise: {sigma_mm: 0.1}\n";
  std::ofstream(dir + "/u.yaml") << "name: c\nseed: 3\ntrials: 12\npool: {size: 60}\n"
                                    "selection: {count: 40}\nvalidation: {size: 10, coverage: "
                                    "false}\nnoise: {sigma_mm: 0.1}\n";
  EXPECT_EQ(LoadStudy(dir + "/t.yaml").cells[0].id, LoadStudy(dir + "/u.yaml").cells[0].id);
  EXPECT_NE(LoadStudy(dir + "/t.yaml").cells[0].id, LoadStudy(dir + "/s.yaml").cells[0].id);
}

TEST(Coverage, NeedsTheCellsOneDesign) {
  const std::string dir = testing::TempDir("coverage_refused");
  std::ofstream(dir + "/s.yaml") << "name: c\nseed: 3\ntrials: 2\n"
                                    "selection: {method: random, redraw: true}\n"
                                    "validation: {coverage: true}\n";
  try {
    LoadStudy(dir + "/s.yaml");
    ADD_FAILURE() << "coverage with a redrawn selection was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("s.yaml:5 key 'validation.coverage'"),
                                HasSubstr("selection.redraw")));
  }
}

}  // namespace
}  // namespace lrcal
