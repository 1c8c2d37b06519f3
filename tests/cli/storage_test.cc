// Nothing lost, whatever the disk: a full store, a full file system, a table or output file that
// cannot be written. Each stops with exit 5 and a message that names the file and says what is
// safe; nothing already written is damaged; the same command resumes to the same bytes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_util.h"

namespace lrcal {
namespace {

namespace fs = std::filesystem;
using testing::LrcalBinary;
using testing::ReadFile;
using testing::RunCommand;

std::string Quick() { return testing::SourcePath("studies/quick.yaml"); }

// The run's tables equal the checked-in golden copy of the quick study.
void ExpectGoldenTables(const std::string& run) {
  const fs::path golden = testing::SourcePath("tests/golden/quick");
  for (const auto& e : fs::directory_iterator(golden))
    EXPECT_EQ(ReadFile(run + "/tables/" + e.path().filename().string()), ReadFile(e.path()))
        << e.path().filename();
}

// A manifest that parses and still holds the study (never emptied or truncated).
void ExpectIntactManifest(const std::string& run) {
  const std::string text = ReadFile(run + "/manifest.json");
  ASSERT_FALSE(text.empty());
  const auto manifest = nlohmann::json::parse(text);
  EXPECT_TRUE(manifest.contains("study"));
  EXPECT_FALSE(manifest["sessions"].empty());
}

TEST(Storage, AFullTrialStoreStopsCleanlyAndTheSameCommandResumes) {
  const std::string run = testing::TempDir("storage_full_store") + "/run";
  const std::string command = LrcalBinary() + " run " + Quick() + " --out " + run + " --quiet";
  std::string out;
  // SQLite refuses to grow the store past 12 pages, exactly as on a full disk.
  ASSERT_EQ(RunCommand("LRCAL_TEST_STORE_MAX_PAGES=12 " + command, &out), 5) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("could not write results")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("trials are safely recorded in " + run + "/trials.sqlite"))
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("run the same command again")) << out;
  ExpectIntactManifest(run);
  EXPECT_FALSE(fs::exists(run + "/tables"));
  // The disk is freed: the same command finishes and gives the golden tables.
  ASSERT_EQ(RunCommand(command, &out), 0) << out;
  ExpectGoldenTables(run);
}

TEST(Storage, AFullFileSystemStopsCleanlyAndResumesOnceSpaceIsFreed) {
  const std::string mount = testing::TempDir("storage_tmpfs");
  if (::mount("tmpfs", mount.c_str(), "tmpfs", 0, "size=96k") != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here (needs root): the injected-failure tests cover "
                    "the same paths";
  const std::string run = mount + "/run";
  const std::string command = LrcalBinary() + " run " + Quick() + " --out " + run + " --quiet";
  std::string out;
  const int first = RunCommand(command, &out);
  EXPECT_EQ(first, 5) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("could not write results")) << out;
  if (fs::exists(run + "/manifest.json")) ExpectIntactManifest(run);
  // Run again on the still-full disk: refused the same way, and nothing already there damaged.
  EXPECT_EQ(RunCommand(command, &out), 5) << out;
  if (fs::exists(run + "/manifest.json")) ExpectIntactManifest(run);
  // Free space (a larger file system) and rerun the same command.
  ASSERT_EQ(::mount("tmpfs", mount.c_str(), "tmpfs", MS_REMOUNT, "size=8m"), 0);
  const int second = RunCommand(command, &out);
  EXPECT_EQ(second, 0) << out;
  if (second == 0) ExpectGoldenTables(run);
  ::umount(mount.c_str());
}

TEST(Storage, TablesThatCannotBeWrittenLeaveTheRunIntactAndAggregateRewritesThem) {
  const std::string run = testing::TempDir("storage_tables") + "/run";
  std::string out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " run " + Quick() + " --out " + run + " --quiet", &out), 0)
      << out;
  const std::string manifest = ReadFile(run + "/manifest.json");
  fs::remove(run + "/tables/summary.json");
  fs::create_directory(run + "/tables/summary.json.tmp");  // the write of summary.json fails
  ASSERT_EQ(RunCommand(LrcalBinary() + " aggregate " + run, &out), 5) << out;
  EXPECT_THAT(out, ::testing::HasSubstr(run + "/tables/summary.json.tmp")) << out;
  EXPECT_EQ(ReadFile(run + "/manifest.json"), manifest);  // untouched
  ASSERT_EQ(RunCommand(LrcalBinary() + " status " + run, &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("tables: missing; write them with: lrcal aggregate"))
      << out;
  fs::remove(run + "/tables/summary.json.tmp");
  ASSERT_EQ(RunCommand(LrcalBinary() + " aggregate " + run, &out), 0) << out;
  ExpectGoldenTables(run);
}

TEST(Storage, MergeAndReportThatCannotWriteAreExitFiveAndKeepTheirInputs) {
  const std::string dir = testing::TempDir("storage_merge_report");
  std::string out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " run " + Quick() + " --out " + dir + "/a --quiet", &out), 0)
      << out;
  // merge: the merged manifest cannot be written.
  fs::create_directories(dir + "/m/manifest.json.tmp");
  ASSERT_EQ(RunCommand(LrcalBinary() + " merge " + dir + "/a --out " + dir + "/m", &out), 5) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("manifest.json.tmp")) << out;
  ExpectGoldenTables(dir + "/a");  // the input is untouched
  // report: report.html cannot be written (its temporary name is taken by a folder).
  fs::create_directories(dir + "/a/report/report.html.tmp");
  ASSERT_EQ(RunCommand(LrcalBinary() + " report " + dir + "/a", &out), 5) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("report.html.tmp")) << out;
  ExpectIntactManifest(dir + "/a");
}

struct WritingCommand {
  std::string name, args;
};
void PrintTo(const WritingCommand& c, std::ostream* os) { *os << c.name; }

class FullDeviceTest : public ::testing::TestWithParam<WritingCommand> {};

// Every command that writes a file: a full device is exit 5 naming it, never exit 0, and the
// device itself is never replaced.
TEST_P(FullDeviceTest, AFullDeviceIsExitFiveNamingTheFile) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string dir = testing::TempDir("full_" + GetParam().name);
  std::ofstream(dir + "/c.csv") << "q1,q2,q3,q4,q5,q6\n0.1,-0.7,1.1,0.4,-0.9,0.2\n";
  std::string out;
  EXPECT_EQ(RunCommand("cd " + dir + " && " + LrcalBinary() + " " + GetParam().args, &out), 5)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("/dev/full")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("No space left on device")) << out;
  struct stat st;
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

INSTANTIATE_TEST_SUITE_P(
    Commands, FullDeviceTest,
    ::testing::Values(WritingCommand{"Sample", "sample --count 5 --out /dev/full"},
                      WritingCommand{"Simulate", "simulate --configs c.csv --out /dev/full"},
                      WritingCommand{"Design",
                                     "design --generate 40 --select 30 --baseline 10 "
                                     "--out /dev/full"}),
    [](const ::testing::TestParamInfo<WritingCommand>& info) { return info.param.name; });

}  // namespace
}  // namespace lrcal
