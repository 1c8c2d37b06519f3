// What lrcal run, merge and plan tell the user about a run: slices by --max-trials are not
// interruptions, a finished run says there is nothing to do, a partial merge writes no tables,
// and redrawn designs show their σ_min over the trials.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "test_util.h"

namespace lrcal {
namespace {

using testing::LrcalBinary;
using testing::RunCommand;
namespace fs = std::filesystem;

int Lrcal(const std::string& args, std::string* out) {
  return RunCommand(LrcalBinary() + " " + args, out);
}

std::string LastSessionEnd(const std::string& run_dir) {
  const auto manifest = nlohmann::json::parse(testing::ReadFile(run_dir + "/manifest.json"));
  return manifest["sessions"].back()["ended"].get<std::string>();
}

TEST(RunBookkeeping, MaxTrialsIsASliceNotAnInterruption) {
  const std::string dir = testing::TempDir("max_trials_slice");
  std::string out;
  ASSERT_EQ(Lrcal("run quick --out " + dir + "/run --quiet --max-trials 50", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr(
                       "stopped after 50 new trials (--max-trials): 50/200 trials recorded"))
      << out;
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("interrupted"))) << out;
  EXPECT_EQ(LastSessionEnd(dir + "/run"), "max_trials");
  // Status, as JSON: progress, the last session's rate, and the commands that go on from here.
  ASSERT_EQ(Lrcal("status " + dir + "/run --format json", &out), 0) << out;
  const auto status = nlohmann::json::parse(out);
  EXPECT_EQ(status["done"], 50);
  EXPECT_EQ(status["total"], 200);
  EXPECT_FALSE(status["complete"].get<bool>());
  EXPECT_EQ(status["cells"].size(), 2u);
  EXPECT_EQ(status["last_session"]["state"], "max_trials");
  EXPECT_EQ(status["last_session"]["trials_computed"], 50);
  EXPECT_GE(status["last_session"]["seconds"].get<double>(), 0.0);
  EXPECT_THAT(status["to_finish"].get<std::string>(), ::testing::HasSubstr("lrcal run "));
  EXPECT_EQ(status["report"], "lrcal report " + dir + "/run");
  ASSERT_EQ(Lrcal("status " + dir + "/run", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("→ max_trials: 50 trials in ")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("report: lrcal report " + dir + "/run")) << out;
  ASSERT_EQ(Lrcal("run quick --out " + dir + "/run --quiet", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("150 trials computed")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("50 were already recorded")) << out;
  EXPECT_EQ(LastSessionEnd(dir + "/run"), "completed");
  // run.log: the run's history in words, one line per session start and end.
  const std::string log = testing::ReadFile(dir + "/run/run.log");
  EXPECT_THAT(log, ::testing::HasSubstr("session 1 started: study 'quick', 2 cells x 100 trials"));
  EXPECT_THAT(log, ::testing::HasSubstr("session 1 ended (max_trials): 50 trials computed"));
  EXPECT_THAT(log, ::testing::HasSubstr("session 2 ended (completed): 150 trials computed, 50 "
                                        "recorded before, of 200"));
  // Once more: nothing to do, said so (not "0 trials computed"), and no cell is prepared for it
  // (issue 32: a finished study's rerun spent minutes preparing cells it would not use).
  ASSERT_EQ(RunCommand("LRCAL_PROGRESS_SECONDS=0 " + LrcalBinary() + " run quick --out " + dir +
                           "/run 2>&1 | cat",
                       &out),
            0)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr(
                       "nothing to compute: all 200 trials of this run were already recorded"))
      << out;
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("preparing cells"))) << out;
  EXPECT_EQ(LastSessionEnd(dir + "/run"), "completed");
  // A short run does not print a meaningless overhead percentage.
  ASSERT_EQ(Lrcal("run quick --out " + dir + "/small --quiet --threads 2", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("too short to measure the runner's overhead")) << out;
}

// A rerun of a finished run leaves its tables as they are when they were written from these very
// records by this lrcal (the manifest's "tables" stamp), so it takes a fraction of a second; a
// table removed since, or `lrcal aggregate`, writes them again.
TEST(RunBookkeeping, ARerunKeepsCurrentTablesAndRewritesIncompleteOnes) {
  const std::string dir = testing::TempDir("current_tables");
  const std::string run = dir + "/run";
  std::string out;
  ASSERT_EQ(Lrcal("run quick --out " + run + " --quiet", &out), 0) << out;
  const auto manifest = nlohmann::json::parse(testing::ReadFile(run + "/manifest.json"));
  ASSERT_TRUE(manifest.contains("tables"));
  EXPECT_EQ(manifest["tables"]["trials"], 200);
  EXPECT_EQ(manifest["tables"]["lrcal"], manifest["lrcal"]);
  EXPECT_THAT(manifest["tables"]["files"], ::testing::Contains(nlohmann::json("summary.md")));
  const std::string summary = run + "/tables/summary.md";
  const auto written = fs::last_write_time(summary);
  fs::last_write_time(summary, written - std::chrono::hours(1));  // marks the file
  ASSERT_EQ(Lrcal("run quick --out " + run, &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("its tables are current")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("tables: " + summary)) << out;
  EXPECT_EQ(fs::last_write_time(summary), written - std::chrono::hours(1));
  // A table removed: written again.
  fs::remove(run + "/tables/validation.csv");
  ASSERT_EQ(Lrcal("run quick --out " + run, &out), 0) << out;
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("its tables are current"))) << out;
  EXPECT_TRUE(fs::exists(run + "/tables/validation.csv"));
  EXPECT_NE(fs::last_write_time(summary), written - std::chrono::hours(1));
  // A stamp that does not match the records (another lrcal, other trials): written again.
  auto stamped = nlohmann::json::parse(testing::ReadFile(run + "/manifest.json"));
  stamped["tables"]["trials"] = 199;
  std::ofstream(run + "/manifest.json") << stamped.dump(1);
  fs::last_write_time(summary, written - std::chrono::hours(1));
  ASSERT_EQ(Lrcal("run quick --out " + run, &out), 0) << out;
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("its tables are current"))) << out;
  EXPECT_NE(fs::last_write_time(summary), written - std::chrono::hours(1));
  EXPECT_EQ(nlohmann::json::parse(testing::ReadFile(run + "/manifest.json"))["tables"]["trials"],
            200);
}

// More trials later: every trial is a pure function of its index, so raising `trials` extends a
// run (the tables equal a fresh run's with the new count, byte for byte); fewer is refused.
// Issue 31: a progress line while the cells are prepared, and the trials' rate and ETA after
// them (on a log: lines every LRCAL_PROGRESS_SECONDS).
TEST(RunBookkeeping, ProgressLinesDuringPreparationAndTrials) {
  const std::string dir = testing::TempDir("progress_lines");
  std::string out;
  ASSERT_EQ(RunCommand("LRCAL_PROGRESS_SECONDS=0 " + LrcalBinary() + " run quick --out " + dir +
                           "/run --threads 1 2>&1 | cat",
                       &out),
            0)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("lrcal run: preparing cells: 1/2 done, ")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("lrcal run: preparing cells: 2/2 done, ")) << out;
  EXPECT_THAT(out, ::testing::ContainsRegex("lrcal run: 200/200 trials, [0-9]+/s, ETA 0:00"))
      << out;
}

TEST(RunBookkeeping, RaisingTrialsExtendsARunToTheTablesOfAFreshOne) {
  const std::string dir = testing::TempDir("extend_trials");
  std::string quick = testing::ReadFile(testing::SourcePath("studies/quick.yaml"));
  const auto with_trials = [&](const std::string& name, int trials) {
    std::string text = quick;
    text.replace(text.find("trials: 100"), 11, "trials: " + std::to_string(trials));
    std::ofstream(dir + "/" + name) << text;
    return dir + "/" + name;
  };
  const std::string s100 = with_trials("quick.yaml", 100);
  std::string out;
  ASSERT_EQ(Lrcal("run " + s100 + " --out " + dir + "/run --quiet", &out), 0) << out;
  const std::string s150 = with_trials("quick.yaml", 150);
  ASSERT_EQ(Lrcal("status " + dir + "/run", &out), 0) << out;
  ASSERT_EQ(Lrcal("run " + s150 + " --out " + dir + "/run --quiet --max-trials 20", &out), 0)
      << out;
  ASSERT_EQ(Lrcal("status " + dir + "/run", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("total: 220/300")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("written before the run was extended")) << out;
  ASSERT_EQ(Lrcal("run " + s150 + " --out " + dir + "/run --quiet", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("80 trials computed")) << out;
  ASSERT_EQ(Lrcal("run " + s150 + " --out " + dir + "/fresh --quiet", &out), 0) << out;
  for (const char* table : {"summary.md", "validation.csv", "parameters.csv", "cells.csv"})
    EXPECT_EQ(testing::ReadFile(dir + "/run/tables/" + table),
              testing::ReadFile(dir + "/fresh/tables/" + table))
        << table;
  const std::string s50 = with_trials("quick.yaml", 50);
  EXPECT_EQ(Lrcal("run " + s50 + " --out " + dir + "/run --quiet", &out), 2) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("key 'trials': 50 trials per cell, but this run "
                                        "directory holds up to 150"))
      << out;
}

TEST(RunBookkeeping, MergingIncompleteShardsWritesNoTablesAndSaysWhatToFinish) {
  const std::string dir = testing::TempDir("merge_incomplete");
  std::string out;
  ASSERT_EQ(Lrcal("run quick --shard 1/2 --out " + dir + "/s1 --quiet", &out), 0) << out;
  // A finished shard has no tables of its own: status points to merge, not to aggregate.
  ASSERT_EQ(Lrcal("status " + dir + "/s1", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("tables: none for a shard; when every shard is done, "
                                        "combine them with: lrcal merge"))
      << out;
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("aggregate"))) << out;
  ASSERT_EQ(Lrcal("run quick --shard 2/2 --out " + dir + "/s2 --quiet --max-trials 30", &out), 0)
      << out;
  ASSERT_EQ(Lrcal("merge " + dir + "/s1 " + dir + "/s2 --out " + dir + "/m", &out), 1) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("tables not written")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("unfinished or missing shards: 2")) << out;
  EXPECT_FALSE(fs::exists(dir + "/m/tables"));
  ASSERT_EQ(Lrcal("run quick --shard 2/2 --out " + dir + "/s2 --quiet", &out), 0) << out;
  ASSERT_EQ(Lrcal("merge " + dir + "/s1 " + dir + "/s2 --out " + dir + "/m", &out), 0) << out;
  EXPECT_EQ(testing::ReadFile(dir + "/m/tables/summary.md"),
            testing::ReadFile(testing::SourcePath("tests/golden/quick/summary.md")));
}

TEST(RunBookkeeping, PlanOfAShortStudySaysItsSecondsWithADecimal) {
  std::string out;
  ASSERT_EQ(Lrcal("plan quick", &out), 0) << out;
  // Tenths under 10 s, whatever this machine's speed (a sanitizer build takes ~1 s here, a
  // release build ~0.2 s): "about 0.2 s" or "about 1.2 s", never "about 0 s".
  EXPECT_TRUE(std::regex_search(out, std::regex("trials, about [0-9]\\.[0-9] s"))) << out;
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("about 0 s"))) << out;
}

TEST(RunBookkeeping, RedrawnDesignsShowSigmaMinOverTheTrials) {
  const std::string dir = testing::TempDir("redraw_sigma_min");
  std::ofstream(dir + "/s.yaml") << "name: redraw\nseed: 4\ntrials: 20\nrobot: "
                                 << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\npool: {size: 40, redraw: true}\nselection: {count: 30}\n"
                                    "validation: {size: 5}\n";
  std::string out;
  ASSERT_EQ(Lrcal("run " + dir + "/s.yaml --out " + dir + "/run --quiet", &out), 0) << out;
  EXPECT_THAT(testing::ReadFile(dir + "/run/tables/summary.md"),
              ::testing::HasSubstr("(redrawn per trial)"));
  // cells.csv: numbers as numbers, the spread in columns of its own.
  std::istringstream csv(testing::ReadFile(dir + "/run/tables/cells.csv"));
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  const auto split = [](const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream in(line);
    for (std::string c; std::getline(in, c, ',');) cells.push_back(c);
    return cells;
  };
  const std::vector<std::string> names = split(header), values = split(row);
  ASSERT_EQ(names.size(), values.size()) << header << "\n" << row;
  std::map<std::string, std::string> cell;
  for (std::size_t i = 0; i < names.size(); ++i) cell[names[i]] = values[i];
  EXPECT_EQ(cell["design_redrawn"], "1");
  EXPECT_EQ(cell["design_efficiency"], "");  // no certificate for a design redrawn per trial
  const double p5 = std::stod(cell["design_sigma_min_p5"]),
               mean = std::stod(cell["design_sigma_min"]),
               p95 = std::stod(cell["design_sigma_min_p95"]);
  EXPECT_LT(p5, mean);
  EXPECT_LT(mean, p95);
}

TEST(RunBookkeeping, CellsCsvHasOneNumericColumnPerVariedSetting) {
  const std::string dir = testing::TempDir("cells_csv_columns");
  std::ofstream(dir + "/s.yaml") << "name: sweep\nseed: 4\ntrials: 2\nrobot: "
                                 << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\npool: {size: 60}\nvalidation: {size: 5}\n"
                                    "sweep:\n  axes:\n    - key: selection.count\n"
                                    "      values: [30, 40]\n    - key: noise.sigma_mm\n"
                                    "      values: [0.1]\n";
  std::string out;
  ASSERT_EQ(Lrcal("run " + dir + "/s.yaml --out " + dir + "/run --quiet", &out), 0) << out;
  const std::string cells = testing::ReadFile(dir + "/run/tables/cells.csv");
  EXPECT_THAT(cells, ::testing::StartsWith(
                         "cell_id,cell_label,trials,ok,failed,failed_reasons,design_sigma_min,"
                         "design_sigma_min_p5,design_sigma_min_p95,design_redrawn,"
                         "design_efficiency,design_criterion,selection.count,noise.sigma_mm\n"));
  EXPECT_THAT(cells,
              ::testing::ContainsRegex(",2,2,0,,0\\.[0-9]{6},,,0,0\\.[0-9]{6},E,30,0\\.1\n"));
  EXPECT_THAT(cells, ::testing::ContainsRegex(",E,40,0\\.1\n"));
}

}  // namespace
}  // namespace lrcal
