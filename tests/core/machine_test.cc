// The machine's provenance: the CPU model a run's manifest and the benchmarks record.
#include "lrcal/core/machine.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

namespace lrcal {
namespace {

TEST(Machine, CpuModelNameIsTheModelNameLineOfProcCpuinfo) {
  const std::string name = CpuModelName();
  ASSERT_FALSE(name.empty());
  std::ifstream in("/proc/cpuinfo");
  std::stringstream text;
  text << in.rdbuf();
  if (text.str().find("model name") == std::string::npos) {
    EXPECT_EQ(name, "unknown");  // no such line (not Linux, or a CPU that Linux names otherwise)
    return;
  }
  // The name is the value of a "model name\t: …" line, whole: no leading blank, no line end.
  EXPECT_THAT(text.str(), ::testing::HasSubstr(": " + name + "\n"));
  EXPECT_NE(name.front(), ' ');
  EXPECT_EQ(name.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace lrcal
