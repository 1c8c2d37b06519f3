#include "lrcal/study/sensitivity.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "lrcal/core/random.h"

namespace lrcal {

namespace {

double Mean(const Eigen::VectorXd& v) { return v.mean(); }

// The sample variance of the 2N values of f at A and B.
double PooledVariance(const Eigen::VectorXd& fa, const Eigen::VectorXd& fb) {
  const Eigen::Index n = fa.size() + fb.size();
  const double mean = (fa.sum() + fb.sum()) / static_cast<double>(n);
  const double ss = (fa.array() - mean).square().sum() + (fb.array() - mean).square().sum();
  return ss / static_cast<double>(n - 1);
}

// First-order (Saltelli 2010) and total (Jansen 1999) indices of input i from the rows given.
// f(B) is centred on the mean of f over A and B: E[f(AB_i) − f(A)] = 0, so the estimator keeps
// its expectation, and its variance no longer grows with the square of f's mean.
void Indices(const Eigen::VectorXd& fa, const Eigen::VectorXd& fb, const Eigen::VectorXd& fab,
             double variance, double* first, double* total) {
  const double mean = 0.5 * (fa.mean() + fb.mean());
  *first = Mean((fb.array() - mean).matrix().cwiseProduct(fab - fa)) / variance;
  *total = Mean((fa - fab).cwiseAbs2()) / (2 * variance);
}

// The `percent` percentile of sorted values, interpolated between order statistics (Hyndman–Fan
// type 7, as statistics.h's Quantile; kept here so that study files load without the store).
double SortedPercentile(const std::vector<double>& v, double percent) {
  const double h = static_cast<double>(v.size() - 1) * percent / 100.0;
  const auto lo = static_cast<std::size_t>(std::floor(h));
  return lo + 1 < v.size() ? v[lo] + (h - static_cast<double>(lo)) * (v[lo + 1] - v[lo]) : v[lo];
}

IntervalEstimate Interval(double estimate, std::vector<double>* replicates, double level) {
  if (replicates->empty()) return {estimate, estimate, estimate};
  std::sort(replicates->begin(), replicates->end());
  return {estimate, SortedPercentile(*replicates, 50 * (1 - level)),
          SortedPercentile(*replicates, 50 * (1 + level))};
}

}  // namespace

SaltelliPlan MakeSaltelliPlan(int base_samples, int inputs, std::uint64_t seed) {
  if (base_samples < 2 || inputs < 1)
    throw std::invalid_argument("Saltelli plan: need at least 2 base samples and 1 input, got " +
                                std::to_string(base_samples) + " and " + std::to_string(inputs));
  const int n = base_samples, d = inputs;
  const RandomStream stream(seed, 0, 0, RandomPurpose::kSensitivity);
  Eigen::MatrixXd a(n, d), b(n, d);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < d; ++c) {
      a(r, c) = stream.Uniform(static_cast<std::uint64_t>(r) * 2 * d + c);
      b(r, c) = stream.Uniform(static_cast<std::uint64_t>(r) * 2 * d + d + c);
    }
  SaltelliPlan plan;
  plan.base_samples = n;
  plan.inputs = d;
  plan.points.resize(static_cast<Eigen::Index>(n) * (d + 2), d);
  plan.points.topRows(n) = a;
  plan.points.middleRows(n, n) = b;
  for (int i = 0; i < d; ++i) {
    Eigen::MatrixXd ab = a;
    ab.col(i) = b.col(i);
    plan.points.middleRows(static_cast<Eigen::Index>(n) * (2 + i), n) = ab;
  }
  return plan;
}

SobolIndices EstimateSobolIndices(const SaltelliPlan& plan, const Eigen::VectorXd& values,
                                  int bootstrap, double level, std::uint64_t seed) {
  const int n = plan.base_samples, d = plan.inputs;
  if (values.size() != static_cast<Eigen::Index>(n) * (d + 2))
    throw std::invalid_argument("Sobol indices: expected " + std::to_string(n * (d + 2)) +
                                " values (N(d+2)), got " + std::to_string(values.size()));
  const Eigen::VectorXd fa = values.head(n), fb = values.segment(n, n);
  SobolIndices out;
  out.variance = PooledVariance(fa, fb);
  std::vector<std::vector<double>> first_rep(d), total_rep(d);
  const RandomStream stream(seed, 1, 0, RandomPurpose::kSensitivity);
  Eigen::VectorXd ra(n), rb(n), rab(n);
  for (int rep = 0; rep < bootstrap; ++rep) {
    std::vector<int> rows(n);
    for (int r = 0; r < n; ++r)
      rows[r] = std::min(
          n - 1, static_cast<int>(stream.Uniform(static_cast<std::uint64_t>(rep) * n + r) * n));
    for (int r = 0; r < n; ++r) {
      ra[r] = fa[rows[r]];
      rb[r] = fb[rows[r]];
    }
    const double variance = PooledVariance(ra, rb);
    if (!(variance > 0)) continue;
    for (int i = 0; i < d; ++i) {
      for (int r = 0; r < n; ++r) rab[r] = values[static_cast<Eigen::Index>(n) * (2 + i) + rows[r]];
      double s = 0, t = 0;
      Indices(ra, rb, rab, variance, &s, &t);
      first_rep[i].push_back(s);
      total_rep[i].push_back(t);
    }
  }
  for (int i = 0; i < d; ++i) {
    double s = 0, t = 0;
    if (out.variance > 0)
      Indices(fa, fb, values.segment(static_cast<Eigen::Index>(n) * (2 + i), n), out.variance, &s,
              &t);
    out.first.push_back(Interval(s, &first_rep[i], level));
    out.total.push_back(Interval(t, &total_rep[i], level));
  }
  return out;
}

MorrisPlan MakeMorrisPlan(int trajectories, int inputs, int levels, std::uint64_t seed) {
  if (trajectories < 2 || inputs < 1 || levels < 2 || levels % 2 != 0)
    throw std::invalid_argument(
        "Morris plan: need at least 2 trajectories, 1 input and an even number of levels >= 2");
  const int d = inputs, p = levels;
  MorrisPlan plan;
  plan.trajectories = trajectories;
  plan.inputs = d;
  plan.levels = p;
  plan.delta = p / (2.0 * (p - 1));
  plan.points.resize(static_cast<Eigen::Index>(trajectories) * (d + 1), d);
  const RandomStream stream(seed, 2, 0, RandomPurpose::kSensitivity);
  std::uint64_t draw = 0;
  for (int t = 0; t < trajectories; ++t) {
    // Start on a random grid level per input; lower half moves up by Δ, upper half down.
    Eigen::RowVectorXd x(d);
    std::vector<int> direction(d);
    for (int c = 0; c < d; ++c) {
      const int level = std::min(p - 1, static_cast<int>(stream.Uniform(draw++) * p));
      x[c] = static_cast<double>(level) / (p - 1);
      direction[c] = level < p / 2 ? 1 : -1;
    }
    // The order in which the inputs move: a random permutation (Fisher–Yates).
    std::vector<int> order(d);
    std::iota(order.begin(), order.end(), 0);
    for (int c = d - 1; c > 0; --c)
      std::swap(order[c], order[std::min(c, static_cast<int>(stream.Uniform(draw++) * (c + 1)))]);
    const Eigen::Index first = static_cast<Eigen::Index>(t) * (d + 1);
    plan.points.row(first) = x;
    for (int s = 0; s < d; ++s) {
      const int c = order[s];
      x[c] += direction[c] * plan.delta;
      plan.points.row(first + s + 1) = x;
      plan.moved.push_back(c);
      plan.sign.push_back(direction[c]);
    }
  }
  return plan;
}

MorrisEffects EstimateMorrisEffects(const MorrisPlan& plan, const Eigen::VectorXd& values) {
  const int d = plan.inputs, r = plan.trajectories;
  if (values.size() != static_cast<Eigen::Index>(r) * (d + 1))
    throw std::invalid_argument("Morris effects: expected " + std::to_string(r * (d + 1)) +
                                " values (r(d+1)), got " + std::to_string(values.size()));
  std::vector<std::vector<double>> effects(d);
  for (int t = 0; t < r; ++t)
    for (int s = 0; s < d; ++s) {
      const Eigen::Index at = static_cast<Eigen::Index>(t) * (d + 1) + s;
      const int c = plan.moved[static_cast<std::size_t>(t) * d + s];
      effects[c].push_back((values[at + 1] - values[at]) /
                           (plan.sign[static_cast<std::size_t>(t) * d + s] * plan.delta));
    }
  MorrisEffects out;
  for (int c = 0; c < d; ++c) {
    const std::vector<double>& e = effects[c];
    double sum = 0, abs_sum = 0;
    for (double v : e) {
      sum += v;
      abs_sum += std::fabs(v);
    }
    const double mean = sum / static_cast<double>(e.size());
    double ss = 0;
    for (double v : e) ss += (v - mean) * (v - mean);
    out.mu.push_back(mean);
    out.mu_star.push_back(abs_sum / static_cast<double>(e.size()));
    out.sigma.push_back(e.size() > 1 ? std::sqrt(ss / static_cast<double>(e.size() - 1)) : 0.0);
  }
  return out;
}

}  // namespace lrcal
