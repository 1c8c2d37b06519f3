// Branch and bound over a selection step's candidates (experiment_design.cc, block_selection.cc).
//
// Private to src/design.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <vector>

namespace lrcal {

// Branch and bound over candidate positions 0 … P−1: evaluates exact(pos, best) in the order of
// `keys` (highest first; ties: the lowest position) and stops at the first position whose upper
// bound bound(pos) is below the best exact score so far (which starts at `floor`). The same
// choice as evaluating every position: the largest exact score above `floor`, ties to the lowest
// position; -1 if none. exact(pos, best) may return any value below `best` once it knows it
// cannot beat it.
template <typename Bound, typename Exact>
int BestInBoundOrder(const Eigen::VectorXd& keys, Bound bound, Exact exact, double floor,
                     long long* evaluations) {
  std::vector<int> order;  // only positions that can beat `floor`: the others come after the stop
  order.reserve(static_cast<std::size_t>(keys.size()));
  for (int pos = 0; pos < keys.size(); ++pos)
    if (!(bound(pos) < floor)) order.push_back(pos);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return keys[a] > keys[b] || (keys[a] == keys[b] && a < b); });
  double best = floor;
  int best_pos = -1;
  for (int pos : order) {
    if (bound(pos) < best) break;
    const double s = exact(pos, best);
    ++*evaluations;
    if (s > best || (s == best && best_pos >= 0 && pos < best_pos)) {
      best = s;
      best_pos = pos;
    }
  }
  return best_pos;
}

}  // namespace lrcal
