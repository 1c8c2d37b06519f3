// Uncertainty of the Monte-Carlo statistics: standard errors against closed forms and
// simulation, order-statistic intervals against a direct binomial sum, and their coverage in
// real studies against a large reference run.
#include "lrcal/study/statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "lrcal/study/runner.h"
#include "lrcal/study/trial_store.h"
#include "test_util.h"

namespace lrcal {
namespace {

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

TEST(Statistics, StandardErrorsMatchTheirGaussianClosedFormsAndWilksBound) {
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

TEST(Statistics, StdStandardErrorMatchesTheSpreadOfStdOverReplicates) {
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

TEST(Statistics, P95IntervalsOfRealTrialsCoverTheReferenceP95AsOftenAsPromised) {
  // One cell of the paper's arm with a fixed design and truth: trials differ only in their
  // noise, so disjoint blocks of trials are independent replicate runs. 40 blocks of 150 trials
  // each give a p95 interval of the validation RMS position error (x); a reference p95 from
  // 20,000 further trials is the truth they should cover, with probability >= 95 % each: 33 to
  // 40 of 40 is the binomial range.
  const std::string dir = testing::TempDir("coverage");
  const std::string study = dir + "/coverage.yaml";
  std::ofstream(study) << "name: coverage\nseed: 3\ntrials: 26000\nrobot: "
                       << testing::SourcePath("studies/robots/paper.yaml")
                       << "\npool: {size: 40}\nselection: {count: 30}\nvalidation: {size: 10}\n";
  RunOptions o;
  o.out_dir = dir + "/run";
  o.threads = 2;
  o.progress = false;
  RunStudy(LoadStudy(study), o);
  TrialStore store(dir + "/run/trials.sqlite");
  const std::vector<StoredCell> cells = store.Cells();
  ASSERT_EQ(cells.size(), 1u);
  std::vector<double> values;
  store.ForEachTrial(cells[0].id, [&](const TrialRecord& r) {
    ASSERT_EQ(r.status, TrialStatus::kOk);
    values.push_back(r.validation[0]);
  });
  ASSERT_EQ(values.size(), 26000u);
  std::vector<double> reference(values.begin() + 6000, values.end());
  const double p95 = Quantile(&reference, 95);
  int covered = 0;
  for (int b = 0; b < 40; ++b) {
    const Distribution d =
        Describe(std::vector<double>(values.begin() + 150 * b, values.begin() + 150 * (b + 1)));
    covered += d.p95_ci.low <= p95 && p95 <= d.p95_ci.high;
  }
  std::cout << "covered " << covered << " of 40\n";
  EXPECT_GE(covered, 33);
  EXPECT_LE(covered, 40);
}

}  // namespace
}  // namespace lrcal
