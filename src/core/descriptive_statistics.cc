#include "lrcal/core/descriptive_statistics.h"

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <tuple>

namespace lrcal {

double Percentile(const std::vector<double>& s, double p) {
  if (s.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double h = (s.size() - 1) * p / 100.0;
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, s.size() - 1);
  return s[lo] + (h - lo) * (s[hi] - s[lo]);
}

double Quantile(std::vector<double>* values, double p) {
  std::vector<double>& v = *values;
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double h = (v.size() - 1) * p / 100.0;
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  std::nth_element(v.begin(), v.begin() + lo, v.end());
  const double below = v[lo];
  if (lo + 1 >= v.size()) return below;
  const double above = *std::min_element(v.begin() + lo + 1, v.end());
  return below + (h - lo) * (above - below);
}

double PercentileRank(const std::vector<double>& v, double x) {
  if (v.empty() || std::isnan(x)) return std::numeric_limits<double>::quiet_NaN();
  std::size_t below = 0, equal = 0;
  for (double y : v) {
    below += y < x;
    equal += y == x;
  }
  return 100.0 * (below + 0.5 * equal) / v.size();
}

namespace {

void ComputeQuantileIntervalRanks(long long n, double p, double level, long long* low_rank,
                                  long long* high_rank);

}  // namespace

// The ranks depend on (n, p, level) only and every series of a cell shares n: remembered (the
// binomial CDF bisection is most of a small cell's aggregation otherwise).
void QuantileIntervalRanks(long long n, double p, double level, long long* low_rank,
                           long long* high_rank) {
  static std::mutex mutex;
  static std::map<std::tuple<long long, double, double>, std::pair<long long, long long>> cache;
  const auto key = std::make_tuple(n, p, level);
  {
    std::lock_guard<std::mutex> g(mutex);
    if (const auto it = cache.find(key); it != cache.end()) {
      *low_rank = it->second.first;
      *high_rank = it->second.second;
      return;
    }
  }
  ComputeQuantileIntervalRanks(n, p, level, low_rank, high_rank);
  std::lock_guard<std::mutex> g(mutex);
  if (cache.size() > 4096) cache.clear();  // bounded: a few entries per cell size
  cache.emplace(key, std::make_pair(*low_rank, *high_rank));
}

namespace {

void ComputeQuantileIntervalRanks(long long n, double p, double level, long long* low_rank,
                                  long long* high_rank) {
  *low_rank = 0;
  *high_rank = n + 1;
  if (n < 1) return;
  const boost::math::binomial_distribution<double> law(static_cast<double>(n), p);
  const double tail = (1 - level) / 2;
  // F(k) = P(Bin ≤ k) grows with k: bisect for the last k with F(k) ≤ tail (l = k + 1) and the
  // first k with F(k) ≥ 1 − tail (u = k + 1).
  auto F = [&](long long k) { return boost::math::cdf(law, static_cast<double>(k)); };
  if (F(0) <= tail) {
    long long lo = 0, hi = n;  // F(lo) ≤ tail; find the largest such
    while (lo < hi) {
      const long long mid = lo + (hi - lo + 1) / 2;
      if (F(mid) <= tail) {
        lo = mid;
      } else {
        hi = mid - 1;
      }
    }
    *low_rank = lo + 1;
  }
  if (F(n - 1) >= 1 - tail) {
    long long lo = 0, hi = n - 1;  // the smallest k with F(k) ≥ 1 − tail
    while (lo < hi) {
      const long long mid = lo + (hi - lo) / 2;
      if (F(mid) >= 1 - tail) {
        hi = mid;
      } else {
        lo = mid + 1;
      }
    }
    *high_rank = lo + 1;
  }
}

}  // namespace

double OrderStatistic(std::vector<double>* values, long long k) {
  std::nth_element(values->begin(), values->begin() + (k - 1), values->end());
  return (*values)[static_cast<std::size_t>(k - 1)];
}

namespace {

QuantileInterval IntervalOf(std::vector<double>* values, double p) {
  QuantileInterval ci;
  const long long n = static_cast<long long>(values->size());
  QuantileIntervalRanks(n, p, 0.95, &ci.low_rank, &ci.high_rank);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ci.low = ci.low_rank >= 1 ? OrderStatistic(values, ci.low_rank) : nan;
  ci.high = ci.high_rank <= n ? OrderStatistic(values, ci.high_rank) : nan;
  return ci;
}

}  // namespace

double StdStandardErrorFromM4(double m4_sum, std::size_t count, double s) {
  const double n = static_cast<double>(count);
  if (count < 4 || !(s > 0)) return std::numeric_limits<double>::quiet_NaN();
  const double m4 = m4_sum / n;
  const double s2 = s * s;
  const double var_s2 = (m4 - s2 * s2 * (n - 3) / (n - 1)) / n;
  return var_s2 > 0 ? std::sqrt(var_s2) / (2 * s) : 0;
}

namespace {

// The same from the values x[0..count) whose mean is `mean`, summed in the given order.
double StdStandardError(const double* x, std::size_t count, double mean, double s) {
  double m4 = 0;
  for (std::size_t t = 0; t < count; ++t) {
    const double c = (x[t] - mean) * (x[t] - mean);
    m4 += c * c;
  }
  return StdStandardErrorFromM4(m4, count, s);
}

// The standard errors of the mean and of the std (see Distribution).
void StandardErrors(const std::vector<double>& v, Distribution* d) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  d->mean_se = d->n > 1 ? d->std / std::sqrt(static_cast<double>(d->n)) : nan;
  d->std_se = StdStandardError(v.data(), v.size(), d->mean, d->std);
}

}  // namespace

Distribution Describe(std::vector<double> v) { return DescribeInPlace(&v); }

Distribution DescribeInPlace(std::vector<double>* values) {
  std::vector<double>& v = *values;
  Distribution d;
  d.n = static_cast<long long>(v.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (v.empty()) {
    d.mean = d.std = d.p5 = d.p50 = d.p95 = d.min = d.max = d.mean_se = d.std_se = nan;
    d.p5_ci = d.p50_ci = d.p95_ci = QuantileInterval{nan, nan, 0, 1};
    return d;
  }
  double sum = 0;
  for (double x : v) sum += x;  // in the given (canonical) order
  d.mean = sum / d.n;
  double ss = 0;
  for (double x : v) ss += (x - d.mean) * (x - d.mean);
  d.std = d.n > 1 ? std::sqrt(ss / (d.n - 1)) : nan;
  StandardErrors(v, &d);
  d.max_bounds_p95 = 1 - std::pow(0.95, static_cast<double>(d.n));
  // Order statistics by selection (O(n)), not a full sort: the same values.
  d.min = *std::min_element(v.begin(), v.end());
  d.max = *std::max_element(v.begin(), v.end());
  d.p5 = Quantile(&v, 5);
  d.p50 = Quantile(&v, 50);
  d.p95 = Quantile(&v, 95);
  d.p5_ci = IntervalOf(&v, 0.05);
  d.p50_ci = IntervalOf(&v, 0.50);
  d.p95_ci = IntervalOf(&v, 0.95);
  return d;
}

}  // namespace lrcal
