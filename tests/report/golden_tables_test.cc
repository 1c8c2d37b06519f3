// The tables of studies/quick.yaml against the checked-in golden copy (tests/golden/), byte for
// byte: a refactoring must not move a single digit; a change meant to alter numbers regenerates
// the copy on purpose (scripts/update_golden.sh). Every instruction-set variant the CPU has is
// forced in turn.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/cpu_dispatch.h"
#include "test_util.h"

namespace lrcal {
namespace {

namespace fs = std::filesystem;

// The run with each instruction-set variant this CPU has, forced (LRCAL_ISA, cpu_dispatch.h):
// the golden copy holds for every one, so a machine without AVX-512 (or AVX2) writes these bytes
// too.
TEST(GoldenTables, QuickStudyTablesAreByteIdenticalOnEveryInstructionSet) {
  const fs::path golden = testing::SourcePath("tests/golden/quick");
  for (Isa isa : SupportedIsas()) {
    SCOPED_TRACE(std::string("LRCAL_ISA=") + IsaName(isa));
    const std::string dir = testing::TempDir(std::string("golden_quick_") + IsaName(isa));
    std::string out;
    ASSERT_EQ(testing::RunCommand(std::string("LRCAL_ISA=") + IsaName(isa) + " " +
                                      testing::LrcalBinary() + " run " +
                                      testing::SourcePath("studies/quick.yaml") + " --out " + dir +
                                      "/run --threads 2 --quiet",
                                  &out),
              0)
        << out;
    int compared = 0;
    for (const auto& entry : fs::directory_iterator(golden)) {
      const fs::path produced = fs::path(dir) / "run" / "tables" / entry.path().filename();
      ASSERT_TRUE(fs::exists(produced)) << produced << " was not written";
      EXPECT_EQ(testing::ReadFile(produced.string()), testing::ReadFile(entry.path().string()))
          << entry.path().filename() << " differs from the golden copy; if the change is meant to "
          << "alter the tables, run scripts/update_golden.sh and say why in the commit";
      ++compared;
    }
    EXPECT_EQ(compared,
              8);  // summary.md/.json, cells/validation/parameters/paper_placement.csv, 2 .tex
    for (const auto& entry : fs::directory_iterator(fs::path(dir) / "run" / "tables"))
      EXPECT_TRUE(fs::exists(golden / entry.path().filename()))
          << entry.path().filename() << " is new: add it to tests/golden/quick";
  }
}

}  // namespace
}  // namespace lrcal
