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
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>

#include "lrcal/build_info.h"
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

RunResult RunStudy(const Study& study, const RunOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  // Prepare the cells (configurations, designs, predicted covariance) first: a study that cannot
  // run fails here, before anything is written.
  std::vector<std::unique_ptr<CellContext>> contexts;
  for (const Cell& cell : study.cells) contexts.push_back(PrepareCell(study, cell));
  const auto t_prepared = std::chrono::steady_clock::now();

  const fs::path dir = options.out_dir;
  fs::create_directories(dir);
  DirectoryLock lock(dir);
  const Json study_json = study.ToJson();
  const fs::path manifest_path = dir / "manifest.json";

  Json manifest;
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
                                      manifest["shard"]["count"].dump() + "; rerun it with that --shard");
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
      "configuration count or selection see the same standard normals (noise of a configuration "
      "is addressed by its index in the candidate pool). Pools and validation sets are keyed by a "
      "hash of the settings they depend on.";
  const int threads = options.threads > 0 ? options.threads
                                          : std::max(1u, std::thread::hardware_concurrency());
  Json session = {{"start", Now()}, {"threads", threads}, {"ended", "running"}};
  manifest["sessions"].push_back(session);
  const std::size_t session_index = manifest["sessions"].size() - 1;
  WriteJsonAtomically(manifest_path, manifest);

  TrialStore store((dir / "trials.sqlite").string());
  store.SetMeta("study", study_json.dump());

  for (const auto& context : contexts) store.PutCell(ToStoredCell(*context));

  // The work: every (cell, trial) of this shard that the store does not have. Claimed lazily
  // from a cursor over (cell, trial) with a done-bitmap per cell, so memory does not grow with
  // the number of trials.
  RunResult result;
  const long long trials = study.trials;
  std::vector<std::vector<bool>> done(study.cells.size());
  for (std::size_t c = 0; c < study.cells.size(); ++c) {
    done[c].assign(trials, false);
    for (long long t : store.DoneTrials(study.cells[c].id))
      if (t >= 0 && t < trials) done[c][t] = true;
    for (long long t = options.shard_index; t < trials; t += options.shard_count) {
      ++result.total;
      if (done[c][t]) ++result.done_before;
    }
  }
  long long budget = result.total - result.done_before;
  if (options.max_new_trials > 0) budget = std::min(budget, options.max_new_trials);
  const long long space = static_cast<long long>(study.cells.size()) * trials;
  std::mutex claim_mutex;
  long long cursor = 0;   // next (cell·trials + trial) to look at
  long long claimed = 0;  // trials handed out
  // Hands out up to `max` (cell, trial) pairs of this shard not done yet, in canonical order.
  auto claim = [&](std::vector<std::pair<int, long long>>* out, int max) {
    out->clear();
    std::lock_guard<std::mutex> g(claim_mutex);
    while (static_cast<int>(out->size()) < max && claimed < budget && cursor < space) {
      const int c = static_cast<int>(cursor / trials);
      const long long t = cursor % trials;
      ++cursor;
      if (t % options.shard_count != options.shard_index || done[c][t]) continue;
      out->emplace_back(c, t);
      ++claimed;
    }
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
  auto report = [&](bool final) {
    if (!options.progress) return;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const long long done = result.done_before + result.computed;
    const double rate = el > 0 ? result.computed / el : 0;
    const double eta = rate > 0 ? (result.total - done) / rate : NAN;
    char line[256];
    if (tty) {
      const int width = 30;
      const int filled = result.total ? static_cast<int>(width * done / result.total) : width;
      std::snprintf(line, sizeof line, "\r[%s%s] %lld/%lld trials  %.0f/s  ETA %s ",
                    std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
                    done, result.total, rate, Duration(eta).c_str());
      std::cerr << line << (final ? "\n" : "") << std::flush;
    } else {
      std::snprintf(line, sizeof line, "lrcal run: %lld/%lld trials, %.0f/s, ETA %s", done,
                    result.total, rate, Duration(eta).c_str());
      std::cerr << line << "\n";
    }
  };
  while (true) {
    bool finished;
    {
      std::unique_lock<std::mutex> g(mutex);
      cv.wait_for(g, std::chrono::milliseconds(100), [&] {
        return running.load() == 0 || pending.size() >= static_cast<std::size_t>(options.batch_size);
      });
      for (auto& r : pending) batch.push_back(std::move(r));
      pending.clear();
      finished = running.load() == 0;
    }
    const auto now = std::chrono::steady_clock::now();
    if (finished || batch.size() >= static_cast<std::size_t>(options.batch_size) ||
        std::chrono::duration<double>(now - last_flush).count() >= 1.0) {
      store.Insert(batch);
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
    if (finished) break;
  }
  for (auto& t : pool) t.join();
  const auto t_ran = std::chrono::steady_clock::now();
  report(true);
  if (failure) std::rethrow_exception(failure);
  result.peak_rss_kb_trials = PeakRssKb();
  result.prepare_seconds = std::chrono::duration<double>(t_prepared - t0).count();
  result.run_seconds = std::chrono::duration<double>(t_ran - t_run).count();

  result.interrupted = g_stop_signals.load() > 0 ||
                       result.done_before + result.computed < result.total;
  manifest["sessions"][session_index]["end"] = Now();
  manifest["sessions"][session_index]["trials_computed"] = result.computed;
  manifest["sessions"][session_index]["ended"] = result.interrupted ? "interrupted" : "completed";
  if (!result.interrupted && options.shard_count == 1) {
    const auto t_tables = std::chrono::steady_clock::now();
    WriteStudyTables(store, study_json, dir.string());
    result.tables_written = true;
    result.tables_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_tables).count();
    manifest["finished"] = Now();
  }
  manifest["sessions"][session_index]["seconds"] = {
      {"prepare", result.prepare_seconds}, {"trials", result.run_seconds},
      {"tables", result.tables_seconds}, {"sum_of_trial_times", result.trial_seconds}};
  result.peak_rss_kb = PeakRssKb();
  manifest["sessions"][session_index]["peak_rss_kb"] = {{"after_trials", result.peak_rss_kb_trials},
                                                        {"after_tables", result.peak_rss_kb}};
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  WriteJsonAtomically(manifest_path, manifest);
  return result;
}

void AggregateRun(const std::string& run_dir) {
  const fs::path dir = run_dir;
  if (!fs::exists(dir / "manifest.json") || !fs::exists(dir / "trials.sqlite"))
    throw InputError(run_dir, "not an lrcal run directory (expected manifest.json and "
                              "trials.sqlite)");
  const Json manifest = ReadJson(dir / "manifest.json");
  TrialStore store((dir / "trials.sqlite").string());
  WriteStudyTables(store, manifest["study"], run_dir);
}

void MergeRuns(const std::vector<std::string>& shard_dirs, const std::string& out_dir) {
  if (shard_dirs.empty()) throw InputError("merge", "give the shard run directories to merge");
  const fs::path out = out_dir;
  fs::create_directories(out);
  DirectoryLock lock(out);
  Json merged;
  for (const std::string& d : shard_dirs) {
    const fs::path m = fs::path(d) / "manifest.json";
    if (!fs::exists(m) || !fs::exists(fs::path(d) / "trials.sqlite"))
      throw InputError(d, "not an lrcal run directory (expected manifest.json and trials.sqlite)");
    const Json manifest = ReadJson(m);
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
    for (const std::string& d : shard_dirs) store.MergeFrom((fs::path(d) / "trials.sqlite").string());
    const StudyTablesResult tables = WriteStudyTables(store, merged["study"], out_dir);
    if (tables.complete) merged["finished"] = Now();
  }
  WriteJsonAtomically(out / "manifest.json", merged);
}

std::string RunStatus(const std::string& run_dir) {
  const fs::path dir = run_dir;
  if (!fs::exists(dir / "manifest.json") || !fs::exists(dir / "trials.sqlite"))
    throw InputError(run_dir, "not an lrcal run directory (expected manifest.json and "
                              "trials.sqlite)");
  const Json manifest = ReadJson(dir / "manifest.json");
  TrialStore store((dir / "trials.sqlite").string());
  const long long trials = manifest["study"]["trials"];
  const int si = manifest["shard"]["index"], sc = manifest["shard"]["count"];
  std::ostringstream out;
  out << "study " << manifest["study"]["name"].get<std::string>() << " in " << run_dir;
  if (sc > 1) out << " (shard " << si << "/" << sc << ")";
  out << "\n";
  long long total_done = 0, total = 0;
  std::map<std::string, std::string> stored;
  for (const auto& c : store.Cells()) stored[c.id] = c.label;
  for (const auto& c : manifest["study"]["cells"]) {
    const std::string id = c["id"];
    long long expected = 0;
    for (long long t = 0; t < trials; ++t)
      if (t % sc == si - 1) ++expected;
    const long long done = store.CountTrials(id);
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
  return out.str();
}

}  // namespace lrcal
