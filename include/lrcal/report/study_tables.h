// The tables of a Monte-Carlo run, written into RUN_DIR/tables/ from the trial store:
//   summary.md        Markdown, laid out like the paper's tables (and the placement of the
//                     paper's published numbers in our distributions, for paper cells)
//   cells.csv, parameters.csv, validation.csv, paper_placement.csv   tidy, for pandas
//   summary.json      everything above plus the empirical covariance and correlation (SI)
//   validation.tex, parameters.tex                                   LaTeX
// Tables are in mm and mrad and say so; CSV columns carry a `unit` column; JSON is SI.
// Nothing here depends on timing, thread count or shard layout: the same records give the same
// bytes.
#pragma once

#include <string>
#include <vector>

#include "lrcal/core/text_document.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/study.h"

namespace lrcal {

struct StudyTablesResult {
  std::vector<CellSummary> cells;
  TextDocument document;  ///< the content of summary.md (TextDocument::ToMarkdown)
  bool complete = true;   ///< every cell has all its trials
};

/// Summarises every cell in `store` and writes RUN_DIR/tables/. `study` is the resolved study
/// (Study::ToJson()) recorded with the run; `trials_per_cell` marks incomplete cells.
StudyTablesResult WriteStudyTables(const TrialStore& store, const Json& study,
                                   const std::string& run_dir);

}  // namespace lrcal
