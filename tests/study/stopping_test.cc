// Adaptive stopping (stop_when): the rule against a brute-force evaluation of every prefix, and
// whole runs that stop every cell with the precision stated, bit-identical whatever the threads,
// shards or restarts.
#include "lrcal/study/stopping.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "lrcal/core/error.h"
#include "lrcal/report/run_tables.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/trial_store.h"
#include "test_util.h"

namespace lrcal {
namespace {

namespace fs = std::filesystem;

// The two criteria at a prefix, computed from scratch with the tables' own statistics
// (Describe: two-pass std, order-statistic intervals).
StopPrecision BruteForce(const std::vector<TrialRecord>& records, long long n) {
  StopPrecision p;
  std::array<std::vector<double>, 12> values;
  for (long long t = 0; t < n; ++t)
    if (records[t].status == TrialStatus::kOk)
      for (int k = 0; k < 12; ++k) values[k].push_back(records[t].validation[k]);
  if (values[0].size() >= 2) {
    p.relative_se = 0;
    for (int k = 0; k < 12; ++k) {
      const Distribution d = Describe(values[k]);
      p.relative_se = std::max(p.relative_se, d.mean_se / std::fabs(d.mean));
    }
  }
  const Distribution d0 = Describe(values[0]);
  if (!std::isnan(d0.p95_ci.low) && !std::isnan(d0.p95_ci.high)) {
    p.p95_relative_halfwidth = 0;
    for (int k = 0; k < 12; ++k) {
      const Distribution d = Describe(values[k]);
      p.p95_relative_halfwidth =
          std::max(p.p95_relative_halfwidth, (d.p95_ci.high - d.p95_ci.low) / 2 / d.p95);
    }
  }
  return p;
}

// Skewed positive metrics (like pose errors) with a few failed trials.
std::vector<TrialRecord> SyntheticRecords(int n, unsigned seed) {
  std::mt19937_64 rng(seed);  // test data only
  std::lognormal_distribution<double> metric(-7, 0.6);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<TrialRecord> records(n);
  for (int t = 0; t < n; ++t) {
    records[t].trial = t;
    records[t].status = u(rng) < 0.03 ? TrialStatus::kNotConverged : TrialStatus::kOk;
    for (int k = 0; k < 12; ++k) records[t].validation[k] = metric(rng) * (1 + k);
  }
  return records;
}

TEST(StopWhen, DecisionAndPrecisionMatchABruteForceEvaluationOfEveryBoundary) {
  const std::vector<TrialRecord> records = SyntheticRecords(6000, 3);
  for (const StopWhen rule : {StopWhen{100, 0.02, 0}, StopWhen{250, 0, 0.08},
                              StopWhen{100, 0.025, 0.1}, StopWhen{1000, 0.001, 0}}) {
    CellStopping state(rule, 6000);
    long long expected_stop = 6000;
    bool expected_precise = false;
    for (long long b = rule.block; b <= 6000; b += rule.block) {
      const StopPrecision p = BruteForce(records, b);
      const bool se_ok = rule.relative_se == 0 || p.relative_se <= rule.relative_se;
      const bool p95_ok = rule.p95_relative_halfwidth == 0 ||
                          p.p95_relative_halfwidth <= rule.p95_relative_halfwidth;
      if (se_ok && p95_ok) {
        expected_stop = b;
        expected_precise = true;
        break;
      }
    }
    for (const TrialRecord& r : records) {
      state.Add(r);
      if (state.next() % rule.block == 0 || state.decided()) {
        const StopPrecision p = BruteForce(records, state.next());
        if (rule.relative_se > 0) {
          EXPECT_NEAR(state.precision().relative_se, p.relative_se, 1e-12 * p.relative_se);
        }
        if (rule.p95_relative_halfwidth > 0) {
          EXPECT_DOUBLE_EQ(state.precision().p95_relative_halfwidth, p.p95_relative_halfwidth);
        }
      }
      if (state.decided()) break;
    }
    ASSERT_TRUE(state.decided());
    EXPECT_EQ(state.trials_used(), expected_stop) << "block " << rule.block;
    EXPECT_EQ(state.precise(), expected_precise) << "block " << rule.block;
    EXPECT_EQ(state.trials_used() % rule.block, 0);
    EXPECT_EQ(expected_precise, rule.relative_se != 0.001) << "the cases should cover both ends";
  }
}

TEST(StopWhen, UndecidedUntilAFullBlockAndZeroMetricsAreExact) {
  CellStopping state(StopWhen{10, 0.5, 0}, 100);
  TrialRecord r;
  for (int t = 0; t < 9; ++t) {
    r.trial = t;
    state.Add(r);  // every metric exactly 0: known exactly, but only at a boundary
  }
  EXPECT_FALSE(state.decided());
  EXPECT_EQ(state.next_boundary(), 10);
  r.trial = 9;
  state.Add(r);
  EXPECT_TRUE(state.decided());
  EXPECT_TRUE(state.precise());
  EXPECT_EQ(state.trials_used(), 10);
  EXPECT_EQ(state.precision().relative_se, 0);
}

TEST(StopWhen, NoSuccessfulTrialNeverStopsEarly) {
  CellStopping state(StopWhen{5, 0.5, 0.5}, 20);
  TrialRecord r;
  r.status = TrialStatus::kRankDeficient;
  for (int t = 0; t < 20; ++t) {
    r.trial = t;
    state.Add(r);
  }
  EXPECT_TRUE(state.decided());
  EXPECT_FALSE(state.precise());
  EXPECT_EQ(state.trials_used(), 20);
  EXPECT_TRUE(std::isinf(state.precision().relative_se));
}

TEST(StopWhen, RulesAreCheckedWithTheFieldNamed) {
  EXPECT_THROW(StopWhen::FromJson({{"relative_se", 0.01}}, "s"), InputError);
  EXPECT_THROW(StopWhen::FromJson({{"block", 1}, {"relative_se", 0.01}}, "s"), InputError);
  EXPECT_THROW(StopWhen::FromJson({{"block", 100}}, "s"), InputError);
  EXPECT_THROW(StopWhen::FromJson({{"block", 100}, {"relative_se", -1}}, "s"), InputError);
  try {
    StopWhen::FromJson({{"block", 100}, {"p95_relative_halfwidth", "tight"}}, "s");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "s.p95_relative_halfwidth");
  }
  const StopWhen rule = StopWhen::FromJson({{"block", 100}, {"relative_se", 0.01}}, "s");
  EXPECT_EQ(rule.block, 100);
  EXPECT_EQ(StopWhen::FromJson(rule.ToJson(), "s").relative_se, 0.01);
  EXPECT_TRUE(StopWhen::FromJson(Json(), "s").block == 0);
}

// ---------------------------------------------------------------------------------------------
// Whole runs.

std::string AdaptiveStudy(const std::string& dir, const std::string& rule, int trials = 2000) {
  const std::string path = dir + "/adaptive.yaml";
  std::ofstream(path) << "name: adaptive\nseed: 5\ntrials: " << trials << "\nstop_when: " << rule
                      << "\nrobot: " << testing::SourcePath("studies/robots/paper.yaml")
                      << "\npool: {size: 60}\nvalidation: {size: 10}\n"
                         "sweep:\n  axes:\n"
                         "    - key: selection.count\n      values: [30, 59]\n"
                         "    - key: noise.sigma_mm\n      values: [0.1, 0.3]\n";
  return path;
}

RunResult RunAdaptive(const std::string& study, const std::string& out, int threads,
                      int shard_index = 0, int shard_count = 1, long long max_new = 0) {
  return testing::RunStudyFile(study, out, threads, shard_index, shard_count, max_new, 13);
}

std::map<std::string, std::string> StoppingTables(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(fs::path(dir) / "tables"))
    out[e.path().filename().string()] = testing::ReadFile(e.path().string());
  return out;
}

TEST(StopWhen, StopsEveryCellWithThePrecisionStatedBitIdenticalAcrossThreadsShardsAndRestarts) {
  const std::string dir = testing::TempDir("stop_when_runs");
  const double relative_se = 0.05, halfwidth = 0.3;
  const std::string study =
      AdaptiveStudy(dir, "{block: 50, relative_se: 0.05, p95_relative_halfwidth: 0.3}", 1000);
  const RunResult one = RunAdaptive(study, dir + "/t1", 1);
  ASSERT_TRUE(one.complete);
  ASSERT_TRUE(one.tables_written);
  EXPECT_LT(one.computed, 4 * 1000) << "no cell stopped early";
  EXPECT_EQ(one.computed, one.total);
  RunAdaptive(study, dir + "/t2", 2);
  for (int i = 0; i < 2; ++i) RunAdaptive(study, dir + "/shard" + std::to_string(i), 2, i, 2);
  ASSERT_TRUE(MergeRuns({dir + "/shard0", dir + "/shard1"}, dir + "/merged"));
  // Restarts: slices of 330 new trials (not a multiple of the block) until complete.
  RunResult slice;
  int slices = 0;
  do {
    slice = RunAdaptive(study, dir + "/sliced", 2, 0, 1, 330);
    ASSERT_LT(++slices, 100);
  } while (!slice.complete);
  EXPECT_GT(slices, 2);

  const auto reference = StoppingTables(dir + "/t1");
  EXPECT_EQ(reference, StoppingTables(dir + "/t2"));
  EXPECT_EQ(reference, StoppingTables(dir + "/merged"));
  EXPECT_EQ(reference, StoppingTables(dir + "/sliced"));

  // Every cell stopped early with the precision stated, checked on the tables' own numbers, and
  // not one block later than needed.
  const Json summary = Json::parse(reference.at("summary.json"));
  TrialStore store(dir + "/t1/trials.sqlite");
  ASSERT_EQ(summary["cells"].size(), 4u);
  for (const auto& c : summary["cells"]) {
    SCOPED_TRACE(c["label"].get<std::string>());
    const Json& stop = c["stop"];
    EXPECT_EQ(stop["reason"], "precision");
    const long long used = stop["trials_used"];
    EXPECT_EQ(c["trials"].get<long long>(), used);
    EXPECT_EQ(used % 50, 0);
    EXPECT_LT(used, 1000);
    EXPECT_LE(stop["relative_se"].get<double>(), relative_se);
    EXPECT_LE(stop["p95_relative_halfwidth"].get<double>(), halfwidth);
    for (const auto& [metric, d] : c["validation"].items()) {
      EXPECT_LE(d["mean_se"].get<double>() / d["mean"].get<double>(), relative_se * (1 + 1e-9))
          << metric;
      const double half = (d["p95_ci"][1].get<double>() - d["p95_ci"][0].get<double>()) / 2;
      EXPECT_LE(half / d["p95"].get<double>(), halfwidth) << metric;
    }
    // One block earlier the rule did not hold.
    StoredCell cell;
    for (const auto& s : store.Cells())
      if (s.id == c["id"]) cell = s;
    const CellSummary before = SummarizeCell(store, cell, used - 50);
    bool failed = false;
    for (const auto& d : before.validation)
      failed |= d.mean_se / d.mean > relative_se ||
                (d.p95_ci.high - d.p95_ci.low) / 2 / d.p95 > halfwidth || std::isnan(d.p95_ci.high);
    EXPECT_TRUE(failed) << "the rule held at " << used - 50;
  }

  std::string out;
  ASSERT_EQ(testing::RunCommand(testing::LrcalBinary() + " status " + dir + "/sliced", &out), 0);
  EXPECT_THAT(out, ::testing::HasSubstr("stopped early, precision reached")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("complete (stop_when: 4 cells stopped early)")) << out;
}

TEST(StopWhen, ACellThatNeverGetsPreciseRunsToTheMaximum) {
  const std::string dir = testing::TempDir("stop_when_max");
  const std::string study = AdaptiveStudy(dir, "{block: 50, relative_se: 0.0001}", 150);
  const RunResult r = RunAdaptive(study, dir + "/run", 2);
  EXPECT_TRUE(r.complete);
  EXPECT_EQ(r.computed, 4 * 150);
  const Json summary = Json::parse(StoppingTables(dir + "/run").at("summary.json"));
  for (const auto& c : summary["cells"]) {
    EXPECT_EQ(c["stop"]["reason"], "maximum");
    EXPECT_EQ(c["stop"]["trials_used"], 150);
    EXPECT_GT(c["stop"]["relative_se"].get<double>(), 0.0001);
  }
  EXPECT_THAT(StoppingTables(dir + "/run").at("summary.md"),
              ::testing::HasSubstr("maximum 150 (precision not reached)"));
}

TEST(StopWhen, AnInterruptedAdaptiveRunIsNotComplete) {
  const std::string dir = testing::TempDir("stop_when_partial");
  const std::string study = AdaptiveStudy(dir, "{block: 100, relative_se: 0.03}");
  const RunResult r = RunAdaptive(study, dir + "/run", 2, 0, 1, 250);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(r.reached_max_trials);
  EXPECT_FALSE(r.tables_written);
  EXPECT_EQ(r.computed, 250);
  std::string out;
  testing::RunCommand(testing::LrcalBinary() + " status " + dir + "/run", &out);
  EXPECT_THAT(out, ::testing::HasSubstr("the next decision at")) << out;
}

}  // namespace
}  // namespace lrcal
