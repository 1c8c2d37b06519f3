#include "lrcal/report/run_tables.h"

#include <chrono>

#include "lrcal/study/run_directory.h"

namespace lrcal {

StudyTablesResult WriteRunTables(const std::string& run_dir) {
  const auto start = std::chrono::steady_clock::now();
  RunDirectory dir(run_dir);
  dir.Lock();
  Json manifest = dir.ReadManifest();
  StudyTablesResult tables;
  {
    TrialStore store(dir.MainStorePath());
    dir.MergeRankStores(&store);  // records of an interrupted MPI job
    tables = WriteStudyTables(store, manifest["study"], run_dir);
  }
  if (tables.complete) {
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
