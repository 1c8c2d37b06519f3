// Test helper: a finished run's cells summarised, for tests that judge a study by its statistics.
#pragma once

#include <string>
#include <vector>

#include "lrcal/study/statistics.h"
#include "lrcal/study/trial_store.h"

namespace lrcal::testing {

/// Every cell of the run in `run_dir` (its trials.sqlite), summarised, in study order.
inline std::vector<CellSummary> SummarizeRun(const std::string& run_dir) {
  TrialStore store(run_dir + "/trials.sqlite");
  std::vector<CellSummary> out;
  for (const StoredCell& cell : store.Cells()) out.push_back(SummarizeCell(store, cell));
  return out;
}

}  // namespace lrcal::testing
