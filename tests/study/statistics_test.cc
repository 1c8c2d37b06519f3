// Uncertainty of the Monte-Carlo statistics in real studies: interval coverage against a large
// reference run, and the streaming summary against sorting (the sample statistics themselves are
// tested in tests/core/descriptive_statistics_test.cc).
#include "lrcal/study/statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "lrcal/core/dense_kernels.h"
#include "lrcal/core/random.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/kinematics/validation_metric.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/trial_store.h"
#include "test_util.h"

namespace lrcal {
namespace {

TEST(Statistics, P95IntervalsOfFortySeedsCoverTheReferenceP95AsOftenAsPromised) {
  // The same small study (the paper's arm, its own pool and validation set from files) run with
  // 40 different seeds of 150 trials: with the configurations from files another seed changes
  // only the noise, so each run's p95 interval of every validation metric should cover the true
  // p95 with probability >= 95 %. The truth is the p95 of a 20,000-trial reference run (another
  // seed); 33 to 40 of 40 is the binomial range.
  const std::string dir = testing::TempDir("coverage");
  testing::WritePaperConfigurationFiles(dir, 40, 10, 5, 6);
  const auto run = [&](int seed, int trials) {
    const std::string study = dir + "/s" + std::to_string(seed) + ".yaml";
    std::ofstream(study) << "name: coverage\nseed: " << seed << "\ntrials: " << trials
                         << "\nrobot: " << testing::SourcePath("studies/robots/paper.yaml")
                         << "\npool: {file: pool.csv}\nselection: {count: 30}\n"
                            "validation: {file: val.csv}\n";
    RunOptions options;
    options.out_dir = dir + "/run" + std::to_string(seed);
    options.threads = 2;
    options.progress = false;
    RunStudy(LoadStudy(study), options);
    TrialStore store(options.out_dir + "/trials.sqlite");
    return SummarizeCell(store, store.Cells().at(0));
  };
  const CellSummary reference = run(1000, 20000);
  ASSERT_EQ(reference.ok, 20000);
  std::array<int, 12> covered{};
  for (int seed = 1; seed <= 40; ++seed) {
    const CellSummary s = run(seed, 150);
    ASSERT_EQ(s.cell.id, reference.cell.id);  // the same cell: only the noise differs
    for (int k = 0; k < 12; ++k) {
      const Distribution& d = s.validation[k];
      covered[k] += d.p95_ci.low <= reference.validation[k].p95 &&
                    reference.validation[k].p95 <= d.p95_ci.high;
    }
  }
  for (int k = 0; k < 12; ++k) {
    SCOPED_TRACE(ValidationColumnName(k));
    EXPECT_GE(covered[k], 33);
    EXPECT_LE(covered[k], 40);
  }
}

// The summary is computed in passes over the store (radix selection for the order statistics,
// covariance lanes); it must give exactly the bits of holding and sorting every value.
TEST(Statistics, StreamingSummaryHasTheBitsOfSortingEveryValue) {
  const std::string dir = testing::TempDir("streaming_summary");
  TrialStore store(dir + "/trials.sqlite");
  StoredCell cell;
  cell.id = "c";
  cell.label = "synthetic";
  cell.settings = "{}";
  cell.parameter_names = {"a1", "theta2", "d3"};
  cell.predicted_std = {1e-5, 2e-5, 3e-5};
  store.PutCell(cell);
  std::mt19937_64 rng(11);                              // test data only
  std::lognormal_distribution<double> metric(-8, 0.3);  // narrow: > 2^16 values in one octave
  std::normal_distribution<double> error(0, 1e-5);
  std::uniform_real_distribution<double> u(0, 1);
  const int n = 150000;
  std::vector<TrialRecord> records;
  for (int t = 0; t < n; ++t) {
    TrialRecord r;
    r.cell_id = cell.id;
    r.trial = t;
    r.status = u(rng) < 0.02 ? TrialStatus::kNotConverged : TrialStatus::kOk;
    for (int k = 0; k < 12; ++k) {
      r.validation[k] = metric(rng) * (k + 1);
      r.nominal[k] = k < 6 ? 0.01 * (k + 1) : metric(rng);  // constant, then varying
    }
    r.validation[1] = std::round(r.validation[1] * 1e5) / 1e5;  // many ties
    r.iterations = 3 + static_cast<int>(u(rng) * 4);
    r.sigma_hat = metric(rng);
    r.sigma_min = 0.4;
    if (r.status == TrialStatus::kOk) r.errors = {error(rng), -std::fabs(error(rng)), error(rng)};
    records.push_back(r);
  }
  store.Insert(records);
  SummaryProbes probes;
  probes.validation[0] = std::exp(-8.0);
  probes.validation[1] = records[5].validation[1];  // a tied value
  probes.errors = {0.0, -1e-5, 2e-5};
  probes.error_quantiles = true;
  const CellSummary s = SummarizeCell(store, store.Cells().at(0), n, &probes);

  // The reference: every value in memory, in canonical order.
  std::array<std::vector<double>, 12> validation, nominal;
  std::vector<double> iterations, sigma_hat, sigma_min;
  std::vector<std::vector<double>> errors(3);
  for (const TrialRecord& r : records) {
    for (int k = 0; k < 12; ++k) nominal[k].push_back(r.nominal[k]);
    if (r.status != TrialStatus::kOk) continue;
    for (int k = 0; k < 12; ++k) validation[k].push_back(r.validation[k]);
    iterations.push_back(r.iterations);
    sigma_hat.push_back(r.sigma_hat);
    sigma_min.push_back(r.sigma_min);
    for (int k = 0; k < 3; ++k) errors[k].push_back(r.errors[k]);
  }
  const auto same = [](const Distribution& a, const Distribution& b, const std::string& what) {
    SCOPED_TRACE(what);
    const auto eq = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
    EXPECT_EQ(a.n, b.n);
    for (auto [x, y] : {std::pair{a.mean, b.mean},
                        {a.std, b.std},
                        {a.p5, b.p5},
                        {a.p50, b.p50},
                        {a.p95, b.p95},
                        {a.min, b.min},
                        {a.max, b.max},
                        {a.mean_se, b.mean_se},
                        {a.std_se, b.std_se},
                        {a.p5_ci.low, b.p5_ci.low},
                        {a.p5_ci.high, b.p5_ci.high},
                        {a.p50_ci.low, b.p50_ci.low},
                        {a.p50_ci.high, b.p50_ci.high},
                        {a.p95_ci.low, b.p95_ci.low},
                        {a.p95_ci.high, b.p95_ci.high}})
      EXPECT_TRUE(eq(x, y)) << x << " vs " << y;
  };
  for (int k = 0; k < 12; ++k) {
    same(s.validation[k], Describe(validation[k]), "validation " + std::to_string(k));
    same(s.nominal[k], Describe(nominal[k]), "nominal " + std::to_string(k));
  }
  same(s.iterations, Describe(iterations), "iterations");
  same(s.sigma_hat, Describe(sigma_hat), "sigma_hat");
  same(s.design_sigma_min, Describe(sigma_min), "sigma_min");
  // A single trial's figure (the mean over x, y, z of each metric): mean, std and their SEs.
  for (int m = 0; m < 4; ++m) {
    SCOPED_TRACE("axis mean " + std::to_string(m));
    std::vector<double> axis_mean;
    for (std::size_t t = 0; t < validation[0].size(); ++t)
      axis_mean.push_back(
          (validation[3 * m][t] + validation[3 * m + 1][t] + validation[3 * m + 2][t]) / 3);
    const Distribution d = Describe(axis_mean);
    EXPECT_EQ(s.axis_mean[m].n, d.n);
    EXPECT_EQ(s.axis_mean[m].mean, d.mean);
    EXPECT_EQ(s.axis_mean[m].std, d.std);
    EXPECT_EQ(s.axis_mean[m].mean_se, d.mean_se);
    EXPECT_EQ(s.axis_mean[m].std_se, d.std_se);
    EXPECT_TRUE(std::isnan(s.axis_mean[m].p95));  // no quantiles for these
  }
  EXPECT_EQ(s.validation_probe_rank[0], PercentileRank(validation[0], probes.validation[0]));
  EXPECT_EQ(s.validation_probe_rank[1], PercentileRank(validation[1], probes.validation[1]));
  EXPECT_TRUE(std::isnan(s.validation_probe_rank[2]));
  // Parameters: the in-memory path (centred errors, NormalMatrix's fixed lanes).
  const long long m = static_cast<long long>(errors[0].size());
  Eigen::MatrixXd centred(m, 3);
  for (int k = 0; k < 3; ++k) {
    double sum = 0;
    for (double x : errors[k]) sum += x;
    for (long long t = 0; t < m; ++t) centred(t, k) = errors[k][t] - sum / m;
    EXPECT_EQ(s.parameters[k].bias, sum / m);
    EXPECT_EQ(s.error_probe_rank[k], PercentileRank(errors[k], probes.errors[k]));
    std::vector<double> v = errors[k];
    EXPECT_EQ(s.error_quantiles[k][0], Quantile(&v, 5));
    EXPECT_EQ(s.error_quantiles[k][1], Quantile(&v, 50));
    EXPECT_EQ(s.error_quantiles[k][2], Quantile(&v, 95));
  }
  Eigen::MatrixXd covariance;
  NormalMatrix(centred, &covariance);
  covariance /= static_cast<double>(m - 1);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) EXPECT_EQ(s.covariance(a, b), covariance(a, b)) << a << b;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(s.parameters[k].std, std::sqrt(covariance(k, k)));
    // The distribution-free SE of the std from the centred errors' fourth moment.
    double m4 = 0;
    for (long long t = 0; t < m; ++t)
      m4 += (centred(t, k) * centred(t, k)) * (centred(t, k) * centred(t, k));
    const double sd = s.parameters[k].std, s2 = sd * sd;
    const double var = (m4 / m - s2 * s2 * (m - 3.0) / (m - 1.0)) / m;
    EXPECT_EQ(s.parameters[k].std_se, std::sqrt(var) / (2 * sd));
  }
  // Only part of the trials (a stop_when stopping point).
  const CellSummary part = SummarizeCell(store, store.Cells().at(0), 1000);
  EXPECT_EQ(part.trials, 1000);
  std::vector<double> first;
  for (int t = 0; t < 1000; ++t)
    if (records[t].status == TrialStatus::kOk) first.push_back(records[t].validation[3]);
  same(part.validation[3], Describe(first), "first 1000");
}

}  // namespace
}  // namespace lrcal
