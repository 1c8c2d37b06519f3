// Study files: any bytes give a study (with its cells) or an InputError naming the file.
#include <cstdint>

#include "fuzz_util.h"
#include "lrcal/study/study.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = lrcal::fuzz::WriteInput(data, size, ".yaml");
  lrcal::fuzz::ExpectCleanAnswer(path, [&] { lrcal::LoadStudy(path); });
  return 0;
}
