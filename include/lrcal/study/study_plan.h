// A dry run of a study (`lrcal plan`): every cell prepared and a few of its trials timed, to
// estimate what the run will cost before it is started.
#pragma once

#include <string>
#include <vector>

#include "lrcal/core/json.h"
#include "lrcal/io/result_json.h"
#include "lrcal/study/study.h"

namespace lrcal {

/// One cell's measured costs.
struct CellPlan {
  std::string label, id;
  long long trials = 0;
  double prepare_seconds = 0;    ///< s, preparing the cell
  double seconds_per_trial = 0;  ///< s, the mean of the first min(trials, 20) trials, one thread
  double estimate_seconds = 0;   ///< s, prepare + trials × per trial / threads
  Json settings;                 ///< the cell's settings
};

struct StudyPlan {
  std::string study;
  int threads = 1;  ///< the threads the estimate is for
  long long total_trials = 0;
  std::vector<CellPlan> cells;
  double estimate_seconds = 0;  ///< s, the sum over the cells

  /// The table of cells and the total.
  std::string ToText() const;
  ResultJson ToJson() const;
};

/// Prepares every cell of `study` and times a few trials. `threads` 0: all cores.
StudyPlan PlanStudy(const Study& study, int threads);

}  // namespace lrcal
