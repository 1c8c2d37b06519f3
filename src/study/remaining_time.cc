#include "lrcal/study/remaining_time.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

namespace lrcal {

RemainingTimeEstimate::RemainingTimeEstimate(std::vector<long long> planned)
    : planned_(std::move(planned)), done_(planned_.size(), 0), seconds_(planned_.size(), 0.0) {}

void RemainingTimeEstimate::Record(int cell, double seconds) {
  const auto c = static_cast<std::size_t>(cell);
  if (c >= planned_.size()) return;
  ++done_[c];
  seconds_[c] += seconds;
}

long long RemainingTimeEstimate::remaining() const {
  long long left = 0;
  for (std::size_t c = 0; c < planned_.size(); ++c) left += std::max(0LL, planned_[c] - done_[c]);
  return left;
}

double RemainingTimeEstimate::SecondsLeft(double elapsed) const {
  double work_done = 0;  // s of compute, every trial at its own cost
  long long measured_trials = 0;
  for (std::size_t c = 0; c < planned_.size(); ++c) {
    work_done += seconds_[c];
    measured_trials += done_[c];
  }
  if (measured_trials == 0 || !(work_done > 0)) return std::nan("");
  const double fallback = work_done / static_cast<double>(measured_trials);
  double work_left = 0;
  for (std::size_t c = 0; c < planned_.size(); ++c) {
    const long long left = std::max(0LL, planned_[c] - done_[c]);
    const double cost = done_[c] > 0 ? seconds_[c] / static_cast<double>(done_[c]) : fallback;
    work_left += static_cast<double>(left) * cost;
  }
  return elapsed * work_left / work_done;
}

}  // namespace lrcal
