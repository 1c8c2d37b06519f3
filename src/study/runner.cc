#include "lrcal/study/runner.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <system_error>
#include <thread>
#include <utility>

#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/study/remaining_time.h"
#include "lrcal/study/run_directory.h"
#include "lrcal/study/stopping.h"
#include "lrcal/study/trial_store.h"
#include "lrcal/study/work_source.h"
#include "study/preparation_memo.h"
#include "study/trial_pipeline.h"

namespace lrcal {

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

// The signal handlers' view of the run in progress.
std::atomic<StopToken*> g_active_stop{nullptr};
std::atomic<int> g_signals{0};

// True while a run prepares its cells: nothing is written yet, so a signal may end the process
// at once (one cell's preparation can take minutes).
std::atomic<bool> g_preparing{false};

void OnStopSignal(int) {
  if (g_preparing.load()) {
    static const char kMessage[] =
        "lrcal run: interrupted while the cells were prepared; nothing was written\n";
    if (::write(STDERR_FILENO, kMessage, sizeof kMessage - 1) < 0) {
    }
    _exit(130);
  }
  if (g_signals.fetch_add(1) >= 1) _exit(130);  // second signal: stop now
  if (StopToken* token = g_active_stop.load()) token->RequestStop();
}

// Registers a run's stop token with the signal handlers for the run's lifetime.
class ActiveStop {
 public:
  explicit ActiveStop(StopToken* token) {
    g_signals.store(0);
    g_active_stop.store(token);
  }
  ~ActiveStop() { g_active_stop.store(nullptr); }
};

std::string Duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  char buf[32];
  const long long t = static_cast<long long>(s + 0.5);
  std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", t / 3600, t / 60 % 60, t % 60);
  return buf;
}

// Records handed over by the workers, taken by the writer (the runner's main thread).
class RecordQueue {
 public:
  RecordQueue(int workers, std::size_t batch) : running_(workers), batch_(batch) {}
  void Push(std::vector<TrialRecord>* records) {
    bool full;
    {
      std::lock_guard<std::mutex> g(mutex_);
      for (auto& r : *records) pending_.push_back(std::move(r));
      full = pending_.size() >= batch_;
    }
    records->clear();
    if (full) cv_.notify_one();  // else the writer wakes on its own
  }
  // A worker has finished. Under the mutex: the writer checks `running_` under it, so this
  // wake-up cannot be lost.
  void WorkerDone() {
    {
      std::lock_guard<std::mutex> g(mutex_);
      --running_;
    }
    cv_.notify_one();
  }
  // Waits up to `wait` for a full batch or the end of the workers; moves what is pending into
  // `out`. Returns true when every worker has finished.
  bool Take(std::chrono::milliseconds wait, std::vector<TrialRecord>* out) {
    std::unique_lock<std::mutex> g(mutex_);
    cv_.wait_for(g, wait, [&] { return running_ == 0 || pending_.size() >= batch_; });
    for (auto& r : pending_) out->push_back(std::move(r));
    pending_.clear();
    return running_ == 0;
  }
  void Fail(std::exception_ptr e) {
    std::lock_guard<std::mutex> g(mutex_);
    if (!failure_) failure_ = e;
  }
  std::exception_ptr failure() {
    std::lock_guard<std::mutex> g(mutex_);
    return failure_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<TrialRecord> pending_;
  int running_;
  std::size_t batch_;
  std::exception_ptr failure_;
};

// Progress on stderr: a bar on a terminal, periodic lines otherwise (rank 0 only). The rate and
// the ETA count from the start of the trials (`start`), not from the cells' preparation; the ETA
// weighs each cell's remaining trials by its own cost (`eta`, remaining_time.h) unless the run
// is adaptive (its total changes as cells stop: then remaining trials over the rate).
class ProgressReporter {
 public:
  ProgressReporter(bool enabled, int ranks, long long total, long long done_before,
                   long long expected_total, Clock::time_point start,
                   const RemainingTimeEstimate* eta)
      : enabled_(enabled),
        tty_(::isatty(STDERR_FILENO) != 0),
        ranks_(ranks),
        total_(total),
        done_before_(done_before),
        expected_total_(expected_total),
        start_(start),
        last_(Clock::now()),
        eta_(eta) {
    if (const char* e = std::getenv("LRCAL_PROGRESS_SECONDS")) line_every_ = std::atof(e);
  }
  void Tick(long long computed) {
    const auto now = Clock::now();
    if (Seconds(last_, now) < (tty_ ? 0.25 : line_every_)) return;
    Report(computed, false);
    last_ = now;
  }
  // An adaptive run learns its total as cells stop; `note` says how many did.
  void SetTotal(long long total, long long expected_total, std::string note) {
    total_ = total;
    expected_total_ = expected_total;
    note_ = std::move(note);
  }
  // The ETA (s; NaN while unknown) after `computed` trials of this process.
  double SecondsLeft(long long computed) const {
    const double elapsed = Seconds(start_, Clock::now());
    if (eta_) return eta_->SecondsLeft(elapsed);
    const double rate = elapsed > 0 ? computed * ranks_ / elapsed : 0;
    return rate > 0 ? (expected_total_ - done_before_ - computed * ranks_) / rate : NAN;
  }
  void Report(long long computed, bool final) const {
    if (!enabled_) return;
    const double elapsed = Seconds(start_, Clock::now());
    const long long done_now = done_before_ + computed * ranks_;
    const double rate = elapsed > 0 ? computed * ranks_ / elapsed : 0;
    const double eta = SecondsLeft(computed);
    const long long shown = std::min(done_now, total_);
    char line[256];
    if (tty_) {
      const int width = 30;
      const int filled = total_ ? static_cast<int>(width * shown / total_) : width;
      std::snprintf(line, sizeof line, "\r[%s%s] %lld/%lld trials  %.0f/s  ETA %s%s ",
                    std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
                    shown, total_, rate, Duration(eta).c_str(), note_.c_str());
      std::cerr << line << (final ? "\n" : "") << std::flush;
    } else {
      std::snprintf(line, sizeof line, "lrcal run: %lld/%lld trials, %.0f/s, ETA %s%s%s", shown,
                    total_, rate, Duration(eta).c_str(),
                    ranks_ > 1 ? " (estimated from rank 0)" : "", note_.c_str());
      std::cerr << line << "\n";
    }
  }

 private:
  bool enabled_, tty_;
  int ranks_;
  long long total_, done_before_, expected_total_;
  Clock::time_point start_, last_;
  const RemainingTimeEstimate* eta_;
  double line_every_ = 10.0;
  std::string note_;
};

// "preparing cells: k/N done" on stderr while cells are prepared (from any thread): rewritten in
// place on a terminal, a line every LRCAL_PROGRESS_SECONDS (10 s) on a log.
class PreparationProgress {
 public:
  PreparationProgress(bool show, Clock::time_point start, int total)
      : show_(show),
        tty_(::isatty(STDERR_FILENO) != 0),
        start_(start),
        last_line_(start),
        total_(total) {
    if (const char* e = std::getenv("LRCAL_PROGRESS_SECONDS")) every_ = std::atof(e);
  }
  void CellDone() {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++done_;
    const auto now = Clock::now();
    if (!show_ || (!tty_ && Seconds(last_line_, now) < every_)) return;
    std::cerr << (tty_ ? "\r" : "") << "lrcal run: preparing cells: " << done_ << "/" << total_
              << " done, " << Duration(Seconds(start_, now)) << (tty_ ? " " : "\n") << std::flush;
    last_line_ = now;
  }
  void Finish() const {
    if (show_ && tty_ && total_ > 0) std::cerr << "\n";
  }

 private:
  bool show_, tty_;
  Clock::time_point start_, last_line_;
  int total_, done_ = 0;
  double every_ = 10.0;  // s between lines on a log (as the trials' progress lines)
  std::mutex mutex_;
};

class StudyRunner {
 public:
  StudyRunner(const Study& study, const RunOptions& options, Collective* collective,
              StopToken* stop)
      : study_(study),
        options_(options),
        collective_(collective),
        stop_(stop),
        rank_(collective->rank()),
        ranks_(collective->size()),
        threads_(options.threads > 0
                     ? options.threads
                     : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))),
        dir_(options.out_dir) {}

  RunResult Run() {
    start_ = Clock::now();
    contexts_.resize(study_.cells.size());
    for (std::size_t i = 0; i < study_.cells.size(); ++i)
      cell_index_.emplace(study_.cells[i].id, static_cast<int>(i));
    PrepareCellsOnEveryRank(CellsToPrepare(), true);
    if (stop_->stop_requested()) {  // a signal while the cells were prepared: nothing written
      result_.interrupted = true;
      result_.seconds = Seconds(start_, Clock::now());
      return result_;
    }
    OpenRunDirectory();
    FindMissingTrials();
    PrepareLateCells();
    try {
      RunTrials();
    } catch (const StorageError& e) {
      CloseSession("stopped: results could not be written");
      throw StorageError(std::string(e.what()) + "\n" + SafeTrialsNote());
    }
    FinishSession();
    result_.seconds = Seconds(start_, Clock::now());
    return result_;
  }

 private:
  bool root() const { return rank_ == 0; }

  // Best effort: the manifest says how the session ended; if even that cannot be written, the
  // old manifest stays as it was (atomic writes never leave a partial file).
  void CloseSession(const std::string& ended) {
    if (!root()) return;
    try {
      Json& session = manifest_["sessions"][session_];
      session["end"] = UtcNow();
      session["ended"] = ended;
      dir_.AppendLog("session " + std::to_string(session_ + 1) + " " + ended);
      dir_.WriteManifest(manifest_);
    } catch (const std::exception&) {
    }
  }

  // What a user needs after a storage failure: what is safe and how to go on.
  std::string SafeTrialsNote() const {
    const long long safe = result_.done_before + result_.computed;
    return std::to_string(safe) + " of " + std::to_string(result_.total) +
           " trials are safely recorded in " + store_path_ +
           " (committed batches are never lost). Free space or fix the disk, then run the same "
           "command again: the run resumes where it stopped and gives the same tables.";
  }

  // An MPI job under the static schedule: each rank knows from the recorded trials which cells
  // its share touches, and prepares only those (RankCells). The dynamic schedule hands out trials
  // of any cell and stop_when decides over every cell: there every rank prepares every cell.
  bool RanksShareCells() const {
    return ranks_ > 1 && !options_.dynamic_schedule &&
           !(study_.stop_when.enabled() && options_.shard_count == 1);
  }

  // The cells this process prepares (indices, in order) and what for: those with trials of its
  // share still to compute, or with no row in the main store, as the run directory stands before
  // the lock. A resume then prepares only its unfinished cells, for their trials alone when the
  // store holds their row (written by the session that prepared them in full), and a rerun of a
  // finished run prepares none. An MPI job under the static schedule: this rank's cells
  // (RankCellsBeforeLock). Every cell in full for a new directory, an MPI job under the dynamic
  // schedule (every rank runs trials of any cell and writes every row to its own store), a
  // stop_when run (it decides in the loop, over every cell) or anything unusual (no manifest,
  // another study, a damaged store), whose checks under the lock then say what is wrong.
  // PrepareLateCells covers a store that changed between this reading and the lock.
  std::vector<std::pair<int, CellPreparation>> CellsToPrepare() {
    if (RanksShareCells()) return RankCellsBeforeLock();
    const int num_cells = static_cast<int>(study_.cells.size());
    std::vector<std::pair<int, CellPreparation>> all;
    for (int i = 0; i < num_cells; ++i) all.emplace_back(i, CellPreparation::kFull);
    DoneSet done;
    std::set<std::string> stored;
    if (ranks_ > 1 || (study_.stop_when.enabled() && options_.shard_count == 1) ||
        !ReadBeforeLock(&done, &stored))
      return all;
    std::vector<std::pair<int, CellPreparation>> needed;
    for (int i = 0; i < num_cells; ++i) {
      const auto u = static_cast<std::size_t>(i);
      if (stored.count(study_.cells[u].id) == 0)
        needed.emplace_back(i, CellPreparation::kFull);
      else if (MissingInShare(done[u]) > 0)
        needed.emplace_back(i, CellPreparation::kForTrials);
    }
    return needed;
  }

  // The run directory as it stands before the lock: the trials recorded in any of its stores and
  // the main store's cell rows. False, with nothing read, for a new directory or anything unusual
  // (another study, a damaged store), whose checks under the lock then say what is wrong.
  bool ReadBeforeLock(DoneSet* done, std::set<std::string>* rows) const {
    if (!dir_.HasManifest()) return false;
    try {
      RunDirectory::CheckCompatible(dir_.ReadManifest(), study_.ToJson(), study_.path,
                                    options_.shard_index, options_.shard_count);
      for (std::string& id : TrialStore(dir_.MainStorePath()).CellIds())
        rows->insert(std::move(id));
      *done = dir_.ReadDone(study_);
      return true;
    } catch (const std::exception&) {
      rows->clear();
      return false;
    }
  }

  // An MPI job under the static schedule: the cells whose trials the schedule deals to this
  // rank, given the recorded trials `done` (about 1/P of the cells), for their trials alone when
  // the main store holds their row (`rows`); and on rank 0, in full, those no rank runs trials of
  // whose row the main store lacks, so that every cell has its row after the merge, as in one
  // process.
  std::vector<std::pair<int, CellPreparation>> RankCells(const DoneSet& done,
                                                         const std::set<std::string>& rows) const {
    const StaticScheduleCells cells = CellsOfStaticSchedule(
        MissingTrials(&done, study_.trials, options_.shard_index, options_.shard_count),
        study_.cells.size(), rank_, ranks_, options_.max_new_trials);
    std::vector<std::pair<int, CellPreparation>> which;
    for (std::size_t c = 0; c < study_.cells.size(); ++c) {
      const bool row = rows.count(study_.cells[c].id) > 0;
      if (cells.mine[c])
        which.emplace_back(static_cast<int>(c),
                           row ? CellPreparation::kForTrials : CellPreparation::kFull);
      else if (root() && !cells.anyone[c] && !row)
        which.emplace_back(static_cast<int>(c), CellPreparation::kFull);
    }
    return which;
  }

  // RankCells as the run directory stands before the lock (every rank reads it; a new or
  // unusual directory counts as holding nothing). PrepareLateCells checks under the lock.
  std::vector<std::pair<int, CellPreparation>> RankCellsBeforeLock() {
    DoneSet done;
    std::set<std::string> rows;
    if (!ReadBeforeLock(&done, &rows))
      done.assign(study_.cells.size(), std::vector<bool>(static_cast<std::size_t>(study_.trials)));
    std::vector<std::pair<int, CellPreparation>> which = RankCells(done, rows);
    rows_before_lock_ = std::move(rows);
    return which;
  }

  // PrepareCells, every rank learning whether any failed: in an MPI job under the static schedule
  // a cell fails on the rank that prepares it alone. Every rank then throws the error of the
  // lowest failing rank (rank 0 prints it; an input error gives exit 2 from every rank), so that
  // no rank goes on to wait for the others and nothing is written before the lock.
  void PrepareCellsOnEveryRank(const std::vector<std::pair<int, CellPreparation>>& which,
                               bool before_writing) {
    if (ranks_ == 1) {
      PrepareCells(which, before_writing);
      return;
    }
    std::exception_ptr failure;
    std::string error;  // "I" (the study's fault) or "E", then the message
    try {
      PrepareCells(which, before_writing);
    } catch (const InputError& e) {
      failure = std::current_exception();
      error = std::string("I") + e.what();
    } catch (const std::exception& e) {
      failure = std::current_exception();
      error = std::string("E") + e.what();
    }
    const std::string first = collective_->FirstNonEmpty(error);
    if (first.empty()) return;
    if (!before_writing) CloseSession("stopped: a cell could not be prepared");
    if (failure && first == error) std::rethrow_exception(failure);
    if (first[0] == 'I') throw InputError("", first.substr(1));
    throw std::runtime_error(first.substr(1));
  }

  // PrepareLateCells of an MPI job under the static schedule: every rank prepares what RankCells
  // gives under the lock and it lacks, and writes the rows of what it prepares in full. Rank 0
  // alone sees the main store under the lock: a row that was there before the lock and is gone
  // belongs to a cell the other ranks prepared for its trials alone, so rank 0 prepares it in
  // full and writes the row.
  void PrepareLateRankCells() {
    std::map<int, CellPreparation> late;
    for (const auto& [c, what] : RankCells(done_, rows_before_lock_))
      if (!contexts_[static_cast<std::size_t>(c)]) late[c] = what;
    if (root())
      for (std::size_t c = 0; c < contexts_.size(); ++c) {
        const std::string& id = study_.cells[c].id;
        const CellContext* context = contexts_[c].get();
        const bool full = context && !context->for_trials_only;
        if (!full && rows_before_lock_.count(id) > 0 && main_rows_.count(id) == 0)
          late[static_cast<int>(c)] = CellPreparation::kFull;
      }
    const std::vector<std::pair<int, CellPreparation>> which(late.begin(), late.end());
    PrepareCellsOnEveryRank(which, false);
    for (const auto& [c, what] : which) {
      const auto& context = contexts_[static_cast<std::size_t>(c)];
      if (context && !context->for_trials_only) store_->PutCell(ToStoredCell(*context));
    }
  }

  // Insurance, under the lock: a cell that FindMissingTrials finds with trials to compute and
  // CellsToPrepare did not prepare, or whose row the main store lacks and that was not prepared
  // in full (the store changed in between), is prepared now (its row written), before any trial.
  void PrepareLateCells() {
    if (RanksShareCells()) {
      PrepareLateRankCells();
      return;
    }
    std::set<std::string> stored;
    if (ranks_ == 1)
      for (std::string& id : store_->CellIds()) stored.insert(std::move(id));
    std::vector<std::pair<int, CellPreparation>> late;
    for (std::size_t c = 0; c < contexts_.size(); ++c) {
      const bool no_row = ranks_ == 1 && stored.count(study_.cells[c].id) == 0;
      const CellContext* context = contexts_[c].get();
      if (no_row && (!context || context->for_trials_only))
        late.emplace_back(static_cast<int>(c), CellPreparation::kFull);
      else if (!context && MissingInShare(done_[c]) > 0)
        late.emplace_back(static_cast<int>(c), CellPreparation::kForTrials);
    }
    if (late.empty()) return;
    PrepareCells(late, false);
    for (const auto& [c, what] : late) {  // a stop between cells leaves some unprepared
      const auto& context = contexts_[static_cast<std::size_t>(c)];
      if (context && what == CellPreparation::kFull) store_->PutCell(ToStoredCell(*context));
    }
  }

  // This shard's trials of a cell: indices shard_index, shard_index + shard_count, ...
  long long ShareSize() const {
    return study_.trials > options_.shard_index
               ? (study_.trials - options_.shard_index + options_.shard_count - 1) /
                     options_.shard_count
               : 0;
  }
  // How many of this shard's trials of a cell (`recorded`: one flag per trial) are not recorded.
  long long MissingInShare(const std::vector<bool>& recorded) const {
    long long missing = 0;
    for (long long t = options_.shard_index; t < study_.trials; t += options_.shard_count)
      missing += !recorded[static_cast<std::size_t>(t)];
    return missing;
  }

  // Prepares the cells `which` ((index, what for), in index order) on all threads. Every rank
  // prepares every cell it needs (the same deterministic result): cells are independent and
  // PrepareCell is a pure function of the study and the cell (memos return the bits they would
  // compute), so the contexts (and everything computed from them) depend neither on the thread
  // count nor on which other cells are prepared. Workers claim cells in order; after a failure no
  // new cell is claimed, and the error of the first failing cell in order is thrown — every earlier
  // cell was claimed and prepared, so it is the error a single thread would have met.
  // `before_writing`: nothing is written yet, so a signal ends the process at once; otherwise
  // (PrepareLateCells) the stop token is checked between cells and the trials then stop.
  void PrepareCells(const std::vector<std::pair<int, CellPreparation>>& which,
                    bool before_writing) {
    // Signals end the process at once while nothing is written (see OnStopSignal); a library
    // caller's own stop token is checked between cells.
    struct Preparing {
      explicit Preparing(bool on) : on_(on) {
        if (on_) g_preparing.store(true);
      }
      ~Preparing() {
        if (on_) g_preparing.store(false);
      }
      bool on_;
    } preparing(before_writing);
    const auto start = Clock::now();
    const int count = static_cast<int>(which.size());
    std::vector<std::unique_ptr<CellContext>> prepared(which.size());
    std::vector<std::exception_ptr> errors(which.size());
    std::atomic<int> next{0};
    std::atomic<bool> failed{false};
    PreparationProgress progress(options_.progress && root(), start_, count);
    const auto work = [&] {
      for (int i = next++; i < count && !failed && !stop_->stop_requested(); i = next++) {
        const auto u = static_cast<std::size_t>(i);
        try {
          prepared[u] = PrepareCell(study_, study_.cells[static_cast<std::size_t>(which[u].first)],
                                    which[u].second);
        } catch (...) {
          errors[u] = std::current_exception();
          failed = true;
        }
        progress.CellDone();
      }
    };
    std::vector<std::thread> workers;
    for (int t = 1; t < std::min(threads_, count); ++t) workers.emplace_back(work);
    work();
    for (std::thread& w : workers) w.join();
    for (const std::exception_ptr& e : errors)
      if (e) std::rethrow_exception(e);
    for (std::size_t i = 0; i < prepared.size() && prepared[i]; ++i) {
      contexts_[static_cast<std::size_t>(which[i].first)] = std::move(prepared[i]);
      ++result_.cells_prepared;
    }
    progress.Finish();
    ClearPreparationMemos();  // the cells hold what they share
    result_.prepare_seconds += Seconds(before_writing ? start_ : start, Clock::now());
  }

  // Rank 0: lock the directory, check and extend the manifest, log the session and write the
  // rows of the cells prepared in full to the main store.
  void StartSession() {
    dir_.CreateAndLock();
    Json manifest;
    if (dir_.HasManifest()) {
      manifest = dir_.ReadManifest();
      RunDirectory::CheckCompatible(manifest, study_.ToJson(), study_.path, options_.shard_index,
                                    options_.shard_count);
    }
    manifest_ = RunDirectory::StartSession(manifest, study_, options_.shard_index,
                                           options_.shard_count, threads_, ranks_, &session_);
    dir_.WriteManifest(manifest_);
    dir_.AppendLog("session " + std::to_string(session_ + 1) + " started: study '" + study_.name +
                   "', " + std::to_string(study_.cells.size()) + " cells x " +
                   std::to_string(study_.trials) + " trials, " + std::to_string(threads_) +
                   " threads" + (ranks_ > 1 ? ", " + std::to_string(ranks_) + " MPI ranks" : "") +
                   (options_.shard_count > 1
                        ? ", shard " + std::to_string(options_.shard_index + 1) + "/" +
                              std::to_string(options_.shard_count)
                        : ""));
    TrialStore main_store(dir_.MainStorePath());
    main_store.SetMeta("study", study_.ToJson().dump());
    if (RanksShareCells())
      for (std::string& id : main_store.CellIds()) main_rows_.insert(std::move(id));
    for (const auto& context : contexts_)
      if (context && !context->for_trials_only) main_store.PutCell(ToStoredCell(*context));
  }

  // Rank 0 owns the directory: lock, manifest (and its refusals), main store. Every rank
  // learns whether that worked; then each opens its own store.
  void OpenRunDirectory() {
    std::string refusal;
    if (root()) {
      try {
        StartSession();
      } catch (const std::exception& e) {
        if (ranks_ == 1) throw;
        refusal = e.what();
      }
    }
    refusal = collective_->Broadcast(refusal);
    if (!refusal.empty()) throw InputError("", refusal);
    // This process's store: the main store, or its own rank store in an MPI job.
    store_path_ = ranks_ == 1 ? dir_.MainStorePath() : dir_.RankStorePath(rank_);
    store_ = std::make_unique<TrialStore>(store_path_);
    if (ranks_ > 1)
      for (const auto& context : contexts_)
        if (context && !context->for_trials_only) store_->PutCell(ToStoredCell(*context));
    collective_->Barrier();  // every store exists with its tables
  }

  // Done: the union over every store of the directory (a killed MPI run leaves rank stores
  // behind; whatever they hold counts, with any number of ranks now).
  void FindMissingTrials() {
    done_ = dir_.ReadDone(study_, store_.get());
    collective_->Barrier();          // nobody writes before every rank has read
    std::vector<long long> missing;  // per cell, this process's share (for the ETA)
    const long long share = ShareSize();
    for (const auto& cell : done_) {
      missing.push_back(MissingInShare(cell));
      result_.total += share;
      result_.done_before += share - missing.back();
      missing.back() = (missing.back() + ranks_ - 1) / ranks_;
    }
    eta_ = std::make_unique<RemainingTimeEstimate>(std::move(missing));
    // stop_when needs every trial of a block to decide; a shard sees only its share, so shards
    // run to the maximum and the merge applies the rule (same tables).
    adaptive_ = study_.stop_when.enabled() && options_.shard_count == 1;
    dynamic_ = options_.dynamic_schedule && ranks_ > 1;
    if (!adaptive_)
      work_ = MakeWorkSource(
          MissingTrials(&done_, study_.trials, options_.shard_index, options_.shard_count),
          options_.max_new_trials);
  }

  std::unique_ptr<WorkSource> MakeWorkSource(MissingTrials missing, long long max_new) {
    return dynamic_ ? MakeDynamicSchedule(std::move(missing), collective_, max_new)
                    : MakeStaticSchedule(std::move(missing), rank_, ranks_, max_new);
  }

  // One worker thread: claims trials, computes them, hands the records to the writer.
  void Worker(RecordQueue* queue) {
    TrialWorkspace ws;
    std::vector<TrialRecord> local;
    std::vector<TrialId> chunk;
    constexpr int kClaim = 8;
    try {
      while (!stop_->stop_requested()) {
        work_->Claim(kClaim, &chunk);
        if (chunk.empty()) break;
        for (const auto& [cell, trial] : chunk) {
          const CellContext* context = contexts_[static_cast<std::size_t>(cell)].get();
          if (!context)  // every cell with a missing trial was prepared (PrepareLateCells)
            throw std::logic_error("trial of cell " + study_.cells[cell].id + " not prepared");
          local.push_back(RunTrial(*context, trial, &ws));
        }
        queue->Push(&local);
      }
    } catch (...) {
      queue->Fail(std::current_exception());
      stop_->RequestStop();
    }
    queue->WorkerDone();
  }

  // Writes one batch of records (the writer's step).
  void Commit(std::vector<TrialRecord>* batch) {
    store_->Insert(*batch);
    for (const auto& r : *batch) {
      result_.trial_seconds += r.seconds;
      const auto cell = cell_index_.find(r.cell_id);
      if (cell != cell_index_.end()) eta_->Record(cell->second, r.seconds);
    }
    result_.computed += static_cast<long long>(batch->size());
    batch->clear();
  }

  // Workers compute; this thread writes batches, reports progress and pumps the schedule. With
  // stop_when the trials run in rounds (one block of every cell still running), each followed by
  // the decisions.
  void RunTrials() {
    const auto t_run = Clock::now();
    const long long expected =
        result_.done_before +
        (adaptive_ ? result_.total - result_.done_before : work_->share() * ranks_);
    progress_ = std::make_unique<ProgressReporter>(
        options_.progress && root(), ranks_, result_.total, result_.done_before, expected, t_run,
        // A run whose total changes as cells stop, or one cut at --max-trials: by the rate.
        adaptive_ || options_.max_new_trials > 0 ? nullptr : eta_.get());
    ProgressReporter& progress = *progress_;
    if (adaptive_) {
      RunRounds(&progress);
    } else {
      RunRound(&progress);
    }
    result_.run_seconds = Seconds(t_run, Clock::now());
    progress.Report(result_.computed, true);
    NotifyProgress();
    result_.peak_rss_kb_trials = PeakRssKb();
  }

  // The adaptive loop: a round computes [next, next boundary) of every undecided cell; then
  // rank 0 feeds those trials, in canonical order, from every store to the cells' stopping
  // rules and tells every rank what it decided. Stops with the run (signal, --max-trials) or
  // when every cell is decided.
  void RunRounds(ProgressReporter* progress) {
    const int num_cells = static_cast<int>(study_.cells.size());
    if (root()) stopping_.assign(num_cells, CellStopping(study_.stop_when, study_.trials));
    std::vector<TrialRange> ranges(num_cells, TrialRange{0, study_.stop_when.block});
    while (true) {
      bool any = false;
      for (const auto& [first, end] : ranges) any |= end > first;
      if (!any) {
        all_decided_ = true;
        break;
      }
      long long max_new = 0;
      if (options_.max_new_trials > 0) {
        max_new = options_.max_new_trials - result_.computed;
        if (max_new <= 0) break;
      }
      work_ = MakeWorkSource(MissingTrials(&done_, study_.trials, 0, 1, ranges), max_new);
      RunRound(progress);
      const bool stopping =
          stop_->stop_requested() ||
          (options_.max_new_trials > 0 && result_.computed >= options_.max_new_trials);
      if (collective_->SumAll(stopping ? 1 : 0) > 0) break;  // every rank leaves together
      ranges = Decide(progress);
    }
  }

  // Rank 0 reads the round's trials (its store, or every rank's once they are committed) and
  // feeds the stopping rules; every rank gets the next round's ranges.
  std::vector<TrialRange> Decide(ProgressReporter* progress) {
    collective_->Barrier();  // every rank has committed its round
    std::string decisions;
    if (root()) {
      std::vector<std::unique_ptr<TrialStore>> others;
      std::vector<const TrialStore*> stores = {store_.get()};
      if (ranks_ > 1) {
        stores.clear();
        for (const std::string& path : dir_.StorePaths()) {
          others.push_back(std::make_unique<TrialStore>(path));
          stores.push_back(others.back().get());
        }
      }
      Json ranges = Json::array();
      long long total = 0;
      int stopped_early = 0, decided = 0;
      for (std::size_t c = 0; c < stopping_.size(); ++c) {
        CellStopping& state = stopping_[c];
        if (!state.decided() &&
            !FeedStopping(stores, study_.cells[c].id, state.next_boundary(), &state))
          throw std::logic_error("stop_when: a round ended with trials of cell " +
                                 study_.cells[c].id + " unrecorded");
        if (state.decided()) {
          ranges.push_back({0, 0});
          ++decided;
          stopped_early += state.trials_used() < study_.trials;
        } else {
          ranges.push_back({state.next(), state.next_boundary()});
        }
        total += state.trials_used();
      }
      result_.total = total;
      const std::string note = "  " + std::to_string(decided) + "/" +
                               std::to_string(stopping_.size()) + " cells done (" +
                               std::to_string(stopped_early) + " stopped early)";
      progress->SetTotal(total, total, note);
      decisions = Json({{"ranges", ranges}, {"total", total}}).dump();
    }
    const Json j = Json::parse(collective_->Broadcast(decisions));
    result_.total = j["total"].get<long long>();
    std::vector<TrialRange> next;
    for (const auto& r : j["ranges"])
      next.emplace_back(r[0].get<long long>(), r[1].get<long long>());
    return next;
  }

  // One pass of the workers over work_: they compute, this thread writes.
  void RunRound(ProgressReporter* progress) {
    RecordQueue queue(threads_, static_cast<std::size_t>(options_.batch_size));
    std::vector<std::thread> pool;
    std::exception_ptr writer_failure;
    try {
      for (int i = 0; i < threads_; ++i) {
        try {
          pool.emplace_back([this, &queue] { Worker(&queue); });
        } catch (const std::system_error& e) {
          // Not every thread could start (a process limit): the others are stopped below.
          for (int k = i; k < threads_; ++k) queue.WorkerDone();
          throw SettingError(RunOptions::Settings()[0].spec,
                             "could start only " + std::to_string(i) + " of " +
                                 std::to_string(threads_) + " worker threads (" + e.what() +
                                 "); run with fewer threads");
        }
      }
      WriterLoop(&queue, progress);
    } catch (...) {
      // The writer failed (e.g. the disk is full) or a thread could not start: stop the
      // workers, join them, and report; committed records stay.
      writer_failure = std::current_exception();
      stop_->RequestStop();
      work_->Pump(true, false);
    }
    for (auto& t : pool) t.join();
    if (writer_failure) std::rethrow_exception(writer_failure);
    if (auto failure = queue.failure()) std::rethrow_exception(failure);
  }

  void NotifyProgress() const {
    if (!options_.on_progress || !root()) return;
    RunProgress p;
    p.total = result_.total;
    p.computed = result_.computed;
    p.done = std::min(result_.total, result_.done_before + result_.computed * ranks_);
    p.seconds = Seconds(start_, Clock::now());
    if (progress_) p.eta_seconds = progress_->SecondsLeft(result_.computed);
    options_.on_progress(p);
  }

  void WriterLoop(RecordQueue* queue, ProgressReporter* progress) {
    const auto wait = std::chrono::milliseconds(dynamic_ ? 1 : 100);
    const std::size_t batch_size = static_cast<std::size_t>(options_.batch_size);
    auto last_flush = Clock::now();
    std::vector<TrialRecord> batch;
    work_->Pump(false, false);
    while (true) {
      const bool workers_done = queue->Take(wait, &batch);
      const auto now = Clock::now();
      if (workers_done || batch.size() >= batch_size || Seconds(last_flush, now) >= 1.0) {
        Commit(&batch);
        last_flush = now;
      }
      progress->Tick(result_.computed);
      NotifyProgress();
      const bool stopping = stop_->stop_requested() || work_->Exhausted();
      if (work_->Pump(stopping, workers_done) && workers_done) break;
    }
  }

  // The run stopped at --max-trials (this process's limit), not at a signal, before the end.
  bool ReachedMaxTrials() const {
    return !result_.complete && !stop_->stop_requested() && options_.max_new_trials > 0 &&
           result_.computed >= options_.max_new_trials;
  }

  // The trials of this shard recorded now, on rank 0 after the merge. One process: those
  // recorded before (the union over every store, read under the lock) and those it committed,
  // none of them recorded before (MissingTrials). Ranks: what the merged store holds.
  long long RecordedInShare(const TrialStore& main_store) const {
    if (ranks_ == 1) return result_.done_before + result_.computed;
    long long recorded = 0;
    for (const Cell& cell : study_.cells)
      for (long long t : main_store.DoneTrials(cell.id))
        if (t >= 0 && t < study_.trials && t % options_.shard_count == options_.shard_index)
          ++recorded;
    return recorded;
  }

  // Rank 0 folds the rank stores into the main store and closes the session in the manifest.
  void FinishSession() {
    result_.ranks_computed = collective_->SumAll(result_.computed);
    const long long cells_prepared = collective_->SumAll(result_.cells_prepared);
    store_.reset();          // close this process's store before rank 0 merges it
    collective_->Barrier();  // every rank's records are committed
    if (root()) {
      TrialStore main_store(dir_.MainStorePath());
      dir_.MergeRankStores(&main_store);
      const long long done_now = RecordedInShare(main_store);
      result_.complete = adaptive_ ? all_decided_ : done_now >= result_.total;
      result_.interrupted = stop_->stop_requested() || !result_.complete;
      result_.reached_max_trials = ReachedMaxTrials();
      Json& session = manifest_["sessions"][session_];
      session["end"] = UtcNow();
      session["trials_computed"] = result_.ranks_computed;
      session["ended"] = result_.reached_max_trials ? "max_trials"
                         : result_.interrupted      ? "interrupted"
                                                    : "completed";
      session["seconds"] = {{"prepare", result_.prepare_seconds},
                            {"trials", result_.run_seconds},
                            {"sum_of_trial_times", result_.trial_seconds}};
      result_.peak_rss_kb = PeakRssKb();
      session["peak_rss_kb"] = {{"after_trials", result_.peak_rss_kb_trials}};
      session["cells_prepared"] = cells_prepared;  // by every rank
      dir_.WriteManifest(manifest_);
      dir_.AppendLog(
          "session " + std::to_string(session_ + 1) + " ended (" +
          session["ended"].get<std::string>() + "): " + std::to_string(result_.ranks_computed) +
          " trials computed, " + std::to_string(result_.done_before) + " recorded before, of " +
          std::to_string(result_.total) + "; prepare " + Fixed(result_.prepare_seconds, 1) +
          " s, trials " + Fixed(result_.run_seconds, 1) + " s; peak memory " +
          std::to_string(result_.peak_rss_kb / 1024) + " MiB");
      dir_.Unlock();
    } else {
      // Completeness is rank 0's to judge (from the merged store); this rank knows its stop
      // token and, under the static schedule, whether it finished its share.
      result_.interrupted =
          stop_->stop_requested() ||
          (adaptive_ ? !all_decided_ : !dynamic_ && result_.computed < work_->share());
      result_.reached_max_trials = result_.interrupted && ReachedMaxTrials();
    }
    collective_->Barrier();  // rank 0 has merged: the run directory is consistent
  }

  const Study& study_;
  const RunOptions& options_;
  Collective* collective_;
  StopToken* stop_;
  const int rank_, ranks_, threads_;
  RunDirectory dir_;
  Clock::time_point start_;
  RunResult result_;
  std::vector<std::unique_ptr<CellContext>> contexts_;  // by cell index; null: not prepared
  Json manifest_;
  std::size_t session_ = 0;
  std::string store_path_;
  std::unique_ptr<TrialStore> store_;
  std::set<std::string> main_rows_;  // rank 0, MPI static schedule: the main store's cell rows
  std::set<std::string> rows_before_lock_;  // MPI static schedule: the same, before the lock
  DoneSet done_;
  std::map<std::string, int> cell_index_;  // cell id → index in study_.cells and contexts_
  std::unique_ptr<RemainingTimeEstimate> eta_;
  std::unique_ptr<ProgressReporter> progress_;
  bool dynamic_ = false;
  std::unique_ptr<WorkSource> work_;
  // stop_when (single process or MPI, not shards): the rules' state (rank 0) and whether every
  // cell is decided.
  bool adaptive_ = false, all_decided_ = false;
  std::vector<CellStopping> stopping_;
};

}  // namespace

namespace {
constexpr double kNoMax = std::numeric_limits<double>::infinity();
}  // namespace

// The run's settings that are not numbers: named for each front end like the numeric ones.
const SettingSpec& RunOptions::OutDirSetting() {
  static const SettingSpec spec =
      SettingSpec::Named("run", "out_dir", "out", "run directory", "out_dir");
  return spec;
}

const SettingSpec& RunOptions::ShardSetting() {
  static const SettingSpec spec =
      SettingSpec::Named("run", "shard", "shard", "this process's part of the trials, i/N");
  return spec;
}

const std::vector<SettingField<RunOptions>>& RunOptions::Settings() {
  using R = RunOptions;
  static const std::vector<SettingField<R>> fields = {
      {{"run", "threads", "threads", "", 1, "", 0, 4096, false, true, "worker threads", "all cores",
        "worker threads"},
       nullptr,
       &R::threads},
      {{"run", "max_new_trials", "max_trials", "", 1, "", 0, kNoMax, false, true,
        "new trials to compute", "no limit", "stop after this many new trials"},
       nullptr,
       nullptr,
       &R::max_new_trials},
      {{"run", "batch_size", "batch_size", "", 1, "", 1, 1e6, false, true, "records per batch", "",
        "trial records per SQLite transaction"},
       nullptr,
       &R::batch_size},
  };
  return fields;
}

void RunOptions::Validate() const {
  if (out_dir.empty())
    throw SettingError(OutDirSetting(), "expected a run directory, got an empty name");
  CheckSettings(*this, Settings());
  if (shard_count < 1 || shard_index < 0 || shard_index >= shard_count)
    throw SettingError(ShardSetting(), "expected i/N with 1 <= i <= N");
}

long PeakRssKb() {
  struct rusage usage;
  return getrusage(RUSAGE_SELF, &usage) == 0 ? usage.ru_maxrss : -1;
}

void InstallStopHandlers() {
  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
}

RunResult RunStudy(const Study& study, const RunOptions& options, Collective* collective,
                   StopToken* stop) {
  options.Validate();
  std::unique_ptr<Collective> single;
  if (!collective) {
    single = SingleProcess();
    collective = single.get();
  }
  StopToken own_stop;
  if (!stop) stop = &own_stop;
  ActiveStop active(stop);
  return StudyRunner(study, options, collective, stop).Run();
}

std::string RunSummaryText(const RunResult& r, const RunOptions& options, int ranks) {
  std::ostringstream out;
  if (r.ranks_computed == 0 && r.done_before >= r.total) {
    out << "lrcal run: nothing to compute: all " << r.total
        << " trials of this run were already recorded"
        << (r.tables_current ? "; its tables are current (lrcal aggregate DIR rewrites them)" : "")
        << "\n";
    return out.str();
  }
  out << "lrcal run: " << r.ranks_computed << " trials computed in " << Fixed(r.seconds, 1)
      << " s (of " << r.total << " in this run; " << r.done_before << " were already recorded";
  if (r.computed > 0)
    out << "; " << Fixed(1e6 * r.trial_seconds / r.computed, 1) << " µs of compute per trial"
        << (ranks > 1 ? " on rank 0" : "");
  out << ")\n";
  if (r.computed == 0) return out.str();
  const int threads = options.threads > 0
                          ? options.threads
                          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // The runner's overhead is only measurable when the trials take a while: on a run of a few
  // milliseconds thread start-up dominates and a percentage would mislead.
  const std::string overhead =
      r.run_seconds >= 1.0
          ? "runner overhead " + Fixed(100 * (r.run_seconds * threads / r.trial_seconds - 1), 1) +
                " % over the trials' own time"
          : "too short to measure the runner's overhead";
  out << "lrcal run: wall time: prepare " << Fixed(r.prepare_seconds, 3) << " s ("
      << r.cells_prepared << (r.cells_prepared == 1 ? " cell" : " cells") << "), trials "
      << Fixed(r.run_seconds, 3) << " s (" << threads << " threads"
      << (ranks > 1 ? " on rank 0 of " + std::to_string(ranks) : std::string()) << "; " << overhead
      << "), tables " << Fixed(r.tables_seconds, 3) << " s; peak memory "
      << r.peak_rss_kb_trials / 1024 << " MiB after the trials, " << r.peak_rss_kb / 1024
      << " MiB with the tables\n";
  return out.str();
}

}  // namespace lrcal
