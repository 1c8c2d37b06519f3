// The tables of a Monte-Carlo run, written into RUN_DIR/tables/ from the trial store:
//   summary.md        Markdown: the sensitivity indices first (a sensitivity plan), then the
//                     validation errors, laid out like the paper's tables (and the placement of
//                     the paper's published numbers in our distributions, for paper cells); a
//                     large study's per-cell tables show its chosen cells (ShownCells)
//   cells.csv, parameters.csv, validation.csv, paper_placement.csv   tidy, for pandas
//   summary.json      everything above plus the empirical covariance and correlation (SI)
//   validation.tex, parameters.tex                                   LaTeX
// Tables are in mm and mrad and say so; CSV columns carry a `unit` column; JSON is SI.
// Nothing here depends on timing, thread count or shard layout: the same records give the same
// bytes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "lrcal/core/text_document.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/study.h"

namespace lrcal {

/// A study of up to this many cells has every cell in the summary's per-cell tables; a larger one
/// shows a chosen few there (ShownCells) and an aggregate over all its cells, and its CSV, JSON
/// and LaTeX files keep every cell.
inline constexpr std::size_t kCellsShownInFull = 24;

/// The cells (indices into `cells`) the summary's per-cell tables and the report's per-cell
/// figures show: every cell of a study of up to kCellsShownInFull cells; of a larger one, the
/// paper's cells and the cells at the minimum, lower quartile, median, upper quartile and
/// maximum of the mean validation RMS position error of the identified model
/// (CellSummary::axis_mean), in study order.
std::vector<std::size_t> ShownCells(const std::vector<CellSummary>& cells);

struct StudyTablesResult {
  std::vector<CellSummary> cells;
  std::vector<std::size_t> shown;  ///< ShownCells(cells)
  TextDocument document;           ///< the content of summary.md (TextDocument::ToMarkdown)
  bool complete = true;            ///< every cell has all its trials
};

/// Summarises every cell in `store` and writes RUN_DIR/tables/. `study` is the resolved study
/// (Study::ToJson()) recorded with the run; `trials_per_cell` marks incomplete cells.
StudyTablesResult WriteStudyTables(const TrialStore& store, const Json& study,
                                   const std::string& run_dir);

}  // namespace lrcal
