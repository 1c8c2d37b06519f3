// Errors that lrcal reports to its users.
//
// Every bad input is reported as an InputError that names where the problem is (file, line,
// field) and what was expected, so that the user can act on it without reading the source.
// The command-line program turns an InputError into exit code 2, and a StorageError (results
// could not be written: a full disk, an I/O error) into exit code 5.
#pragma once

#include <stdexcept>
#include <string>

namespace lrcal {

/// A problem with something the user gave us: a file, a command-line option, a study setting.
class InputError : public std::runtime_error {
 public:
  /// `where` names the source ("robot.yaml:12", "--plane", "study.yaml:4 key 'noise.sigma_mm'"),
  /// `what` says what is wrong and what was expected.
  InputError(const std::string& where, const std::string& what)
      : std::runtime_error(where.empty() ? what : where + ": " + what), where_(where) {}
  const std::string& where() const { return where_; }

 private:
  std::string where_;
};

/// Results could not be written or read back: a full disk, an I/O error, a read-only or vanished
/// folder. What was already committed is intact; the message says where and what to do.
class StorageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Formats "file:line" (line is 1-based; 0 means unknown and is omitted).
inline std::string Location(const std::string& file, int line) {
  return line > 0 ? file + ":" + std::to_string(line) : file;
}

}  // namespace lrcal
