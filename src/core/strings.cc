#include "lrcal/core/strings.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace lrcal {

namespace {

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

void SkipBlanks(const std::string& s, std::size_t* i) {
  while (*i < s.size() && (s[*i] == ' ' || s[*i] == '\t')) ++*i;
}

// An unsigned decimal number at *i: digits[.digits] or .digits, then an optional exponent.
// Strict: no "inf", "nan" or hexadecimal, unlike strtod. Advances *i past it.
bool ScanNumber(const std::string& s, std::size_t* i, double* value) {
  const std::size_t start = *i;
  std::size_t k = start, digits = 0;
  while (k < s.size() && IsDigit(s[k])) ++k, ++digits;
  if (k < s.size() && s[k] == '.') {
    ++k;
    while (k < s.size() && IsDigit(s[k])) ++k, ++digits;
  }
  if (digits == 0) return false;
  if (k < s.size() && (s[k] == 'e' || s[k] == 'E')) {
    std::size_t e = k + 1;
    if (e < s.size() && (s[e] == '+' || s[e] == '-')) ++e;
    if (e < s.size() && IsDigit(s[e])) {
      while (e < s.size() && IsDigit(s[e])) ++e;
      k = e;
    }
  }
  *value = std::strtod(s.substr(start, k - start).c_str(), nullptr);
  *i = k;
  return std::isfinite(*value);
}

}  // namespace

bool ParseDecimal(const std::string& text, double* value) {
  std::size_t i = 0;
  SkipBlanks(text, &i);
  double sign = 1;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) sign = text[i++] == '-' ? -1 : 1;
  double magnitude = 0;
  if (!ScanNumber(text, &i, &magnitude)) return false;
  SkipBlanks(text, &i);
  if (i != text.size()) return false;
  *value = sign * magnitude;
  return true;
}

bool ParseAngleExpression(const std::string& text, double* value) {
  // [blanks] [sign] (number | [number '*'] pi ['/' number]) [blanks]
  std::size_t i = 0;
  SkipBlanks(text, &i);
  double sign = 1;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) sign = text[i++] == '-' ? -1 : 1;
  SkipBlanks(text, &i);
  double factor = 1;
  const bool has_number = i < text.size() && (IsDigit(text[i]) || text[i] == '.');
  if (has_number && !ScanNumber(text, &i, &factor)) return false;
  SkipBlanks(text, &i);
  bool pi = !has_number;                                  // "pi", "-pi/2"
  if (has_number && i < text.size() && text[i] == '*') {  // "3*pi/4"
    ++i;
    SkipBlanks(text, &i);
    pi = true;
  }
  if (pi) {
    if (text.compare(i, 2, "pi") != 0) return false;
    i += 2;
    SkipBlanks(text, &i);
    double divisor = 1;
    if (i < text.size() && text[i] == '/') {
      ++i;
      SkipBlanks(text, &i);
      if (!ScanNumber(text, &i, &divisor) || divisor == 0) return false;
      SkipBlanks(text, &i);
    }
    factor = factor * M_PI / divisor;
  }
  if (i != text.size()) return false;
  *value = sign * factor;
  return std::isfinite(*value);
}

bool IsValidUtf8(const std::string& text) {
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n;) {
    const unsigned char c = s[i];
    int extra;
    unsigned min;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      extra = 1, min = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
      extra = 2, min = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
      extra = 3, min = 0x10000;
    } else {
      return false;
    }
    unsigned cp = c & (0x3F >> extra);
    for (int k = 1; k <= extra; ++k) {
      if (i + k >= n || (s[i + k] & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (s[i + k] & 0x3F);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += extra + 1;
  }
  return true;
}

std::string JoinList(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (std::size_t k = 0; k < items.size(); ++k) out += (k ? separator : "") + items[k];
  return out;
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

std::string CellExcerpt(const std::string& cell) {
  constexpr std::size_t kShown = 40;
  return cell.size() <= kShown
             ? cell
             : cell.substr(0, kShown) + "... (" + std::to_string(cell.size()) + " characters)";
}

std::string FormatExact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string FileNumber(double v) { return FormatExact(v == 0 ? 0.0 : v); }

}  // namespace lrcal
