// The time a run has left, from what its cells' trials have cost so far.
//
// Cells of one study can differ in cost by orders of magnitude (a 2,000-configuration design
// against a 50-configuration one), so a run's overall trial rate misleads while it works through
// cheap cells first. The estimate weighs each cell's remaining trials by that cell's measured mean
// compute time per trial (one thread), and turns work into wall time by the run's own measured
// pace: seconds left = elapsed × remaining work / work done, with the elapsed time counted from
// the start of the trials (cell preparation excluded) and the work of a trial its cell's mean
// cost. A cell none of whose trials has finished yet is costed at the mean per-trial cost of the
// cells that have (`lrcal plan`'s model, one measured cell standing for the others).
#pragma once

#include <vector>

namespace lrcal {

class RemainingTimeEstimate {
 public:
  /// `planned` holds each cell's trials this process will compute (its missing trials).
  explicit RemainingTimeEstimate(std::vector<long long> planned);
  /// A trial of cell `cell` finished, having taken `seconds` of compute (one thread).
  void Record(int cell, double seconds);
  /// Seconds left after `elapsed` seconds of trials; NaN until a trial has been recorded.
  double SecondsLeft(double elapsed) const;
  long long remaining() const;

 private:
  std::vector<long long> planned_, done_;
  std::vector<double> seconds_;
};

}  // namespace lrcal
