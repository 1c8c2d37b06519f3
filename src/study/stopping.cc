#include "lrcal/study/stopping.h"

#include <algorithm>
#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/core/settings.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/trial_store.h"

namespace lrcal {

CellStopping::CellStopping(const StopWhen& rule, long long max_trials)
    : rule_(rule), max_trials_(max_trials) {
  if (max_trials_ <= 0) {  // nothing to run: decided at once
    decided_ = true;
    next_ = 0;
  }
}

long long CellStopping::next_boundary() const {
  if (!rule_.enabled()) return max_trials_;
  return std::min(max_trials_, (next_ / rule_.block + 1) * rule_.block);
}

void CellStopping::Add(const TrialRecord& r) {
  if (decided_) return;
  ++next_;
  if (r.status == TrialStatus::kOk) {
    ++ok_;
    const double n = static_cast<double>(ok_);
    for (int k = 0; k < 12; ++k) {
      const double x = r.validation[k];
      sum_[k] += x;
      const double delta = x - welford_mean_[k];
      welford_mean_[k] += delta / n;
      welford_m2_[k] += delta * (x - welford_mean_[k]);
      if (rule_.p95_relative_halfwidth > 0) pending_[k].push_back(x);
    }
  }
  if (next_ == max_trials_ || (rule_.enabled() && next_ % rule_.block == 0)) Evaluate();
}

void CellStopping::Evaluate() {
  // x/|y| with 0/0 = 0 (a metric that is exactly zero in every trial is known exactly).
  const auto relative = [](double x, double y) {
    if (x == 0) return 0.0;
    return y != 0 ? x / std::fabs(y) : kInf;
  };
  precision_ = StopPrecision{};
  if (rule_.relative_se > 0 && ok_ >= 2) {
    precision_.relative_se = 0;
    const double n = static_cast<double>(ok_);
    for (int k = 0; k < 12; ++k) {
      const double se = std::sqrt(welford_m2_[k] / (n - 1) / n);
      precision_.relative_se = std::max(precision_.relative_se, relative(se, sum_[k] / n));
    }
  }
  if (rule_.p95_relative_halfwidth > 0) {
    for (int k = 0; k < 12; ++k) {
      std::vector<double>& s = sorted_[k];
      std::sort(pending_[k].begin(), pending_[k].end());
      const auto middle = static_cast<std::ptrdiff_t>(s.size());
      s.insert(s.end(), pending_[k].begin(), pending_[k].end());
      std::inplace_merge(s.begin(), s.begin() + middle, s.end());
      pending_[k].clear();
    }
    const long long n = ok_;
    long long low = 0, high = 0;
    QuantileIntervalRanks(n, 0.95, 0.95, &low, &high);
    if (low >= 1 && high <= n) {
      precision_.p95_relative_halfwidth = 0;
      for (int k = 0; k < 12; ++k) {
        const std::vector<double>& s = sorted_[k];
        const double half = (s[high - 1] - s[low - 1]) / 2;
        precision_.p95_relative_halfwidth =
            std::max(precision_.p95_relative_halfwidth, relative(half, Percentile(s, 95)));
      }
    }
  }
  const bool se_ok = rule_.relative_se == 0 || precision_.relative_se <= rule_.relative_se;
  const bool p95_ok = rule_.p95_relative_halfwidth == 0 ||
                      precision_.p95_relative_halfwidth <= rule_.p95_relative_halfwidth;
  precise_ = rule_.enabled() && ok_ > 0 && se_ok && p95_ok;
  if (precise_ || next_ == max_trials_) {
    decided_ = true;
    for (auto& v : sorted_) std::vector<double>().swap(v);  // no more decisions: free the values
  }
}

bool FeedStopping(const std::vector<const TrialStore*>& stores, const std::string& cell_id,
                  long long end, CellStopping* state) {
  const long long first = state->next();
  if (end <= first) return true;
  // The union of the stores' records of [first, end), by trial (a record may be in two stores
  // after an interrupted merge of an MPI run; they are the same bits).
  std::vector<TrialRecord> records(static_cast<std::size_t>(end - first));
  std::vector<char> have(records.size(), 0);
  long long count = 0;
  for (const TrialStore* store : stores)
    store->ForEachTrial(
        cell_id,
        [&](const TrialRecord& r) {
          const std::size_t i = static_cast<std::size_t>(r.trial - first);
          if (have[i]) return;
          have[i] = 1;
          ++count;
          records[i].trial = r.trial;
          records[i].status = r.status;
          records[i].validation = r.validation;
        },
        first, end);
  if (count < end - first) return false;
  for (const TrialRecord& r : records) state->Add(r);
  return true;
}

CellStopping EvaluateStopping(const std::vector<const TrialStore*>& stores,
                              const std::string& cell_id, const StopWhen& rule,
                              long long max_trials) {
  CellStopping state(rule, max_trials);
  while (!state.decided() && FeedStopping(stores, cell_id, state.next_boundary(), &state)) {
  }
  return state;
}

}  // namespace lrcal
