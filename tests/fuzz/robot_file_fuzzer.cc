// Robot files: any bytes give a robot or an InputError naming the file.
#include <cstdint>

#include "fuzz_util.h"
#include "lrcal/io/robot_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = lrcal::fuzz::WriteInput(data, size, ".yaml");
  lrcal::fuzz::ExpectCleanAnswer(path, [&] { lrcal::LoadRobotFile(path); });
  return 0;
}
