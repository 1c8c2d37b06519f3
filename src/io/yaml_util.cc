#include "io/yaml_util.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "lrcal/core/strings.h"

namespace lrcal::yaml {

namespace {

// A value quoted in a message: at most 40 characters.
std::string Abbreviate(const std::string& text) {
  return text.size() <= 40 ? text : text.substr(0, 37) + "...";
}

}  // namespace

YAML::Node LoadFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path, "is a directory; expected a YAML file");
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open file");
  try {
    return YAML::Load(in);
  } catch (const YAML::ParserException& e) {
    throw InputError(Location(path, e.mark.line + 1), "YAML syntax error: " + e.msg);
  }
}

std::string Key(const YAML::Node& key, const std::string& file, const std::string& context) {
  if (!key.IsScalar())
    throw InputError(Where(file, key, context), "expected a plain key (a name), got a " +
                                                    std::string(key.IsSequence() ? "list"
                                                                : key.IsMap()    ? "mapping"
                                                                                 : "null") +
                                                    " as a key");
  return key.Scalar();
}

void RequireMap(const YAML::Node& node, const std::string& file, const std::string& key) {
  if (!node.IsDefined() || !node.IsMap())
    throw InputError(Where(file, node, key), "expected a mapping of keys");
}

void CheckKeys(const YAML::Node& map, const std::set<std::string>& allowed, const std::string& file,
               const std::string& context) {
  RequireMap(map, file, context);
  std::map<std::string, int> seen;  // key → line
  for (const auto& kv : map) {
    const std::string key = Key(kv.first, file, context);
    const int line = kv.first.Mark().line + 1;
    if (!seen.emplace(key, line).second)
      throw InputError(Where(file, kv.first, context.empty() ? key : context + "." + key),
                       "repeated key (first at line " + std::to_string(seen[key]) + ")");
    if (!allowed.count(key)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw InputError(Where(file, kv.first, context.empty() ? key : context + "." + key),
                       "unknown key; expected one of: " + list);
    }
  }
}

double Number(const YAML::Node& node, const std::string& file, const std::string& key,
              bool allow_pi) {
  if (!node.IsDefined() || node.IsNull()) throw InputError(Where(file, node, key), "missing value");
  if (!node.IsScalar()) throw InputError(Where(file, node, key), "expected a number");
  const std::string text = node.Scalar();
  double value = 0;
  if (allow_pi) {
    if (ParseAngleExpression(text, &value)) return value;
    throw InputError(Where(file, node, key),
                     "expected a finite number or an expression like pi/2, -pi, 3*pi/4; got '" +
                         Abbreviate(text) + "'");
  }
  if (!ParseDecimal(text, &value))
    throw InputError(Where(file, node, key),
                     "expected a finite number; got '" + Abbreviate(text) + "'");
  return value;
}

int Integer(const YAML::Node& node, const std::string& file, const std::string& key) {
  double v = Number(node, file, key);
  if (v != std::floor(v) || std::fabs(v) > 2e9)
    throw InputError(Where(file, node, key),
                     "expected a whole number; got '" + node.Scalar() + "'");
  return static_cast<int>(v);
}

std::string String(const YAML::Node& node, const std::string& file, const std::string& key) {
  if (!node.IsDefined() || node.IsNull()) throw InputError(Where(file, node, key), "missing value");
  if (!node.IsScalar()) throw InputError(Where(file, node, key), "expected a string");
  return node.Scalar();
}

bool Bool(const YAML::Node& node, const std::string& file, const std::string& key) {
  std::string s = String(node, file, key);
  if (s == "true" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "no" || s == "off") return false;
  throw InputError(Where(file, node, key), "expected true or false; got '" + s + "'");
}

std::vector<double> NumberList(const YAML::Node& node, const std::string& file,
                               const std::string& key, bool allow_pi) {
  // A missing key is an invalid node, whose IsSequence() throws YAML::InvalidNode.
  if (!node.IsDefined() || node.IsNull())
    throw InputError(Where(file, node, key), "missing: expected a list of numbers");
  if (!node.IsSequence()) throw InputError(Where(file, node, key), "expected a list of numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < node.size(); ++i)
    out.push_back(Number(node[i], file, key + "[" + std::to_string(i) + "]", allow_pi));
  return out;
}

std::vector<std::string> StringList(const YAML::Node& node, const std::string& file,
                                    const std::string& key) {
  if (!node.IsDefined() || node.IsNull())
    throw InputError(Where(file, node, key), "missing: expected a list of names");
  if (node.IsScalar()) return {node.Scalar()};
  if (!node.IsSequence()) throw InputError(Where(file, node, key), "expected a list of names");
  std::vector<std::string> out;
  for (std::size_t i = 0; i < node.size(); ++i)
    out.push_back(String(node[i], file, key + "[" + std::to_string(i) + "]"));
  return out;
}

}  // namespace lrcal::yaml
