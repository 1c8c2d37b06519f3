// The Monte-Carlo runner: every (cell, trial) of a study on a thread pool, recorded durably in a
// run directory (run_directory.h), resumable, shardable, and bit-identical whatever the thread
// count, shard split, MPI rank count or restart history.
//
// A run is a sequence of named steps (StudyRunner::Run, after Ceres' TrustRegionMinimizer):
//   CellsToPrepare    every cell of a new run; on a resume (one process, fixed trial counts)
//                     only the cells with trials still to compute in this process's share, for
//                     their trials alone when the store holds their row (no certificate, no
//                     first-order prediction: the row has them)
//   PrepareCells      those cells' pools, designs and predicted covariance; a study that cannot
//                     run fails here, before anything is written
//   OpenRunDirectory  rank 0 locks the directory, refuses an incompatible one, starts a session
//                     in the manifest and records the prepared cells in the store
//   FindMissingTrials the union of every store's records; the rest is this run's work
//   PrepareLateCells  any cell with work that was not prepared (the store changed before the
//                     lock), before any trial
//   RunTrials         workers claim trials from a WorkSource (static or dynamic schedule) and
//                     hand records to the writer (this thread), which commits them in batches
//                     and reports progress
//   FinishSession     rank 0 folds MPI rank stores into the main store and closes the session
// The tables are the caller's (report/run_tables.h): the runner never formats results.
//
// Stopping: a StopToken per run. The signal handlers (InstallStopHandlers) set the token of the
// run in progress; a worker's exception sets it too. Finished trials are committed; a second
// signal exits at once (exit 130).
#pragma once

#include <atomic>
#include <functional>
#include <limits>
#include <string>

#include "lrcal/core/settings.h"
#include "lrcal/study/collective.h"
#include "lrcal/study/study.h"

namespace lrcal {

/// Asks one run to stop. Safe to set from a signal handler (a lock-free atomic).
class StopToken {
 public:
  void RequestStop() { requested_.store(true); }
  bool stop_requested() const { return requested_.load(); }

 private:
  std::atomic<bool> requested_{false};
  static_assert(std::atomic<bool>::is_always_lock_free);
};

/// Where a run stands, as a progress callback sees it.
struct RunProgress {
  long long done = 0;      ///< trials of the run (or shard) recorded so far, this process's view
  long long total = 0;     ///< trials of the run (or shard)
  long long computed = 0;  ///< computed by this call so far
  double seconds = 0;      ///< since the call started
  /// Seconds left (NaN until a trial has finished): each cell's remaining trials at its own
  /// measured cost, at the run's pace since its trials started (remaining_time.h).
  double eta_seconds = std::numeric_limits<double>::quiet_NaN();
};

struct RunOptions {
  std::string out_dir;  ///< run directory (created)
  int threads = 0;      ///< 0: all cores
  int shard_index = 0;  ///< this process runs trials with trial % shard_count == shard_index
  int shard_count = 1;
  bool progress = true;  ///< progress on stderr (a bar on a terminal, lines otherwise)
  int batch_size = 512;  ///< records per SQLite transaction (also flushed every second)
  /// Stop (as if interrupted) after this many new trials; 0 = no limit. For tests and for
  /// running a study in slices.
  long long max_new_trials = 0;
  /// MPI only: rank 0 hands out chunks of missing trials on request, instead of dealing blocks
  /// of them to the ranks in turn (kStaticBlocksPerRank each; every rank then prepares only its
  /// blocks' cells). For sweeps whose cells differ a lot in cost; every rank then prepares every
  /// cell. Same results.
  bool dynamic_schedule = false;
  /// Called on the thread that called RunStudy about every 0.1 s while the trials run, and once
  /// when they end (rank 0 only). It must not throw; to stop the run it sets the run's
  /// StopToken. How the Python module reports progress and honours Ctrl-C.
  std::function<void(const RunProgress&)> on_progress;
  /// The numeric settings (settings.h): threads (0: all cores, to 4096), max_trials
  /// (max_new_trials; 0: no limit) and batch_size (at least 1).
  static const std::vector<SettingField<RunOptions>>& Settings();
  /// The run directory (`out`: --out, out_dir=) and the shard (`shard`: --shard, shard=), for
  /// errors in each front end's words.
  static const SettingSpec& OutDirSetting();
  static const SettingSpec& ShardSetting();
  /// Throws SettingError naming the library field (run.threads, run.out_dir, ...) and what was
  /// expected; the command line says --threads, Python threads=.
  void Validate() const;
};

struct RunResult {
  long long total = 0;        ///< trials of this run (or shard)
  long long done_before = 0;  ///< already in the store at start
  long long computed = 0;     ///< computed by this session (this process)
  bool interrupted = false;   ///< stopped before every trial of the run was recorded
  /// Stopped because max_new_trials were computed (not by a signal): a slice, not an interruption.
  bool reached_max_trials = false;
  bool complete = false;        ///< every trial of the run (or shard) is recorded (rank 0)
  bool tables_written = false;  ///< set by the caller that writes the tables
  /// A rerun with nothing new found the tables already written for these very records by this
  /// lrcal (TablesAreCurrent) and left them as they were; tables_written is set too.
  bool tables_current = false;
  double seconds = 0;          ///< wall time of the whole call
  double trial_seconds = 0;    ///< sum of the computed trials' own wall time
  double prepare_seconds = 0;  ///< wall time preparing the cells (pools, designs, covariance)
  /// Cells this process prepared: every cell in a new run, only those with trials of its share
  /// still to compute (or no row in the store) on a resume, none on a rerun of a finished run;
  /// an MPI rank under the static schedule, the cells of its blocks. (The manifest's session
  /// counts every rank's.)
  int cells_prepared = 0;
  double run_seconds = 0;        ///< wall time from the first trial to the last record written
  double tables_seconds = 0;     ///< wall time aggregating and writing the tables (the caller's)
  long peak_rss_kb_trials = 0;   ///< peak resident memory when the trials were done (kB)
  long peak_rss_kb = 0;          ///< peak resident memory at the end (kB)
  long long ranks_computed = 0;  ///< trials computed by all ranks of this job
};

/// Runs (or resumes) a study; see the file comment. Throws InputError for a bad study or a busy
/// or incompatible run directory. With a `collective` of P > 1 ranks (an MPI job) every rank
/// calls this. `stop` (optional) is the run's stop token; without one the run makes its own.
RunResult RunStudy(const Study& study, const RunOptions& options, Collective* collective = nullptr,
                   StopToken* stop = nullptr);

/// What a run did, for its end: the trials computed and already recorded, µs per trial, and the
/// wall time of preparation, trials and tables with the runner's overhead and peak memory (`ranks`
/// MPI ranks; this is rank 0's view).
std::string RunSummaryText(const RunResult& r, const RunOptions& options, int ranks);

/// Installs the SIGINT/SIGTERM handlers: the first signal sets the stop token of the run in
/// progress (if any), the second exits at once with code 130.
void InstallStopHandlers();

/// Peak resident set size of this process so far (kB), -1 if unknown.
long PeakRssKb();

}  // namespace lrcal
