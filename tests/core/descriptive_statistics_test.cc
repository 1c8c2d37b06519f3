// Descriptive statistics: type-7 percentiles against numpy's values, order-statistic intervals
// against a direct binomial sum, and the standard errors against closed forms and simulation.
#include "lrcal/core/descriptive_statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace lrcal {
namespace {

TEST(DescriptiveStatistics, PercentilesAreNumpysLinearInterpolation) {
  // numpy.percentile([3, 1, 4, 1, 5, 9, 2, 6], p) for p = 0, 5, 25, 50, 95, 100 (type 7):
  // 1.0, 1.0, 1.75, 3.5, 7.95, 9.0.
  const std::vector<double> v = {3, 1, 4, 1, 5, 9, 2, 6};
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  const double p[] = {0, 5, 25, 50, 95, 100};
  const double numpy[] = {1.0, 1.0, 1.75, 3.5, 7.95, 9.0};
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(Percentile(sorted, p[k]), numpy[k], 1e-12) << p[k];
    std::vector<double> copy = v;
    EXPECT_EQ(Quantile(&copy, p[k]), Percentile(sorted, p[k])) << p[k];
  }
  EXPECT_EQ(PercentileRank(v, 4.0), 100.0 * (4 + 0.5) / 8);  // 3, 1, 1, 2 below
  std::vector<double> copy = v;
  EXPECT_EQ(OrderStatistic(&copy, 3), 2.0);
  EXPECT_TRUE(std::isnan(Percentile({}, 50)));
}

// P(Bin(n, p) ≤ k) by summing the probabilities (long double, logs): independent of Boost.
long double BinomialCdf(long long n, double p, long long k) {
  long double sum = 0;
  for (long long i = 0; i <= k; ++i)
    sum += std::exp(std::lgamma(n + 1.0L) - std::lgamma(i + 1.0L) - std::lgamma(n - i + 1.0L) +
                    i * std::log(static_cast<long double>(p)) +
                    (n - i) * std::log1p(-static_cast<long double>(p)));
  return sum;
}

TEST(QuantileInterval, RanksMatchADirectBinomialSum) {
  for (long long n : {1, 10, 58, 59, 71, 72, 100, 333, 1000}) {
    for (double p : {0.05, 0.5, 0.95}) {
      long long l = 0, u = 0;
      QuantileIntervalRanks(n, p, 0.95, &l, &u);
      // l: the largest rank with P(Bin ≤ l − 1) ≤ 2.5 %; u: the smallest with ≥ 97.5 %.
      long long l_ref = 0, u_ref = n + 1;
      for (long long k = 0; k <= n; ++k)
        if (BinomialCdf(n, p, k) <= 0.025L) l_ref = k + 1;
      for (long long k = n; k >= 0; --k)
        if (BinomialCdf(n, p, k) >= 0.975L) u_ref = k + 1;
      EXPECT_EQ(l, l_ref) << "n " << n << " p " << p;
      EXPECT_EQ(u, u_ref) << "n " << n << " p " << p;
      if (l >= 1 && u <= n) {  // the coverage the ranks promise
        EXPECT_GE(BinomialCdf(n, p, u - 1) - BinomialCdf(n, p, l - 1), 0.95L);
      }
    }
  }
  long long l = 0, u = 0;
  QuantileIntervalRanks(71, 0.95, 0.95, &l, &u);
  EXPECT_EQ(u, 72);  // 71 values cannot bound the p95 from above with 97.5 %
  QuantileIntervalRanks(72, 0.95, 0.95, &l, &u);
  EXPECT_EQ(u, 72);  // 72 can: its maximum (1 − 0.95^72 ≥ 0.975)
}

TEST(DescriptiveStatistics, StandardErrorsMatchTheirGaussianClosedFormsAndWilksBound) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss(2.0, 3.0);  // test data only
  std::vector<double> v(200000);
  for (double& x : v) x = gauss(rng);
  const Distribution d = Describe(v);
  EXPECT_DOUBLE_EQ(d.mean_se, d.std / std::sqrt(200000.0));
  // For Gaussian values SE(s) → σ/√(2(n−1)).
  EXPECT_NEAR(d.std_se / (3.0 / std::sqrt(2.0 * 199999)), 1.0, 0.02);
  EXPECT_DOUBLE_EQ(d.max_bounds_p95, 1 - std::pow(0.95, 200000.0));
  EXPECT_LT(d.p95_ci.low, d.p95);
  EXPECT_GT(d.p95_ci.high, d.p95);
  EXPECT_GE(Describe(std::vector<double>(59, 1.0)).max_bounds_p95, 0.95);
  EXPECT_LT(Describe(std::vector<double>(58, 1.0)).max_bounds_p95, 0.95);
  EXPECT_TRUE(std::isnan(Describe({1, 2, 3}).std_se));
}

TEST(DescriptiveStatistics, StdStandardErrorMatchesTheSpreadOfStdOverReplicates) {
  // 2000 replicates of n = 100 exponential values: the spread of s against the SE formula
  // (heavy-tailed values, where the Gaussian s/√(2(n−1)) would be far off).
  std::mt19937_64 rng(9);
  std::exponential_distribution<double> expo(1.0);  // test data only
  std::vector<double> stds, ses;
  for (int r = 0; r < 2000; ++r) {
    std::vector<double> v(100);
    for (double& x : v) x = expo(rng);
    const Distribution d = Describe(v);
    stds.push_back(d.std);
    ses.push_back(d.std_se);
  }
  const Distribution spread = Describe(stds);
  const Distribution mean_se = Describe(ses);
  EXPECT_NEAR(mean_se.mean / spread.std, 1.0, 0.15);
}

}  // namespace
}  // namespace lrcal
