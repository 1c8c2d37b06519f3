// JSON as lrcal records it (manifests, cell settings, summary.json): nlohmann's json with sorted
// keys, the canonical form that cell hashes are taken of; and the few file operations on it.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lrcal {

using Json = nlohmann::json;

/// Differences between two JSON values, one line per changed key ("noise.sigma_mm: 0.2 ->
/// 0.3"). Empty when equal.
std::vector<std::string> DiffJson(const Json& before, const Json& after,
                                  const std::string& prefix = "");

/// Reads a JSON file. InputError naming the file if it cannot be read or parsed.
Json ReadJsonFile(const std::string& path);

/// Writes `text` to `path` through a temporary file in the same folder, checked and renamed:
/// the file is either the old one or the complete new one, never partial. Throws
/// std::runtime_error naming the file on any failure (the temporary is removed).
void WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace lrcal
