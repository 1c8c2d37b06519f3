// Shared by the fuzz targets: the input as a file (lrcal's readers take paths), and the rule
// that only InputError (a clear message) may come out of a reader; anything else is a finding.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "lrcal/core/error.h"

namespace lrcal::fuzz {

// Writes the input to a per-process temporary file with the given suffix; returns its path.
inline std::string WriteInput(const uint8_t* data, size_t size, const char* suffix) {
  const std::string path = "/tmp/lrcal_fuzz_" + std::to_string(::getpid()) + suffix;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) __builtin_trap();
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

// Runs `read`; an InputError is the expected answer to bad input, and its message must name
// the file.
template <typename Read>
void ExpectCleanAnswer(const std::string& path, Read read) {
  try {
    read();
  } catch (const InputError& e) {
    if (std::string(e.what()).find(path) == std::string::npos &&
        std::string(e.what()).find("--") == std::string::npos)
      __builtin_trap();  // a message that does not say where
  }
}

}  // namespace lrcal::fuzz
