// Where lrcal's shipped data lives: the robot files and studies (studies/) and the analysis
// scripts (analysis/). Found relative to the lrcal program, never through a path baked in at build
// time, so an installed or moved lrcal still finds them:
//   1. $LRCAL_DATA_DIR, if set (an error if it is not such a folder);
//   2. the folder registered by a program that embeds lrcal away from its data (the Python
//      module registers the one relative to its own installed location);
//   3. <program folder>/../share/lrcal   (installed: P/bin/lrcal → P/share/lrcal);
//   4. <program folder>/share/lrcal      (the build tree: CMake links it to the sources).
#pragma once

#include <string>

namespace lrcal {

/// True if `path` exists. A name the file system cannot even look up (too long, invalid) is
/// simply not there: no exception.
bool PathExists(const std::string& path);

/// True if `path` is a directory (false for anything the file system cannot look up).
bool IsDirectory(const std::string& path);

/// The data folder (see the file comment). Throws InputError if none is found.
std::string DataDirectory();

/// Registers the data folder of a program that embeds lrcal (step 2 above); "" removes it.
void SetEmbeddedDataDirectory(const std::string& dir);

/// `relative` (e.g. "studies/robots/paper.yaml") inside the data folder, or "" if there is no
/// data folder or no such file.
std::string FindDataFile(const std::string& relative);

}  // namespace lrcal
