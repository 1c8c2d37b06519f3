// The Monte-Carlo runner: every (cell, trial) of a study on a thread pool, recorded durably in the
// run directory, resumable, shardable, and bit-identical whatever the thread count, shard split or
// restart history.
//
// Run directory layout:
//   manifest.json   resolved study, seed, lrcal version and commit, compiler, dependency versions,
//                   shard, and one entry per session (start, end, threads, trials, how it ended)
//   trials.sqlite   the trial store (trial_store.h)
//   tables/         written when every trial of the run (or shard) is done (study_report.h)
//   lock            held (flock) by the process running on the directory
//
// Resume: running the same study on the same directory computes only the trials that are not in
// the store. A study whose seed, trials or base settings changed is refused with the list of
// changes; a changed sweep only adds (or leaves out) cells, whose ids are hashes of their settings.
// SIGINT/SIGTERM stop after the trials in flight and flush them; a second signal kills at once.
#pragma once

#include <functional>
#include <string>

#include "lrcal/collective.h"
#include "lrcal/study.h"

namespace lrcal {

struct RunOptions {
  std::string out_dir;   ///< run directory (created)
  int threads = 0;       ///< 0: all cores
  int shard_index = 0;   ///< this process runs trials with trial % shard_count == shard_index
  int shard_count = 1;
  bool progress = true;  ///< progress on stderr (a bar on a terminal, lines otherwise)
  int batch_size = 512;  ///< records per SQLite transaction (also flushed every second)
  /// Stop (as if interrupted) after this many new trials; 0 = no limit. For tests and for
  /// running a study in slices.
  long long max_new_trials = 0;
  /// MPI only: rank 0 hands out chunks of missing trials on request, instead of dealing every
  /// P-th trial to each rank. For sweeps whose cells differ a lot in cost. Same results.
  bool dynamic_schedule = false;
};

struct RunResult {
  long long total = 0;          ///< trials of this run (or shard)
  long long done_before = 0;    ///< already in the store at start
  long long computed = 0;       ///< computed by this session
  bool interrupted = false;
  bool tables_written = false;
  double seconds = 0;           ///< wall time of the whole call
  double trial_seconds = 0;     ///< sum of the computed trials' own wall time
  double prepare_seconds = 0;   ///< wall time preparing the cells (pools, designs, covariance)
  double run_seconds = 0;       ///< wall time from the first trial to the last record written
  double tables_seconds = 0;    ///< wall time aggregating and writing the tables
  long peak_rss_kb_trials = 0;  ///< peak resident memory when the trials were done (kB)
  long peak_rss_kb = 0;         ///< peak resident memory at the end, tables included (kB)
  long long ranks_computed = 0; ///< trials computed by all ranks of this job
};

/// Parses "i/N" (1-based i) into index i−1 and count N. Throws InputError.
void ParseShard(const std::string& text, int* index, int* count);

/// Runs (or resumes) a study. Throws InputError for a bad study, a busy or incompatible run
/// directory. With a `collective` of P > 1 ranks (an MPI job) every rank calls this: the missing
/// trials are dealt to the ranks in turn (static schedule), each rank writes its own
/// trials.rank<r>.sqlite, and rank 0 merges them and writes the tables. A rank store left by a
/// killed job counts as done in any later run (with any P, or none) and is merged then.
RunResult RunStudy(const Study& study, const RunOptions& options,
                   Collective* collective = nullptr);

/// Writes the tables of a run directory from its store (also for partial runs).
void AggregateRun(const std::string& run_dir);

/// Combines shard run directories into `out_dir` (records, manifest, tables). Throws InputError
/// if the shards ran different studies.
void MergeRuns(const std::vector<std::string>& shard_dirs, const std::string& out_dir);

/// Done / total per cell of a run directory, as text lines (and, for a shard, the command that
/// finishes it).
struct RunStatusInfo {
  std::string text;
  bool complete = false;
  int shard_index = 1, shard_count = 1;  ///< 1-based
  std::string study_file;
};
RunStatusInfo GetRunStatus(const std::string& run_dir);
std::string RunStatus(const std::string& run_dir);

/// Installs the SIGINT/SIGTERM handlers that ask a running study to stop.
void InstallStopHandlers();

}  // namespace lrcal
