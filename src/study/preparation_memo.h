// Process-wide memos of the steps of a cell's preparation that the cells of a sweep or a
// sensitivity plan share (the robot file and whether its chain is coupled, the pool and
// validation draws, the pool's identifiability, the design's selection, its certificate, the
// first-order draws): the cells of a noise sweep differ in σ alone, yet each would otherwise
// parse, draw, analyse, select and propagate the same configurations again.
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

/// What every memo is to ClearPreparationMemos: it registers itself while it exists.
class PreparationMemoBase {
 public:
  PreparationMemoBase(const PreparationMemoBase&) = delete;
  PreparationMemoBase& operator=(const PreparationMemoBase&) = delete;
  virtual void Clear() = 0;

 protected:
  PreparationMemoBase();
  virtual ~PreparationMemoBase();
};

/// Empties every memo: the runner calls it once its cells are prepared, so a long-lived process
/// (Python) does not keep a study's pools and draws.
void ClearPreparationMemos();

/// The last `kEntries` results of a step, keyed by `Key` (its operator== compares every input).
/// A plan's cells may return to a setting after many others (a Sobol plan's matrices A, B and
/// their mixtures), so the memos hold a few hundred entries of a few kilobytes.
template <typename Key, typename Value, std::size_t kEntries = 256>
class PreparationMemo : public PreparationMemoBase {
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

  void Clear() override {
    const std::lock_guard<std::mutex> lock(mutex_);
    entries_.clear();
  }

 private:
  std::mutex mutex_;
  std::vector<std::pair<Key, Value>> entries_;
};

}  // namespace lrcal
