#include "lrcal/study/run_directory.h"

#include <ceres/version.h>
#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include "lrcal/build_info.h"
#include "lrcal/core/error.h"
#include "lrcal/core/machine.h"
#include "lrcal/core/text_table.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/stopping.h"
#include "lrcal/study/study.h"

namespace lrcal {

namespace fs = std::filesystem;

namespace {

Json Dependencies() {
  return {
      {"eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) +
                    "." + std::to_string(EIGEN_MINOR_VERSION)},
      {"ceres", CERES_VERSION_STRING},
      {"sqlite", sqlite3_libversion()},
      {"random123", "Philox4x64-10, Random123 boxmuller"}};
}

constexpr const char* kRandomNumbers =
    "Philox4x64-10 (Random123) addressed by (seed, stream, trial, purpose, index); standard "
    "normals by Random123's Box-Muller. Common random numbers: the reading noise and drawn "
    "truths are keyed by the trial index only, so cells that differ in sigma, repetitions, "
    "configuration count or selection see the same standard normals (noise of a "
    "configuration is addressed by its index in the candidate pool). Pools and validation "
    "sets are keyed by a hash of the settings they depend on.";

// The keys lrcal relies on; a manifest without them is damaged (or not lrcal's).
void CheckManifest(const Json& manifest, const std::string& path) {
  const auto require = [&](const Json& j, const std::string& key, bool (Json::*is)() const,
                           const char* what) {
    const auto dot = key.rfind('.');
    const std::string last = dot == std::string::npos ? key : key.substr(dot + 1);
    if (!j.is_object() || !j.contains(last) || !(j[last].*is)())
      throw InputError(path + " key '" + key + "'",
                       std::string("missing or not ") + what +
                           ": the manifest is damaged or was not written by lrcal");
    return j[last];
  };
  const Json study = require(manifest, "study", &Json::is_object, "a mapping");
  require(study, "study.name", &Json::is_string, "a name");
  require(study, "study.seed", &Json::is_number_unsigned, "a seed");
  require(study, "study.trials", &Json::is_number_integer, "a number of trials");
  require(study, "study.base", &Json::is_object, "a mapping");
  const Json cells = require(study, "study.cells", &Json::is_array, "a list of cells");
  for (const auto& c : cells)
    if (!c.is_object() || !c.contains("id") || !c["id"].is_string() || !c.contains("label") ||
        !c["label"].is_string())
      throw InputError(path + " key 'study.cells'",
                       "every cell needs an id and a label: the manifest is damaged");
  const Json shard = require(manifest, "shard", &Json::is_object, "a mapping");
  require(shard, "shard.index", &Json::is_number_integer, "a number");
  require(shard, "shard.count", &Json::is_number_integer, "a number");
  require(manifest, "sessions", &Json::is_array, "a list");
}

}  // namespace

Json LrcalBuildInfo() {
  return {{"version", LRCAL_VERSION},
          {"commit", LRCAL_GIT_COMMIT},
          {"compiler", LRCAL_COMPILER},
          {"build_type", LRCAL_BUILD_TYPE}};
}

std::string UtcNow() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

Json StudyFingerprint(const Json& study) {
  return {{"name", study["name"]},
          {"seed", study["seed"]},
          {"trials", study["trials"]},
          {"base", CellIdentity(study["base"])}};
}

DirectoryLock::DirectoryLock(const std::string& dir) {
  const std::string path = dir + "/lock";
  // Never through a symbolic link (its target would be truncated and overwritten with our pid,
  // even when the run is then refused), and never anything but a regular file (a FIFO would
  // block).
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
  if (fd_ < 0 && errno == ELOOP)
    throw InputError(path,
                     "is a symbolic link; lrcal's lock file must be a regular file of the "
                     "run directory (remove the link; its target is left untouched)");
  if (fd_ < 0) throw InputError(path, "cannot create the lock file");
  struct stat info {};
  if (::fstat(fd_, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    throw InputError(path, "is not a regular file; lrcal's lock file must be one (remove it)");
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    fd_ = -1;
    throw InputError(dir,
                     "another lrcal process is running on this run directory; wait for it "
                     "or stop it first");
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) == 0 && ::write(fd_, pid.data(), pid.size()) < 0) {
    // The pid is a courtesy for people looking at the file; the flock is the lock.
  }
}

bool DirectoryLock::IsHeld(const std::string& dir) {
  const std::string path = dir + "/lock";
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return false;  // no lock file: no run ever locked it
  const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::flock(fd, LOCK_UN);
  ::close(fd);
  return held;
}

DirectoryLock::~DirectoryLock() {
  if (fd_ >= 0) {
    ::flock(fd_, LOCK_UN);
    ::close(fd_);
  }
}

std::string RunDirectory::RankStorePath(int rank) const {
  return path_ + "/trials.rank" + std::to_string(rank) + ".sqlite";
}

void RunDirectory::CreateAndLock() {
  std::error_code ec;
  if (fs::exists(path_, ec) && !fs::is_directory(path_, ec))
    throw SettingError(RunOptions::OutDirSetting(),
                       "'" + path_ + "' is a file; expected a run directory");
  fs::create_directories(path_, ec);
  if (ec)
    throw SettingError(RunOptions::OutDirSetting(),
                       "cannot create the run directory '" + path_ + "': " + ec.message());
  lock_ = std::make_unique<DirectoryLock>(path_);
}

void RunDirectory::Lock() {
  ReadManifest();  // refuses what is not a run directory
  lock_ = std::make_unique<DirectoryLock>(path_);
}

bool RunDirectory::HasManifest() const {
  std::error_code ec;
  return fs::exists(ManifestPath(), ec);
}

Json RunDirectory::ReadManifest() const {
  std::error_code ec;
  if (!fs::exists(ManifestPath(), ec) || !fs::exists(MainStorePath(), ec))
    throw InputError(path_,
                     "not an lrcal run directory (expected manifest.json and "
                     "trials.sqlite)");
  const Json manifest = ReadJsonFile(ManifestPath());
  CheckManifest(manifest, ManifestPath());
  return manifest;
}

void RunDirectory::WriteManifest(const Json& manifest) const {
  WriteFileAtomically(ManifestPath(), manifest.dump(2) + "\n");
}

void RunDirectory::CheckCompatible(const Json& manifest, const Json& study,
                                   const std::string& study_path, int shard_index,
                                   int shard_count) {
  Json before = StudyFingerprint(manifest["study"]), after = StudyFingerprint(study);
  before.erase("trials");
  after.erase("trials");
  const auto changes = DiffJson(before, after);
  if (!changes.empty()) {
    std::string msg = "this run directory holds a different study; changed:";
    for (const auto& c : changes) msg += "\n  " + c;
    msg += "\nrun it in a new directory (--out), or restore the study file";
    throw InputError(study_path, msg);
  }
  // More trials extend the run (every trial is a pure function of its index: the recorded ones
  // stay valid); fewer would leave recorded trials outside the study.
  const long long recorded = manifest["study"].value("trials", 0LL);
  const long long wanted = study.value("trials", 0LL);
  if (wanted < recorded)
    throw InputError(study_path + " key 'trials'",
                     std::to_string(wanted) +
                         " trials per cell, but this run directory holds up "
                         "to " +
                         std::to_string(recorded) + "; give trials: " + std::to_string(recorded) +
                         " or more (more extends the run), or run it in a new directory (--out)");
  const Json shard = {{"index", shard_index + 1}, {"count", shard_count}};
  if (manifest.contains("shard") && manifest["shard"] != shard)
    throw SettingError(RunOptions::ShardSetting(),
                       "this run directory is shard " + manifest["shard"]["index"].dump() + "/" +
                           manifest["shard"]["count"].dump() + "; rerun it with that shard");
}

void RunDirectory::AppendLog(const std::string& line) const {
  std::FILE* f = std::fopen((fs::path(path_) / "run.log").c_str(), "a");
  if (!f) return;
  std::fprintf(f, "%s  %s\n", UtcNow().c_str(), line.c_str());
  std::fclose(f);
}

Json RunDirectory::StartSession(Json manifest, const Study& study, int shard_index, int shard_count,
                                int threads, int ranks, std::size_t* session) {
  if (manifest.is_null()) {
    manifest["created"] = UtcNow();
    manifest["sessions"] = Json::array();
  }
  manifest["study_file"] = study.path;
  manifest["study"] = study.ToJson();
  manifest["seed"] = study.seed;
  manifest["shard"] = {{"index", shard_index + 1}, {"count", shard_count}};
  manifest["lrcal"] = LrcalBuildInfo();
  manifest["dependencies"] = Dependencies();
  manifest["random_numbers"] = kRandomNumbers;
  manifest["sessions"].push_back({{"start", UtcNow()},
                                  {"threads", threads},
                                  {"ranks", ranks},
                                  {"cpu", CpuModelName()},
                                  {"kernels", KernelVariant()},
                                  {"ended", "running"}});
  *session = manifest["sessions"].size() - 1;
  return manifest;
}

std::vector<std::string> RunDirectory::RankStorePaths() const {
  std::vector<std::string> out;
  std::error_code ec;
  if (!fs::is_directory(path_, ec)) return out;
  for (const auto& e : fs::directory_iterator(path_, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("trials.rank", 0) == 0 && name.size() > 18 &&
        name.compare(name.size() - 7, 7, ".sqlite") == 0)
      out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> RunDirectory::StorePaths() const {
  std::vector<std::string> out;
  std::error_code ec;
  if (fs::exists(MainStorePath(), ec)) out.push_back(MainStorePath());
  for (const auto& p : RankStorePaths()) out.push_back(p);
  return out;
}

void RunDirectory::MergeRankStores(TrialStore* main_store) const {
  for (const std::string& path : RankStorePaths()) {
    main_store->MergeFrom(path);
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(path + suffix);
  }
}

DoneSet RunDirectory::ReadDone(const Study& study, const TrialStore* open_store) const {
  const long long trials = study.trials;
  DoneSet done(study.cells.size(), std::vector<bool>(trials, false));
  for (const std::string& path : StorePaths()) {
    std::unique_ptr<TrialStore> other;
    const TrialStore* s = open_store;
    if (!open_store || path != open_store->path()) {
      other = std::make_unique<TrialStore>(path);
      s = other.get();
    }
    for (std::size_t c = 0; c < study.cells.size(); ++c)
      for (long long t : s->DoneTrials(study.cells[c].id))
        if (t >= 0 && t < trials) done[c][t] = true;
  }
  return done;
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
    throw SettingError(RunOptions::ShardSetting(),
                       "expected i/N with 1 <= i <= N (e.g. 2/8), got '" + text + "'");
  }
}

void MergeRunStores(const std::vector<std::string>& shard_dirs, const std::string& out_dir) {
  if (shard_dirs.empty()) throw InputError("merge", "give the shard run directories to merge");
  std::error_code ec;
  for (const std::string& d : shard_dirs)
    if (fs::equivalent(d, out_dir, ec))
      throw SettingError(RunOptions::OutDirSetting(), "'" + out_dir +
                                                          "' is one of the directories to merge; "
                                                          "merge into a new directory");
  // A shard still running would give a partial snapshot: refuse until it has stopped.
  std::vector<std::unique_ptr<RunDirectory>> shards;
  for (const std::string& d : shard_dirs) {
    shards.push_back(std::make_unique<RunDirectory>(d));
    try {
      shards.back()->Lock();
    } catch (const InputError& e) {
      throw InputError(d, std::string("cannot merge it now: ") + e.what());
    }
  }
  RunDirectory out(out_dir);
  out.CreateAndLock();
  Json merged;
  for (const std::string& d : shard_dirs) {
    const Json manifest = RunDirectory(d).ReadManifest();
    if (merged.is_null()) {
      merged = manifest;
      merged["merged_from"] = Json::array();
      merged["sessions"] = Json::array();
      merged["shard"] = {{"index", 1}, {"count", 1}};
      merged.erase("finished");
    } else {
      const auto changes =
          DiffJson(StudyFingerprint(merged["study"]), StudyFingerprint(manifest["study"]));
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
    TrialStore store(out.MainStorePath());
    store.SetMeta("study", merged["study"].dump());
    for (const std::string& d : shard_dirs)
      for (const std::string& path : RunDirectory(d).StorePaths()) store.MergeFrom(path);
  }
  out.WriteManifest(merged);
}

namespace {

// Whether RUN_DIR/tables/ is there and matches the records (its summary.json says whether every
// trial was in when it was written).
std::string TablesStatus(const std::string& run_dir, bool run_complete, int shard_count) {
  const std::string summary = run_dir + "/tables/summary.json";
  // A shard holds only its part of every cell: its tables are the merged run's.
  if (shard_count > 1 && !fs::exists(summary))
    return run_complete ? "tables: none for a shard; when every shard is done, combine them with: "
                          "lrcal merge SHARD_DIR... --out DIR (lrcal status SHARD_DIR... says "
                          "which are)\n"
                        : "tables: none for a shard (lrcal merge writes them)\n";
  if (!fs::exists(summary))
    return run_complete ? "tables: missing; write them with: lrcal aggregate " + run_dir + "\n"
                        : "tables: not written yet (they are written when every trial is done)\n";
  bool tables_complete = false;
  try {
    tables_complete = ReadJsonFile(summary).value("complete", false);
  } catch (const InputError&) {
    return "tables: " + summary + " is damaged; rewrite them with: lrcal aggregate " + run_dir +
           "\n";
  }
  if (tables_complete && !run_complete)  // the study was extended (more trials) since
    return "tables: " + run_dir +
           "/tables/summary.md, written before the run was extended; rewritten when every "
           "trial is done\n";
  if (tables_complete) return "tables: " + run_dir + "/tables/summary.md (complete)\n";
  return std::string("tables: written from a partial run") +
         (run_complete ? "; rewrite them with: lrcal aggregate " + run_dir : "") + "\n";
}

// One cell's line of `lrcal status` and its counts toward the total.
struct CellProgress {
  long long done = 0, total = 0;
  bool stopped_early = false;
  std::string text;
};

CellProgress FixedCellProgress(const std::set<long long>& done, long long trials, int shard_index,
                               int shard_count) {
  CellProgress p;
  for (long long t = shard_index; t < trials; t += shard_count) ++p.total;
  p.done = static_cast<long long>(done.size());
  p.text = std::to_string(p.done) + "/" + std::to_string(p.total) +
           (p.done >= p.total ? " done" : " remaining " + std::to_string(p.total - p.done));
  return p;
}

// Under stop_when: the cell's own stopping point, decided from its recorded trials.
CellProgress AdaptiveCellProgress(const std::vector<const TrialStore*>& stores,
                                  const std::string& id, const StopWhen& rule, long long trials,
                                  const std::set<long long>& done) {
  const CellStopping stop = EvaluateStopping(stores, id, rule, trials);
  const long long used = stop.trials_used();
  CellProgress p;
  const std::string of = "/" + std::to_string(trials);
  if (!stop.decided()) {
    p.done = static_cast<long long>(std::distance(done.begin(), done.lower_bound(used)));
    p.total = trials;
    p.text = std::to_string(p.done) + of + " (at most; the next decision at " +
             std::to_string(stop.next_boundary()) + ")";
    return p;
  }
  p.done = p.total = used;
  p.stopped_early = stop.precise() && used < trials;
  p.text = std::to_string(used) + of +
           (p.stopped_early  ? " done: stopped early, precision reached"
            : stop.precise() ? " done: precision reached at the maximum"
                             : " done: the maximum, precision not reached");
  return p;
}

// Seconds since the epoch of a manifest time ("2026-11-25T14:07:57Z"); NaN if it is not one.
double EpochSeconds(const std::string& utc) {
  std::tm t{};
  const char* end = ::strptime(utc.c_str(), "%Y-%m-%dT%H:%M:%SZ", &t);
  if (!end || *end != '\0') return std::nan("");
  return static_cast<double>(::timegm(&t));
}

// "42 s", "3 min 5 s", "2 h 07 min".
std::string FormatDuration(double seconds) {
  const long long s = std::llround(seconds);
  char buf[48];
  if (s < 60) {
    std::snprintf(buf, sizeof buf, "%lld s", s);
  } else if (s < 3600) {
    std::snprintf(buf, sizeof buf, "%lld min %lld s", s / 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lld h %02lld min", s / 3600, (s % 3600) / 60);
  }
  return buf;
}

// The last session of a run as status shows it.
struct SessionState {
  std::string start, end, ended;
  std::string state;              // running, stopped (gone without closing), or how it ended
  long long trials = -1;          // trials it computed (-1: not recorded: it did not close)
  double seconds = std::nan("");  // its wall time (so far, if running)
};

SessionState LastSession(const Json& manifest, const std::string& run_dir) {
  SessionState s;
  const auto& sessions = manifest["sessions"];
  if (sessions.empty()) return s;
  const Json& last = sessions.back();
  s.start = last.value("start", std::string());
  s.end = last.value("end", std::string());
  s.ended = s.state = last.value("ended", std::string());
  s.trials = last.value("trials_computed", -1LL);
  if (s.ended != "running") {
    s.seconds = EpochSeconds(s.end) - EpochSeconds(s.start);
  } else if (DirectoryLock::IsHeld(run_dir)) {
    s.seconds = static_cast<double>(std::time(nullptr)) - EpochSeconds(s.start);
  } else {
    // A session records "running" until it closes; no process holds the directory's lock, so
    // the process that ran it is gone without closing it (killed, or its machine went down).
    s.state = "stopped";
    s.ended =
        "stopped without closing (its process is gone: killed, or the machine went down; the "
        "trials it committed are kept)";
  }
  return s;
}

std::string SessionText(const SessionState& s) {
  if (s.start.empty()) return "";
  std::string text = "last session: " + s.start + " → " + s.ended;
  if (s.state == "running" && std::isfinite(s.seconds))
    text += " (for " + FormatDuration(s.seconds) + " so far)";
  if (s.trials >= 0 && std::isfinite(s.seconds)) {
    text += ": " + std::to_string(s.trials) + " trials in " + FormatDuration(s.seconds);
    if (s.seconds > 0 && s.trials > 0)
      text += " (" + Fixed(static_cast<double>(s.trials) / s.seconds, 1) + " trials/s)";
  }
  return text + "\n";
}

Json SessionJson(const SessionState& s) {
  if (s.start.empty()) return Json();
  const auto number = [](double x) { return std::isfinite(x) ? Json(x) : Json(); };
  const bool rate = s.trials > 0 && s.seconds > 0;
  return {{"start", s.start},
          {"end", s.end.empty() ? Json() : Json(s.end)},
          {"state", s.state},
          {"ended", s.ended},
          {"trials_computed", s.trials >= 0 ? Json(s.trials) : Json()},
          {"seconds", number(s.seconds)},
          {"trials_per_second", rate ? Json(static_cast<double>(s.trials) / s.seconds) : Json()}};
}

}  // namespace

std::string RunStatus(const std::string& run_dir) { return GetRunStatus(run_dir).text; }

RunStatusInfo GetRunStatus(const std::string& run_dir) {
  RunStatusInfo info;
  const RunDirectory dir(run_dir);
  const Json manifest = dir.ReadManifest();
  // Every store of the directory: the main one and any rank stores of an MPI job.
  std::vector<std::unique_ptr<TrialStore>> stores;
  for (const std::string& path : dir.StorePaths())
    stores.push_back(std::make_unique<TrialStore>(path));
  const long long trials = manifest["study"]["trials"];
  const int si = manifest["shard"]["index"], sc = manifest["shard"]["count"];
  std::ostringstream out;
  out << "study " << manifest["study"]["name"].get<std::string>() << " in " << run_dir;
  if (sc > 1) out << " (shard " << si << "/" << sc << ")";
  out << "\n";
  long long total_done = 0, total = 0;
  const StopWhen rule = StopWhen::FromJson(manifest["study"].value("stop_when", Json()),
                                           dir.ManifestPath() + " key 'study.stop_when'");
  const bool adaptive = rule.enabled() && sc == 1;
  std::vector<const TrialStore*> store_list;
  for (const auto& st : stores) store_list.push_back(st.get());
  int stopped_early = 0;
  Json cells_json = Json::array();
  for (const auto& c : manifest["study"]["cells"]) {
    const std::string id = c["id"];
    std::set<long long> union_done;
    for (const auto& st : stores)
      for (long long t : st->DoneTrials(id)) union_done.insert(t);
    out << "  " << c["label"].get<std::string>() << " (" << id << "): ";
    const CellProgress p = adaptive ? AdaptiveCellProgress(store_list, id, rule, trials, union_done)
                                    : FixedCellProgress(union_done, trials, si - 1, sc);
    total_done += p.done;
    total += p.total;
    stopped_early += p.stopped_early;
    out << p.text << "\n";
    cells_json.push_back({{"id", id},
                          {"label", c["label"]},
                          {"done", p.done},
                          {"total", p.total},
                          {"stopped_early", p.stopped_early}});
  }
  out << "total: " << total_done << "/" << total << (total_done >= total ? " — complete" : "");
  if (adaptive) out << " (stop_when: " << stopped_early << " cells stopped early)";
  out << "\n";
  if (rule.enabled() && sc > 1)
    out << "stop_when: a shard cannot see the other shards' trials, so it runs up to the "
           "maximum; lrcal merge applies the rule\n";
  const SessionState session = LastSession(manifest, run_dir);
  out << SessionText(session) << TablesStatus(run_dir, total_done >= total, sc);
  std::string finish;
  if (total_done < total) {
    finish = "lrcal run " + manifest.value("study_file", std::string("STUDY.yaml")) + " --out " +
             run_dir + (sc > 1 ? " --shard " + std::to_string(si) + "/" + std::to_string(sc) : "");
    out << "to finish: " << finish << "\n";
  }
  // Figures and report.html of what is recorded, partial or not (a shard's are the merged run's).
  if (total_done > 0 && sc == 1) out << "report: lrcal report " << run_dir << "\n";
  info.text = out.str();
  info.json = {{"run", run_dir},
               {"study", manifest["study"]["name"]},
               {"shard", {{"index", si}, {"count", sc}}},
               {"cells", cells_json},
               {"done", total_done},
               {"total", total},
               {"complete", total_done >= total},
               {"last_session", SessionJson(session)},
               {"to_finish", finish.empty() ? Json() : Json(finish)},
               {"report", total_done > 0 && sc == 1 ? Json("lrcal report " + run_dir) : Json()}};
  info.complete = total_done >= total;
  info.shard_index = si;
  info.shard_count = sc;
  info.study_file = manifest.value("study_file", std::string("STUDY.yaml"));
  return info;
}

std::string ShardAdvice(const std::vector<std::string>& dirs,
                        const std::vector<RunStatusInfo>& infos) {
  std::ostringstream out;
  std::string unfinished;
  std::set<int> present;
  for (const auto& i : infos) {
    present.insert(i.shard_index);
    if (!i.complete) unfinished += (unfinished.empty() ? "" : ",") + std::to_string(i.shard_index);
  }
  const int n = infos.front().shard_count;
  for (int i = 1; i <= n; ++i)
    if (!present.count(i)) unfinished += (unfinished.empty() ? "" : ",") + std::to_string(i);
  if (unfinished.empty()) {
    out << "all " << n << " shards complete: lrcal merge ";
    for (const auto& d : dirs) out << d << " ";
    out << "--out DIR\n";
    return out.str();
  }
  out << "unfinished or missing shards: " << unfinished << "\n"
      << "resubmit: sbatch --array=" << unfinished << " studies/slurm/lrcal_array.sbatch "
      << infos.front().study_file << " " << n << "\n";
  return out.str();
}

}  // namespace lrcal
