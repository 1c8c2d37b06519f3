#include "lrcal/report/report_data.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "lrcal/core/error.h"
#include "lrcal/report/study_tables.h"
#include "lrcal/study/prepared_cell.h"
#include "lrcal/study/run_directory.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial_store.h"

namespace lrcal {

namespace fs = std::filesystem;

namespace {

Json Vector(const std::vector<double>& v, double scale) {
  Json j = Json::array();
  for (double x : v) j.push_back(x * scale);
  return j;
}

// Per configuration: [x, y, z] rows, scaled.
Json Columns(const Eigen::Matrix3Xd& m, double scale) {
  Json j = Json::array();
  for (int c = 0; c < m.cols(); ++c)
    j.push_back({m(0, c) * scale, m(1, c) * scale, m(2, c) * scale});
  return j;
}

}  // namespace

namespace {

Json ReadReportManifest(const std::string& run_dir) {
  const fs::path dir = run_dir;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(run_dir, "no such run directory");
  const fs::path manifest_path = dir / "manifest.json";
  if (!fs::exists(manifest_path, ec))
    throw InputError(run_dir, "not an lrcal run directory: manifest.json is missing");
  const Json manifest = ReadJsonFile(manifest_path.string());
  if (!manifest.contains("study") || !manifest["study"].contains("cells") ||
      !manifest["study"].contains("trials"))
    throw InputError(manifest_path.string(),
                     "malformed manifest: expected study.cells and study.trials");
  return manifest;
}

// A consistent snapshot of every store (SQLite readers do not block a running writer), and the
// tables from it.
// Returns the ids of the cells the tables show.
std::vector<std::string> SnapshotAndTables(const std::string& run_dir, const Json& manifest,
                                           ReportData* data) {
  const fs::path snapshot = fs::path(data->dir) / "trials.snapshot.sqlite";
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(snapshot.string() + suffix);
  TrialStore snap(snapshot.string());
  const std::vector<std::string> stores = RunDirectory(run_dir).StorePaths();
  if (stores.empty())
    throw InputError(run_dir, "no trial store (trials.sqlite): the run has not started");
  for (const std::string& path : stores) snap.MergeFrom(path);
  // Done and expected as the tables count them: up to each cell's stopping point under
  // stop_when, the maximum until it is decided.
  const StudyTablesResult tables = WriteStudyTables(snap, manifest["study"], data->dir);
  // The summary as blocks (headings, paragraphs, tables) for the page: lrcal.report lays them
  // out without parsing summary.md back.
  WriteFileAtomically((fs::path(data->dir) / "document.json").string(),
                      tables.document.ToJson().dump(1) + "\n");
  for (const CellSummary& s : tables.cells) {
    data->done += s.trials;
    data->expected += s.stop.trials_used;
  }
  data->complete = tables.complete;
  std::vector<std::string> shown;
  for (std::size_t i : tables.shown) shown.push_back(tables.cells[i].cell.id);
  return shown;
}

Json PoseErrorsJson(const PoseErrors& nominal, const PoseErrors& identified) {
  return {{"position_nominal", Columns(nominal.position, 1e3)},
          {"position_identified", Columns(identified.position, 1e3)},
          {"orientation_nominal", Columns(nominal.orientation, 1e3)},
          {"orientation_identified", Columns(identified.orientation, 1e3)}};
}

// Trial 0 of a cell in detail, recomputed (it is a pure function of the settings).
Json CellRealisation(const Study& study, const Cell& cell) {
  const PreparedCell prepared = PreparedCell::Prepare(study, cell);
  TrialDetails d;
  const TrialRecord r = prepared.Run(0, &d);
  Json cj = {{"id", cell.id},
             {"label", cell.label},
             {"status", TrialStatusName(r.status)},
             {"paper_case", cell.typed.paper_case}};
  if (r.status == TrialStatus::kOk) {
    cj["distance_error_nominal"] = Vector(d.distance_error_nominal, 1e3);
    cj["distance_error_identified"] = Vector(d.distance_error_identified, 1e3);
    cj["measurement"] = PoseErrorsJson(d.measurement_nominal, d.measurement_identified);
    cj["validation"] = PoseErrorsJson(d.validation_nominal, d.validation_identified);
  }
  return cj;
}

// The cells of the run that the tables show (ShownCells: every cell of a small study, a chosen
// few of a large one) that the study file still has; InputError when none can be recomputed.
Json Realisation(const Json& manifest, const std::vector<std::string>& shown) {
  Json realisation;
  realisation["trial"] = 0;
  realisation["units"] = "distance errors mm; position errors mm; orientation errors mrad";
  realisation["cells"] = Json::array();
  const std::string study_file = manifest.value("study_file", std::string());
  const Study study = LoadStudy(study_file);
  if (study.seed != manifest["study"]["seed"].get<std::uint64_t>())
    throw InputError(study_file, "the study file changed since the run (seed)");
  for (const Cell& cell : study.cells)
    if (std::find(shown.begin(), shown.end(), cell.id) != shown.end())
      realisation["cells"].push_back(CellRealisation(study, cell));
  if (realisation["cells"].empty())
    throw InputError(study_file,
                     "none of its cells is in this run (the study file, or lrcal's "
                     "settings, changed since the run)");
  return realisation;
}

}  // namespace

void RemoveReportSnapshot(const ReportData& data) {
  std::error_code ec;
  const std::string snapshot = (fs::path(data.dir) / "trials.snapshot.sqlite").string();
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) fs::remove(snapshot + suffix, ec);
}

ReportData PrepareReportData(const std::string& run_dir) {
  const Json manifest = ReadReportManifest(run_dir);
  ReportData data;
  data.dir = (fs::path(run_dir) / "report").string();
  fs::create_directories(data.dir);
  const std::vector<std::string> shown = SnapshotAndTables(run_dir, manifest, &data);
  const fs::path realisation_path = fs::path(data.dir) / "realisation.json";
  fs::remove(realisation_path);
  try {
    const Json realisation = Realisation(manifest, shown);
    WriteFileAtomically(realisation_path.string(), realisation.dump(1) + "\n");
    data.realisation = true;
  } catch (const InputError& e) {
    data.note = std::string("one-realisation figures left out: ") + e.what();
  }
  const Json status = {{"done", data.done},
                       {"expected", data.expected},
                       {"complete", data.complete},
                       {"realisation", data.realisation},
                       {"note", data.note}};
  WriteFileAtomically((fs::path(data.dir) / "status.json").string(), status.dump(2) + "\n");
  return data;
}

}  // namespace lrcal
