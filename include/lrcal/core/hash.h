// Content hashes: the names of cells, the fingerprints of files a run depends on.
#pragma once

#include <cstdint>
#include <string>

namespace lrcal {

/// 64-bit FNV-1a of a string.
std::uint64_t Fnv1a(const std::string& text);
/// The same as 16 lowercase hex digits.
std::string HashHex(const std::string& text);

}  // namespace lrcal
