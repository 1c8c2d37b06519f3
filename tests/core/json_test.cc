// Atomic, checked file writes and JSON differences.
#include "lrcal/core/json.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "test_util.h"

namespace lrcal {
namespace {

namespace fs = std::filesystem;

std::string Message(const std::string& path, const std::string& text) {
  try {
    WriteFileAtomically(path, text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

TEST(WriteFileAtomically, ReplacesTheFileWholeAndLeavesNoTemporary) {
  const std::string dir = testing::TempDir("atomic_replace");
  const std::string path = dir + "/t.json";
  WriteFileAtomically(path, "first\n");
  WriteFileAtomically(path, "second, longer\n");
  EXPECT_EQ(testing::ReadFile(path), "second, longer\n");
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST(WriteFileAtomically, AFailedWriteKeepsTheOldFileAndNamesThePath) {
  const std::string dir = testing::TempDir("atomic_fail");
  const std::string path = dir + "/manifest.json";
  WriteFileAtomically(path, "{\"complete\": true}\n");
  fs::create_directory(path + ".tmp");  // the temporary cannot be created
  const std::string message = Message(path, "{}\n");
  EXPECT_THAT(message, ::testing::HasSubstr(path + ".tmp")) << message;
  EXPECT_EQ(testing::ReadFile(path), "{\"complete\": true}\n");
}

TEST(WriteFileAtomically, AFullDeviceIsAnErrorAndIsNeverReplaced) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string message = Message("/dev/full", std::string(1 << 16, 'x'));
  EXPECT_THAT(message, ::testing::HasSubstr("/dev/full")) << message;
  EXPECT_THAT(message, ::testing::HasSubstr("No space left on device")) << message;
  struct stat st;
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/full was replaced";
  EXPECT_FALSE(fs::exists("/dev/full.tmp"));
}

TEST(WriteFileAtomically, ADirectoryOrAMissingFolderIsAnErrorNamingIt) {
  const std::string dir = testing::TempDir("atomic_dir");
  EXPECT_THAT(Message(dir, "x"), ::testing::HasSubstr("is a directory"));
  const std::string missing = dir + "/no/such/folder/file.csv";
  EXPECT_THAT(Message(missing, "x"), ::testing::HasSubstr(missing));
}

TEST(DiffJson, NamesEveryChangedAddedAndRemovedKey) {
  const Json a = Json::parse(R"({"noise": {"sigma_mm": 0.2}, "seed": 1, "gone": true})");
  const Json b = Json::parse(R"({"noise": {"sigma_mm": 0.3}, "seed": 1, "new": 5})");
  const std::vector<std::string> d = DiffJson(a, b);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(d[0], "gone: removed (was true)");
  EXPECT_EQ(d[1], "noise.sigma_mm: 0.2 -> 0.3");
  EXPECT_EQ(d[2], "new: added 5");
  EXPECT_TRUE(DiffJson(a, a).empty());
}

}  // namespace
}  // namespace lrcal
