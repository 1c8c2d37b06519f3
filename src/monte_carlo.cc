#include "lrcal/monte_carlo.h"

#include <ceres/version.h>
#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <unistd.h>

#include <Eigen/Core>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "lrcal/build_info.h"
#include "lrcal/collective.h"
#include "lrcal/error.h"
#include "lrcal/study_report.h"
#include "lrcal/trial.h"
#include "lrcal/trial_store.h"

namespace lrcal {

namespace fs = std::filesystem;

namespace {

std::atomic<int> g_stop_signals{0};

void OnStopSignal(int) {
  if (g_stop_signals.fetch_add(1) >= 1) _exit(130);  // second signal: stop now
}

std::string Now() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

Json BuildInfo() {
  return {{"version", LRCAL_VERSION},
          {"commit", LRCAL_GIT_COMMIT},
          {"compiler", LRCAL_COMPILER},
          {"build_type", LRCAL_BUILD_TYPE}};
}

Json Dependencies() {
  return {{"eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) +
                        "." + std::to_string(EIGEN_MINOR_VERSION)},
          {"ceres", CERES_VERSION_STRING},
          {"sqlite", sqlite3_libversion()},
          {"random123", "Philox4x64-10, Random123 boxmuller"}};
}

Json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "cannot open file");
  try {
    return Json::parse(in);
  } catch (const Json::exception& e) {
    throw InputError(path.string(), std::string("not valid JSON: ") + e.what());
  }
}

void WriteJsonAtomically(const fs::path& path, const Json& j) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << j.dump(2) << "\n";
  }
  fs::rename(tmp, path);
}

// The parts of a study that must not change under a run directory.
Json Fingerprint(const Json& study) {
  return {{"name", study["name"]}, {"seed", study["seed"]}, {"trials", study["trials"]},
          {"base", study["base"]}};
}

class DirectoryLock {
 public:
  explicit DirectoryLock(const fs::path& dir) {
    const std::string path = (dir / "lock").string();
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT, 0644);
    if (fd_ < 0) throw InputError(path, "cannot create the lock file");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      fd_ = -1;
      throw InputError(dir.string(), "another lrcal process is running on this run directory; "
                                     "wait for it or stop it first");
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd_, 0) == 0 && ::write(fd_, pid.data(), pid.size()) < 0) {
    }
  }
  ~DirectoryLock() {
    if (fd_ >= 0) {
      ::flock(fd_, LOCK_UN);
      ::close(fd_);
    }
  }

 private:
  int fd_ = -1;
};

std::string RankStoreName(int rank) { return "trials.rank" + std::to_string(rank) + ".sqlite"; }

// The run directory's rank stores (trials.rank<r>.sqlite), sorted.
std::vector<fs::path> RankStorePaths(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("trials.rank", 0) == 0 && name.size() > 18 &&
        name.compare(name.size() - 7, 7, ".sqlite") == 0)
      out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The main store (if present) and every rank store.
std::vector<fs::path> StorePaths(const fs::path& dir) {
  std::vector<fs::path> out;
  if (fs::exists(dir / "trials.sqlite")) out.push_back(dir / "trials.sqlite");
  for (const auto& p : RankStorePaths(dir)) out.push_back(p);
  return out;
}

// Moves every rank store's records into the main store and removes the rank stores.
void MergeRankStores(const fs::path& dir, TrialStore* main_store) {
  for (const fs::path& path : RankStorePaths(dir)) {
    main_store->MergeFrom(path.string());
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(path.string() + suffix);
  }
}

// The manifest of a run directory; InputError if `dir` is not one.
Json ReadRunManifest(const fs::path& dir) {
  if (!fs::exists(dir / "manifest.json") || !fs::exists(dir / "trials.sqlite"))
    throw InputError(dir.string(), "not an lrcal run directory (expected manifest.json and "
                                   "trials.sqlite)");
  return ReadJson(dir / "manifest.json");
}

// Peak resident set size of this process so far (kB).
long PeakRssKb() {
  struct rusage usage;
  return getrusage(RUSAGE_SELF, &usage) == 0 ? usage.ru_maxrss : -1;
}

std::string Duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  char buf[32];
  const long long t = static_cast<long long>(s + 0.5);
  std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", t / 3600, t / 60 % 60, t % 60);
  return buf;
}

}  // namespace

void InstallStopHandlers() {
  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
}

void ParseShard(const std::string& text, int* index, int* count) {
  const auto slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("");
    std::size_t a = 0, b = 0;
    const int i = std::stoi(text.substr(0, slash), &a);
    const int n = std::stoi(text.substr(slash + 1), &b);
    if (a != slash || b != text.size() - slash - 1 || n < 1 || i < 1 || i > n)
      throw std::invalid_argument("");
    *index = i - 1;
    *count = n;
  } catch (const std::exception&) {
    throw InputError("--shard", "expected i/N with 1 <= i <= N (e.g. 2/8), got '" + text + "'");
  }
}

RunResult RunStudy(const Study& study, const RunOptions& options, Collective* collective) {
  std::unique_ptr<Collective> single;
  if (!collective) {
    single = SingleProcess();
    collective = single.get();
  }
  const int rank = collective->rank(), ranks = collective->size();
  const bool root = rank == 0;
  const auto t0 = std::chrono::steady_clock::now();
  // Prepare the cells (configurations, designs, predicted covariance) first, on every rank (the
  // same deterministic result): a study that cannot run fails here, before anything is written.
  std::vector<std::unique_ptr<CellContext>> contexts;
  for (const Cell& cell : study.cells) contexts.push_back(PrepareCell(study, cell));
  const auto t_prepared = std::chrono::steady_clock::now();

  const fs::path dir = options.out_dir;
  const Json study_json = study.ToJson();
  const fs::path manifest_path = dir / "manifest.json";
  const int threads = options.threads > 0 ? options.threads
                                          : std::max(1u, std::thread::hardware_concurrency());
  // Rank 0 owns the directory: lock, manifest (and its refusals), main store. Every rank learns
  // whether that worked.
  std::unique_ptr<DirectoryLock> lock;
  Json manifest;
  std::size_t session_index = 0;
  std::string refusal;
  if (root) {
    try {
      fs::create_directories(dir);
      lock = std::make_unique<DirectoryLock>(dir);
      if (fs::exists(manifest_path)) {
        manifest = ReadJson(manifest_path);
        const auto changes = DiffJson(Fingerprint(manifest["study"]), Fingerprint(study_json));
        if (!changes.empty()) {
          std::string msg = "this run directory holds a different study; changed:";
          for (const auto& c : changes) msg += "\n  " + c;
          msg += "\nrun it in a new directory (--out), or restore the study file";
          throw InputError(study.path, msg);
        }
        const Json shard = {{"index", options.shard_index + 1}, {"count", options.shard_count}};
        if (manifest.contains("shard") && manifest["shard"] != shard)
          throw InputError("--shard", "this run directory is shard " +
                                          manifest["shard"]["index"].dump() + "/" +
                                          manifest["shard"]["count"].dump() +
                                          "; rerun it with that --shard");
      } else {
        manifest["created"] = Now();
        manifest["sessions"] = Json::array();
      }
      manifest["study_file"] = study.path;
      manifest["study"] = study_json;
      manifest["seed"] = study.seed;
      manifest["shard"] = {{"index", options.shard_index + 1}, {"count", options.shard_count}};
      manifest["lrcal"] = BuildInfo();
      manifest["dependencies"] = Dependencies();
      manifest["random_numbers"] =
          "Philox4x64-10 (Random123) addressed by (seed, stream, trial, purpose, index); standard "
          "normals by Random123's Box-Muller. Common random numbers: the reading noise and drawn "
          "truths are keyed by the trial index only, so cells that differ in sigma, repetitions, "
          "configuration count or selection see the same standard normals (noise of a "
          "configuration is addressed by its index in the candidate pool). Pools and validation "
          "sets are keyed by a hash of the settings they depend on.";
      manifest["sessions"].push_back(
          {{"start", Now()}, {"threads", threads}, {"ranks", ranks}, {"ended", "running"}});
      session_index = manifest["sessions"].size() - 1;
      WriteJsonAtomically(manifest_path, manifest);
      TrialStore main_store((dir / "trials.sqlite").string());
      main_store.SetMeta("study", study_json.dump());
      for (const auto& context : contexts) main_store.PutCell(ToStoredCell(*context));
    } catch (const std::exception& e) {
      if (ranks == 1) throw;
      refusal = e.what();
    }
  }
  refusal = collective->Broadcast(refusal);
  if (!refusal.empty()) throw InputError("", refusal);

  // This process's store: the main store, or its own rank store in an MPI job ("each rank
  // writes its own records"; rank 0 merges them at the end).
  const fs::path my_path = ranks == 1 ? dir / "trials.sqlite" : dir / RankStoreName(rank);
  auto store = std::make_unique<TrialStore>(my_path.string());
  if (ranks > 1)
    for (const auto& context : contexts) store->PutCell(ToStoredCell(*context));
  collective->Barrier();  // every store exists with its tables

  // Done: the union over the main store and every rank store in the directory (a killed MPI run
  // leaves rank stores behind; whatever they hold counts, with any number of ranks now).
  RunResult result;
  const long long trials = study.trials;
  std::vector<std::vector<bool>> done(study.cells.size(), std::vector<bool>(trials, false));
  for (const fs::path& path : StorePaths(dir)) {
    std::unique_ptr<TrialStore> other;
    const TrialStore* s = store.get();
    if (path != my_path) {
      other = std::make_unique<TrialStore>(path.string());
      s = other.get();
    }
    for (std::size_t c = 0; c < study.cells.size(); ++c)
      for (long long t : s->DoneTrials(study.cells[c].id))
        if (t >= 0 && t < trials) done[c][t] = true;
  }
  collective->Barrier();  // nobody writes before every rank has read
  for (std::size_t c = 0; c < study.cells.size(); ++c)
    for (long long t = options.shard_index; t < trials; t += options.shard_count) {
      ++result.total;
      if (done[c][t]) ++result.done_before;
    }
  // The missing trials, in canonical order, are dealt to the ranks in turn (static schedule:
  // no messages while trials run); max_new_trials limits each process.
  const long long missing = result.total - result.done_before;
  long long my_share = missing / ranks + (rank < missing % ranks ? 1 : 0);
  if (options.max_new_trials > 0) my_share = std::min(my_share, options.max_new_trials);
  const long long space = static_cast<long long>(study.cells.size()) * trials;
  std::mutex claim_mutex;
  long long cursor = 0;        // next (cell·trials + trial) to look at
  long long missing_seen = 0;  // missing trials passed so far (all ranks' turns)
  long long claimed = 0;       // trials handed to this process's workers
  // Dynamic schedule (MPI): chunks of kDynamicChunk missing trials, numbered in canonical order,
  // handed out by rank 0; each rank's chunks arrive in increasing order, so its cursor only
  // moves forward.
  const bool dynamic = options.dynamic_schedule && ranks > 1;
  constexpr long long kDynamicChunk = 64;
  const long long num_chunks = (missing + kDynamicChunk - 1) / kDynamicChunk;
  if (dynamic) {
    my_share = missing;  // bounded by the chunks this rank receives
    if (options.max_new_trials > 0) my_share = std::min(my_share, options.max_new_trials);
  }
  std::deque<long long> chunks;      // chunk ids received, not started
  bool no_more_chunks = false;
  long long chunk_left = 0;          // trials left in the chunk being handed out
  std::condition_variable chunk_cv;
  // Advances the cursor to the next missing trial of this shard; returns false at the end.
  auto next_missing = [&](int* c, long long* t) {
    while (cursor < space) {
      *c = static_cast<int>(cursor / trials);
      *t = cursor % trials;
      ++cursor;
      if (*t % options.shard_count != options.shard_index || done[*c][*t]) continue;
      ++missing_seen;
      return true;
    }
    return false;
  };
  auto claim = [&](std::vector<std::pair<int, long long>>* out, int max) {
    out->clear();
    std::unique_lock<std::mutex> g(claim_mutex);
    int c;
    long long t;
    while (static_cast<int>(out->size()) < max && claimed < my_share) {
      if (!dynamic) {
        bool found = false;
        while (next_missing(&c, &t)) {
          if ((missing_seen - 1) % ranks == rank) {
            found = true;
            break;
          }
        }
        if (!found) break;
      } else {
        if (chunk_left == 0) {
          if (!out->empty()) break;  // hand out what we have; wait for more later
          chunk_cv.wait(g, [&] { return !chunks.empty() || no_more_chunks; });
          if (chunks.empty()) break;
          const long long first = chunks.front() * kDynamicChunk;
          chunks.pop_front();
          while (missing_seen < first && next_missing(&c, &t)) {
          }
          chunk_left = std::min(kDynamicChunk, missing - first);
        }
        if (!next_missing(&c, &t)) break;
        --chunk_left;
      }
      out->emplace_back(c, t);
      ++claimed;
    }
  };
  // Rank 0's side of the dynamic schedule, and every rank's supply of chunks (main thread only:
  // MPI is called from no other thread).
  enum : int { kTagRequest = 1, kTagChunk = 2, kTagDone = 3 };
  long long next_chunk = 0;
  int ranks_released = 0;    // rank 0: other ranks told "no more" or that said they stopped
  bool requested_done = false;
  auto serve_and_supply = [&](bool stopping) {
    if (!dynamic) return;
    if (root) {
      int from, tag;
      long long value;
      while (collective->TryReceive(&from, &tag, &value)) {
        if (tag == kTagDone) {
          ++ranks_released;
        } else if (tag == kTagRequest) {
          const long long id = !stopping && next_chunk < num_chunks ? next_chunk++ : -1;
          if (id < 0) ++ranks_released;
          collective->Send(from, kTagChunk, id);
        }
      }
    }
    std::lock_guard<std::mutex> g(claim_mutex);
    if (no_more_chunks || chunks.size() >= 2) return;
    if (stopping) {
      no_more_chunks = true;
    } else if (root) {
      if (next_chunk < num_chunks) chunks.push_back(next_chunk++);
      else no_more_chunks = true;
    } else {
      collective->Send(0, kTagRequest, 0);
      const long long id = collective->Receive(0, kTagChunk);
      if (id < 0) {
        no_more_chunks = true;
        requested_done = true;
      } else {
        chunks.push_back(id);
      }
    }
    chunk_cv.notify_all();
  };

  // Workers compute; this thread writes batches and reports progress.
  std::atomic<int> running{threads};
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<TrialRecord> pending;
  std::exception_ptr failure;
  constexpr int kChunk = 8;
  auto worker = [&] {
    TrialWorkspace ws;
    std::vector<TrialRecord> local;
    std::vector<std::pair<int, long long>> chunk;
    try {
      while (g_stop_signals.load() == 0) {
        claim(&chunk, kChunk);
        if (chunk.empty()) break;
        for (const auto& [cell, trial] : chunk) local.push_back(RunTrial(*contexts[cell], trial, &ws));
        bool full;
        {
          std::lock_guard<std::mutex> g(mutex);
          for (auto& r : local) pending.push_back(std::move(r));
          full = pending.size() >= static_cast<std::size_t>(options.batch_size);
        }
        local.clear();
        if (full) cv.notify_one();  // else the writer wakes on its own every 100 ms
      }
    } catch (...) {
      std::lock_guard<std::mutex> g(mutex);
      if (!failure) failure = std::current_exception();
      g_stop_signals.fetch_add(1);
    }
    {
      // Under the mutex: the writer checks `running` under it, so this wake-up cannot be lost.
      std::lock_guard<std::mutex> g(mutex);
      running.fetch_sub(1);
    }
    cv.notify_one();
  };
  const auto t_run = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(worker);

  const bool tty = ::isatty(STDERR_FILENO);
  double line_every = 10.0;
  if (const char* e = std::getenv("LRCAL_PROGRESS_SECONDS")) line_every = std::atof(e);
  auto last_flush = std::chrono::steady_clock::now();
  auto last_report = last_flush;
  std::vector<TrialRecord> batch;
  const bool progress = options.progress && root;
  const long long my_total = result.done_before + my_share * ranks;  // progress estimate
  auto report = [&](bool final) {
    if (!progress) return;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const long long done_now = result.done_before + result.computed * ranks;
    const double rate = el > 0 ? result.computed * ranks / el : 0;
    const double eta = rate > 0 ? (my_total - done_now) / rate : NAN;
    char line[256];
    const long long shown = std::min(done_now, result.total);
    if (tty) {
      const int width = 30;
      const int filled = result.total ? static_cast<int>(width * shown / result.total) : width;
      std::snprintf(line, sizeof line, "\r[%s%s] %lld/%lld trials  %.0f/s  ETA %s ",
                    std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
                    shown, result.total, rate, Duration(eta).c_str());
      std::cerr << line << (final ? "\n" : "") << std::flush;
    } else {
      std::snprintf(line, sizeof line, "lrcal run: %lld/%lld trials, %.0f/s, ETA %s%s", shown,
                    result.total, rate, Duration(eta).c_str(),
                    ranks > 1 ? " (estimated from rank 0)" : "");
      std::cerr << line << "\n";
    }
  };
  serve_and_supply(false);
  while (true) {
    bool finished;
    {
      std::unique_lock<std::mutex> g(mutex);
      cv.wait_for(g, std::chrono::milliseconds(dynamic ? 1 : 100), [&] {
        return running.load() == 0 || pending.size() >= static_cast<std::size_t>(options.batch_size);
      });
      for (auto& r : pending) batch.push_back(std::move(r));
      pending.clear();
      finished = running.load() == 0;
    }
    const auto now = std::chrono::steady_clock::now();
    if (finished || batch.size() >= static_cast<std::size_t>(options.batch_size) ||
        std::chrono::duration<double>(now - last_flush).count() >= 1.0) {
      store->Insert(batch);
      for (const auto& r : batch) result.trial_seconds += r.seconds;
      result.computed += static_cast<long long>(batch.size());
      batch.clear();
      last_flush = now;
    }
    const double since = std::chrono::duration<double>(now - last_report).count();
    if (since >= (tty ? 0.25 : line_every)) {
      report(false);
      last_report = now;
    }
    const bool stopping = g_stop_signals.load() > 0 || claimed >= my_share;
    serve_and_supply(stopping);
    if (finished) {
      if (!dynamic) break;
      if (!root) {
        // Tell rank 0 this rank asks for nothing more (unless it was told so already).
        if (!requested_done) collective->Send(0, kTagDone, 0);
        break;
      }
      if (ranks_released >= ranks - 1) break;  // rank 0 serves until every rank is released
    }
  }
  for (auto& t : pool) t.join();
  const auto t_ran = std::chrono::steady_clock::now();
  report(true);
  if (failure) std::rethrow_exception(failure);
  result.peak_rss_kb_trials = PeakRssKb();
  result.prepare_seconds = std::chrono::duration<double>(t_prepared - t0).count();
  result.run_seconds = std::chrono::duration<double>(t_ran - t_run).count();
  result.ranks_computed = collective->SumAll(result.computed);
  store.reset();          // close this process's store before rank 0 merges it
  collective->Barrier();  // every rank's records are committed

  if (root) {
    // Fold the rank stores (this job's, and any an earlier job left) into the main store.
    TrialStore main_store((dir / "trials.sqlite").string());
    MergeRankStores(dir, &main_store);
    long long done_now = 0;
    for (std::size_t c = 0; c < study.cells.size(); ++c)
      for (long long t : main_store.DoneTrials(study.cells[c].id))
        if (t >= 0 && t < trials && t % options.shard_count == options.shard_index) ++done_now;
    result.interrupted = g_stop_signals.load() > 0 || done_now < result.total;
    manifest["sessions"][session_index]["end"] = Now();
    manifest["sessions"][session_index]["trials_computed"] = result.ranks_computed;
    manifest["sessions"][session_index]["ended"] = result.interrupted ? "interrupted" : "completed";
    if (!result.interrupted && options.shard_count == 1) {
      const auto t_tables = std::chrono::steady_clock::now();
      WriteStudyTables(main_store, study_json, dir.string());
      result.tables_written = true;
      result.tables_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t_tables).count();
      manifest["finished"] = Now();
    }
    manifest["sessions"][session_index]["seconds"] = {
        {"prepare", result.prepare_seconds}, {"trials", result.run_seconds},
        {"tables", result.tables_seconds}, {"sum_of_trial_times", result.trial_seconds}};
    result.peak_rss_kb = PeakRssKb();
    manifest["sessions"][session_index]["peak_rss_kb"] = {
        {"after_trials", result.peak_rss_kb_trials}, {"after_tables", result.peak_rss_kb}};
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    WriteJsonAtomically(manifest_path, manifest);
  } else {
    // Completeness is rank 0's to judge (from the merged store); this rank knows its signals and,
    // under the static schedule, whether it finished its share.
    result.interrupted = g_stop_signals.load() > 0 || (!dynamic && result.computed < my_share);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  collective->Barrier();  // rank 0 has merged: the run directory is consistent
  return result;
}

void AggregateRun(const std::string& run_dir) {
  const fs::path dir = run_dir;
  const Json manifest = ReadRunManifest(dir);
  DirectoryLock lock(dir);
  TrialStore store((dir / "trials.sqlite").string());
  MergeRankStores(dir, &store);  // records of an interrupted MPI job
  WriteStudyTables(store, manifest["study"], run_dir);
}

void MergeRuns(const std::vector<std::string>& shard_dirs, const std::string& out_dir) {
  if (shard_dirs.empty()) throw InputError("merge", "give the shard run directories to merge");
  const fs::path out = out_dir;
  fs::create_directories(out);
  DirectoryLock lock(out);
  Json merged;
  for (const std::string& d : shard_dirs) {
    const Json manifest = ReadRunManifest(d);
    if (merged.is_null()) {
      merged = manifest;
      merged["merged_from"] = Json::array();
      merged["sessions"] = Json::array();
      merged["shard"] = {{"index", 1}, {"count", 1}};
    } else {
      const auto changes = DiffJson(Fingerprint(merged["study"]), Fingerprint(manifest["study"]));
      if (!changes.empty()) {
        std::string msg = "ran a different study than " + shard_dirs[0] + ":";
        for (const auto& c : changes) msg += "\n  " + c;
        throw InputError(d, msg);
      }
    }
    merged["merged_from"].push_back({{"dir", d}, {"shard", manifest["shard"]}});
    for (const auto& s : manifest["sessions"]) merged["sessions"].push_back(s);
  }
  {
    TrialStore store((out / "trials.sqlite").string());
    store.SetMeta("study", merged["study"].dump());
    for (const std::string& d : shard_dirs)
      for (const fs::path& path : StorePaths(d)) store.MergeFrom(path.string());
    const StudyTablesResult tables = WriteStudyTables(store, merged["study"], out_dir);
    if (tables.complete) merged["finished"] = Now();
  }
  WriteJsonAtomically(out / "manifest.json", merged);
}

std::string RunStatus(const std::string& run_dir) { return GetRunStatus(run_dir).text; }

RunStatusInfo GetRunStatus(const std::string& run_dir) {
  RunStatusInfo info;
  const fs::path dir = run_dir;
  const Json manifest = ReadRunManifest(dir);
  // Open every store of the directory: the main one and any rank stores of an MPI job.
  std::vector<std::unique_ptr<TrialStore>> stores;
  for (const fs::path& path : StorePaths(dir))
    stores.push_back(std::make_unique<TrialStore>(path.string()));
  const long long trials = manifest["study"]["trials"];
  const int si = manifest["shard"]["index"], sc = manifest["shard"]["count"];
  std::ostringstream out;
  out << "study " << manifest["study"]["name"].get<std::string>() << " in " << run_dir;
  if (sc > 1) out << " (shard " << si << "/" << sc << ")";
  out << "\n";
  long long total_done = 0, total = 0;
  for (const auto& c : manifest["study"]["cells"]) {
    const std::string id = c["id"];
    long long expected = 0;
    for (long long t = 0; t < trials; ++t)
      if (t % sc == si - 1) ++expected;
    std::set<long long> union_done;
    for (const auto& st : stores)
      for (long long t : st->DoneTrials(id)) union_done.insert(t);
    const long long done = static_cast<long long>(union_done.size());
    total_done += done;
    total += expected;
    out << "  " << c["label"].get<std::string>() << " (" << id << "): " << done << "/" << expected
        << (done >= expected ? " done" : " remaining " + std::to_string(expected - done)) << "\n";
  }
  out << "total: " << total_done << "/" << total << (total_done >= total ? " — complete" : "")
      << "\n";
  const auto& sessions = manifest["sessions"];
  if (!sessions.empty())
    out << "last session: " << sessions.back().value("start", std::string()) << " → "
        << sessions.back().value("ended", std::string()) << "\n";
  if (total_done < total) {
    out << "to finish: lrcal run " << manifest.value("study_file", std::string("STUDY.yaml"))
        << " --out " << run_dir;
    if (sc > 1) out << " --shard " << si << "/" << sc;
    out << "\n";
  }
  info.text = out.str();
  info.complete = total_done >= total;
  info.shard_index = si;
  info.shard_count = sc;
  info.study_file = manifest.value("study_file", std::string("STUDY.yaml"));
  return info;
}

}  // namespace lrcal
