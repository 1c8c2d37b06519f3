// Descriptive statistics of a sample: mean, standard deviation with standard errors, type-7
// percentiles and distribution-free confidence intervals of quantiles. Used by the study layer's
// aggregation, the design layer's random baseline and the accuracy planner.
#pragma once

#include <cstddef>
#include <vector>

namespace lrcal {

/// A distribution-free confidence interval for a quantile from order statistics: [X_(l), X_(u)]
/// with l, u chosen from the Binomial(n, p) law so that each side misses with probability at most
/// (1 − level)/2. A side that n values cannot give (too few trials) is NaN.
struct QuantileInterval {
  double low = 0, high = 0;
  long long low_rank = 0, high_rank = 0;  ///< 1-based order statistics; 0 / n+1 when missing
};

struct Distribution {
  long long n = 0;
  double mean = 0, std = 0, p5 = 0, p50 = 0, p95 = 0, min = 0, max = 0;
  /// Standard error of the mean, std/√n.
  double mean_se = 0;
  /// Standard error of the sample std, distribution-free (delta method on the sample variance):
  /// √((m₄ − s⁴·(n−3)/(n−1))/n) / (2s), m₄ the fourth central moment; s/√(2(n−1)) for Gaussian
  /// values. NaN for n < 4 or s = 0.
  double std_se = 0;
  /// 95 % distribution-free confidence intervals of the true p5, p50 and p95.
  QuantileInterval p5_ci, p50_ci, p95_ci;
  /// Confidence that the max of n values is at least the true p95: 1 − 0.95ⁿ (Wilks; ≥ 95 % from
  /// n = 59 on).
  double max_bounds_p95 = 0;
};

/// The distribution-free interval of the p-quantile (p in (0, 1)) of n values at `level`, as
/// ranks: the largest l with P(Bin(n, p) ≤ l − 1) ≤ (1 − level)/2 and the smallest u with
/// P(Bin(n, p) ≤ u − 1) ≥ (1 + level)/2 (l = 0 or u = n + 1 when none exists).
void QuantileIntervalRanks(long long n, double p, double level, long long* low_rank,
                           long long* high_rank);

/// Sample statistics of `values` (std with n−1; NaN fields when n = 0). Mean and std are summed
/// in the given (canonical) order.
Distribution Describe(std::vector<double> values);
/// The same without a copy: reorders `values`.
Distribution DescribeInPlace(std::vector<double>* values);
/// Percentile p in [0, 100] of ascending `sorted` values (type 7).
double Percentile(const std::vector<double>& sorted, double p);
/// The same percentile of values in any order, by selection in O(n) (reorders `values`).
double Quantile(std::vector<double>* values, double p);
/// Where x falls among `values` (any order), in percent: 100·(number below + ½·number equal)/n.
double PercentileRank(const std::vector<double>& values, double x);

/// The k-th smallest (1-based, 1 ≤ k ≤ size) of `values`, by selection in O(n) (reorders them).
double OrderStatistic(std::vector<double>* values, long long k);
/// The standard error of the sample std s of `count` values from the sum of their fourth central
/// powers about the mean (see Distribution::std_se); NaN for count < 4 or s = 0.
double StdStandardErrorFromM4(double m4_sum, std::size_t count, double s);

}  // namespace lrcal
