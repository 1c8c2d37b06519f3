#include "lrcal/study/trial_store.h"

#include <sqlite3.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

#include "lrcal/kinematics/validation_metric.h"
#include "study/trial_pipeline.h"

namespace lrcal {

namespace {

// How long an operation waits for another connection's lock before it fails.
constexpr int kBusyTimeoutMs = 10000;

// SQLite's result codes that mean the storage failed (not the query): a StorageError, which the
// runner turns into a clean stop that keeps every committed trial.
bool IsStorageFailure(int rc) {
  switch (rc & 0xff) {
    case SQLITE_FULL:
    case SQLITE_IOERR:
    case SQLITE_READONLY:
    case SQLITE_CANTOPEN:
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB:
      return true;
    default:
      return false;
  }
}

[[noreturn]] void ThrowSqlite(int rc, const std::string& message) {
  if (IsStorageFailure(rc)) throw StorageError(message);
  throw std::runtime_error(message);
}

// Runs `sql` once: SQLite's result code, and its message in `message` when it is not SQLITE_OK.
int ExecOnce(sqlite3* db, const std::string& sql, std::string* message) {
  char* err = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err);
  if (rc != SQLITE_OK) *message = err ? err : "unknown error";
  sqlite3_free(err);
  return rc;
}

class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) : db_(db) {
    const int rc = sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr);
    if (rc != SQLITE_OK)
      ThrowSqlite(rc, std::string("sqlite: ") + sqlite3_errmsg(db) + " in: " + sql);
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  sqlite3_stmt* get() { return stmt_; }
  bool Step() {
    int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    ThrowSqlite(rc, std::string("sqlite (") + sqlite3_db_filename(db_, "main") +
                        "): " + sqlite3_errmsg(db_));
  }
  void Reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  void Text(int i, const std::string& s) {
    sqlite3_bind_text(stmt_, i, s.c_str(), static_cast<int>(s.size()), SQLITE_TRANSIENT);
  }
  std::string ColumnText(int i) {
    const unsigned char* t = sqlite3_column_text(stmt_, i);
    return t ? reinterpret_cast<const char*>(t) : "";
  }

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

constexpr const char* kCellColumns =
    "cell_id, ord, label, settings, parameter_names, predicted_std, design_sigma_min, "
    "fixed_for_rank, pool_report, truth_errors, predicted_std_truth, predicted_validation, "
    "design_efficiency";

// Standard deviations as JSON, NaN (a parameter without a prediction) as null, and back.
std::string StdJson(const std::vector<double>& sd) {
  nlohmann::json j = nlohmann::json::array();
  for (double v : sd) j.push_back(std::isnan(v) ? nlohmann::json() : nlohmann::json(v));
  return j.dump();
}

std::vector<double> StdFromJson(const std::string& text) {
  std::vector<double> sd;
  for (const auto& v : nlohmann::json::parse(text))
    sd.push_back(v.is_null() ? std::nan("") : v.get<double>());
  return sd;
}

std::string TrialColumns() {
  std::string cols = "cell_id, trial, status, iterations, residual_rms, sigma_hat, sigma_min";
  for (const char* prefix : {"val_", "nom_"})
    for (int k = 0; k < kNumValidationColumns; ++k)
      cols += std::string(", ") + prefix + ValidationColumnName(k);
  return cols + ", errors, seconds, missed_configurations, coverage, coverage_total";
}

}  // namespace

TrialStore::TrialStore(const std::string& path) : path_(path) {
  // One connection per TrialStore, used by one thread at a time: no per-call mutex.
  if (sqlite3_open_v2(path.c_str(), &db_,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                      nullptr) != SQLITE_OK) {
    std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw StorageError("cannot open trial store " + path + ": " + msg);
  }
  // Whatever fails below, the connection is closed (which rolls back an open transaction).
  try {
    sqlite3_busy_timeout(db_, kBusyTimeoutMs);
    // Switching to WAL takes the file's exclusive lock. While another process opens the same new
    // store (a run starting as `lrcal status` or a test polls it), SQLite answers SQLITE_BUSY
    // here without calling the busy handler, so wait for it as the handler would.
    ExecWhileBusy("PRAGMA journal_mode=WAL");
    Exec("PRAGMA synchronous=NORMAL");
    // Fault injection for tests: a store that holds at most this many pages fails with
    // SQLITE_FULL exactly as a full disk does.
    if (const char* pages = std::getenv("LRCAL_TEST_STORE_MAX_PAGES"))
      Exec("PRAGMA max_page_count=" + std::to_string(std::atol(pages)));
    // The schema in one write transaction taken up front: two processes opening an old store
    // must not both find a column missing and both add it, and a read transaction that turns
    // into a write one gets SQLITE_BUSY at once, without waiting, when another connection wrote
    // first.
    ExecWhileBusy("BEGIN IMMEDIATE");
    CreateSchema();
    Exec("COMMIT");
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

void TrialStore::CreateSchema() {
  Exec("CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT)");
  Exec(
      "CREATE TABLE IF NOT EXISTS cells(cell_id TEXT PRIMARY KEY, ord INTEGER, label TEXT, "
      "settings TEXT, parameter_names TEXT, predicted_std TEXT, design_sigma_min REAL, "
      "fixed_for_rank TEXT, pool_report TEXT, truth_errors TEXT, predicted_std_truth TEXT, "
      "predicted_validation TEXT, design_efficiency REAL)");
  // Stores written before lrcal recorded the truth or its prediction: add the columns (the tables
  // then leave out what needs them rather than re-reading a robot file that may have changed).
  bool has_truth = false, has_truth_prediction = false, has_validation_prediction = false,
       has_efficiency = false;
  {
    Statement info(db_, "PRAGMA table_info(cells)");
    while (info.Step()) {
      has_truth |= info.ColumnText(1) == "truth_errors";
      has_truth_prediction |= info.ColumnText(1) == "predicted_std_truth";
      has_validation_prediction |= info.ColumnText(1) == "predicted_validation";
      has_efficiency |= info.ColumnText(1) == "design_efficiency";
    }
  }
  if (!has_truth) Exec("ALTER TABLE cells ADD COLUMN truth_errors TEXT");
  if (!has_truth_prediction) Exec("ALTER TABLE cells ADD COLUMN predicted_std_truth TEXT");
  if (!has_validation_prediction) Exec("ALTER TABLE cells ADD COLUMN predicted_validation TEXT");
  if (!has_efficiency) Exec("ALTER TABLE cells ADD COLUMN design_efficiency REAL");
  std::string trials =
      "CREATE TABLE IF NOT EXISTS trials(cell_id TEXT NOT NULL, trial INTEGER NOT NULL, "
      "status TEXT NOT NULL, iterations INTEGER, residual_rms REAL, sigma_hat REAL, sigma_min REAL";
  for (const char* prefix : {"val_", "nom_"})
    for (int k = 0; k < kNumValidationColumns; ++k)
      trials += std::string(", ") + prefix + ValidationColumnName(k) + " REAL";
  trials +=
      ", errors BLOB, seconds REAL, missed_configurations INTEGER NOT NULL DEFAULT 0, "
      "coverage REAL, coverage_total REAL, PRIMARY KEY(cell_id, trial)) WITHOUT ROWID";
  Exec(trials);
  // Stores written before a missed beam dropped its configuration (every such trial failed):
  // the column, 0 for every trial already recorded; before validation.coverage: NULL.
  bool has_missed = false, has_coverage = false;
  {
    Statement info(db_, "PRAGMA table_info(trials)");
    while (info.Step()) {
      has_missed |= info.ColumnText(1) == "missed_configurations";
      has_coverage |= info.ColumnText(1) == "coverage";
    }
  }
  if (!has_missed)
    Exec("ALTER TABLE trials ADD COLUMN missed_configurations INTEGER NOT NULL DEFAULT 0");
  if (!has_coverage) {
    Exec("ALTER TABLE trials ADD COLUMN coverage REAL");
    Exec("ALTER TABLE trials ADD COLUMN coverage_total REAL");
  }
}

TrialStore::~TrialStore() { sqlite3_close(db_); }

void TrialStore::ExecWhileBusy(const std::string& sql) const {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(kBusyTimeoutMs);
  for (;;) {
    std::string msg;
    const int rc = ExecOnce(db_, sql, &msg);
    if (rc == SQLITE_OK) return;
    const bool busy = (rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED;
    if (!busy || std::chrono::steady_clock::now() >= deadline)
      ThrowSqlite(rc, "sqlite (" + path_ + "): " + msg + " in: " + sql);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

void TrialStore::Exec(const std::string& sql) const {
  std::string msg;
  const int rc = ExecOnce(db_, sql, &msg);
  if (rc != SQLITE_OK) ThrowSqlite(rc, "sqlite (" + path_ + "): " + msg + " in: " + sql);
}

StoredCell ToStoredCell(const CellContext& c) {
  if (c.for_trials_only)
    throw std::logic_error("ToStoredCell: cell " + c.cell->id +
                           " was prepared for its trials alone");
  StoredCell s;
  s.id = c.cell->id;
  s.label = c.cell->label;
  s.order = c.cell->order;
  s.settings = c.cell->settings.dump();
  s.parameter_names = c.parameter_names;
  s.predicted_std.assign(c.predicted_std.data(), c.predicted_std.data() + c.predicted_std.size());
  s.design_sigma_min = c.design.sigma_min;
  s.fixed_for_rank = c.fixed_for_rank;
  s.pool_report = c.pool_report.ToString();
  if (!c.cell->typed.truth.random)
    s.truth_errors.assign(c.fixed_truth.errors.data(),
                          c.fixed_truth.errors.data() + c.fixed_truth.errors.size());
  s.predicted_std_truth.assign(c.predicted_std_truth.data(),
                               c.predicted_std_truth.data() + c.predicted_std_truth.size());
  if (!std::isnan(c.predicted_validation[0]))
    s.predicted_validation.assign(c.predicted_validation.begin(), c.predicted_validation.end());
  s.design_efficiency = c.design_efficiency;
  return s;
}

void TrialStore::PutCell(const StoredCell& cell) {
  Statement st(db_, "INSERT OR REPLACE INTO cells(" + std::string(kCellColumns) +
                        ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  st.Text(1, cell.id);
  sqlite3_bind_int(st.get(), 2, cell.order);
  st.Text(3, cell.label);
  st.Text(4, cell.settings);
  st.Text(5, nlohmann::json(cell.parameter_names).dump());
  st.Text(6, StdJson(cell.predicted_std));
  sqlite3_bind_double(st.get(), 7, cell.design_sigma_min);
  st.Text(8, nlohmann::json(cell.fixed_for_rank).dump());
  st.Text(9, cell.pool_report);
  if (cell.truth_errors.empty())
    sqlite3_bind_null(st.get(), 10);
  else
    st.Text(10, nlohmann::json(cell.truth_errors).dump());
  if (cell.predicted_std_truth.empty())
    sqlite3_bind_null(st.get(), 11);
  else
    st.Text(11, StdJson(cell.predicted_std_truth));
  if (cell.predicted_validation.empty())
    sqlite3_bind_null(st.get(), 12);
  else
    st.Text(12, StdJson(cell.predicted_validation));
  if (std::isnan(cell.design_efficiency))
    sqlite3_bind_null(st.get(), 13);
  else
    sqlite3_bind_double(st.get(), 13, cell.design_efficiency);
  st.Step();
}

std::vector<std::string> TrialStore::CellIds() const {
  Statement st(db_, "SELECT cell_id FROM cells ORDER BY ord, cell_id");
  std::vector<std::string> out;
  while (st.Step()) out.push_back(st.ColumnText(0));
  return out;
}

std::vector<StoredCell> TrialStore::Cells() const {
  Statement st(db_, "SELECT " + std::string(kCellColumns) + " FROM cells ORDER BY ord, cell_id");
  std::vector<StoredCell> out;
  while (st.Step()) {
    StoredCell c;
    c.id = st.ColumnText(0);
    c.order = sqlite3_column_int(st.get(), 1);
    c.label = st.ColumnText(2);
    c.settings = st.ColumnText(3);
    c.parameter_names = nlohmann::json::parse(st.ColumnText(4)).get<std::vector<std::string>>();
    c.predicted_std = StdFromJson(st.ColumnText(5));
    c.design_sigma_min = sqlite3_column_double(st.get(), 6);
    c.fixed_for_rank = nlohmann::json::parse(st.ColumnText(7)).get<std::vector<std::string>>();
    c.pool_report = st.ColumnText(8);
    if (sqlite3_column_type(st.get(), 9) != SQLITE_NULL)
      c.truth_errors = nlohmann::json::parse(st.ColumnText(9)).get<std::vector<double>>();
    if (sqlite3_column_type(st.get(), 10) != SQLITE_NULL)
      c.predicted_std_truth = StdFromJson(st.ColumnText(10));
    if (sqlite3_column_type(st.get(), 11) != SQLITE_NULL)
      c.predicted_validation = StdFromJson(st.ColumnText(11));
    if (sqlite3_column_type(st.get(), 12) != SQLITE_NULL)
      c.design_efficiency = sqlite3_column_double(st.get(), 12);
    out.push_back(c);
  }
  return out;
}

void TrialStore::Insert(const std::vector<TrialRecord>& records) {
  if (records.empty()) return;
  Exec("BEGIN IMMEDIATE");
  try {
    std::string q = "INSERT OR IGNORE INTO trials(" + TrialColumns() + ") VALUES (?";
    for (int i = 1; i < 7 + 24 + 3 + 2; ++i) q += ", ?";
    q += ")";
    Statement st(db_, q);
    for (const TrialRecord& r : records) {
      st.Reset();
      st.Text(1, r.cell_id);
      sqlite3_bind_int64(st.get(), 2, r.trial);
      st.Text(3, TrialStatusName(r.status));
      sqlite3_bind_int(st.get(), 4, r.iterations);
      sqlite3_bind_double(st.get(), 5, r.residual_rms);
      sqlite3_bind_double(st.get(), 6, r.sigma_hat);
      sqlite3_bind_double(st.get(), 7, r.sigma_min);
      const bool ok = r.status == TrialStatus::kOk;
      for (int k = 0; k < 12; ++k) {
        if (ok)
          sqlite3_bind_double(st.get(), 8 + k, r.validation[k]);
        else
          sqlite3_bind_null(st.get(), 8 + k);
        sqlite3_bind_double(st.get(), 20 + k, r.nominal[k]);
      }
      if (ok)
        sqlite3_bind_blob(st.get(), 32, r.errors.data(),
                          static_cast<int>(r.errors.size() * sizeof(double)), SQLITE_TRANSIENT);
      else
        sqlite3_bind_null(st.get(), 32);
      sqlite3_bind_double(st.get(), 33, r.seconds);
      sqlite3_bind_int(st.get(), 34, r.missed_configurations);
      for (int k = 0; k < 2; ++k) {
        const double share = k == 0 ? r.coverage : r.coverage_total;
        if (ok && std::isfinite(share))
          sqlite3_bind_double(st.get(), 35 + k, share);
        else
          sqlite3_bind_null(st.get(), 35 + k);
      }
      st.Step();
    }
    Exec("COMMIT");  // a full disk usually shows here: the batch is rolled back, nothing half-done
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

std::vector<long long> TrialStore::DoneTrials(const std::string& cell_id) const {
  Statement st(db_, "SELECT trial FROM trials WHERE cell_id = ? ORDER BY trial");
  st.Text(1, cell_id);
  std::vector<long long> out;
  while (st.Step()) out.push_back(sqlite3_column_int64(st.get(), 0));
  return out;
}

long long TrialStore::CountTrials() const {
  Statement st(db_, "SELECT COUNT(*) FROM trials");
  st.Step();
  return sqlite3_column_int64(st.get(), 0);
}

long long TrialStore::CountTrials(const std::string& cell_id) const {
  Statement st(db_, "SELECT COUNT(*) FROM trials WHERE cell_id = ?");
  st.Text(1, cell_id);
  st.Step();
  return sqlite3_column_int64(st.get(), 0);
}

namespace {
TrialStatus StatusFromName(const std::string& s) {
  TrialStatus status;
  if (!TryParseName(kTrialStatusNames, s, &status))
    throw std::runtime_error("trial store: unknown status '" + s + "'");
  return status;
}
}  // namespace

namespace {

// One row of SELECT TrialColumns() into a record (the cell id is the caller's).
void ReadTrialRow(Statement& st, TrialRecord* r) {
  r->trial = sqlite3_column_int64(st.get(), 1);
  r->status = StatusFromName(st.ColumnText(2));
  r->iterations = sqlite3_column_int(st.get(), 3);
  r->residual_rms = sqlite3_column_double(st.get(), 4);
  r->sigma_hat = sqlite3_column_double(st.get(), 5);
  r->sigma_min = sqlite3_column_double(st.get(), 6);
  for (int k = 0; k < 12; ++k) {
    r->validation[k] = sqlite3_column_type(st.get(), 7 + k) == SQLITE_NULL
                           ? std::nan("")
                           : sqlite3_column_double(st.get(), 7 + k);
    r->nominal[k] = sqlite3_column_double(st.get(), 19 + k);
  }
  const int bytes = sqlite3_column_bytes(st.get(), 31);
  r->errors.resize(bytes / sizeof(double));
  if (bytes) std::memcpy(r->errors.data(), sqlite3_column_blob(st.get(), 31), bytes);
  r->seconds = sqlite3_column_double(st.get(), 32);
  r->missed_configurations = sqlite3_column_int(st.get(), 33);
  for (int k = 0; k < 2; ++k)
    (k == 0 ? r->coverage : r->coverage_total) =
        sqlite3_column_type(st.get(), 34 + k) == SQLITE_NULL
            ? std::nan("")
            : sqlite3_column_double(st.get(), 34 + k);
}

}  // namespace

void TrialStore::ForEachTrial(const std::string& cell_id,
                              const std::function<void(const TrialRecord&)>& visit, long long first,
                              long long end) const {
  Statement st(db_,
               "SELECT " + TrialColumns() +
                   " FROM trials WHERE cell_id = ? AND trial >= ? AND trial < ? ORDER BY trial");
  st.Text(1, cell_id);
  sqlite3_bind_int64(st.get(), 2, first);
  sqlite3_bind_int64(st.get(), 3, end);
  TrialRecord r;
  r.cell_id = cell_id;  // every row has it: no per-row string
  while (st.Step()) {
    ReadTrialRow(st, &r);
    visit(r);
  }
}

std::optional<TrialRecord> TrialStore::GetTrial(const std::string& cell_id, long long trial) const {
  Statement st(db_, "SELECT " + TrialColumns() + " FROM trials WHERE cell_id = ? AND trial = ?");
  st.Text(1, cell_id);
  sqlite3_bind_int64(st.get(), 2, trial);
  if (!st.Step()) return std::nullopt;
  TrialRecord r;
  r.cell_id = cell_id;
  ReadTrialRow(st, &r);
  return r;
}

void TrialStore::MapForReading() {
  Exec("PRAGMA mmap_size=33554432");
}  // 32 MiB: small stores whole

void TrialStore::MergeFrom(const std::string& other_path) {
  { TrialStore upgraded(other_path); }  // opening brings an older store's schema up to date
  Statement attach(db_, "ATTACH DATABASE ? AS other");
  attach.Text(1, other_path);
  attach.Step();
  try {
    Exec("BEGIN IMMEDIATE");
    Exec("INSERT OR IGNORE INTO cells(" + std::string(kCellColumns) + ") SELECT " + kCellColumns +
         " FROM other.cells");
    Exec("INSERT OR IGNORE INTO trials SELECT * FROM other.trials");
    Exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    Exec("DETACH DATABASE other");
    throw;
  }
  Exec("DETACH DATABASE other");
}

void TrialStore::SetMeta(const std::string& key, const std::string& value) {
  Statement st(db_, "INSERT OR REPLACE INTO meta VALUES (?, ?)");
  st.Text(1, key);
  st.Text(2, value);
  st.Step();
}

std::optional<std::string> TrialStore::GetMeta(const std::string& key) const {
  Statement st(db_, "SELECT value FROM meta WHERE key = ?");
  st.Text(1, key);
  if (!st.Step()) return std::nullopt;
  return st.ColumnText(0);
}

}  // namespace lrcal
