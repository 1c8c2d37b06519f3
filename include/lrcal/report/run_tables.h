// The report layer's side of a run: the tables of a run directory, written from its records.
// The runner (study/runner.h) never formats results; these functions are what `lrcal run`,
// `lrcal aggregate` and `lrcal merge` call.
#pragma once

#include <string>
#include <vector>

#include "lrcal/report/study_tables.h"
#include "lrcal/study/run_directory.h"
#include "lrcal/study/runner.h"

namespace lrcal {

/// Writes RUN_DIR/tables/ from the run's store (also for partial runs: the tables say so),
/// under the directory's lock; MPI rank stores left by an interrupted job are folded in first.
/// When every trial is there the manifest gets "finished" and the last session the tables'
/// time and peak memory.
StudyTablesResult WriteRunTables(const std::string& run_dir);

/// True when RUN_DIR's tables were written (complete) from exactly the records its store holds,
/// by this lrcal (version and commit), and every file they wrote is still there: the manifest's
/// "tables" entry, which WriteRunTables records, says so. Never with MPI rank stores left over.
bool TablesAreCurrent(const std::string& run_dir);

/// Runs (or resumes) a study and, when the run is complete and not a shard, writes its tables
/// (rank 0): what `lrcal run` does. A rerun that computes nothing leaves current tables as they
/// are (RunResult::tables_current).
RunResult RunStudyAndWriteTables(const Study& study, const RunOptions& options,
                                 Collective* collective = nullptr, StopToken* stop = nullptr);

/// Combines shard run directories into `out_dir` (records, manifest) and, when every trial of
/// the study is there, writes the tables; returns whether it did (a partial merge writes none:
/// finish the shards and merge again).
bool MergeRuns(const std::vector<std::string>& shard_dirs, const std::string& out_dir);

/// What a merge came to, as `lrcal merge` and Python's lrcal.merge say it: complete (the tables
/// are written), the merged run's status and, when the shards do not hold every trial, which
/// shards to finish (ShardAdvice) and that no tables were written.
struct MergeOutcome {
  bool complete = false;
  RunStatusInfo status;  ///< of `out_dir` after the merge
  std::string text;      ///< the command's output
};
/// MergeRuns, then the outcome.
MergeOutcome MergeRunsAndReport(const std::vector<std::string>& shard_dirs,
                                const std::string& out_dir);

}  // namespace lrcal
