// Process-wide memos of the steps of a cell's preparation that the cells of a sweep or a
// sensitivity plan share (the robot file, the pool and validation draws, the design's selection,
// its certificate, the first-order draws): the cells of a noise sweep differ in σ alone, yet each
// would otherwise draw, select and propagate the same configurations again.
//
// An entry is matched on exact equality of every input the step reads (no hash is trusted), so a
// hit returns the bits of computing the step again: the memo changes time, never a result.
// Thread-safe: two workers may compute the same entry at once, and either result is the same.
// A step that throws stores nothing (the next cell computes it again and meets the same error).
//
// Private to src/study.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <mutex>
#include <utility>
#include <vector>

namespace lrcal {

/// Exact equality of two matrices of any sizes (Eigen's == asserts equal sizes).
inline bool SameMatrix(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a == b;
}

/// The last `kEntries` results of a step, keyed by `Key` (its operator== compares every input).
template <typename Key, typename Value, std::size_t kEntries = 8>
class PreparationMemo {
 public:
  /// The value stored for `key`, else compute() stored and returned.
  template <typename Compute>
  Value Get(const Key& key, Compute&& compute) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& [k, v] : entries_)
        if (k == key) return v;
    }
    Value value = compute();
    const std::lock_guard<std::mutex> lock(mutex_);
    if (entries_.size() == kEntries) entries_.erase(entries_.begin());
    entries_.emplace_back(key, value);
    return value;
  }

 private:
  std::mutex mutex_;
  std::vector<std::pair<Key, Value>> entries_;
};

}  // namespace lrcal
