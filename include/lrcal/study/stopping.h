// Adaptive stopping (`stop_when` in a study file): a cell runs in blocks of trials and stops at
// the first block boundary where its Monte-Carlo estimates are precise enough, in the spirit of
// the adaptive procedure of the GUM Supplement 1 (§7.9), with the decision rule stated up front.
//
// Bit-reproducibility: the decision at boundary b uses exactly the cell's trials 0 … b−1 in
// canonical order and nothing else, so the stopping point N of a cell is a function of the study
// alone (trials are pure functions of seed, cell and index). Whatever computed the trials — any
// number of threads, shards, MPI ranks or restarts, even trials computed beyond N — the tables use
// trials 0 … N−1 and are the same bytes.
//
// The criteria, over the validation metrics of the identified model (the 12 RMS / max position /
// orientation errors per axis, from the trials that identified successfully):
//   relative_se             SE(mean)/|mean| ≤ relative_se for every metric (SE = s/√n)
//   p95_relative_halfwidth  half the width of the p95's 95 % distribution-free confidence interval
//                           (order statistics, statistics.h) over the p95 ≤ this, for every metric
// A cell that never meets them stops at the study's `trials` (the maximum).
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "lrcal/core/json.h"
#include "lrcal/study/trial.h"

namespace lrcal {

class TrialStore;

/// The `stop_when` rule of a study. Off (a fixed trial count) when block = 0.
struct StopWhen {
  long long block = 0;                ///< trials per block; decisions only at multiples of it
  double relative_se = 0;             ///< 0: no criterion on the means
  double p95_relative_halfwidth = 0;  ///< 0: no criterion on the p95s
  bool enabled() const { return block > 0; }
  /// {"block", "relative_se", "p95_relative_halfwidth"} (criteria that are off are left out);
  /// null when off.
  Json ToJson() const;
  /// The inverse of ToJson (null → off). Throws InputError naming `where` and the field.
  static StopWhen FromJson(const Json& j, const std::string& where);
};

/// The precision of a cell's estimates at a boundary: the worst metric for each criterion
/// (+inf when it cannot be stated, e.g. no successful trial or too few for the p95 interval).
struct StopPrecision {
  double relative_se = std::numeric_limits<double>::infinity();
  double p95_relative_halfwidth = std::numeric_limits<double>::infinity();
};

/// Decides when one cell stops, from its records fed in canonical order. Memory: a few numbers
/// per metric, plus the successful trials' metric values when the p95 criterion is on.
class CellStopping {
 public:
  CellStopping(const StopWhen& rule, long long max_trials);
  /// Feeds trial next(); evaluates the rule when the trial closes a block (or the maximum).
  void Add(const TrialRecord& record);
  /// The index of the next trial to feed.
  long long next() const { return next_; }
  /// The next boundary at which the rule is evaluated.
  long long next_boundary() const;
  /// True once a boundary met every criterion or the maximum was reached.
  bool decided() const { return decided_; }
  /// Trials the cell uses (the stopping point); the maximum until decided.
  long long trials_used() const { return decided_ ? next_ : max_trials_; }
  /// True when the cell stopped because every criterion held (possibly at the maximum).
  bool precise() const { return precise_; }
  /// The precision at the last boundary evaluated.
  const StopPrecision& precision() const { return precision_; }

 private:
  void Evaluate();

  StopWhen rule_;
  long long max_trials_;
  long long next_ = 0, ok_ = 0;
  bool decided_ = false, precise_ = false;
  StopPrecision precision_;
  // Per metric: the running sum (in canonical order, as the tables sum), Welford's mean and M2
  // (for the std), and, with the p95 criterion, the sorted values of the blocks evaluated and
  // the values of the block in progress.
  std::array<double, 12> sum_{}, welford_mean_{}, welford_m2_{};
  std::array<std::vector<double>, 12> sorted_, pending_;
};

/// The stopping state of a cell from the trials recorded in `stores` (their union; e.g. an MPI
/// run's rank stores): fed block by block until a decision or the first block not fully
/// recorded. With the rule off: decided at `max_trials` once every trial is recorded.
CellStopping EvaluateStopping(const std::vector<const TrialStore*>& stores,
                              const std::string& cell_id, const StopWhen& rule,
                              long long max_trials);

/// Feeds `state` the trials [state->next(), end) of a cell from `stores` if every one of them is
/// recorded; returns false (feeding nothing) otherwise.
bool FeedStopping(const std::vector<const TrialStore*>& stores, const std::string& cell_id,
                  long long end, CellStopping* state);

}  // namespace lrcal
