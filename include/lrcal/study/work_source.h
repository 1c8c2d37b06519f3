// Where a run's workers get their trials: the missing (cell, trial) pairs of this process, in
// canonical order. Two schedules (Dakota's split of one concern per class):
//  - StaticSchedule: the missing trials are dealt to the ranks in blocks, in turn (about
//    kStaticBlocksPerRank blocks each, spread over the study so that cheap and dear cells are
//    shared); no messages while trials run. A rank's trials then fall in a fraction of the
//    cells, and it prepares only those (CellsOfStaticSchedule). The only schedule of a single
//    process.
//  - DynamicSchedule (MPI): rank 0 hands out chunks of missing trials on request, for sweeps
//    whose cells differ a lot in cost.
// Claim() is called by worker threads; Pump() by the runner's main thread only (it alone talks
// to other ranks). Results do not depend on the schedule: trials are pure functions.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "lrcal/study/collective.h"
#include "lrcal/study/run_directory.h"

namespace lrcal {

/// (cell index in the study, trial index).
using TrialId = std::pair<int, long long>;

/// Trials [first, end) of one cell.
using TrialRange = std::pair<long long, long long>;

/// The missing trials of this shard in canonical order, with a forward-only cursor.
class MissingTrials {
 public:
  /// Within `ranges` (one per cell; every trial [0, trials) of every cell when empty): an
  /// adaptive run's round is one block of each cell still running.
  MissingTrials(const DoneSet* done, long long trials, int shard_index, int shard_count,
                std::vector<TrialRange> ranges = {});
  /// The next missing trial; false at the end.
  bool Next(TrialId* id);
  /// Missing trials passed so far.
  long long seen() const { return seen_; }
  /// All missing trials of the shard.
  long long Count() const;

 private:
  const DoneSet* done_;
  std::vector<TrialRange> ranges_;
  std::size_t cell_ = 0;
  long long t_ = 0, seen_ = 0;
  int shard_index_, shard_count_;
};

class WorkSource {
 public:
  virtual ~WorkSource() = default;
  /// Up to `max` trials for a worker; empty when there is no more work for this process (or a
  /// stop was requested). Thread-safe.
  virtual void Claim(int max, std::vector<TrialId>* out) = 0;
  /// The main thread's turn: exchange messages with other ranks; `stopping` asks for no new
  /// work. Returns true once this process may finish (after its workers are done).
  virtual bool Pump(bool stopping, bool workers_done) = 0;
  /// Trials handed to this process's workers so far.
  virtual long long claimed() const = 0;
  /// True when this process will get no more trials (its share is claimed).
  virtual bool Exhausted() const = 0;
  /// Trials this process expects to run (for progress and the static-schedule check).
  virtual long long share() const = 0;
};

/// How many blocks of missing trials the static schedule deals to each rank: more balance the
/// ranks' work better when cells differ in cost, fewer leave each rank fewer cells to prepare
/// (about cells / P + this many).
inline constexpr long long kStaticBlocksPerRank = 8;

/// Which cells (one flag per cell) have trials the static schedule deals to `rank`, and to any
/// rank, each rank stopping after max_new_trials (when positive) as its schedule does.
struct StaticScheduleCells {
  std::vector<bool> mine, anyone;
};
StaticScheduleCells CellsOfStaticSchedule(MissingTrials missing, std::size_t num_cells, int rank,
                                          int ranks, long long max_new_trials);

std::unique_ptr<WorkSource> MakeStaticSchedule(MissingTrials missing, int rank, int ranks,
                                               long long max_new_trials);
std::unique_ptr<WorkSource> MakeDynamicSchedule(MissingTrials missing, Collective* collective,
                                                long long max_new_trials);

}  // namespace lrcal
