#include "lrcal/study/statistics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <tuple>

#include "lrcal/core/dense_kernels.h"

namespace lrcal {

using Json = nlohmann::json;

// ---------------------------------------------------------------------------------------------
// A cell's summary in passes over the store, memory flat in the trial count.

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// An order-preserving unsigned key of a double: a < b ⇔ Key(a) < Key(b) (with −0 < +0).
std::uint64_t Key(double x) {
  std::uint64_t u;
  std::memcpy(&u, &x, sizeof u);
  return (u >> 63) ? ~u : (u | (std::uint64_t{1} << 63));
}
double FromKey(std::uint64_t k) {
  const std::uint64_t u = (k >> 63) ? (k & ~(std::uint64_t{1} << 63)) : ~k;
  double x;
  std::memcpy(&x, &u, sizeof x);
  return x;
}

// Radix selection: each level histograms the next kLevelBits of the keys of the values that share
// the known leading bits; a bracket with at most kCollectMax values is then collected and the
// order statistic selected among them.
constexpr int kLevelBits = 12;
constexpr long long kCollectMax = 1 << 16;

// One wanted order statistic (1-based rank) of a series and how far it is bracketed.
struct RankTarget {
  long long rank = 0;
  std::uint64_t prefix = 0;  // the key's leading `bits` bits
  int bits = 0;
  long long within = 0;  // rank among the values with that prefix
  long long count = 0;   // values with that prefix
  bool done = false;
  double value = kNan;
};

// The work of one pass on one bracket of a series: a histogram of the next bits, or the values.
struct Bracket {
  std::uint64_t prefix = 0;
  int bits = 0;
  bool collect = false;
  std::vector<std::uint32_t> histogram;
  std::vector<double> values;
  bool Holds(std::uint64_t key) const { return bits == 0 || (key >> (64 - bits)) == prefix; }
  int LevelBits() const { return std::min(kLevelBits, 64 - bits); }
  void Add(double x, std::uint64_t key) {
    if (collect) {
      values.push_back(x);
    } else {
      const int level = LevelBits();
      ++histogram[(key << bits) >> (64 - level)];
    }
  }
};

// The values of one quantity over a cell's trials (canonical order), what the passes gather.
struct Series {
  long long n = 0;
  double sum = 0, mean = 0, ss = 0, m4 = 0;
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  bool quantiles = false;
  std::vector<RankTarget> targets;
  std::vector<Bracket> brackets;  // this pass's work
  double probe = kNan;
  long long probe_below = 0, probe_equal = 0;

  void Pass1(double x) {
    ++n;
    sum += x;
    min = std::min(min, x);
    max = std::max(max, x);
    if (quantiles) AddToBrackets(x);
  }
  void Pass2(double x) {
    const double d = x - mean;
    ss += d * d;
    m4 += (d * d) * (d * d);
    probe_below += x < probe;
    probe_equal += x == probe;
    AddToBrackets(x);
  }
  void AddToBrackets(double x) {
    if (brackets.empty()) return;
    const std::uint64_t key = Key(x);
    for (Bracket& b : brackets)
      if (b.Holds(key)) b.Add(x, key);
  }
  void Want(long long rank) {
    if (rank < 1 || rank > n) return;
    for (const RankTarget& t : targets)
      if (t.rank == rank) return;
    RankTarget t;
    t.rank = t.within = rank;
    t.count = n;
    targets.push_back(t);
  }
  // The brackets of the next pass: one per distinct unresolved prefix.
  void PlanBrackets() {
    brackets.clear();
    for (const RankTarget& t : targets) {
      if (t.done) continue;
      bool seen = false;
      for (const Bracket& b : brackets) seen |= b.prefix == t.prefix && b.bits == t.bits;
      if (seen) continue;
      Bracket b;
      b.prefix = t.prefix;
      b.bits = t.bits;
      b.collect = t.count <= kCollectMax;
      if (!b.collect) b.histogram.assign(std::size_t{1} << b.LevelBits(), 0);
      brackets.push_back(std::move(b));
    }
  }
  // Narrows every target whose bracket was just passed over. A bracket's collected values are
  // sorted once for all its targets (a cell's quantiles and their intervals ask a dozen ranks of
  // the same values; a selection per rank was most of a large study's tables).
  void Resolve() {
    for (Bracket& b : brackets) {
      if (b.collect) std::sort(b.values.begin(), b.values.end());
      for (RankTarget& t : targets)
        if (!t.done && t.prefix == b.prefix && t.bits == b.bits) {
          if (b.collect) {
            Select(b, &t);
          } else {
            Narrow(b, &t);
          }
        }
    }
    brackets.clear();
  }
  // The target's value among the bracket's collected values (sorted).
  static void Select(const Bracket& b, RankTarget* t) {
    t->value = b.values[static_cast<std::size_t>(t->within - 1)];
    t->done = true;
  }
  // The next bits of the target's key, from the bracket's histogram.
  void Narrow(const Bracket& b, RankTarget* t) const {
    const int level = b.LevelBits();
    long long below = 0;
    std::size_t bin = 0;
    while (below + b.histogram[bin] < t->within) below += b.histogram[bin++];
    t->prefix = (t->bits == 0 ? 0 : t->prefix << level) | bin;
    t->bits += level;
    t->within -= below;
    t->count = b.histogram[bin];
    if (t->bits == 64 || min == max) {  // every value in the bracket is the same
      t->value = t->bits == 64 ? FromKey(t->prefix) : min;
      t->done = true;
    }
  }
  bool Pending() const {
    for (const RankTarget& t : targets)
      if (!t.done) return true;
    return false;
  }
  double OrderStatistic(long long rank) const {
    for (const RankTarget& t : targets)
      if (t.rank == rank) return t.value;
    return kNan;
  }
};

// The type-7 percentile p (0–100) from the order statistics (as Quantile()).
double SeriesQuantile(const Series& s, double p) {
  if (s.n == 0) return kNan;
  const double h = (s.n - 1) * p / 100.0;
  const long long lo = static_cast<long long>(std::floor(h));
  const double below = s.OrderStatistic(lo + 1);
  if (lo + 1 >= s.n) return below;
  const double above = s.OrderStatistic(lo + 2);
  return below + (h - lo) * (above - below);
}

void WantQuantile(Series* s, double p) {
  const double h = (s->n - 1) * p / 100.0;
  const long long lo = static_cast<long long>(std::floor(h));
  s->Want(lo + 1);
  s->Want(lo + 2);
}

QuantileInterval SeriesInterval(const Series& s, double p) {
  QuantileInterval ci;
  QuantileIntervalRanks(s.n, p, 0.95, &ci.low_rank, &ci.high_rank);
  ci.low = ci.low_rank >= 1 ? s.OrderStatistic(ci.low_rank) : kNan;
  ci.high = ci.high_rank <= s.n ? s.OrderStatistic(ci.high_rank) : kNan;
  return ci;
}

// The ranks a Distribution needs: type-7 p5, p50, p95 and their intervals.
void WantDistribution(Series* s) {
  for (double p : {5.0, 50.0, 95.0}) {
    WantQuantile(s, p);
    long long low = 0, high = 0;
    QuantileIntervalRanks(s->n, p / 100, 0.95, &low, &high);
    s->Want(low);
    s->Want(high);
  }
}

Distribution SeriesDistribution(const Series& s) {
  Distribution d;
  d.n = s.n;
  if (s.n == 0) {
    d.mean = d.std = d.p5 = d.p50 = d.p95 = d.min = d.max = d.mean_se = d.std_se = kNan;
    d.p5_ci = d.p50_ci = d.p95_ci = QuantileInterval{kNan, kNan, 0, 1};
    return d;
  }
  d.mean = s.mean;
  d.std = d.n > 1 ? std::sqrt(s.ss / (d.n - 1)) : kNan;
  d.mean_se = d.n > 1 ? d.std / std::sqrt(static_cast<double>(d.n)) : kNan;
  d.std_se = StdStandardErrorFromM4(s.m4, static_cast<std::size_t>(d.n), d.std);
  d.max_bounds_p95 = 1 - std::pow(0.95, static_cast<double>(d.n));
  d.min = s.min;
  d.max = s.max;
  d.p5 = SeriesQuantile(s, 5);
  d.p50 = SeriesQuantile(s, 50);
  d.p95 = SeriesQuantile(s, 95);
  d.p5_ci = SeriesInterval(s, 0.05);
  d.p50_ci = SeriesInterval(s, 0.50);
  d.p95_ci = SeriesInterval(s, 0.95);
  return d;
}

// Hands blocks of records from a reading thread to a computing one, in order.
class BlockPipeline {
 public:
  static constexpr std::size_t kBlock = 2048, kInFlight = 4;

  BlockPipeline() {
    for (std::size_t i = 0; i < kInFlight; ++i) free_.emplace_back();
  }

  // The reader's side: fills recycled blocks in canonical order.
  void Read(const TrialStore& store, const std::string& cell_id, long long end) {
    try {
      std::vector<TrialRecord> block = TakeFree();
      std::size_t used = 0;
      store.ForEachTrial(
          cell_id,
          [&](const TrialRecord& r) {
            if (used == block.size()) block.emplace_back();
            CopyRecord(r, &block[used++]);
            if (used == kBlock) {
              HandOver(std::move(block));
              block = TakeFree();
              used = 0;
            }
          },
          0, end);
      block.resize(used);
      HandOver(std::move(block));
      Finish(nullptr);
    } catch (...) {
      Finish(std::current_exception());
    }
  }

  // The computing side: every record in order; then the reader's failure, if any.
  void Consume(const std::function<void(const TrialRecord&)>& visit) {
    while (true) {
      std::vector<TrialRecord> block;
      {
        std::unique_lock<std::mutex> g(mutex_);
        cv_.wait(g, [&] { return !full_.empty() || finished_; });
        if (full_.empty()) break;
        block = std::move(full_.front());
        full_.pop_front();
      }
      for (const TrialRecord& r : block) visit(r);
      std::lock_guard<std::mutex> g(mutex_);
      free_.push_back(std::move(block));
      cv_.notify_all();
    }
    if (failure_) std::rethrow_exception(failure_);
  }

  // Tells the reader to stop (the computing side failed).
  void Cancel() {
    std::lock_guard<std::mutex> g(mutex_);
    cancelled_ = true;
    cv_.notify_all();
  }

 private:
  // Only the fields the summary reads; the errors vector keeps its capacity.
  static void CopyRecord(const TrialRecord& r, TrialRecord* slot) {
    slot->trial = r.trial;
    slot->status = r.status;
    slot->iterations = r.iterations;
    slot->sigma_hat = r.sigma_hat;
    slot->sigma_min = r.sigma_min;
    slot->errors.assign(r.errors.begin(), r.errors.end());
    slot->validation = r.validation;
    slot->nominal = r.nominal;
  }
  std::vector<TrialRecord> TakeFree() {
    std::unique_lock<std::mutex> g(mutex_);
    cv_.wait(g, [&] { return !free_.empty() || cancelled_; });
    if (cancelled_) throw std::runtime_error("aggregation cancelled");
    std::vector<TrialRecord> block = std::move(free_.front());
    free_.pop_front();
    return block;
  }
  void HandOver(std::vector<TrialRecord> block) {
    std::lock_guard<std::mutex> g(mutex_);
    full_.push_back(std::move(block));
    cv_.notify_all();
  }
  void Finish(std::exception_ptr failure) {
    std::lock_guard<std::mutex> g(mutex_);
    if (!cancelled_) failure_ = failure;
    finished_ = true;
    cv_.notify_all();
  }

  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::vector<TrialRecord>> full_, free_;
  bool finished_ = false, cancelled_ = false;
  std::exception_ptr failure_;
};

// Records of a cell with trial < end in canonical order, decoded from SQLite on a second thread
// while this one computes (a large cell's aggregation uses two cores; the order, hence every
// bit, is that of a single thread). Blocks are recycled, so memory stays a few blocks.
void ReadInBlocks(const TrialStore& store, const std::string& cell_id, long long end,
                  const std::function<void(const TrialRecord&)>& visit) {
  BlockPipeline pipeline;
  std::thread reader([&] { pipeline.Read(store, cell_id, end); });
  try {
    pipeline.Consume(visit);
  } catch (...) {
    pipeline.Cancel();
    reader.join();
    throw;
  }
  reader.join();
}

// The series of a cell, in one layout: validation (12, ok trials), nominal (12, every trial),
// iterations, σ̂, σ_min, the 4 axis means of the validation metrics (ok trials), the coverage
// shares (ok trials that have them), then the parameter errors (ok trials).
enum : int {
  kValidation = 0,
  kNominal = 12,
  kIterations = 24,
  kSigmaHat,
  kSigmaMin,
  kAxisMean,
  kCoverage = kAxisMean + 4,
  kCoverageTotal,
  kErrors
};

class CellPasses {
 public:
  CellPasses(const TrialStore& store, const StoredCell& cell, long long end,
             const SummaryProbes* probes, CellSummary* summary)
      : store_(store), cell_(cell), end_(end), s_(summary) {
    num_params_ = static_cast<int>(cell.parameter_names.size());
    series_.resize(kErrors + num_params_);
    for (int k = 0; k < kAxisMean; ++k) series_[k].quantiles = true;
    series_[kCoverage].quantiles = series_[kCoverageTotal].quantiles = true;
    if (probes) {
      for (int k = 0; k < 12; ++k) series_[kValidation + k].probe = probes->validation[k];
      for (int k = 0; k < num_params_ && k < static_cast<int>(probes->errors.size()); ++k)
        series_[kErrors + k].probe = probes->errors[k];
      if (probes->error_quantiles)
        for (int k = 0; k < num_params_; ++k) series_[kErrors + k].quantiles = true;
      probes_ = probes;
    }
  }

  void Run() {
    // A cell small enough is read once and its passes run over memory (at most ~35 MB); a larger
    // one is read from the store in every pass.
    if (const long long stored = store_.CountTrials(cell_.id); stored <= kInMemoryTrials) {
      cached_.reserve(static_cast<std::size_t>(stored));
      store_.ForEachTrial(
          cell_.id, [&](const TrialRecord& r) { cached_.push_back(r); }, 0, end_);
      in_memory_ = true;
    }
    for (Series& x : series_)
      if (x.quantiles) x.brackets.assign(1, LevelOneBracket());
    Scan([&](int k, double x) { series_[k].Pass1(x); }, true);
    for (Series& x : series_) {
      x.mean = x.n ? x.sum / x.n : 0;
      if (!x.quantiles) continue;
      WantDistribution(&x);
      x.Resolve();
      x.PlanBrackets();
    }
    lanes_.assign(static_cast<std::size_t>(num_params_) * (num_params_ + 1) / 2,
                  std::array<double, 9>{});
    centred_.assign(static_cast<std::size_t>(num_params_) * 8, 0.0);
    Scan([&](int k, double x) { series_[k].Pass2(x); }, false, true);
    for (Series& x : series_) x.Resolve();
    while (true) {  // further levels until every order statistic is found
      bool pending = false;
      for (Series& x : series_) {
        x.PlanBrackets();
        pending |= !x.brackets.empty();
      }
      if (!pending) break;
      Scan([&](int k, double x) { series_[k].AddToBrackets(x); }, false);
      for (Series& x : series_) x.Resolve();
    }
    Fill();
  }

 private:
  static Bracket LevelOneBracket() {
    Bracket b;
    b.histogram.assign(std::size_t{1} << kLevelBits, 0);
    return b;
  }

  // An ok record's validation metrics, their means over x, y, z (a single trial's figure) and
  // its coverage shares where it has them.
  template <typename Visit>
  static void VisitValidation(Visit& visit, const TrialRecord& r) {
    for (int k = 0; k < 12; ++k) visit(kValidation + k, r.validation[k]);
    for (int m = 0; m < 4; ++m)
      visit(kAxisMean + m,
            (r.validation[3 * m] + r.validation[3 * m + 1] + r.validation[3 * m + 2]) / 3);
    if (!std::isnan(r.coverage)) visit(kCoverage, r.coverage);
    if (!std::isnan(r.coverage_total)) visit(kCoverageTotal, r.coverage_total);
  }

  // One pass over the records in canonical order; `count` also counts trials and statuses,
  // `covariance` also accumulates the parameter errors' covariance lanes.
  template <typename Visit>
  void Scan(Visit visit, bool count, bool covariance = false) {
    long long ok_index = 0;
    const long long ok_total = series_[kIterations].n;
    const long long full = ok_total - ok_total % 8;
    const auto record = [&](const TrialRecord& r) {
      if (count) ++s_->trials;
      for (int k = 0; k < 12; ++k) visit(kNominal + k, r.nominal[k]);
      if (r.status != TrialStatus::kOk) {
        if (count) ++s_->failed[TrialStatusName(r.status)];
        return;
      }
      if (count) ++s_->ok;
      VisitValidation(visit, r);
      visit(kIterations, r.iterations);
      visit(kSigmaHat, r.sigma_hat);
      visit(kSigmaMin, r.sigma_min);
      const int n = std::min<int>(num_params_, static_cast<int>(r.errors.size()));
      for (int k = 0; k < n; ++k) visit(kErrors + k, r.errors[k]);
      if (covariance) {
        AddToLanes(r, ok_index < full ? ok_index % 8 : 8);  // lane 8: the tail
        ++ok_index;
      }
    };
    if (in_memory_) {
      for (const TrialRecord& r : cached_) record(r);
    } else {
      ReadInBlocks(store_, cell_.id, end_, record);
    }
  }

  // The parameter errors' products, centred, into the 8 lanes + tail of NormalMatrix (the same
  // operations in the same order: the same bits as the in-memory product). Lane rows are
  // buffered 8 at a time so that the 8 lanes update together (vectorised, as NormalMatrix).
  void AddToLanes(const TrialRecord& r, long long lane) {
    const std::size_t row = lane < 8 ? static_cast<std::size_t>(lane) : 0;
    for (int k = 0; k < num_params_; ++k)
      centred_[static_cast<std::size_t>(k) * 8 + row] =
          (k < static_cast<int>(r.errors.size()) ? r.errors[k] : 0) - series_[kErrors + k].mean;
    if (lane == 8) {  // the tail: one row at a time, in order
      std::size_t pair = 0;
      for (int a = 0; a < num_params_; ++a)
        for (int b = 0; b <= a; ++b)
          lanes_[pair++][8] +=
              centred_[static_cast<std::size_t>(a) * 8] * centred_[static_cast<std::size_t>(b) * 8];
      return;
    }
    if (lane != 7) return;  // a full group of 8 rows is buffered
    std::size_t pair = 0;
    for (int a = 0; a < num_params_; ++a) {
      const double* __restrict ca = centred_.data() + static_cast<std::size_t>(a) * 8;
      for (int b = 0; b <= a; ++b) {
        const double* __restrict cb = centred_.data() + static_cast<std::size_t>(b) * 8;
        double* __restrict acc = lanes_[pair++].data();
        for (int l = 0; l < 8; ++l) acc[l] += ca[l] * cb[l];
      }
    }
  }

  void Fill() {
    for (int k = 0; k < 12; ++k) {
      s_->validation[k] = SeriesDistribution(series_[kValidation + k]);
      s_->nominal[k] = SeriesDistribution(series_[kNominal + k]);
    }
    s_->iterations = SeriesDistribution(series_[kIterations]);
    s_->sigma_hat = SeriesDistribution(series_[kSigmaHat]);
    s_->design_sigma_min = SeriesDistribution(series_[kSigmaMin]);
    for (int m = 0; m < 4; ++m) s_->axis_mean[m] = SeriesDistribution(series_[kAxisMean + m]);
    s_->coverage = SeriesDistribution(series_[kCoverage]);
    s_->coverage_total = SeriesDistribution(series_[kCoverageTotal]);
    const auto rank = [](const Series& x) {
      if (x.n == 0 || std::isnan(x.probe)) return kNan;
      return 100.0 * (x.probe_below + 0.5 * x.probe_equal) / x.n;
    };
    for (int k = 0; k < 12; ++k) s_->validation_probe_rank[k] = rank(series_[kValidation + k]);
    if (probes_) {
      for (int k = 0; k < num_params_; ++k) {
        const Series& x = series_[kErrors + k];
        s_->error_probe_rank.push_back(rank(x));
        if (probes_->error_quantiles)
          s_->error_quantiles.push_back(
              {SeriesQuantile(x, 5), SeriesQuantile(x, 50), SeriesQuantile(x, 95)});
      }
    }
    FillParameters();
  }

  void FillParameters() {
    const int n = num_params_;
    const long long m = s_->ok;
    s_->covariance.resize(n, n);
    std::size_t pair = 0;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b <= a; ++b) {
        const auto& acc = lanes_[pair++];
        const double sum = ((acc[0] + acc[1]) + (acc[2] + acc[3])) +
                           ((acc[4] + acc[5]) + (acc[6] + acc[7])) + acc[8];
        s_->covariance(a, b) = s_->covariance(b, a) = sum;
      }
    if (m > 1) s_->covariance /= static_cast<double>(m - 1);
    const Eigen::VectorXd sd = s_->covariance.diagonal().cwiseSqrt();
    s_->correlation = s_->covariance;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) s_->correlation(a, b) /= sd[a] * sd[b];
    for (int k = 0; k < n; ++k) {
      const Series& x = series_[kErrors + k];
      ParameterStats p;
      p.name = cell_.parameter_names[k];
      p.bias = m ? x.sum / m : kNan;
      p.std = m > 1 ? sd[k] : kNan;
      p.bias_se = m > 1 ? p.std / std::sqrt(static_cast<double>(m)) : kNan;
      p.predicted_std =
          k < static_cast<int>(cell_.predicted_std.size()) ? cell_.predicted_std[k] : kNan;
      p.ratio = p.std / p.predicted_std;
      p.std_se = StdStandardErrorFromM4(x.m4, static_cast<std::size_t>(m), p.std);
      p.ratio_se = p.std_se / p.predicted_std;
      p.predicted_std_truth = k < static_cast<int>(cell_.predicted_std_truth.size())
                                  ? cell_.predicted_std_truth[k]
                                  : kNan;
      p.ratio_truth = p.std / p.predicted_std_truth;
      p.ratio_truth_se = p.std_se / p.predicted_std_truth;
      s_->parameters.push_back(p);
    }
  }

  const TrialStore& store_;
  const StoredCell& cell_;
  long long end_;
  CellSummary* s_;
  const SummaryProbes* probes_ = nullptr;
  int num_params_ = 0;
  std::vector<Series> series_;
  std::vector<std::array<double, 9>> lanes_;  // per (a, b ≤ a): 8 lanes and the tail
  std::vector<double> centred_;
  static constexpr long long kInMemoryTrials = 1 << 16;
  bool in_memory_ = false;
  std::vector<TrialRecord> cached_;
};

}  // namespace

CellSummary SummarizeCell(const TrialStore& store, const StoredCell& cell, long long end,
                          const SummaryProbes* probes) {
  CellSummary s;
  s.cell = cell;
  s.validation_probe_rank.fill(kNan);
  CellPasses(store, cell, end, probes, &s).Run();
  return s;
}

}  // namespace lrcal
