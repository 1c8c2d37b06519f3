#include "lrcal/measurement/averaging.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <utility>

#include "lrcal/core/random.h"
#include "lrcal/core/strings.h"

namespace lrcal {

namespace {

// The simulated sets of readings behind a variance factor: the factor's excess over 1 has a
// relative standard error of about √(2/kFactorSamples) = 0.4 %.
constexpr int kFactorSamples = 1 << 17;

// n·Var(T) for T = average.Combine of n standard normal readings. The mean X̄ is complete and
// sufficient for the normal's location and T − X̄ is location-invariant, so by Basu's theorem they
// are independent: Var(T) = 1/n + Var(T − X̄). Only the small second term is simulated (a fixed
// counter-based stream, so the factor is the same bits everywhere), which makes the estimate far
// more precise than simulating Var(T) itself.
double SimulatedFactor(const Averaging& average, int n) {
  const RandomStream stream(0, 0, static_cast<std::uint64_t>(n), RandomPurpose::kAveraging);
  std::vector<double> z(static_cast<std::size_t>(n));
  double sum = 0, square = 0;
  for (int s = 0; s < kFactorSamples; ++s) {
    stream.Normals(static_cast<std::uint64_t>(s) * static_cast<std::uint64_t>(n), n, z.data());
    const double d = average.Combine(z.data(), n) - Averaging{}.Combine(z.data(), n);
    sum += d;
    square += d * d;
  }
  const double mean = sum / kFactorSamples;
  const double excess = (square - kFactorSamples * mean * mean) / (kFactorSamples - 1);
  return 1 + n * excess;
}

}  // namespace

SettingSpec Averaging::Spec() {
  return SettingSpec::Named(
      "noise", "average", "average",
      "how a configuration's repeated readings are combined: mean, median or trimmed:F (F in "
      "(0, 0.5) cut from each end)");
}

Averaging Averaging::Parse(const std::string& text) {
  Averaging a;
  if (text == "mean") return a;
  if (text == "median") {
    a.kind = Kind::kMedian;
    return a;
  }
  const std::string prefix = "trimmed:";
  if (text.compare(0, prefix.size(), prefix) == 0) {
    double v = 0;
    if (ParseDecimal(text.substr(prefix.size()), &v) && v > 0 && v < 0.5) {
      a.kind = Kind::kTrimmed;
      a.trim = v;
      return a;
    }
    throw SettingError(Spec(),
                       "expected trimmed:F with F, the fraction cut from each end, in "
                       "(0, 0.5) (trimmed:0.1), got '" +
                           CellExcerpt(text) + "'");
  }
  throw SettingError(Spec(), "expected mean, median or trimmed:F (F in (0, 0.5)), got '" +
                                 CellExcerpt(text) + "'");
}

std::string Averaging::Name() const {
  switch (kind) {
    case Kind::kMean:
      return "mean";
    case Kind::kMedian:
      return "median";
    case Kind::kTrimmed: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "trimmed:%.15g", trim);
      return buf;
    }
  }
  return "mean";
}

int Averaging::Cut(int n) const {
  switch (kind) {
    case Kind::kMean:
      return 0;
    case Kind::kMedian:
      return n <= 2 ? 0 : (n - 1) / 2;
    case Kind::kTrimmed:
      return std::min(static_cast<int>(std::floor(trim * n)), (n - 1) / 2);
  }
  return 0;
}

double Averaging::Combine(const double* readings, int n) const {
  const int g = Cut(n);
  if (kind == Kind::kMean || g == 0) {
    double sum = 0;
    for (int r = 0; r < n; ++r) sum += readings[r];
    return sum / n;
  }
  std::vector<double> sorted(readings, readings + n);
  if (kind == Kind::kMedian) {  // the middle reading, or the mean of the two middle ones
    const auto middle = sorted.begin() + n / 2;
    std::nth_element(sorted.begin(), middle, sorted.end());
    if (n % 2) return *middle;
    return (*std::max_element(sorted.begin(), middle) + *middle) / 2;
  }
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (int r = g; r < n - g; ++r) sum += sorted[static_cast<std::size_t>(r)];
  return sum / (n - 2 * g);
}

void Averaging::CheckCount(int n) const {
  if (!IsMean() && n > kMaxRobustReadings)
    throw SettingError(Spec(), "a " + Name() + " takes at most " +
                                   std::to_string(kMaxRobustReadings) +
                                   " readings per configuration, got " + std::to_string(n) +
                                   " (use mean, or fewer repetitions)");
}

double Averaging::VarianceFactor(int n) const {
  const int g = Cut(n);
  if (g == 0) return 1;
  CheckCount(n);
  static std::mutex mutex;
  static std::map<std::pair<int, int>, double> cache;
  {
    std::lock_guard<std::mutex> lock(mutex);
    const auto found = cache.find({n, g});
    if (found != cache.end()) return found->second;
  }
  const double factor = SimulatedFactor(*this, n);
  std::lock_guard<std::mutex> lock(mutex);
  cache.emplace(std::make_pair(n, g), factor);
  return factor;
}

}  // namespace lrcal
