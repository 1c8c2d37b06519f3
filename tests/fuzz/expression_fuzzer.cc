// The number and angle-expression parsers (robot files, CSVs, --plane): any text, no crash, and
// a parsed value is always finite.
#include <cmath>
#include <cstdint>
#include <string>

#include "lrcal/core/strings.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  double value = 0;
  if (lrcal::ParseAngleExpression(text, &value) && !std::isfinite(value)) __builtin_trap();
  if (lrcal::ParseDecimal(text, &value) && !std::isfinite(value)) __builtin_trap();
  lrcal::IsValidUtf8(text);
  lrcal::SplitList(text);
  return 0;
}
