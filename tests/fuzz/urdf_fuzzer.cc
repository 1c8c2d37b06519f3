// URDF files: any bytes give a robot or an InputError naming the file; never a hang (a cycle),
// a stack overflow (a deep chain) or a crash in urdfdom.
#include <cstdint>

#include "fuzz_util.h"
#include "lrcal/io/urdf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = lrcal::fuzz::WriteInput(data, size, ".urdf");
  lrcal::fuzz::ExpectCleanAnswer(path, [&] { lrcal::LoadUrdfRobotFile(path); });
  return 0;
}
