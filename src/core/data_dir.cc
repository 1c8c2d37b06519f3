#include "lrcal/core/data_dir.h"

#include <cstdlib>
#include <filesystem>
#include <mutex>

#include "lrcal/core/error.h"

namespace lrcal {

namespace fs = std::filesystem;

namespace {

bool IsDataDirectory(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir / "studies", ec);
}

std::mutex g_embedded_mutex;
std::string g_embedded_dir;  // guarded by g_embedded_mutex

std::string EmbeddedDataDirectory() {
  std::lock_guard<std::mutex> lock(g_embedded_mutex);
  return g_embedded_dir;
}

}  // namespace

bool PathExists(const std::string& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

bool IsDirectory(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

std::string DataDirectory() {
  if (const char* env = std::getenv("LRCAL_DATA_DIR")) {
    if (!IsDataDirectory(env))
      throw InputError("LRCAL_DATA_DIR", "'" + std::string(env) +
                                             "' is not an lrcal data folder (expected studies/ in "
                                             "it); unset it to use the installed data");
    return env;
  }
  std::error_code ec;
  if (const std::string embedded = EmbeddedDataDirectory();
      !embedded.empty() && IsDataDirectory(embedded))
    return fs::weakly_canonical(embedded, ec).string();
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path bin = program.parent_path();
    for (const fs::path& dir : {bin / ".." / "share" / "lrcal", bin / "share" / "lrcal"})
      if (IsDataDirectory(dir)) return fs::weakly_canonical(dir, ec).string();
  }
  throw InputError("LRCAL_DATA_DIR",
                   "cannot find lrcal's data (studies/, analysis/) next to this program; set "
                   "LRCAL_DATA_DIR to the folder that holds them (P/share/lrcal after "
                   "cmake --install --prefix P)");
}

void SetEmbeddedDataDirectory(const std::string& dir) {
  std::lock_guard<std::mutex> lock(g_embedded_mutex);
  g_embedded_dir = dir;
}

std::string FindDataFile(const std::string& relative) {
  try {
    const fs::path p = fs::path(DataDirectory()) / relative;
    return PathExists(p.string()) ? p.string() : "";
  } catch (const InputError&) {
    return "";
  }
}

}  // namespace lrcal
