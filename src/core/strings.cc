#include "lrcal/core/strings.h"

#include <cmath>
#include <regex>

namespace lrcal {

bool ParseAngleExpression(const std::string& text, double* value) {
  static const std::regex kNumber(R"(\s*([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)\s*)");
  static const std::regex kPi(
      R"(\s*([-+])?\s*(?:(\d+\.?\d*)\s*\*\s*)?pi\s*(?:/\s*(\d+\.?\d*))?\s*)");
  std::smatch m;
  if (std::regex_match(text, m, kNumber)) {
    *value = std::stod(m[1].str());
    return std::isfinite(*value);
  }
  if (std::regex_match(text, m, kPi)) {
    double v = M_PI;
    if (m[2].matched) v *= std::stod(m[2].str());
    if (m[3].matched) {
      double den = std::stod(m[3].str());
      if (den == 0) return false;
      v /= den;
    }
    if (m[1].matched && m[1].str() == "-") v = -v;
    *value = v;
    return true;
  }
  return false;
}

std::vector<std::string> SplitList(const std::string& text, char separator) {
  std::vector<std::string> out;
  std::string item;
  auto flush = [&] {
    auto b = item.find_first_not_of(" \t");
    auto e = item.find_last_not_of(" \t");
    out.push_back(b == std::string::npos ? "" : item.substr(b, e - b + 1));
    item.clear();
  };
  if (text.empty()) return out;
  for (char c : text) {
    if (c == separator)
      flush();
    else
      item += c;
  }
  flush();
  return out;
}

}  // namespace lrcal
