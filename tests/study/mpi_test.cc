// `mpirun -np P lrcal run` over loopback: the tables are byte-identical to a single-process run
// whatever P, and a job whose rank is killed resumes (with another P) to the same tables.
// Skipped when lrcal is built without MPI or mpirun is missing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "lrcal/study/collective.h"
#include "lrcal/study/trial_store.h"
#include "test_util.h"

namespace lrcal {
namespace {

namespace fs = std::filesystem;

// As root (CI) OpenMPI wants these; --oversubscribe lets 3 ranks share 2 cores.
const std::string kMpirun =
    "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe";

bool MpiAvailable() {
  std::string out;
  return BuiltWithMpi() && testing::RunCommand("command -v mpirun", &out) == 0;
}

std::map<std::string, std::string> MpiTables(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(fs::path(dir) / "tables")) {
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    out[e.path().filename().string()] = ss.str();
  }
  return out;
}

std::string MpiStudyFile(const std::string& dir, int trials) {
  const std::string path = dir + "/mpi.yaml";
  std::ofstream(path) << "name: mpi\nseed: 5\ntrials: " << trials
                      << "\nrobot: " << testing::SourcePath("studies/robots/paper.yaml")
                      << "\npool: {size: 60}\nvalidation: {size: 10}\n"
                         "sweep:\n  axes:\n    - key: selection.count\n      values: [30, 59]\n"
                         "    - key: noise.sigma_mm\n      values: [0.1, 0.2]\n";
  return path;
}

// Runs `study` in one process and with 2 and 3 ranks (`extra` options added); every run's
// tables must be those of the single process.
void ExpectRanksMatchSingleProcess(const std::string& dir, const std::string& study,
                                   const std::string& extra) {
  std::string out;
  ASSERT_EQ(
      testing::RunCommand(
          testing::LrcalBinary() + " run " + study + " --out " + dir + "/single --quiet", &out),
      0)
      << out;
  for (int np : {2, 3}) {
    const std::string run = dir + "/np" + std::to_string(np);
    ASSERT_EQ(
        testing::RunCommand(kMpirun + " -np " + std::to_string(np) + " " + testing::LrcalBinary() +
                                " run " + study + " --out " + run + " --threads 1 --quiet " + extra,
                            &out),
        0)
        << out;
    EXPECT_EQ(MpiTables(dir + "/single"), MpiTables(run)) << "np " << np << " " << extra;
    EXPECT_FALSE(fs::exists(run + "/trials.rank1.sqlite"));  // merged into trials.sqlite
  }
}

TEST(Mpi, TablesAreByteIdenticalToASingleProcessForTwoAndThreeRanks) {
  if (!MpiAvailable()) GTEST_SKIP() << "lrcal built without MPI, or no mpirun";
  ExpectRanksMatchSingleProcess(testing::TempDir("mpi_np"),
                                testing::SourcePath("studies/quick.yaml"), "");
}

TEST(Mpi, DynamicScheduleGivesTheSameTables) {
  if (!MpiAvailable()) GTEST_SKIP() << "lrcal built without MPI, or no mpirun";
  const std::string dir = testing::TempDir("mpi_dynamic");
  // 600 trials: 10 chunks of 64 over the ranks.
  ExpectRanksMatchSingleProcess(dir, MpiStudyFile(dir, 150), "--schedule dynamic");
}

TEST(Mpi, StopWhenStopsTheCellsAtTheSameTrialsAsASingleProcess) {
  if (!MpiAvailable()) GTEST_SKIP() << "lrcal built without MPI, or no mpirun";
  const std::string dir = testing::TempDir("mpi_stop_when");
  const std::string study = dir + "/adaptive.yaml";
  std::ofstream(study)
      << "name: adaptive\nseed: 5\ntrials: 1500\n"
         "stop_when: {block: 50, relative_se: 0.06, p95_relative_halfwidth: 0.35}\n"
         "robot: "
      << testing::SourcePath("studies/robots/paper.yaml")
      << "\npool: {size: 60}\nvalidation: {size: 10}\n"
         "sweep:\n  axes:\n    - key: selection.count\n      values: [30, 59]\n";
  ExpectRanksMatchSingleProcess(dir, study, "");
  ExpectRanksMatchSingleProcess(dir + "/dynamic", study, "--schedule dynamic");
  const std::string summary = MpiTables(dir + "/np2").at("summary.json");
  EXPECT_THAT(summary, ::testing::HasSubstr("\"reason\": \"precision\""));
}

// The manifest's "cells_prepared" of each session (every rank's preparations summed).
std::vector<long long> CellsPreparedPerSession(const std::string& run) {
  std::vector<long long> out;
  const auto manifest =
      nlohmann::json::parse(testing::ReadFile((fs::path(run) / "manifest.json").string()));
  for (const auto& session : manifest.at("sessions"))
    out.push_back(session.at("cells_prepared").get<long long>());
  return out;
}

TEST(Mpi, EachRankPreparesOnlyTheCellsItsTrialsFallIn) {
  if (!MpiAvailable()) GTEST_SKIP() << "lrcal built without MPI, or no mpirun";
  const std::string dir = testing::TempDir("mpi_cells");
  // 40 cells of 8 trials: two ranks get 8 blocks of 20 trials each, so each touches about half
  // the cells (when every rank prepared every cell: 80 preparations).
  constexpr int kCells = 40;
  const std::string study = dir + "/cells.yaml";
  {
    std::ofstream out(study);
    out << "name: cells\nseed: 5\ntrials: 8\nrobot: "
        << testing::SourcePath("studies/robots/paper.yaml")
        << "\npool: {size: 60}\nvalidation: {size: 10}\n"
           "sweep:\n  axes:\n    - key: selection.count\n      values: [30, 59]\n"
           "    - key: noise.sigma_mm\n      values: [";
    for (int k = 1; k <= kCells / 2; ++k) out << (k > 1 ? ", " : "") << 0.05 * k;
    out << "]\n";
  }
  std::string out;
  ASSERT_EQ(
      testing::RunCommand(
          testing::LrcalBinary() + " run " + study + " --out " + dir + "/single --quiet", &out),
      0)
      << out;
  const std::string mpi = kMpirun + " -np 2 " + testing::LrcalBinary() + " run " + study +
                          " --threads 1 --quiet --out ";
  // A whole run: each cell prepared by one rank, or by both at a block's edge.
  ASSERT_EQ(testing::RunCommand(mpi + dir + "/whole", &out), 0) << out;
  EXPECT_EQ(MpiTables(dir + "/single"), MpiTables(dir + "/whole"));
  const long long whole = CellsPreparedPerSession(dir + "/whole").at(0);
  EXPECT_GE(whole, kCells);
  EXPECT_LE(whole, kCells + 2 * 8);  // at most one shared cell per block
  // Rerun when finished: nothing to prepare.
  ASSERT_EQ(testing::RunCommand(mpi + dir + "/whole", &out), 0) << out;
  EXPECT_EQ(CellsPreparedPerSession(dir + "/whole").at(1), 0);
  // A session cut at 30 trials a rank: rank 0 runs trials 0–19 and 40–49 in canonical order
  // (cells 0–2, 5–6), rank 1 trials 20–39 and 60–69 (cells 2–4, 7–8), and rank 0 prepares the
  // 31 cells no rank touches, for their rows: 41. The resume prepares only the cells with trials
  // left, and the tables are the same.
  ASSERT_EQ(testing::RunCommand(mpi + dir + "/cut --max-trials 30", &out), 0) << out;
  EXPECT_EQ(CellsPreparedPerSession(dir + "/cut").at(0), 5 + 5 + 31);
  ASSERT_EQ(testing::RunCommand(mpi + dir + "/cut", &out), 0) << out;
  EXPECT_EQ(MpiTables(dir + "/single"), MpiTables(dir + "/cut"));
  EXPECT_LE(CellsPreparedPerSession(dir + "/cut").at(1), whole);
}

// A cell that cannot be prepared, on one rank only (the other prepares other cells): every rank
// stops before anything is written, and the job names the cell, whichever rank met it.
TEST(Mpi, ACellThatFailsOnOneRankStopsEveryRankBeforeAnythingIsWritten) {
  if (!MpiAvailable()) GTEST_SKIP() << "lrcal built without MPI, or no mpirun";
  // 21 cells of 5 trials dealt in blocks of 7: cell 6 (trials 30–34) falls in rank 0's block
  // 28–34 alone, cell 7 (35–39) in rank 1's block 35–41 alone.
  for (int bad : {6, 7}) {
    SCOPED_TRACE(bad);
    const std::string dir = testing::TempDir("mpi_bad_cell" + std::to_string(bad));
    const std::string study = dir + "/bad.yaml";
    {
      std::ofstream out(study);
      out << "name: bad\nseed: 1\ntrials: 5\nrobot: "
          << testing::SourcePath("studies/robots/paper.yaml")
          << "\nplane: {normal: [0, 1, 4.6], offset: -0.69}\npool: {size: 30}\n"
             "selection: {count: 26}\nsweep:\n  axes:\n    - key: plane.offset\n      values: [";
      for (int k = 0; k < 21; ++k)
        out << (k ? ", " : "") << (k == bad ? -100.0 : -0.68 - 0.001 * k);
      out << "]\n";
    }
    std::string out;
    // The study's fault: exit 2 from every rank, whichever mpirun reports. A rank left waiting
    // for the other would hang the job: `timeout` ends it with 124.
    EXPECT_EQ(
        testing::RunCommand("timeout 120 env " + kMpirun + " -np 2 " + testing::LrcalBinary() +
                                " run " + study + " --threads 1 --quiet --out " + dir + "/run",
                            &out),
        2)
        << out;
    EXPECT_THAT(out, ::testing::HasSubstr("error: " + study + " cell 'plane.offset=-100'"));
    EXPECT_THAT(out, ::testing::HasSubstr("could only accept 0 of 30"));
    EXPECT_FALSE(fs::exists(dir + "/run/trials.sqlite"));
    EXPECT_FALSE(fs::exists(dir + "/run/manifest.json"));
  }
}

TEST(Mpi, KilledRankResumesWithAnotherRankCountToTheSameTables) {
  if (!MpiAvailable()) GTEST_SKIP() << "lrcal built without MPI, or no mpirun";
  const std::string dir = testing::TempDir("mpi_kill");
  const std::string study =
      MpiStudyFile(dir, 6000);  // 24,000 trials: about a second on 3 single-thread ranks
  const std::string run = dir + "/run";
  const pid_t launcher = fork();
  if (launcher == 0) {
    const std::string cmd = kMpirun + " -np 3 " + testing::LrcalBinary() + " run " + study +
                            " --out " + run + " --threads 1 --quiet > /dev/null 2>&1";
    execl("/bin/sh", "sh", "-c", ("exec env " + cmd).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until rank 1 has committed some records, then kill that rank.
  long long stored = 0;
  for (int i = 0; i < 3000 && stored < 50; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (!fs::exists(run + "/trials.rank1.sqlite")) continue;
    try {
      TrialStore s(run + "/trials.rank1.sqlite");
      stored = 0;
      for (const auto& c : s.Cells()) stored += s.CountTrials(c.id);
    } catch (const std::exception&) {
    }
  }
  ASSERT_GE(stored, 50) << "rank 1 never stored records";
  std::string pids;
  testing::RunCommand("pgrep -f 'lrcal run " + study + "' | tr '\\n' ' '", &pids);
  // Kill every lrcal rank process whose store is rank 1's: find it by its open file.
  std::string victim;
  testing::RunCommand("for p in " + pids +
                          "; do ls -l /proc/$p/fd 2>/dev/null | grep -q "
                          "'trials.rank1.sqlite' && echo $p; done | head -1 | tr -d '\\n'",
                      &victim);
  ASSERT_FALSE(victim.empty()) << "no process holds rank 1's store; pids: " << pids;
  kill(std::stoi(victim), SIGKILL);
  int status;
  waitpid(launcher, &status, 0);  // mpirun ends the job when a rank dies
  EXPECT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  ASSERT_FALSE(fs::exists(run + "/tables/summary.md")) << "the job finished before the kill";

  // Rerun with two ranks: only what is missing is computed, and the tables are those of an
  // uninterrupted single-process run.
  std::string out;
  ASSERT_EQ(testing::RunCommand(kMpirun + " -np 2 " + testing::LrcalBinary() + " run " + study +
                                    " --out " + run + " --threads 1 --quiet",
                                &out),
            0)
      << out;
  ASSERT_EQ(
      testing::RunCommand(
          testing::LrcalBinary() + " run " + study + " --out " + dir + "/single --quiet", &out),
      0)
      << out;
  EXPECT_EQ(MpiTables(dir + "/single"), MpiTables(run));
}

}  // namespace
}  // namespace lrcal
