// One list of (value, name) pairs per enum, and the conversions both ways, so that every enum
// that appears in files, tables or options is spelled in exactly one place.
//
//   inline constexpr EnumName<Color> kColorNames[] = {{Color::kRed, "red"}, {Color::kBlue,
//   "blue"}}; NameOf(kColorNames, Color::kRed)         → "red" ParseName(kColorNames, "blue",
//   "--color", "color") → Color::kBlue, or InputError
//       "--color: unknown color 'green'; expected red or blue"
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "lrcal/core/error.h"

namespace lrcal {

template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

/// The name of `value`, or "unknown" if the list lacks it.
template <typename Enum, std::size_t N>
constexpr const char* NameOf(const EnumName<Enum> (&names)[N], Enum value) {
  for (const auto& e : names)
    if (e.value == value) return e.name;
  return "unknown";
}

/// "a, b or c": the accepted names, for messages.
template <typename Enum, std::size_t N>
std::string NameList(const EnumName<Enum> (&names)[N]) {
  std::string out;
  for (std::size_t i = 0; i < N; ++i)
    out += (i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(names[i].name);
  return out;
}

/// True and `*value` set if `text` is one of the names.
template <typename Enum, std::size_t N>
bool TryParseName(const EnumName<Enum> (&names)[N], std::string_view text, Enum* value) {
  for (const auto& e : names)
    if (text == e.name) {
      *value = e.value;
      return true;
    }
  return false;
}

/// The value named `text`; otherwise InputError (where = `source`): "unknown <what> 'text';
/// expected a, b or c".
template <typename Enum, std::size_t N>
Enum ParseName(const EnumName<Enum> (&names)[N], std::string_view text, const std::string& source,
               const std::string& what) {
  Enum value{};
  if (!TryParseName(names, text, &value))
    throw InputError(
        source, "unknown " + what + " '" + std::string(text) + "'; expected " + NameList(names));
  return value;
}

}  // namespace lrcal
