// Helpers for reading YAML with messages that name the file, line and key (private to src/).
#pragma once

#include <yaml-cpp/yaml.h>

#include <set>
#include <string>
#include <vector>

#include "lrcal/core/error.h"

namespace lrcal::yaml {

/// "file:line key 'path'".
inline std::string Where(const std::string& file, const YAML::Node& node, const std::string& key) {
  int line = node.IsDefined() && node.Mark().line >= 0 ? node.Mark().line + 1 : 0;
  std::string where = Location(file, line);
  if (!key.empty()) where += " key '" + key + "'";
  return where;
}

/// Loads a YAML file; a syntax error becomes an InputError with the line.
YAML::Node LoadFile(const std::string& path);

/// Every key of `map` must be in `allowed`.
void CheckKeys(const YAML::Node& map, const std::set<std::string>& allowed, const std::string& file,
               const std::string& context);

/// A mapping key as text; InputError for a complex key (`? [a, b]`) or a null one.
std::string Key(const YAML::Node& key, const std::string& file, const std::string& context);

void RequireMap(const YAML::Node& node, const std::string& file, const std::string& key);

/// A number (also "pi/2"-style expressions when `allow_pi`). Throws naming file/line/key.
double Number(const YAML::Node& node, const std::string& file, const std::string& key,
              bool allow_pi = false);
int Integer(const YAML::Node& node, const std::string& file, const std::string& key);
std::string String(const YAML::Node& node, const std::string& file, const std::string& key);
bool Bool(const YAML::Node& node, const std::string& file, const std::string& key);
std::vector<double> NumberList(const YAML::Node& node, const std::string& file,
                               const std::string& key, bool allow_pi = false);
std::vector<std::string> StringList(const YAML::Node& node, const std::string& file,
                                    const std::string& key);

}  // namespace lrcal::yaml
