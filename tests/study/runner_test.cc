// The Monte-Carlo engine: bit-identical tables whatever the threads, shards, interruptions and
// restarts; resume and refusal rules; bad study files; and statistics that match the
// linear-Gaussian theory.
#include "lrcal/study/runner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "core/cpu_dispatch.h"
#include "lrcal/core/error.h"
#include "lrcal/core/json.h"
#include "lrcal/core/random.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/report/run_tables.h"
#include "lrcal/study/run_directory.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/trial_store.h"
#include "test_util.h"

namespace lrcal {
namespace {

namespace fs = std::filesystem;

// Every table file of a run directory, by name.
std::map<std::string, std::string> Tables(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(fs::path(dir) / "tables"))
    out[e.path().filename().string()] = testing::ReadFile(e.path().string());
  return out;
}

// A small study: the paper's arm, two designs and two noise levels, few trials.
std::string SmallStudy(const std::string& dir, int trials, const std::string& extra = "",
                       const std::string& sigmas = "[0.1, 0.2]", std::uint64_t seed = 11) {
  const std::string path = dir + "/small.yaml";
  std::ofstream(path) << "name: small\nseed: " << seed << "\ntrials: " << trials
                      << "\nrobot: " << testing::SourcePath("studies/robots/paper.yaml")
                      << "\npool: {size: 60}\nvalidation: {size: 10}\n"
                      << extra
                      << "sweep:\n  axes:\n"
                         "    - key: selection.count\n      values: [30, 59]\n"
                         "    - key: noise.sigma_mm\n      values: "
                      << sigmas << "\n";
  return path;
}

RunResult RunSmall(const std::string& study_path, const std::string& out, int threads,
                   int shard_index = 0, int shard_count = 1, long long max_new = 0) {
  return testing::RunStudyFile(study_path, out, threads, shard_index, shard_count, max_new);
}

TEST(MonteCarlo, TablesAreBitIdenticalForOneTwoAndFourThreads) {
  const std::string dir = testing::TempDir("mc_threads");
  const std::string study = SmallStudy(dir, 40);
  RunSmall(study, dir + "/t1", 1);
  RunSmall(study, dir + "/t2", 2);
  RunSmall(study, dir + "/t4", 4);
  const auto t1 = Tables(dir + "/t1");
  EXPECT_GE(t1.size(), 6u);
  EXPECT_EQ(t1, Tables(dir + "/t2"));
  EXPECT_EQ(t1, Tables(dir + "/t4"));
}

TEST(MonteCarlo, ProgressCallbackSeesTheRunAndCanStopIt) {
  // The stop is asked from the writer thread at the first committed records; the workers see it
  // at their next claim. On a loaded machine the writer can be descheduled while the workers
  // finish every trial, so a run that ended complete is tried again (fresh directory): a stop
  // that never works fails every attempt.
  const std::string dir = testing::TempDir("mc_progress");
  const std::string study = SmallStudy(dir, 500);
  constexpr long long kTotal = 2000;
  constexpr int kAttempts = 4;
  RunOptions o;
  o.threads = 2;
  o.progress = false;
  o.batch_size = 5;
  RunResult r;
  std::vector<RunProgress> seen;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    o.out_dir = dir + "/run" + std::to_string(attempt);
    StopToken stop;
    seen.clear();
    o.on_progress = [&](const RunProgress& p) {
      seen.push_back(p);
      if (p.done > 0) stop.RequestStop();  // the first records: stop, as Ctrl-C from Python does
    };
    r = RunStudyAndWriteTables(LoadStudy(study), o, nullptr, &stop);
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(r.interrupted);
    EXPECT_EQ(seen.back().total, kTotal);
    EXPECT_EQ(seen.back().done, r.computed);  // the last call reports the final count
    for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i].done, seen[i - 1].done);
    if (r.computed < kTotal) break;
  }
  EXPECT_FALSE(r.tables_written);
  ASSERT_LT(r.computed, kTotal) << "no attempt of " << kAttempts << " stopped early";
  // The rest of the run, without a callback, gives the uninterrupted tables.
  o.on_progress = nullptr;
  StopToken fresh;
  EXPECT_TRUE(RunStudyAndWriteTables(LoadStudy(study), o, nullptr, &fresh).tables_written);
  RunSmall(study, dir + "/whole", 2);
  EXPECT_EQ(Tables(o.out_dir), Tables(dir + "/whole"));
}

TEST(MonteCarlo, TablesAreBitIdenticalWhicheverInstructionSetRuns) {
  // A machine without AVX-512 (or a shard on another node) runs another variant of the hot
  // kernels: the tables must not change. Each variant this CPU has is forced, the AVX-512
  // variant's code compiled for AVX2 among them where AVX-512 itself is missing; the manifest
  // says which variant ran.
  const std::string dir = testing::TempDir("mc_isa");
  const std::string study = SmallStudy(dir, 30);
  std::string out;
  for (Isa isa : SupportedIsas()) {
    const std::string name = IsaName(isa);
    ASSERT_EQ(testing::RunCommand("LRCAL_ISA=" + name + " " + testing::LrcalBinary() + " run " +
                                      study + " --out " + dir + "/" + name + " --quiet",
                                  &out),
              0)
        << out;
    const Json session = ReadJsonFile(dir + "/" + name + "/manifest.json").at("sessions").at(0);
    EXPECT_EQ(session.at("kernels").get<std::string>(), name);
    EXPECT_FALSE(session.at("cpu").get<std::string>().empty());
    EXPECT_EQ(Tables(dir + "/" + name), Tables(dir + "/default")) << name;
  }
}

TEST(MonteCarlo, ShardsMergedEqualOneRun) {
  const std::string dir = testing::TempDir("mc_shards");
  const std::string study = SmallStudy(dir, 30);
  RunSmall(study, dir + "/single", 2);
  std::vector<std::string> shards;
  for (int i = 0; i < 3; ++i) {
    shards.push_back(dir + "/shard" + std::to_string(i));
    RunResult r = RunSmall(study, shards.back(), 1, i, 3);
    EXPECT_FALSE(r.tables_written);  // a shard alone writes no tables
    EXPECT_EQ(r.total, 4 * 10);
  }
  MergeRuns(shards, dir + "/merged");
  EXPECT_EQ(Tables(dir + "/single"), Tables(dir + "/merged"));
}

TEST(MonteCarlo, StatusOfShardsNamesTheTasksToResubmit) {
  const std::string dir = testing::TempDir("mc_status");
  const std::string study = SmallStudy(dir, 20);
  RunSmall(study, dir + "/s1", 1, 0, 4);
  RunSmall(study, dir + "/s2", 1, 1, 4, 7);  // interrupted
  RunSmall(study, dir + "/s3", 1, 2, 4);     // shard 4 never ran
  std::string out;
  ASSERT_EQ(
      testing::RunCommand(
          testing::LrcalBinary() + " status " + dir + "/s1 " + dir + "/s2 " + dir + "/s3", &out),
      0)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("unfinished or missing shards: 2,4")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("sbatch --array=2,4")) << out;
}

TEST(MonteCarlo, ResumedInSlicesEqualsUninterrupted) {
  const std::string dir = testing::TempDir("mc_slices");
  const std::string study = SmallStudy(dir, 30);
  RunSmall(study, dir + "/whole", 2);
  RunResult a = RunSmall(study, dir + "/sliced", 2, 0, 1, 37);
  EXPECT_TRUE(a.interrupted);
  EXPECT_EQ(a.computed, 37);
  RunResult b = RunSmall(study, dir + "/sliced", 1, 0, 1, 50);
  EXPECT_EQ(b.done_before, 37);
  EXPECT_EQ(b.computed, 50);
  RunResult c = RunSmall(study, dir + "/sliced", 2);
  EXPECT_EQ(c.done_before, 87);
  EXPECT_EQ(c.computed, 120 - 87);
  EXPECT_TRUE(c.tables_written);
  EXPECT_EQ(Tables(dir + "/whole"), Tables(dir + "/sliced"));
  // A finished run recomputes nothing.
  RunResult d = RunSmall(study, dir + "/sliced", 2);
  EXPECT_EQ(d.computed, 0);
  EXPECT_EQ(Tables(dir + "/whole"), Tables(dir + "/sliced"));
}

// How many of the run's cells hold all `trials` trials in its main store.
int CompleteCells(const std::string& run_dir, long long trials) {
  TrialStore store((fs::path(run_dir) / "trials.sqlite").string());
  int complete = 0;
  for (const auto& c : store.Cells()) complete += store.CountTrials(c.id) == trials;
  return complete;
}

// A resume prepares only the cells with trials left to compute (cells are prepared one by one in
// a new run, so a fresh run of four cells prepares four), a rerun of a finished run none, and
// the tables are those of an uninterrupted run.
TEST(MonteCarlo, AResumePreparesOnlyTheCellsWithTrialsToCompute) {
  const std::string dir = testing::TempDir("mc_lazy");
  const std::string study = SmallStudy(dir, 30);  // four cells of 30 trials, run cell by cell
  EXPECT_EQ(RunSmall(study, dir + "/whole", 2).cells_prepared, 4);
  RunResult a = RunSmall(study, dir + "/sliced", 2, 0, 1, 75);
  EXPECT_EQ(a.cells_prepared, 4);
  const int complete = CompleteCells(dir + "/sliced", 30);
  EXPECT_EQ(complete, 2);  // 75 trials: two whole cells and half of the third
  RunResult b = RunSmall(study, dir + "/sliced", 1);
  EXPECT_EQ(b.done_before, 75);
  EXPECT_EQ(b.computed, 45);
  EXPECT_EQ(b.cells_prepared, 4 - complete);
  EXPECT_EQ(Tables(dir + "/whole"), Tables(dir + "/sliced"));
  // The resumed cells were prepared for their trials alone: their rows stay as the first session
  // wrote them, the certificate and the first-order prediction included.
  const std::vector<StoredCell> whole_rows = TrialStore(dir + "/whole/trials.sqlite").Cells();
  const std::vector<StoredCell> sliced_rows = TrialStore(dir + "/sliced/trials.sqlite").Cells();
  ASSERT_EQ(whole_rows.size(), sliced_rows.size());
  for (std::size_t i = 0; i < whole_rows.size(); ++i) {
    EXPECT_EQ(sliced_rows[i].id, whole_rows[i].id);
    EXPECT_EQ(sliced_rows[i].predicted_validation.size(), 12u);
    EXPECT_EQ(sliced_rows[i].predicted_validation, whole_rows[i].predicted_validation);
    EXPECT_FALSE(std::isnan(sliced_rows[i].design_efficiency));
    EXPECT_EQ(sliced_rows[i].design_efficiency, whole_rows[i].design_efficiency);
  }
  EXPECT_EQ(RunSmall(study, dir + "/sliced", 2).cells_prepared, 0);
  EXPECT_EQ(Tables(dir + "/whole"), Tables(dir + "/sliced"));

  // A finished cell whose row the store lacks is prepared again and its row written back.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir + "/sliced/trials.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "DELETE FROM cells WHERE ord = 0", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  RunResult c = RunSmall(study, dir + "/sliced", 2);
  EXPECT_EQ(c.cells_prepared, 1);
  EXPECT_EQ(c.computed, 0);
  EXPECT_EQ(CompleteCells(dir + "/sliced", 30), 4);

  // An unfinished cell whose row the store lacks is prepared in full, and its row written back
  // as the first session wrote it.
  RunSmall(study, dir + "/sliced2", 2, 0, 1, 75);
  ASSERT_EQ(sqlite3_open((dir + "/sliced2/trials.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "DELETE FROM cells WHERE ord = 2", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  EXPECT_EQ(RunSmall(study, dir + "/sliced2", 2).cells_prepared, 2);
  const std::vector<StoredCell> rows2 = TrialStore(dir + "/sliced2/trials.sqlite").Cells();
  ASSERT_EQ(rows2.size(), whole_rows.size());
  for (std::size_t i = 0; i < rows2.size(); ++i) {
    EXPECT_EQ(rows2[i].predicted_validation, whole_rows[i].predicted_validation);
    EXPECT_EQ(rows2[i].design_efficiency, whole_rows[i].design_efficiency);
  }
  EXPECT_EQ(Tables(dir + "/whole"), Tables(dir + "/sliced2"));

  // A shard's rerun prepares nothing either: its share of every cell is recorded.
  RunSmall(study, dir + "/shard", 2, 1, 2);
  EXPECT_EQ(RunSmall(study, dir + "/shard", 2, 1, 2).cells_prepared, 0);
}

// Starts `lrcal run` in the background; returns its pid.
pid_t Spawn(const std::vector<std::string>& args) {
  pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    std::string bin = testing::LrcalBinary();
    argv.push_back(bin.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    freopen("/dev/null", "w", stderr);
    freopen("/dev/null", "w", stdout);
    execv(bin.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

long long StoredTrials(const std::string& run_dir) {
  if (!fs::exists(fs::path(run_dir) / "trials.sqlite")) return 0;
  try {
    TrialStore store((fs::path(run_dir) / "trials.sqlite").string());
    long long n = 0;
    for (const auto& c : store.Cells()) n += store.CountTrials(c.id);
    return n;
  } catch (const std::exception&) {
    return 0;
  }
}

// Waits until the run has stored some trials (or exited); returns the count seen.
long long WaitForProgress(pid_t pid, const std::string& run_dir, long long at_least) {
  for (int i = 0; i < 3000; ++i) {
    const long long n = StoredTrials(run_dir);
    if (n >= at_least) return n;
    int status;
    if (waitpid(pid, &status, WNOHANG) == pid) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return StoredTrials(run_dir);
}

TEST(MonteCarlo, KilledProcessResumesToTheSameTables) {
  const std::string dir = testing::TempDir("mc_kill");
  const std::string study = SmallStudy(dir, 4000);  // 16,000 trials: about a second on one thread
  const std::string killed = dir + "/killed";
  pid_t pid = Spawn({"run", study, "--out", killed, "--threads", "1"});
  const long long seen = WaitForProgress(pid, killed, 100);
  ASSERT_GT(seen, 0) << "the run ended before it could be killed";
  kill(pid, SIGKILL);
  int status;
  waitpid(pid, &status, 0);
  const long long stored = StoredTrials(killed);
  EXPECT_LT(stored, 16000) << "the run finished before the kill: the test proved nothing";
  // The morning after: the session still says "running" in the manifest, but status sees that
  // no process holds the run's lock and says the run stopped; while a process holds it (here
  // this one), status says it is running.
  std::string out;
  ASSERT_EQ(testing::RunCommand(testing::LrcalBinary() + " status " + killed, &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("stopped without closing (its process is gone")) << out;
  ASSERT_EQ(
      testing::RunCommand(testing::LrcalBinary() + " status " + killed + " --format json", &out), 0)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("\"state\": \"stopped\"")) << out;
  {
    const DirectoryLock held(killed);
    EXPECT_TRUE(DirectoryLock::IsHeld(killed));
    ASSERT_EQ(testing::RunCommand(testing::LrcalBinary() + " status " + killed, &out), 0) << out;
    EXPECT_THAT(out, ::testing::HasSubstr(" → running (for ")) << out;
  }
  EXPECT_FALSE(DirectoryLock::IsHeld(killed));
  // Resume, then compare with an uninterrupted run.
  ASSERT_EQ(testing::RunCommand(testing::LrcalBinary() + " run " + study + " --out " + killed +
                                    " --threads 2 --quiet",
                                &out),
            0)
      << out;
  RunSmall(study, dir + "/whole", 2);
  EXPECT_EQ(Tables(dir + "/whole"), Tables(killed));
  const std::string manifest = testing::ReadFile((fs::path(killed) / "manifest.json").string());
  EXPECT_THAT(manifest, ::testing::HasSubstr("\"running\""));  // the killed session's entry
  EXPECT_THAT(manifest, ::testing::HasSubstr("\"completed\""));
}

TEST(MonteCarlo, SigintStopsCleanlyAndResumes) {
  const std::string dir = testing::TempDir("mc_sigint");
  const std::string study = SmallStudy(dir, 4000);
  const std::string run = dir + "/run";
  pid_t pid = Spawn({"run", study, "--out", run, "--threads", "1"});
  ASSERT_GT(WaitForProgress(pid, run, 50), 0);
  kill(pid, SIGINT);
  int status;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);  // interrupted, everything in flight flushed
  const std::string manifest = testing::ReadFile((fs::path(run) / "manifest.json").string());
  EXPECT_THAT(manifest, ::testing::HasSubstr("\"interrupted\""));
  std::string out;
  ASSERT_EQ(testing::RunCommand(testing::LrcalBinary() + " status " + run, &out), 0);
  EXPECT_THAT(out, ::testing::HasSubstr("remaining")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("to finish: lrcal run")) << out;
}

TEST(MonteCarlo, SecondProcessOnTheSameDirectoryIsRefused) {
  const std::string dir = testing::TempDir("mc_lock");
  const std::string study = SmallStudy(dir, 4000);
  const std::string run = dir + "/run";
  pid_t pid = Spawn({"run", study, "--out", run, "--threads", "1"});
  ASSERT_GT(WaitForProgress(pid, run, 1), 0);
  std::string out;
  EXPECT_EQ(testing::RunCommand(testing::LrcalBinary() + " run " + study + " --out " + run, &out),
            2);
  EXPECT_THAT(out, ::testing::HasSubstr("another lrcal process is running")) << out;
  kill(pid, SIGKILL);
  int status;
  waitpid(pid, &status, 0);
}

// Issue 31: a symbolic link named lock is never followed; its target keeps its bytes.
TEST(MonteCarlo, ALockThatIsASymbolicLinkIsRefusedAndItsTargetKept) {
  const std::string dir = testing::TempDir("mc_lock_link");
  const std::string study = SmallStudy(dir, 4);
  const std::string run = dir + "/run";
  std::filesystem::create_directories(run);
  std::ofstream(dir + "/precious.txt") << "keep me\n";
  std::filesystem::create_symlink(dir + "/precious.txt", run + "/lock");
  std::string out;
  EXPECT_EQ(testing::RunCommand(testing::LrcalBinary() + " run " + study + " --out " + run, &out),
            2);
  EXPECT_THAT(out, ::testing::HasSubstr(run + "/lock: is a symbolic link")) << out;
  EXPECT_EQ(testing::ReadFile(dir + "/precious.txt"), "keep me\n");
  std::filesystem::remove(run + "/lock");
  ASSERT_EQ(::mkfifo((run + "/lock").c_str(), 0644), 0);
  EXPECT_EQ(testing::RunCommand(testing::LrcalBinary() + " run " + study + " --out " + run, &out),
            2);
  EXPECT_THAT(out, ::testing::HasSubstr("lock: is not a regular file")) << out;
}

TEST(MonteCarlo, ChangedStudyIsRefusedWithWhatChanged) {
  const std::string dir = testing::TempDir("mc_changed");
  RunSmall(SmallStudy(dir, 10), dir + "/run", 2, 0, 1, 5);
  try {
    RunSmall(SmallStudy(dir, 10, "noise: {repetitions: 5}\n"), dir + "/run", 2);
    FAIL() << "a changed study was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("base.noise.repetitions: 10 -> 5"))
        << e.what();
  }
  try {
    RunSmall(SmallStudy(dir, 10, "", "[0.1, 0.2]", 12), dir + "/run", 2);
    FAIL() << "a changed seed was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("seed: 11 -> 12")) << e.what();
  }
}

TEST(MonteCarlo, AddingASweepValueKeepsExistingCells) {
  const std::string dir = testing::TempDir("mc_add");
  const std::string run = dir + "/run";
  RunResult a = RunSmall(SmallStudy(dir, 10), run, 2);
  EXPECT_EQ(a.computed, 40);
  const Study before = LoadStudy(SmallStudy(dir, 10));
  RunResult b = RunSmall(SmallStudy(dir, 10, "", "[0.1, 0.2, 0.4]"), run, 2);
  EXPECT_EQ(b.done_before, 40);
  EXPECT_EQ(b.computed, 20);  // only the two new cells
  EXPECT_EQ(b.cells_prepared, 2);
  const Study after = LoadStudy(SmallStudy(dir, 10, "", "[0.1, 0.2, 0.4]"));
  for (const Cell& c : before.cells) {
    bool found = false;
    for (const Cell& d : after.cells) found |= d.id == c.id;
    EXPECT_TRUE(found) << c.label;
  }
}

TEST(MonteCarlo, SelectionRedrawnPerTrialVariesTheDesign) {
  // selection.redraw: a random design per trial (the baseline of studies/design.yaml); a fixed
  // selection gives one design (one σ_min) for the whole cell.
  const std::string dir = testing::TempDir("mc_redraw");
  const std::string path = dir + "/redraw.yaml";
  std::ofstream(path) << "name: redraw\nseed: 4\ntrials: 12\nrobot: "
                      << testing::SourcePath("studies/robots/paper.yaml")
                      << "\npool: {size: 60}\nvalidation: {size: 5}\n"
                         "sweep:\n  axes:\n    - key: selection\n      values:\n"
                         "        - {count: 30, method: random, redraw: true}\n"
                         "        - {count: 30, method: exchange, scaling: unit, criterion: A}\n";
  // A pool redrawn every trial: every trial has its own candidates, hence its own design.
  const std::string pool_path = dir + "/pool.yaml";
  std::ofstream(pool_path) << "name: pool\nseed: 4\ntrials: 8\nrobot: "
                           << testing::SourcePath("studies/robots/paper.yaml")
                           << "\npool: {size: 40, redraw: true}\nselection: {count: 30}\n"
                              "validation: {size: 5}\n";
  RunSmall(pool_path, dir + "/pool_run", 2);
  {
    TrialStore pool_store(dir + "/pool_run/trials.sqlite");
    std::set<double> pool_sigma;
    pool_store.ForEachTrial(pool_store.Cells()[0].id, [&](const TrialRecord& r) {
      EXPECT_EQ(r.status, TrialStatus::kOk);
      pool_sigma.insert(r.sigma_min);
    });
    EXPECT_EQ(pool_sigma.size(), 8u) << "a redrawn pool should give every trial its own design";
  }
  RunSmall(path, dir + "/run", 2);
  TrialStore store(dir + "/run/trials.sqlite");
  const auto cells = store.Cells();
  ASSERT_EQ(cells.size(), 2u);
  for (const auto& cell : cells) {
    std::set<double> sigma_min;
    long long ok = 0;
    store.ForEachTrial(cell.id, [&](const TrialRecord& r) {
      sigma_min.insert(r.sigma_min);
      ok += r.status == TrialStatus::kOk;
    });
    EXPECT_EQ(ok, 12) << cell.label;
    if (cell.label.find("random") != std::string::npos) {
      EXPECT_GT(sigma_min.size(), 6u) << "random designs should differ from trial to trial";
    } else {
      EXPECT_EQ(sigma_min.size(), 1u);
    }
  }
}

// pool.file / validation.file: the user's configurations, hashed into the cell id; with both
// from files, another seed changes only the noise (the design, even a randomised selection, and
// the validation set stay).
TEST(MonteCarlo, PoolAndValidationFromFilesChangeOnlyTheNoiseWithTheSeed) {
  const std::string dir = testing::TempDir("mc_files");
  testing::WritePaperConfigurationFiles(dir, 70, 12, 4, 9);
  const auto study = [&](int seed, bool files) {
    const std::string path = dir + "/s" + std::to_string(seed) + (files ? "f" : "d") + ".yaml";
    std::ofstream(path) << "name: files\nseed: " << seed << "\ntrials: 20\nrobot: "
                        << testing::SourcePath("studies/robots/paper.yaml") << "\n"
                        << (files ? "pool: {file: pool.csv}\nvalidation: {file: val.csv}\n"
                                  : "pool: {size: 70}\nvalidation: {size: 12}\n")
                        << "selection: {count: 40, method: sampled, samples: 30}\n";
    return path;
  };
  const auto cell_of = [&](const std::string& run) {
    TrialStore store(run + "/trials.sqlite");
    return SummarizeCell(store, store.Cells().at(0));
  };
  for (bool files : {true, false}) {
    const std::string tag = files ? "f" : "d";
    RunSmall(study(1, files), dir + "/r1" + tag, 2);
    RunSmall(study(2, files), dir + "/r2" + tag, 2);
    const CellSummary a = cell_of(dir + "/r1" + tag), b = cell_of(dir + "/r2" + tag);
    EXPECT_EQ(a.cell.id, b.cell.id);                        // the seed is not a setting
    EXPECT_NE(a.validation[0].mean, b.validation[0].mean);  // other noise
    if (files) {
      EXPECT_EQ(a.cell.design_sigma_min, b.cell.design_sigma_min);
      EXPECT_EQ(a.nominal[0].mean, b.nominal[0].mean);  // the same validation set
    } else {  // drawn: the seed changes the pool, the design and the validation set too
      EXPECT_NE(a.cell.design_sigma_min, b.cell.design_sigma_min);
      EXPECT_NE(a.nominal[0].mean, b.nominal[0].mean);
    }
  }
  // The file's content is part of the cell id.
  const std::string before = cell_of(dir + "/r1f").cell.id;
  std::ofstream(dir + "/pool.csv", std::ios::app) << "0.1,0.2,0.3,0.4,0.5,0.6\n";
  EXPECT_NE(LoadStudy(study(1, true)).cells.at(0).id, before);
}

struct BadStudy {
  std::string name, text, expected;
};
// Short, stable test names in ctest (not the struct's bytes).
void PrintTo(const BadStudy& s, std::ostream* os) { *os << s.name; }
class BadStudyTest : public ::testing::TestWithParam<BadStudy> {};

TEST_P(BadStudyTest, FailsBeforeAnythingRunsNamingLineAndKey) {
  const std::string dir = testing::TempDir("mc_bad_" + GetParam().name);
  const std::string path = dir + "/bad.yaml";
  std::ofstream(path) << "name: bad\nseed: 1\ntrials: 5\nrobot: "
                      << testing::SourcePath("studies/robots/paper.yaml") << "\n"
                      << GetParam().text;
  try {
    RunSmall(path, dir + "/run", 1);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr(GetParam().expected)) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/run/trials.sqlite"));
}

// Cells are prepared on every thread; when two fail, the error is the first failing cell's in
// the study's order (the one a single thread meets), whichever thread got there first, and
// nothing is written.
TEST(MonteCarlo, PreparationOnThreadsNamesTheFirstFailingCell) {
  const std::string dir = testing::TempDir("mc_two_bad_cells");
  const std::string path = dir + "/two_bad.yaml";
  std::ofstream(path) << "name: two_bad\nseed: 1\ntrials: 2\nrobot: "
                      << testing::SourcePath("studies/robots/paper.yaml") << "\n"
                      << "plane: {normal: [0, 1, 4.6], offset: -0.69}\n"
                         "pool: {size: 30}\nselection: {count: 26}\n"
                         "sweep:\n  axes:\n    - key: plane.offset\n"
                         "      values: [-0.69, -0.7, -100, -200, -0.68]\n";
  for (int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    try {
      RunSmall(path, dir + "/run", threads);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("cell 'plane.offset=-100'"));
      EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("could only accept 0 of 30"));
    }
    EXPECT_FALSE(fs::exists(dir + "/run/trials.sqlite"));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadStudyTest,
    ::testing::Values(
        BadStudy{"UnknownKey", "noise: {sigma_mm: 0.2, repetition: 3}\n",
                 "bad.yaml:5 key 'noise.repetition': unknown key"},
        BadStudy{"WrongType", "noise: {sigma_mm: high}\n",
                 "bad.yaml:5 key 'noise.sigma_mm': expected a number"},
        BadStudy{"UnknownAverage", "noise: {average: mode}\n",
                 "bad.yaml:5 key 'noise.average': expected mean, median or trimmed:F"},
        BadStudy{"MedianOfTooMany", "noise: {average: median, repetitions: 2000}\n",
                 "key 'noise.average': a median takes at most 1000 readings"},
        BadStudy{"NegativeSigma", "noise: {sigma_mm: -0.2}\n",
                 "key 'noise.sigma_mm': expected a finite value >= 0 (mm), got -0.2"},
        BadStudy{"MoreSelectedThanCandidates", "pool: {size: 40}\nselection: {count: 50}\n",
                 "key 'selection.count': cannot select 50 configurations from a pool of 40"},
        BadStudy{"FewerThanParameters", "selection: {count: 20}\n", "need at least as many"},
        BadStudy{"PlaneNeverHit", "plane: {normal: [0, 0, 1], offset: -100}\n",
                 "could only accept 0 of 101"},
        BadStudy{"BadSweepValue",
                 "sweep:\n  axes:\n    - key: noise.sigma_mm\n      values: [0.1, -1]\n",
                 "sweep value at"},
        BadStudy{"UnknownSweepKey", "sweep:\n  axes:\n    - key: noise.sigma\n      values: [1]\n",
                 "'noise.sigma' is not a study setting"},
        BadStudy{"UnknownMethod", "selection: {method: best}\n", "unknown selection method 'best'"},
        BadStudy{"UnknownScaling", "selection: {scaling: log}\n", "unknown scaling 'log'"},
        BadStudy{"StopWhenBlockOfOne", "stop_when: {block: 1, relative_se: 0.01}\n",
                 "bad.yaml:5 key 'stop_when.block': expected a whole number of trials per block"},
        BadStudy{"StopWhenWithoutCriterion", "stop_when: {block: 2}\n",
                 "bad.yaml:5 key 'stop_when': expected at least one criterion"},
        BadStudy{"StopWhenNegativeSe", "stop_when: {block: 2, relative_se: -0.1}\n",
                 "key 'stop_when.relative_se': expected a number > 0"},
        BadStudy{"StopWhenUnknownKey", "stop_when: {block: 2, relative_sd: 0.1}\n",
                 "key 'stop_when.relative_sd': unknown key; expected block, relative_se"},
        BadStudy{"StopWhenBlockAboveTrials", "stop_when: {block: 10, relative_se: 0.1}\n",
                 "key 'stop_when.block': expected at most the study's trials (5)"},
        BadStudy{"StopWhenOtherMaximum", "stop_when: {block: 2, relative_se: 0.1, trials: 9}\n",
                 "key 'stop_when.trials': differs from the study's trials (5)"},
        BadStudy{"PoolFileMissing", "pool: {file: nowhere.csv}\n",
                 "bad.yaml:5 key 'pool.file': cannot open the configuration file"},
        BadStudy{"PoolFileRedrawn", "pool: {file: bad.yaml, redraw: true}\n",
                 "key 'pool.redraw': a pool read from a file (pool.file) cannot be redrawn"},
        BadStudy{"ValidationFileNotCsv", "validation: {file: bad.yaml}\n", "validation.file: "},
        BadStudy{
            "ZipOfUnequalAxes",
            "sweep:\n  combine: zip\n  axes:\n    - {key: noise.sigma_mm, values: [0.1, 0.2]}\n"
            "    - {key: noise.repetitions, values: [1]}\n",
            "zip needs axes of equal length"}),
    [](const ::testing::TestParamInfo<BadStudy>& info) { return info.param.name; });

TEST(Statistics, DescribeAndPercentilesMatchClosedForms) {
  Distribution d = Describe({4, 1, 3, 2, 5});
  EXPECT_DOUBLE_EQ(d.mean, 3.0);
  EXPECT_DOUBLE_EQ(d.std, std::sqrt(2.5));
  EXPECT_DOUBLE_EQ(d.p50, 3.0);
  EXPECT_DOUBLE_EQ(d.p5, 1.2);  // numpy.percentile([1..5], 5) = 1.2
  EXPECT_DOUBLE_EQ(d.p95, 4.8);
  EXPECT_DOUBLE_EQ(d.max, 5.0);
  const std::vector<double> s = {1, 2, 2, 3};
  EXPECT_DOUBLE_EQ(PercentileRank(s, 2), 50.0);
  EXPECT_DOUBLE_EQ(PercentileRank(s, 0), 0.0);
  EXPECT_DOUBLE_EQ(PercentileRank(s, 10), 100.0);
}

TEST(Statistics, SpreadMatchesTheLinearGaussianPredictionAndBiasIsZero) {
  // With the truth at the nominal model (scale 0) and σ = 0.2 mm the estimator is linear in the
  // noise to first order: its covariance is σ²(GᵀWG)⁻¹ and its mean the truth. With n = 2000
  // trials the empirical std / predicted std has relative standard error 1/√(2n) ≈ 1.6 %; every
  // parameter must be within 4.5 of those (7 %), and every bias within 4.5 Monte-Carlo SE.
  const std::string dir = testing::TempDir("mc_gauss");
  const std::string path = dir + "/gauss.yaml";
  std::ofstream(path) << "name: gauss\nseed: 3\ntrials: 2000\nrobot: "
                      << testing::SourcePath("studies/robots/paper.yaml")
                      << "\ntruth: {scale: 0}\npool: {size: 60}\nselection: {count: 60, method: "
                         "exhaustive}\nvalidation: {size: 5}\n";
  RunSmall(path, dir + "/run", 2);
  TrialStore store(dir + "/run/trials.sqlite");
  const auto cells = store.Cells();
  ASSERT_EQ(cells.size(), 1u);
  CellSummary s = SummarizeCell(store, cells[0]);
  ASSERT_EQ(s.ok, 2000);
  const double se_ratio = 1.0 / std::sqrt(2.0 * 2000);
  for (const auto& p : s.parameters) {
    EXPECT_NEAR(p.ratio, 1.0, 4.5 * se_ratio) << p.name;
    EXPECT_LT(std::fabs(p.bias), 4.5 * p.bias_se) << p.name;
  }
}

}  // namespace
}  // namespace lrcal
