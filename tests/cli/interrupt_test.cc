// SIGTERM while the cells of a study are still being prepared: the run stops at the next cell
// with exit 130 and writes nothing (no half-made run directory).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "test_util.h"

namespace lrcal {
namespace {

namespace fs = std::filesystem;

TEST(Interrupt, SigtermWhileCellsArePreparedStopsWithoutWritingAnything) {
  const std::string dir = testing::TempDir("interrupt_prepare");
  // Eight cells whose preparation (an exchange design over 3000 candidates) takes seconds each.
  std::ofstream(dir + "/slow.yaml")
      << "name: slow\nseed: 1\ntrials: 10\nrobot: "
      << testing::SourcePath("studies/robots/paper.yaml")
      << "\npool: {size: 3000}\nselection: {count: 200, method: exchange, restarts: 20}\n"
         "sweep:\n  axes:\n    - {key: selection.count, values: [200, 201, 202, 203, 204, 205, "
         "206, 207]}\n";
  std::string out;
  const int code = testing::RunCommand(
      "cd " + dir + " && (" + testing::LrcalBinary() +
          " run slow.yaml --out run --quiet & pid=$!; sleep 1; kill -TERM $pid; wait $pid)",
      &out);
  EXPECT_EQ(code, 130) << out;
  EXPECT_THAT(
      out, ::testing::HasSubstr("interrupted while the cells were prepared; nothing was written"))
      << out;
  EXPECT_FALSE(fs::exists(dir + "/run/manifest.json"));
}

}  // namespace
}  // namespace lrcal
