// PreparedCell, the public face of the trial pipeline: a trial run through it is the record the
// runner stored for that trial, bit for bit, from any thread; its accessors describe the cell.
#include "lrcal/study/prepared_cell.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "lrcal/study/runner.h"
#include "lrcal/study/trial_store.h"
#include "test_util.h"

namespace lrcal {
namespace {

std::string PreparedSmallStudy(const std::string& dir) {
  std::ofstream(dir + "/s.yaml") << "name: p\nseed: 3\ntrials: 4\nrobot: "
                                 << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\npool: {size: 60}\nvalidation: {size: 5}\n"
                                    "selection: {count: 40}\n";
  return dir + "/s.yaml";
}

void ExpectSameRecord(const TrialRecord& a, const TrialRecord& b) {
  EXPECT_EQ(a.cell_id, b.cell_id);
  EXPECT_EQ(a.trial, b.trial);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.residual_rms, b.residual_rms);
  EXPECT_EQ(a.errors, b.errors);
  EXPECT_EQ(a.validation, b.validation);
  EXPECT_EQ(a.nominal, b.nominal);
}

TEST(PreparedCell, ATrialIsTheRunnersRecordBitForBitFromAnyThread) {
  const std::string dir = testing::TempDir("prepared_cell");
  const Study study = LoadStudy(PreparedSmallStudy(dir));
  RunOptions o;
  o.out_dir = dir + "/run";
  o.threads = 2;
  o.progress = false;
  ASSERT_EQ(RunStudy(study, o).computed, 4);
  const TrialStore store(dir + "/run/trials.sqlite");
  const PreparedCell cell = PreparedCell::Prepare(study, study.cells.at(0));
  std::vector<TrialRecord> stored;
  store.ForEachTrial(study.cells[0].id, [&](const TrialRecord& r) { stored.push_back(r); });
  ASSERT_EQ(stored.size(), 4U);
  std::vector<TrialRecord> mine(4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) threads.emplace_back([&, t] { mine[t] = cell.Run(t); });
  for (auto& t : threads) t.join();
  for (int t = 0; t < 4; ++t) ExpectSameRecord(mine[t], stored[t]);
  // With the realisation's details, the same record.
  TrialDetails details;
  ExpectSameRecord(cell.Run(2, &details), stored[2]);
  EXPECT_EQ(details.distance_error_identified.size(), 40U);
}

TEST(PreparedCell, DescribesTheCell) {
  const std::string dir = testing::TempDir("prepared_cell_describe");
  const Study study = LoadStudy(PreparedSmallStudy(dir));
  const PreparedCell cell = PreparedCell::Prepare(study, study.cells.at(0));
  EXPECT_EQ(cell.pool().size(), 60);
  EXPECT_EQ(cell.validation().size(), 5);
  EXPECT_EQ(cell.num_parameters(), 25);
  EXPECT_EQ(cell.parameter_names().size(), 25U);
  EXPECT_THAT(cell.parameter_names(), ::testing::Contains("beta2"));
  EXPECT_EQ(cell.num_planes(), 1);
  const Eigen::MatrixXd draws = cell.LinearisedValidationDraws(50);
  EXPECT_EQ(draws.rows(), 50);
  EXPECT_EQ(draws.cols(), 12);
  EXPECT_TRUE(draws.allFinite());
  EXPECT_TRUE((draws.array() >= 0).all());  // RMS and max errors
}

// The draws at R readings and of each part: the data part at the cell's own readings is the
// cell's prediction bit for bit and scales as 1/√R without priors; the held terms' part has, on
// average over the draws, the mean-square position error that the total statement's sources give
// (an independent path: per-pose covariances, not draws); the total's mean square is the sum of
// the parts'.
TEST(PreparedCell, FirstOrderDrawsOfEachPartAgreeWithTheTotalStatement) {
  const std::string dir = testing::TempDir("prepared_cell_parts");
  std::ofstream(dir + "/s.yaml") << "name: p\nseed: 3\ntrials: 4\nrobot: "
                                 << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\npool: {size: 60}\nvalidation: {size: 30}\n"
                                    "noise: {repetitions: 4}\nselection: {count: 40}\n"
                                    "identification: {fix: [d6]}\n";
  const Study study = LoadStudy(dir + "/s.yaml");
  const PreparedCell cell = PreparedCell::Prepare(study, study.cells.at(0));
  constexpr int kDraws = 4000;
  const FirstOrderDraws own = cell.LinearisedValidationDraws(kDraws, 4);
  EXPECT_EQ(own.data, cell.LinearisedValidationDraws(kDraws));
  // One reading: the same normals, the covariance 4 times larger.
  EXPECT_TRUE(cell.LinearisedValidationDraws(kDraws, 1).data.isApprox(2 * own.data, 1e-12));

  const auto mean_square_position = [](const Eigen::MatrixXd& d) {
    return d.leftCols(3).array().square().rowwise().sum().mean();  // Σ axes rms², mean over draws
  };
  const std::optional<AccuracyPrediction> stated = cell.StatedValidationAccuracy(4);
  ASSERT_TRUE(stated.has_value());
  double held_ms = 0, data_ms = 0;
  for (const AccuracySource& s : stated->sources)
    (s.prior_sigma > 0 ? held_ms : data_ms) += s.position_rms * s.position_rms;
  EXPECT_THAT(stated->defaulted, ::testing::Contains("d6"));
  EXPECT_THAT(stated->defaulted, ::testing::Contains("ranger_offset"));
  // 4000 draws of a sum of squares: a relative standard error of a few per cent at most.
  constexpr double kDrawTolerance = 0.08;
  EXPECT_NEAR(mean_square_position(own.held) / held_ms, 1, kDrawTolerance);
  EXPECT_NEAR(mean_square_position(own.data) / data_ms, 1, kDrawTolerance);
  EXPECT_NEAR(mean_square_position(own.total) / (held_ms + data_ms), 1, kDrawTolerance);
  EXPECT_THROW(cell.LinearisedValidationDraws(10, 0), InputError);
}

}  // namespace
}  // namespace lrcal
