// Averaging: the parse and spelling of noise.average, what each estimator keeps, and the
// variance factor against a closed form, an independent quadrature of one order statistic's
// density, a plain Monte Carlo of the estimator's variance, and the asymptotic laws.
#include "lrcal/measurement/averaging.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/math/constants/constants.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/quadrature/sinh_sinh.hpp>
#include <boost/math/special_functions/beta.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;

// The library simulates a factor's excess over 1 from 2^17 sets of readings (relative standard
// error about √(2/2^17)); comparisons allow five of those, and 1.5 for the excess's tails.
double FactorTolerance(double factor) {
  return 5 * 1.5 * std::sqrt(2.0 / (1 << 17)) * (factor - 1);
}

TEST(Averaging, ParsesItsThreeFormsAndSpellsThemBack) {
  EXPECT_TRUE(Averaging::Parse("mean").IsMean());
  EXPECT_EQ(Averaging::Parse("median").kind, Averaging::Kind::kMedian);
  const Averaging trimmed = Averaging::Parse("trimmed:0.1");
  EXPECT_EQ(trimmed.kind, Averaging::Kind::kTrimmed);
  EXPECT_EQ(trimmed.trim, 0.1);
  for (const char* text : {"mean", "median", "trimmed:0.1", "trimmed:0.25"})
    EXPECT_EQ(Averaging::Parse(Averaging::Parse(text).Name()).Name(), text);
}

TEST(Averaging, RefusesOtherTextNamingTheSettingAndWhatIsExpected) {
  for (const char* bad : {"", "Median", "trimmed", "trimmed:", "trimmed:0.5", "trimmed:0",
                          "trimmed:-0.1", "trimmed:nan", "trimmed:0.1x", "mode"}) {
    try {
      Averaging::Parse(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const SettingError& e) {
      EXPECT_THAT(e.what(), HasSubstr("noise.average")) << bad;
      EXPECT_THAT(e.Respelled(Frontend::kCommandLine).what(), HasSubstr("--average")) << bad;
      EXPECT_THAT(e.what(), HasSubstr("expected")) << bad;
    }
  }
}

TEST(Averaging, CutsTheStatedReadingsFromEachEnd) {
  const Averaging median = Averaging::Parse("median"), tenth = Averaging::Parse("trimmed:0.1");
  EXPECT_EQ(median.Cut(1), 0);
  EXPECT_EQ(median.Cut(2), 0);
  EXPECT_EQ(median.Cut(3), 1);
  EXPECT_EQ(median.Cut(4), 1);  // the two middle readings, averaged
  EXPECT_EQ(median.Cut(5), 2);
  EXPECT_EQ(tenth.Cut(9), 0);
  EXPECT_EQ(tenth.Cut(10), 1);
  EXPECT_EQ(tenth.Cut(25), 2);
  EXPECT_EQ(Averaging{}.Cut(100), 0);
}

TEST(Averaging, CombinesTheKeptReadings) {
  const std::vector<double> three = {3.0, 1.0, 2.0}, four = {4.0, 1.0, 3.0, 2.0};
  EXPECT_EQ(Averaging::Parse("median").Combine(three.data(), 3), 2.0);
  EXPECT_EQ(Averaging::Parse("median").Combine(four.data(), 4), 2.5);
  const std::vector<double> ten = {9, -50, 8, 1, 7, 2, 6, 3, 5, 4};
  // Cut one from each end: -50 and 9 go, the mean of 1..8 stays.
  EXPECT_EQ(Averaging::Parse("trimmed:0.1").Combine(ten.data(), 10), 4.5);
  // The mean keeps its bits: summed in the given order, divided by the count.
  const std::vector<double> r = {0.1, 0.7, 0.2};
  EXPECT_EQ(Averaging{}.Combine(r.data(), 3), ((0.1 + 0.7) + 0.2) / 3);
}

TEST(Averaging, NothingCutIsTheMeansVariance) {
  EXPECT_EQ(Averaging{}.VarianceFactor(10), 1.0);
  EXPECT_EQ(Averaging::Parse("median").VarianceFactor(2), 1.0);
  EXPECT_EQ(Averaging::Parse("trimmed:0.1").VarianceFactor(9), 1.0);
}

TEST(Averaging, MedianOfThreeHasItsClosedForm) {
  // Var(median of three standard normals) = 1 − √3/π.
  const double pi = boost::math::constants::pi<double>();
  const double exact = 3 * (1 - std::sqrt(3.0) / pi);
  EXPECT_NEAR(Averaging::Parse("median").VarianceFactor(3), exact, FactorTolerance(exact));
}

// Var of the k-th of n standard normal order statistics from its own density
// n!/((k−1)!(n−k)!) Φ^{k−1} (1−Φ)^{n−k} φ, integrated over the real line by sinh-sinh (a
// different variable, rule and formula from the library's).
double OrderStatisticVariance(int n, int k) {
  const boost::math::normal normal;
  const double log_coefficient = std::lgamma(n + 1.0) - std::lgamma(k) - std::lgamma(n - k + 1.0);
  auto density = [&](double x) {
    const double F = boost::math::cdf(normal, x), S = boost::math::cdf(complement(normal, x));
    return std::exp(log_coefficient + (k - 1) * std::log(F) + (n - k) * std::log(S)) *
           boost::math::pdf(normal, x);
  };
  boost::math::quadrature::sinh_sinh<double> rule;
  const double mean = rule.integrate([&](double x) { return x * density(x); });
  const double square = rule.integrate([&](double x) { return x * x * density(x); });
  return square - mean * mean;
}

TEST(Averaging, OddMediansAgreeWithTheOrderStatisticsDensity) {
  const Averaging median = Averaging::Parse("median");
  for (int n : {5, 11, 51}) {
    const double exact = n * OrderStatisticVariance(n, (n + 1) / 2);
    EXPECT_NEAR(median.VarianceFactor(n), exact, FactorTolerance(exact)) << n;
  }
}

// n·Var of the estimator by Monte Carlo, and the standard error of that estimate.
std::pair<double, double> MonteCarloFactor(const Averaging& average, int n, int samples) {
  std::mt19937_64 engine(20261126);
  std::normal_distribution<double> z;
  std::vector<double> x(static_cast<std::size_t>(n)), values;
  values.reserve(static_cast<std::size_t>(samples));
  for (int s = 0; s < samples; ++s) {
    for (double& v : x) v = z(engine);
    values.push_back(average.Combine(x.data(), n));
  }
  double sum = 0, square = 0, fourth = 0;
  for (double v : values) sum += v;
  const double mean = sum / samples;
  for (double v : values) {
    square += (v - mean) * (v - mean);
    fourth += std::pow(v - mean, 4);
  }
  const double var = square / (samples - 1), m4 = fourth / samples;
  return {n * var, n * std::sqrt((m4 - var * var) / samples)};
}

TEST(Averaging, EvenMediansAndTrimmedMeansAgreeWithMonteCarlo) {
  struct Case {
    const char* average;
    int n;
  };
  for (const Case& c : {Case{"median", 4}, Case{"median", 10}, Case{"trimmed:0.1", 10},
                        Case{"trimmed:0.2", 7}, Case{"trimmed:0.25", 20}}) {
    const Averaging average = Averaging::Parse(c.average);
    const auto [factor, se] = MonteCarloFactor(average, c.n, 400000);
    EXPECT_NEAR(average.VarianceFactor(c.n), factor, 4 * se + FactorTolerance(factor))
        << c.average << " of " << c.n;
  }
}

TEST(Averaging, LargeCountsApproachTheAsymptoticEfficiency) {
  const double pi = boost::math::constants::pi<double>();
  EXPECT_NEAR(Averaging::Parse("median").VarianceFactor(201), pi / 2, 0.01 * pi / 2);
  // The α-trimmed mean of normals: [(1 − 2α) − 2cφ(c) + 2αc²]/(1 − 2α)², c = Φ⁻¹(1 − α).
  const double alpha = 0.1;
  const boost::math::normal normal;
  const double c = boost::math::quantile(normal, 1 - alpha), phi = boost::math::pdf(normal, c);
  const double asymptotic =
      ((1 - 2 * alpha) - 2 * c * phi + 2 * alpha * c * c) / ((1 - 2 * alpha) * (1 - 2 * alpha));
  EXPECT_NEAR(Averaging::Parse("trimmed:0.1").VarianceFactor(200), asymptotic, 0.01 * asymptotic);
}

TEST(Averaging, RefusesMoreReadingsThanItsSimulationTakes) {
  try {
    Averaging::Parse("median").VarianceFactor(Averaging::kMaxRobustReadings + 1);
    ADD_FAILURE() << "accepted";
  } catch (const SettingError& e) {
    EXPECT_THAT(e.what(), HasSubstr("at most 1000 readings"));
  }
  EXPECT_EQ(Averaging{}.VarianceFactor(Averaging::kMaxRobustReadings + 1), 1.0);
}

}  // namespace
}  // namespace lrcal
