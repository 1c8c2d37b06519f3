// A run directory: what one study run (or shard of it) leaves on disk, and the rules for
// touching it.
//
// Layout:
//   manifest.json   resolved study, seed, lrcal version and commit, compiler, dependency versions,
//                   shard, and one entry per session (start, end, threads, trials, how it ended)
//   trials.sqlite   the trial store (trial_store.h); an MPI job's ranks each write
//                   trials.rank<r>.sqlite, folded into trials.sqlite by rank 0
//   tables/         written by the report layer when every trial of the run is done
//   lock            held (flock) by the process working on the directory
//
// A study whose seed, trials or base settings differ from the manifest's is refused with the
// list of changes; a changed sweep only adds (or leaves out) cells, whose ids are hashes of their
// settings. Every file is written to a temporary name, checked and renamed (core/json.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "lrcal/core/json.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial_store.h"

namespace lrcal {

/// An exclusive lock on a run directory (flock on DIR/lock), released on destruction.
class DirectoryLock {
 public:
  /// Throws InputError if another process holds it.
  explicit DirectoryLock(const std::string& dir);
  ~DirectoryLock();
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;
  /// True if a process (this one included, through another DirectoryLock) holds the lock of
  /// `dir`: a run is going on there. The lock is the kernel's, released when its process ends,
  /// however it ends (kill -9 too).
  static bool IsHeld(const std::string& dir);

 private:
  int fd_ = -1;
};

/// Which trials a store set already holds: done[c][t] for the study's cells in order.
using DoneSet = std::vector<std::vector<bool>>;

class RunDirectory {
 public:
  explicit RunDirectory(std::string path) : path_(std::move(path)) {}
  const std::string& path() const { return path_; }
  std::string ManifestPath() const { return path_ + "/manifest.json"; }
  std::string MainStorePath() const { return path_ + "/trials.sqlite"; }
  std::string RankStorePath(int rank) const;

  /// Creates the directory and takes its lock (throws InputError if busy).
  void CreateAndLock();
  /// Takes the lock of an existing run directory (InputError if it is not one, or busy).
  void Lock();
  void Unlock() { lock_.reset(); }

  /// True if manifest.json exists.
  bool HasManifest() const;
  /// The manifest; InputError if the directory is not a run directory or the file is damaged.
  Json ReadManifest() const;
  /// Writes the manifest atomically (never a partial file).
  void WriteManifest(const Json& manifest) const;
  /// Appends "UTC-TIME  line" to RUN_DIR/run.log, the run's history in words (sessions started
  /// and ended, with what they did). A courtesy to the reader: a log that cannot be written
  /// stops nothing.
  void AppendLog(const std::string& line) const;

  /// Refuses (InputError naming what changed) if the manifest holds another study or shard.
  static void CheckCompatible(const Json& manifest, const Json& study,
                              const std::string& study_path, int shard_index, int shard_count);
  /// The manifest of a new session: study, build, dependencies, shard, and a session entry
  /// ("running") appended; `*session` gets its index.
  static Json StartSession(Json manifest, const Study& study, int shard_index, int shard_count,
                           int threads, int ranks, std::size_t* session);

  /// The main store (if present) and every rank store, sorted.
  std::vector<std::string> StorePaths() const;
  std::vector<std::string> RankStorePaths() const;
  /// Moves every rank store's records into `main_store` and removes the rank stores.
  void MergeRankStores(TrialStore* main_store) const;
  /// The union of the trials held by every store of the directory, for `study`'s cells.
  DoneSet ReadDone(const Study& study, const TrialStore* open_store = nullptr) const;

 private:
  std::string path_;
  std::unique_ptr<DirectoryLock> lock_;
};

/// The fingerprint of a study that must not change under a run directory.
Json StudyFingerprint(const Json& study);

/// Current UTC time, ISO 8601.
std::string UtcNow();

/// What built this lrcal: version, commit, compiler and build type (a manifest's "lrcal").
Json LrcalBuildInfo();

/// Done / total per cell of a run directory, as text lines (and, for a shard, the command that
/// finishes it).
struct RunStatusInfo {
  std::string text;
  /// The same as JSON (`lrcal status --format json`): run, study, shard, cells [{id, label,
  /// done, total, stopped_early}], done, total, complete, last_session {start, end, state
  /// (running, stopped, completed, interrupted, max_trials, ...), ended, trials_computed,
  /// seconds, trials_per_second}, to_finish and report (commands, or null).
  Json json;
  bool complete = false;
  int shard_index = 1, shard_count = 1;  ///< 1-based
  std::string study_file;
};
RunStatusInfo GetRunStatus(const std::string& run_dir);
std::string RunStatus(const std::string& run_dir);
/// Shards of one study (`dirs` with their statuses): which array tasks to resubmit, or the
/// command that merges them.
std::string ShardAdvice(const std::vector<std::string>& dirs,
                        const std::vector<RunStatusInfo>& infos);

/// Parses "i/N" (1-based i) into index i−1 and count N. Throws InputError.
void ParseShard(const std::string& text, int* index, int* count);

/// Combines shard run directories into `out_dir` (records and manifest; the report layer writes
/// the tables). Throws InputError if the shards ran different studies.
void MergeRunStores(const std::vector<std::string>& shard_dirs, const std::string& out_dir);

}  // namespace lrcal
