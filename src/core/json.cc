#include "lrcal/core/json.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "lrcal/core/error.h"

namespace lrcal {

namespace {

std::string Join(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

std::string Errno(const std::string& what, const std::string& path) {
  return "cannot " + what + " " + path + ": " + std::strerror(errno);
}

}  // namespace

std::vector<std::string> DiffJson(const Json& a, const Json& b, const std::string& prefix) {
  std::vector<std::string> out;
  if (a.is_object() && b.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it) {
      const std::string p = Join(prefix, it.key());
      if (!b.contains(it.key()))
        out.push_back(p + ": removed (was " + it.value().dump() + ")");
      else {
        auto sub = DiffJson(it.value(), b[it.key()], p);
        out.insert(out.end(), sub.begin(), sub.end());
      }
    }
    for (auto it = b.begin(); it != b.end(); ++it)
      if (!a.contains(it.key()))
        out.push_back(Join(prefix, it.key()) + ": added " + it.value().dump());
    return out;
  }
  if (a != b)
    out.push_back((prefix.empty() ? "(root)" : prefix) + ": " + a.dump() + " -> " + b.dump());
  return out;
}

Json ReadJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in || std::filesystem::is_directory(path)) throw InputError(path, "cannot open file");
  try {
    return Json::parse(in);
  } catch (const Json::exception& e) {
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
}

namespace {

// Writes all of `text` to `fd`; false (errno set) on any failure, including a short write.
bool WriteAll(int fd, const std::string& text) {
  const char* data = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = ENOSPC;
      return false;
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  return true;
}

// A device or pipe (/dev/stdout, /dev/null, /dev/full): written in place, checked; never
// replaced by a rename.
void WriteToSpecialFile(const std::string& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw StorageError(Errno("open", path));
  const bool ok = WriteAll(fd, text);
  const std::string message = ok ? "" : Errno("write", path);
  if (::close(fd) != 0 && ok) throw StorageError(Errno("write", path));
  if (!ok) throw StorageError(message);
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& text) {
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    if (S_ISDIR(st.st_mode)) throw StorageError(path + " is a directory, not a file");
    WriteToSpecialFile(path, text);
    return;
  }
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw StorageError(Errno("create", tmp));
  if (!WriteAll(fd, text) || ::fsync(fd) != 0) {
    const std::string message = Errno("write", tmp);
    ::close(fd);
    ::unlink(tmp.c_str());
    throw StorageError(message);
  }
  if (::close(fd) != 0) {
    const std::string message = Errno("write", tmp);
    ::unlink(tmp.c_str());
    throw StorageError(message);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string message = Errno("rename " + tmp + " to", path);
    ::unlink(tmp.c_str());
    throw StorageError(message);
  }
}

}  // namespace lrcal
