#include "lrcal/study/statistics.h"

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "identification/levenberg_marquardt.h"

namespace lrcal {

using Json = nlohmann::json;

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

void QuantileIntervalRanks(long long n, double p, double level, long long* low_rank,
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

namespace {

// The k-th smallest (1-based) of `values`, by selection (reorders them).
double OrderStatistic(std::vector<double>* values, long long k) {
  std::nth_element(values->begin(), values->begin() + (k - 1), values->end());
  return (*values)[static_cast<std::size_t>(k - 1)];
}

QuantileInterval IntervalOf(std::vector<double>* values, double p) {
  QuantileInterval ci;
  const long long n = static_cast<long long>(values->size());
  QuantileIntervalRanks(n, p, 0.95, &ci.low_rank, &ci.high_rank);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ci.low = ci.low_rank >= 1 ? OrderStatistic(values, ci.low_rank) : nan;
  ci.high = ci.high_rank <= n ? OrderStatistic(values, ci.high_rank) : nan;
  return ci;
}

// The standard error of the sample std s of the values x[0..count) whose mean is `mean` (see
// Distribution::std_se), summed in the given order.
double StdStandardError(const double* x, std::size_t count, double mean, double s) {
  const double n = static_cast<double>(count);
  if (count < 4 || !(s > 0)) return std::numeric_limits<double>::quiet_NaN();
  double m4 = 0;
  for (std::size_t t = 0; t < count; ++t) {
    const double c = (x[t] - mean) * (x[t] - mean);
    m4 += c * c;
  }
  m4 /= n;
  const double s2 = s * s;
  const double var_s2 = (m4 - s2 * s2 * (n - 3) / (n - 1)) / n;
  return var_s2 > 0 ? std::sqrt(var_s2) / (2 * s) : 0;
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

namespace {

// One pass over a cell's records in canonical order: counts, metric values, parameter errors.
struct CellValues {
  Eigen::MatrixXd errors;  ///< row = ok trial in canonical order, column-major
  std::array<std::vector<double>, 12> validation, nominal;
  std::vector<double> iterations, sigma_hat, sigma_min;
};

CellValues ReadCellValues(const TrialStore& store, const StoredCell& cell, long long end,
                          CellSummary* s) {
  const int n = static_cast<int>(cell.parameter_names.size());
  CellValues v;
  const std::size_t expected = static_cast<std::size_t>(std::min(end, store.CountTrials(cell.id)));
  v.errors.resize(static_cast<Eigen::Index>(expected), n);
  for (int k = 0; k < 12; ++k) {
    v.validation[k].reserve(expected);
    v.nominal[k].reserve(expected);
  }
  v.iterations.reserve(expected);
  v.sigma_hat.reserve(expected);
  store.ForEachTrial(
      cell.id,
      [&](const TrialRecord& r) {
        ++s->trials;
        for (int k = 0; k < 12; ++k) v.nominal[k].push_back(r.nominal[k]);
        if (r.status != TrialStatus::kOk) {
          ++s->failed[TrialStatusName(r.status)];
          return;
        }
        ++s->ok;
        for (int k = 0; k < n && k < static_cast<int>(r.errors.size()); ++k)
          v.errors(s->ok - 1, k) = r.errors[k];
        for (int k = 0; k < 12; ++k) v.validation[k].push_back(r.validation[k]);
        v.iterations.push_back(r.iterations);
        v.sigma_hat.push_back(r.sigma_hat);
        v.sigma_min.push_back(r.sigma_min);
      },
      0, end);
  v.errors.conservativeResize(s->ok, n);
  return v;
}

// Bias, spread and the empirical covariance of the parameter errors (two passes, canonical
// order; the covariance is one fixed-lane normal-matrix product of the centred errors).
void SummarizeParameters(const StoredCell& cell, Eigen::MatrixXd* errors, CellSummary* s) {
  const int n = static_cast<int>(cell.parameter_names.size());
  const long long m = s->ok;
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    const double* x = errors->col(k).data();
    for (long long t = 0; t < m; ++t) mean[k] += x[t];
    if (m) mean[k] /= m;
  }
  for (int k = 0; k < n; ++k) errors->col(k).array() -= mean[k];
  NormalMatrix(*errors, &s->covariance);
  if (m > 1) s->covariance /= static_cast<double>(m - 1);
  const Eigen::VectorXd sd = s->covariance.diagonal().cwiseSqrt();
  s->correlation = s->covariance;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) s->correlation(a, b) /= sd[a] * sd[b];
  for (int k = 0; k < n; ++k) {
    ParameterStats p;
    p.name = cell.parameter_names[k];
    p.bias = m ? mean[k] : std::nan("");
    p.std = m > 1 ? sd[k] : std::nan("");
    p.bias_se = m > 1 ? p.std / std::sqrt(static_cast<double>(m)) : std::nan("");
    p.predicted_std =
        k < static_cast<int>(cell.predicted_std.size()) ? cell.predicted_std[k] : std::nan("");
    p.ratio = p.std / p.predicted_std;
    p.std_se = StdStandardError(errors->col(k).data(), static_cast<std::size_t>(m), 0, p.std);
    p.ratio_se = p.std_se / p.predicted_std;
    p.predicted_std_truth = k < static_cast<int>(cell.predicted_std_truth.size())
                                ? cell.predicted_std_truth[k]
                                : std::nan("");
    p.ratio_truth = p.std / p.predicted_std_truth;
    p.ratio_truth_se = p.std_se / p.predicted_std_truth;
    s->parameters.push_back(p);
  }
}

}  // namespace

CellSummary SummarizeCell(const TrialStore& store, const StoredCell& cell, long long end) {
  CellSummary s;
  s.cell = cell;
  CellValues v = ReadCellValues(store, cell, end, &s);
  for (int k = 0; k < 12; ++k) {
    s.validation[k] = DescribeInPlace(&v.validation[k]);
    s.nominal[k] = DescribeInPlace(&v.nominal[k]);
    s.validation_values[k] = std::move(v.validation[k]);
    std::vector<double>().swap(v.nominal[k]);
  }
  s.iterations = DescribeInPlace(&v.iterations);
  s.sigma_hat = DescribeInPlace(&v.sigma_hat);
  s.design_sigma_min = DescribeInPlace(&v.sigma_min);
  // The paper's placement needs the raw errors of paper cells; keep only those.
  if (Json::parse(cell.settings).value("paper_case", 0) > 0)
    for (int k = 0; k < v.errors.cols(); ++k)
      s.error_values.emplace_back(v.errors.col(k).data(), v.errors.col(k).data() + s.ok);
  SummarizeParameters(cell, &v.errors, &s);
  return s;
}

}  // namespace lrcal
