// The per-run trial store: one SQLite database (trials.sqlite) in the run directory.
//
// Tables (queryable from Python/pandas; lrcal.load_run reads them):
//   cells(cell_id, ord, label, settings JSON, parameter_names JSON, predicted_std JSON (SI),
//         design_sigma_min, fixed_for_rank JSON, pool_report, truth_errors JSON (SI, 5N),
//         predicted_std_truth JSON (SI), predicted_validation JSON (SI, 12 metrics),
//         design_efficiency)
//   trials(cell_id, trial, status, iterations, residual_rms, sigma_hat, sigma_min,
//          val_{rms,max}_{pos,ori}_{x,y,z}, nom_{...}, errors BLOB, seconds,
//          missed_configurations, coverage, coverage_total)
//     coverage, coverage_total: TrialRecord's (a share, 0..1); NULL where there is none.
//     errors: the parameter errors (estimate − truth, SI) as little-endian float64, in the order
//     of cells.parameter_names; NULL unless status = 'ok'. Other lengths in m, angles in rad.
//   meta(key, value)
// A trial is inserted once (primary key (cell_id, trial)); inserts are batched per transaction
// (WAL journal), so a killed process loses at most the batch in flight, which a resume recomputes
// bit for bit.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/study/trial.h"

struct sqlite3;

namespace lrcal {}

namespace lrcal {

/// What the store keeps of a cell (enough to aggregate without re-preparing it).
struct StoredCell {
  std::string id, label;
  int order = 0;
  std::string settings;  ///< JSON
  std::vector<std::string> parameter_names;
  std::vector<double> predicted_std;  ///< SI, G at the nominal model
  /// SI, G at the true parameters (the Cramér–Rao bound of the simulated experiment); empty
  /// unless the truth and the design are fixed.
  std::vector<double> predicted_std_truth;
  /// The first-order prediction of each validation metric's mean (identified model, the 12 of
  /// TrialRecord::validation, SI): the nominal-model covariance propagated to the validation
  /// poses. Empty when it cannot be predicted (rank deficient) or for older stores.
  std::vector<double> predicted_validation;
  /// The design's certified efficiency (design_certificate.h), NaN when there is none.
  double design_efficiency = std::numeric_limits<double>::quiet_NaN();
  double design_sigma_min = 0;
  std::vector<std::string> fixed_for_rank;
  std::string pool_report;
  /// The fixed truth's errors of the robot's 5N link values (SI, robot file order, scaled by
  /// truth.scale); empty when the truth is drawn per trial. The tables need it (bias against the
  /// truth in the paper's layout, the paper's identified errors), so no table re-reads a robot
  /// file after the run.
  std::vector<double> truth_errors;
};

class TrialStore {
 public:
  /// Opens (creating if needed) the database at `path`. Throws std::runtime_error on failure.
  explicit TrialStore(const std::string& path);
  ~TrialStore();
  TrialStore(const TrialStore&) = delete;
  TrialStore& operator=(const TrialStore&) = delete;

  void PutCell(const StoredCell& cell);
  std::vector<StoredCell> Cells() const;  ///< by ord
  /// The ids of the stored cells, by ord: Cells() without reading their rows' JSON.
  std::vector<std::string> CellIds() const;
  /// Inserts records in one transaction; already present (cell_id, trial) are left as they are.
  void Insert(const std::vector<TrialRecord>& records);
  /// Trial indices stored for a cell, ascending.
  std::vector<long long> DoneTrials(const std::string& cell_id) const;
  long long CountTrials(const std::string& cell_id) const;
  long long CountTrials() const;  ///< of every cell
  /// The record of (cell, trial), if stored.
  std::optional<TrialRecord> GetTrial(const std::string& cell_id, long long trial) const;
  /// Every record of a cell with first <= trial < end, in trial order (the canonical order for
  /// aggregation).
  void ForEachTrial(const std::string& cell_id,
                    const std::function<void(const TrialRecord&)>& visit, long long first = 0,
                    long long end = std::numeric_limits<long long>::max()) const;
  /// Copies every cell and trial of another store (INSERT OR IGNORE).
  void MergeFrom(const std::string& other_path);
  /// Reads the first 32 MiB of the database through a memory map instead of copies (an
  /// aggregating connection: fewer system calls; mapped pages count as resident memory, hence
  /// the bound). Not for writers.
  void MapForReading();
  void SetMeta(const std::string& key, const std::string& value);
  std::optional<std::string> GetMeta(const std::string& key) const;

  const std::string& path() const { return path_; }

 private:
  void Exec(const std::string& sql) const;
  /// Exec, retried for up to the busy timeout while another connection holds a lock SQLite does
  /// not wait for by itself (the switch to WAL, BEGIN IMMEDIATE on a store being created).
  void ExecWhileBusy(const std::string& sql) const;
  /// Creates the tables and adds the columns older stores lack; inside a write transaction.
  void CreateSchema();
  sqlite3* db_ = nullptr;
  std::string path_;
};

}  // namespace lrcal
