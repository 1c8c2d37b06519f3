#include "lrcal/core/settings.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace lrcal {

namespace {

// 1000000 → "1,000,000" (whole numbers from 10,000 on); other values as %.12g.
std::string Number(double v) {
  if (v == std::floor(v) && std::fabs(v) >= 1e4 && std::fabs(v) < 1e15) {
    std::string digits = std::to_string(static_cast<long long>(std::fabs(v)));
    for (int p = static_cast<int>(digits.size()) - 3; p > 0; p -= 3) digits.insert(p, ",");
    return (v < 0 ? "-" : "") + digits;
  }
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.12g", v);
  return buffer;
}

std::string Unit(const char* unit) {
  return *unit ? std::string(" (") + unit + ")" : std::string();
}

}  // namespace

std::string SettingSpec::Spelling(Frontend frontend) const {
  switch (frontend) {
    case Frontend::kLibrary:
      return std::string(section) + "." + field;
    case Frontend::kStudyFile:
      return std::string(section) + "." + name;
    case Frontend::kCommandLine: {
      std::string option = std::string("--") + name;
      for (char& c : option)
        if (c == '_') c = '-';
      return option;
    }
    case Frontend::kPython:
      return std::string(python_name ? python_name : name) + "=";
  }
  return name;
}

std::string SettingSpec::Expected(bool si) const {
  const bool bounded = std::isfinite(max);
  const double lo = si ? min * to_si : min, hi = si ? max * to_si : max;
  const char* u = si ? si_unit : unit;
  if (integer) {
    const std::string low = Number(lo) + (*min_note ? std::string(" (") + min_note + ")" : "");
    const std::string what = *noun ? std::string(" ") + noun : std::string();
    if (bounded) return "expected " + low + " to " + Number(hi) + what;
    return "expected " + low + " or more" + what;
  }
  if (bounded)
    return std::string("expected a value in ") + (min_exclusive ? "(" : "[") + Number(lo) + ", " +
           Number(hi) + (max_exclusive ? ")" : "]") + Unit(u);
  return std::string("expected a finite value ") + (min_exclusive ? "> " : ">= ") + Number(lo) +
         Unit(u);
}

bool SettingSpec::Allows(double value_si) const {
  if (!std::isfinite(value_si)) return false;
  const double v = value_si / to_si;
  if (integer && v != std::floor(v)) return false;
  const double lo = min * to_si, hi = max * to_si;
  return (min_exclusive ? value_si > lo : value_si >= lo) &&
         (max_exclusive ? value_si < hi : value_si <= hi);
}

void SettingSpec::Check(double value_si) const {
  if (!Allows(value_si)) throw SettingError(*this, value_si);
}

SettingSpec SettingSpec::Named(const char* section, const char* field, const char* name,
                               const char* help, const char* python_name) {
  SettingSpec spec{section, field, name, ""};
  spec.help = help;
  spec.python_name = python_name;
  return spec;
}

double SettingSpec::FromSi(double value_si) const {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.12g", value_si / to_si);
  return std::strtod(buffer, nullptr);
}

SettingError::SettingError(const SettingSpec& spec, double value_si)
    : InputError(spec.Spelling(Frontend::kLibrary),
                 spec.Expected(/*si=*/true) + ", got " + Number(value_si)),
      spec_(spec),
      problem_(spec.Expected() + ", got " + Number(spec.FromSi(value_si))) {}

SettingError::SettingError(const SettingSpec& spec, const std::string& problem)
    : InputError(spec.Spelling(Frontend::kLibrary), problem), spec_(spec), problem_(problem) {}

namespace {

// How `frontend` writes setting `spec` given `value`: "--plan-on data", "plan_on='data'",
// "plan.plan_on: data" (library and study file).
std::string WithValue(const SettingSpec& spec, Frontend frontend, const std::string& value) {
  switch (frontend) {
    case Frontend::kCommandLine:
      return spec.Spelling(frontend) + " " + value;
    case Frontend::kPython:
      return spec.Spelling(frontend) + "'" + value + "'";
    default:
      return spec.Spelling(frontend) + ": " + value;
  }
}

// `text` with every {i} replaced by mentions[i] as `frontend` spells it, and every {i:value} by
// that setting given `value`.
std::string WithMentions(const std::string& text, const std::vector<SettingSpec>& mentions,
                         Frontend frontend) {
  std::string out;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t open = text.find('{', at);
    const std::size_t close = open == std::string::npos ? open : text.find('}', open);
    if (close == std::string::npos) break;
    const std::string inner = text.substr(open + 1, close - open - 1);
    const std::size_t colon = inner.find(':');
    const std::string index = inner.substr(0, colon);
    // At most three digits: a longer number in braces is text, not a mention (and never
    // overflows the conversion).
    if (index.empty() || index.size() > 3 ||
        index.find_first_not_of("0123456789") != std::string::npos ||
        std::stoul(index) >= mentions.size()) {
      out += text.substr(at, close + 1 - at);  // not a mention: kept as written
    } else {
      const SettingSpec& spec = mentions[std::stoul(index)];
      out += text.substr(at, open - at) +
             (colon == std::string::npos ? spec.Spelling(frontend)
                                         : WithValue(spec, frontend, inner.substr(colon + 1)));
    }
    at = close + 1;
  }
  return out + text.substr(std::min(at, text.size()));
}

}  // namespace

SettingError::SettingError(const SettingSpec& spec, const std::string& problem,
                           std::vector<SettingSpec> mentions)
    : InputError(spec.Spelling(Frontend::kLibrary),
                 WithMentions(problem, mentions, Frontend::kLibrary)),
      spec_(spec),
      problem_(problem),
      mentions_(std::move(mentions)) {}

std::string SettingError::ProblemFor(Frontend frontend) const {
  return WithMentions(problem_, mentions_, frontend);
}

InputError SettingError::Respelled(Frontend frontend, const std::string& where) const {
  return InputError(where.empty() ? spec_.Spelling(frontend) : where, ProblemFor(frontend));
}

}  // namespace lrcal
