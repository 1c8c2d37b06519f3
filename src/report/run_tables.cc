#include "lrcal/report/run_tables.h"

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "lrcal/study/run_directory.h"

namespace lrcal {

namespace {

namespace fs = std::filesystem;

// What the manifest records about written tables: the records they summarise, the lrcal that
// wrote them and their files.
Json TablesStamp(long long trials, const std::string& run_dir) {
  Json files = Json::array();
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(fs::path(run_dir) / "tables", ec))
    if (entry.is_regular_file()) files.push_back(entry.path().filename().string());
  std::sort(files.begin(), files.end());
  return {{"trials", trials}, {"lrcal", LrcalBuildInfo()}, {"files", files}};
}

}  // namespace

bool TablesAreCurrent(const std::string& run_dir) {
  try {
    RunDirectory dir(run_dir);
    if (!dir.HasManifest() || !dir.RankStorePaths().empty()) return false;
    const Json manifest = dir.ReadManifest();
    if (!manifest.contains("tables") || !manifest.contains("finished")) return false;
    const Json& stamp = manifest["tables"];
    if (stamp.value("lrcal", Json()) != LrcalBuildInfo()) return false;
    if (stamp.value("trials", -1LL) != TrialStore(dir.MainStorePath()).CountTrials()) return false;
    return TablesStamp(stamp["trials"].get<long long>(), run_dir) == stamp;
  } catch (const std::exception&) {
    return false;  // anything unusual: the tables are written again
  }
}

StudyTablesResult WriteRunTables(const std::string& run_dir) {
  const auto start = std::chrono::steady_clock::now();
  RunDirectory dir(run_dir);
  dir.Lock();
  Json manifest = dir.ReadManifest();
  StudyTablesResult tables;
  long long trials = 0;
  {
    TrialStore store(dir.MainStorePath());
    dir.MergeRankStores(&store);  // records of an interrupted MPI job
    tables = WriteStudyTables(store, manifest["study"], run_dir);
    trials = store.CountTrials();
  }
  manifest.erase("tables");
  if (tables.complete) {
    manifest["tables"] = TablesStamp(trials, run_dir);
    manifest["finished"] = UtcNow();
    if (!manifest["sessions"].empty()) {
      Json& session = manifest["sessions"].back();
      session["seconds"]["tables"] =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      session["peak_rss_kb"]["after_tables"] = PeakRssKb();
    }
    dir.WriteManifest(manifest);
  }
  return tables;
}

RunResult RunStudyAndWriteTables(const Study& study, const RunOptions& options,
                                 Collective* collective, StopToken* stop) {
  RunResult result = RunStudy(study, options, collective, stop);
  const bool root = !collective || collective->rank() == 0;
  if (root && result.complete && options.shard_count == 1) {
    if (result.ranks_computed == 0 && TablesAreCurrent(options.out_dir)) {
      result.tables_written = result.tables_current = true;
      return result;
    }
    const auto start = std::chrono::steady_clock::now();
    WriteRunTables(options.out_dir);
    result.tables_written = true;
    result.tables_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.peak_rss_kb = PeakRssKb();
    result.seconds += result.tables_seconds;
  }
  return result;
}

bool MergeRuns(const std::vector<std::string>& shard_dirs, const std::string& out_dir) {
  MergeRunStores(shard_dirs, out_dir);
  if (!GetRunStatus(out_dir).complete) return false;
  WriteRunTables(out_dir);
  return true;
}

MergeOutcome MergeRunsAndReport(const std::vector<std::string>& shard_dirs,
                                const std::string& out_dir) {
  MergeOutcome out;
  out.complete = MergeRuns(shard_dirs, out_dir);
  out.status = GetRunStatus(out_dir);
  if (out.complete) {
    out.text = out.status.text + "tables: " + out_dir + "/tables/summary.md\n";
    return out;
  }
  // Not every trial is in the shards: say which shards to finish; no tables were written.
  std::vector<RunStatusInfo> shards;
  for (const auto& d : shard_dirs) shards.push_back(GetRunStatus(d));
  out.text = out.status.text.substr(0, out.status.text.find("last session")) +
             ShardAdvice(shard_dirs, shards) +
             "tables not written: the shards do not hold every trial yet; finish them and run "
             "lrcal merge again\n";
  return out;
}

}  // namespace lrcal
