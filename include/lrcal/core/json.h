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

/// Writes `text` to `path` through a temporary file in the same folder, checked, synced and
/// renamed: the file is either the old one or the complete new one, never partial. A device or
/// pipe (/dev/stdout, /dev/full) is written in place, checked, never replaced. Throws
/// StorageError naming the file on any failure (a full disk, a short write, a folder that
/// cannot be written; the temporary is removed).
void WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace lrcal
