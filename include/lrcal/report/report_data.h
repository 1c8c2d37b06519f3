// What `lrcal report` prepares for the report page (python3 -m lrcal.report), in RUN_DIR/report/:
//   trials.snapshot.sqlite  a consistent copy of every store of the run (main and rank stores),
//                           so a run still going, or interrupted, can be reported; removed once
//                           the report is written (RemoveReportSnapshot)
//   tables/                 the tables of study_report.h, from the snapshot
//   document.json           summary.md as blocks (TextDocument::ToJson), for the page
//   realisation.json        trial 0 of every cell in detail (TrialDetails): the paper's figures
//   status.json             trials done / expected, and whether the run is complete
#pragma once

#include <string>

namespace lrcal {

struct ReportData {
  std::string dir;         ///< RUN_DIR/report
  long long done = 0;      ///< trials in the snapshot (up to each cell's stopping point)
  long long expected = 0;  ///< trials of the whole study (stop_when: as decided so far)
  bool complete = false;
  bool realisation = false;  ///< realisation.json written (needs the study file)
  std::string note;          ///< why the realisation is missing, if it is
};

/// Prepares RUN_DIR/report. Throws InputError for a missing or malformed run directory.
ReportData PrepareReportData(const std::string& run_dir);
/// Removes the snapshot once the page has been drawn (it is as large as the store).
void RemoveReportSnapshot(const ReportData& data);

}  // namespace lrcal
