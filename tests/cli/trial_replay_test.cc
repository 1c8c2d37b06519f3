// lrcal trial: a recorded trial is recomputed bit for bit; a tampered record, an unknown cell or
// trial, and a study file changed since the run are reported.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "test_util.h"

namespace lrcal {
namespace {

using testing::LrcalBinary;
using testing::RunCommand;

int ReplayLrcal(const std::string& args, std::string* out) {
  return RunCommand(LrcalBinary() + " " + args, out);
}

// Writes a study on the paper's arm into dir/s.yaml (`head` before the robot line, `body` after
// it) and runs it into dir/run.
void RunPaperStudy(const std::string& dir, const std::string& head, const std::string& body) {
  std::ofstream(dir + "/s.yaml") << head
                                 << "robot: " << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\n"
                                 << body;
  std::string out;
  ASSERT_EQ(ReplayLrcal("run " + dir + "/s.yaml --out " + dir + "/run --quiet", &out), 0) << out;
}

// The rows of `sql` on dir/run/trials.sqlite, every column as text.
std::vector<std::vector<std::string>> StoreRows(const std::string& dir, const std::string& sql) {
  std::vector<std::vector<std::string>> rows;
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open((dir + "/run/trials.sqlite").c_str(), &db), SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &st, nullptr), SQLITE_OK) << sql;
  while (st != nullptr && sqlite3_step(st) == SQLITE_ROW) {
    rows.emplace_back();
    for (int c = 0; c < sqlite3_column_count(st); ++c)
      rows.back().emplace_back(reinterpret_cast<const char*>(sqlite3_column_text(st, c)));
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
  return rows;
}

class TrialReplayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::TempDir("trial_replay");
    study_ = dir_ + "/s.yaml";
    WriteStudy(7);
    std::string out;
    ASSERT_EQ(ReplayLrcal("run " + study_ + " --out " + dir_ + "/run --quiet", &out), 0) << out;
  }
  void WriteStudy(int seed) const {
    std::ofstream(study_)
        << "name: replay\nseed: " << seed
        << "\ntrials: 30\nrobot: " << testing::SourcePath("studies/robots/paper.yaml")
        << "\npool: {size: 40}\nselection: {count: 30}\nvalidation: {size: 5}\n"
           "sweep:\n  axes:\n    - key: noise.sigma_mm\n      values: [0.1, 0.3]\n";
  }
  std::string dir_, study_;
};

TEST_F(TrialReplayTest, RecomputesARecordedTrialBitForBit) {
  std::string out;
  ASSERT_EQ(
      ReplayLrcal("trial " + dir_ + "/run --cell 'noise.sigma_mm=0.3' --trial 12 --format json",
                  &out),
      0)
      << out;
  const auto j = nlohmann::json::parse(out);
  EXPECT_TRUE(j["stored"].get<bool>());
  EXPECT_TRUE(j["identical"].get<bool>());
  EXPECT_EQ(j["configurations"].size(), 30u);
  EXPECT_EQ(j["record"]["errors"].size(), j["parameters"].size());
  ASSERT_EQ(ReplayLrcal("trial " + dir_ + "/run --cell 'noise.sigma_mm=0.1' --trial 0", &out), 0)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("identical to the stored record, bit for bit")) << out;
}

TEST_F(TrialReplayTest, ATamperedRecordIsReportedWithTheFieldsThatDiffer) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir_ + "/run/trials.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db,
                         "UPDATE trials SET iterations = iterations + 1, val_rms_pos_y = 1 "
                         "WHERE trial = 4",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  std::string out;
  EXPECT_EQ(ReplayLrcal("trial " + dir_ + "/run --cell 'noise.sigma_mm=0.1' --trial 4", &out), 1)
      << out;
  EXPECT_THAT(out,
              ::testing::HasSubstr("DIFFERS from the stored record in: iterations val_rms_pos_y"))
      << out;
}

TEST_F(TrialReplayTest, BadRequestsAndAChangedStudyAreClearErrors) {
  std::string out;
  EXPECT_EQ(ReplayLrcal("trial " + dir_ + "/run --cell nope --trial 1", &out), 2) << out;
  EXPECT_THAT(out,
              ::testing::HasSubstr("--cell: no cell 'nope' in the run; cells: noise.sigma_mm=0.1"))
      << out;
  EXPECT_EQ(ReplayLrcal("trial " + dir_ + "/run --cell 'noise.sigma_mm=0.1' --trial 30", &out), 2)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("--trial: expected 0 to 29, got 30")) << out;
  EXPECT_EQ(ReplayLrcal("trial " + dir_ + " --cell x --trial 1", &out), 2) << out;  // not a run
  WriteStudy(8);
  EXPECT_EQ(ReplayLrcal("trial " + dir_ + "/run --cell 'noise.sigma_mm=0.1' --trial 1", &out), 2)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("has changed since the run")) << out;
}

// Issue 31: a failed trial replays without a crash, says why it failed, and matches its record
// (the store keeps no validation for it), in text and JSON, for every status a study produces.
TEST(TrialReplayOfFailedTrials, EachStatusReplaysAndMatchesItsRecord) {
  const std::string dir = testing::TempDir("trial_replay_statuses");
  ASSERT_NO_FATAL_FAILURE(RunPaperStudy(
      dir, "name: statuses\nseed: 3\ntrials: 8\n",
      "pool: {size: 40}\nselection: {count: 30}\nvalidation: {size: 5}\n"
      "sweep:\n  axes:\n    - key: .\n      values:\n"
      "        - {identification: {max_iterations: 100}}\n"
      "        - {identification: {max_iterations: 1}}\n"
      "        - {truth: {mode: random, length_sigma_mm: 150, angle_sigma_mrad: 150}}\n"
      "      labels: [ok, one_iteration, wild_truth]\n"));
  std::set<std::string> statuses;
  std::string out;
  for (const auto& row : StoreRows(dir,
                                   "SELECT c.label, t.trial, t.status FROM trials t JOIN cells c "
                                   "USING (cell_id) GROUP BY t.status")) {
    const std::string& label = row[0];
    const std::string& trial = row[1];
    const std::string& status = row[2];
    statuses.insert(status);
    SCOPED_TRACE(status + " in cell " + label);
    const std::string args = "trial " + dir + "/run --cell " + label + " --trial " + trial;
    ASSERT_EQ(ReplayLrcal(args + " --format json", &out), 0) << out;
    const auto j = nlohmann::json::parse(out);
    EXPECT_TRUE(j["identical"].get<bool>()) << out;
    EXPECT_EQ(j["record"]["status"], status);
    EXPECT_EQ(j["failure"].is_null(), status == "ok");
    ASSERT_EQ(ReplayLrcal(args, &out), 0) << out;
    EXPECT_THAT(out, ::testing::HasSubstr("identical to the stored record, bit for bit"));
    if (status != "ok") {
      EXPECT_THAT(out, ::testing::HasSubstr("the trial failed (" + status + "): "));
      EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("Validation errors")));
    }
  }
  EXPECT_EQ(statuses, (std::set<std::string>{"ok", "not_converged", "beam_missed"}));
}

// Issue 31: a configuration whose true beam misses its plane has no reading and is left out;
// the trial goes on with the others (recorded with the count), and fails as beam_missed only
// when fewer readings than parameters remain.
TEST(TrialReplayOfFailedTrials, AMissedBeamDropsItsConfigurationNotTheTrial) {
  const std::string dir = testing::TempDir("trial_replay_missed");
  ASSERT_NO_FATAL_FAILURE(
      RunPaperStudy(dir, "name: missed\nseed: 3\ntrials: 8\n",
                    "pool: {size: 60}\nselection: {count: 40}\nvalidation: {size: 5}\n"
                    "truth: {mode: random, length_sigma_mm: 60, angle_sigma_mrad: 60}\n"));
  const auto rows = StoreRows(dir,
                              "SELECT trial, status, missed_configurations FROM trials "
                              "ORDER BY missed_configurations DESC LIMIT 1");
  ASSERT_EQ(rows.size(), 1u);
  const std::string& trial = rows[0][0];
  const std::string& status = rows[0][1];
  const int missed = std::stoi(rows[0][2]);
  std::string out;
  EXPECT_EQ(status, "ok");
  ASSERT_GT(missed, 0) << "the study should make some true beams miss";
  const std::string args = "trial " + dir + "/run --cell base --trial " + trial;
  ASSERT_EQ(ReplayLrcal(args + " --format json", &out), 0) << out;
  const auto j = nlohmann::json::parse(out);
  EXPECT_TRUE(j["identical"].get<bool>()) << out;
  EXPECT_EQ(j["record"]["missed_configurations"], missed);
  EXPECT_EQ(j["configurations"].size() + static_cast<std::size_t>(missed), 40u);
  ASSERT_EQ(ReplayLrcal(args, &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr(std::to_string(missed) +
                                        " more of the design had no reading (the true beam "
                                        "missed its plane) and were left out"));
}

}  // namespace
}  // namespace lrcal
