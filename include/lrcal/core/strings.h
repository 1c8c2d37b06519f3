// Small text utilities shared by every layer: list splitting and the angle expressions that robot
// files may use ("pi/2").
#pragma once

#include <string>
#include <vector>

namespace lrcal {

/// Splits "a,b,c" into items, each trimmed of blanks; an empty string gives an empty list, and
/// an empty item between two separators is kept as "" (callers report it).
std::vector<std::string> SplitList(const std::string& text, char separator = ',');
/// The items written one after the other with `separator` between them ("a, b, c").
std::string JoinList(const std::vector<std::string>& items, const std::string& separator = ", ");

/// True if `text` is well-formed UTF-8 (no stray continuation bytes, no overlong forms, no
/// surrogates, nothing above U+10FFFF).
bool IsValidUtf8(const std::string& text);

/// Parses a plain decimal number ("-1.5", "2e-3", surrounding blanks allowed): no "inf", "nan"
/// or hexadecimal, and the value must be finite. Returns false otherwise.
bool ParseDecimal(const std::string& text, double* value);

/// Parses a number that may be written with pi: "1.5", "-pi/2", "pi", "3*pi/4".
/// Returns false if `text` is none of those forms (or the value is not finite).
bool ParseAngleExpression(const std::string& text, double* value);

/// Formats a double with 17 significant digits (reads back to the same bits).
std::string FormatExact(double v);
/// FormatExact without a negative zero (-0 is written as 0): how numbers go into the files lrcal
/// writes (robot files, URDFs).
std::string FileNumber(double v);

/// A value (a CSV cell, a setting's text) as error messages show it: at most 40 characters,
/// longer ones cut with "..." and their length.
std::string CellExcerpt(const std::string& cell);

}  // namespace lrcal
