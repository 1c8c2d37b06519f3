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
