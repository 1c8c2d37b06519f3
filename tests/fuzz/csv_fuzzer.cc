// The CSV readers: any bytes give a table or an InputError naming the file.
#include <cstdint>
#include <vector>

#include "fuzz_util.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/scanner_data.h"
#include "lrcal/io/socket_data.h"

namespace {

// A six-joint arm for the readers that check joint ranges (socket and scanner data).
const lrcal::RobotModel& SixJoints() {
  static const lrcal::RobotModel robot = [] {
    std::vector<lrcal::Link> links(6);
    for (lrcal::Link& link : links) link.is_parameter = {true, true, true, true, false};
    return lrcal::RobotModel("fuzz", links);
  }();
  return robot;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = lrcal::fuzz::WriteInput(data, size, ".csv");
  lrcal::fuzz::ExpectCleanAnswer(path, [&] { lrcal::ReadConfigurations(path, 6); });
  const lrcal::RangerSpec ranger;
  lrcal::fuzz::ExpectCleanAnswer(path, [&] { lrcal::ReadMeasurements(path, 6, &ranger); });
  lrcal::fuzz::ExpectCleanAnswer(path, [&] { lrcal::ReadSocketData(path, SixJoints()); });
  const lrcal::PlaneSet planes({lrcal::Plane::FromCoefficients(0, 0, 1, -0.5)}, {}, "fuzz");
  lrcal::fuzz::ExpectCleanAnswer(path,
                                 [&] { lrcal::ReadScannerData(path, SixJoints(), planes, 3); });
  return 0;
}
