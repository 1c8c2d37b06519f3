// The CSV readers: any bytes give a table or an InputError naming the file.
#include <cstdint>

#include "fuzz_util.h"
#include "lrcal/io/csv.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = lrcal::fuzz::WriteInput(data, size, ".csv");
  lrcal::fuzz::ExpectCleanAnswer(path, [&] { lrcal::ReadConfigurations(path, 6); });
  const lrcal::RangerSpec ranger;
  lrcal::fuzz::ExpectCleanAnswer(path, [&] { lrcal::ReadMeasurements(path, 6, &ranger); });
  return 0;
}
