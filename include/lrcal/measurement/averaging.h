// How the repeated readings of one configuration become the one value an identification fits:
// their mean, their median, or a trimmed mean. The median and the trimmed mean resist gross
// errors (a reflection, a dropout) that pull a mean by their full size over R; they pay for it
// with a larger variance under Gaussian noise, which the identification's weights account for
// (VarianceFactor). The setting is noise.average in a study file, --average on the command line
// and average= in Python: "mean" (the default), "median" or "trimmed:F".
#pragma once

#include <string>
#include <vector>

#include "lrcal/core/settings.h"

namespace lrcal {

/// The estimator of a configuration's reading from its R repeated readings.
struct Averaging {
  enum class Kind { kMean, kMedian, kTrimmed };
  Kind kind = Kind::kMean;
  /// kTrimmed: the fraction of the readings cut from each end, in (0, 0.5). g = ⌊F·R⌋ readings
  /// are cut from each end and the mean of the R − 2g others is the value.
  double trim = 0;

  /// The setting's spelling for messages (section "noise", field "average", name "average").
  static SettingSpec Spec();
  /// Reads "mean", "median" or "trimmed:F" (0 < F < 0.5). Throws SettingError naming
  /// noise.average and what was expected.
  static Averaging Parse(const std::string& text);
  /// The text Parse reads back: "mean", "median", "trimmed:0.1".
  std::string Name() const;
  bool IsMean() const { return kind == Kind::kMean; }

  /// The readings cut from each end of `n` sorted readings (0 for the mean; for the median of
  /// an even count the two middle readings are kept and averaged).
  int Cut(int n) const;
  /// The value of `n` readings (any unit). The mean sums them in the given order and divides by
  /// n (what lrcal has always done); the median is the middle reading (the mean of the two middle
  /// ones for even n); the trimmed mean sorts a copy and averages the n − 2·Cut(n) middle ones
  /// in ascending order.
  double Combine(const double* readings, int n) const;
  /// n·Var(value of n independent N(0, 1) readings): the value's variance is VarianceFactor(n)·σ²/n
  /// for readings of standard deviation σ. Exactly 1 when nothing is cut (the mean, n ≤ 2 for the
  /// median). Otherwise 1 + n·Var(value − mean) (the two are independent for normal readings,
  /// Basu's theorem), the second term simulated from 2¹⁷ sets of n readings of a fixed stream: the
  /// same bits on every machine, a standard error of about 0.4 % of the factor's excess over 1
  /// (0.002 for a median's ≈ 1.5), computed once per (estimator, n) and cached. The median of 3
  /// has 3·(1 − √3/π) ≈ 1.346; the median's factor tends to π/2 as n grows. Throws SettingError
  /// for n above kMaxRobustReadings when something is cut (CheckCount).
  double VarianceFactor(int n) const;
  /// Throws SettingError (naming noise.average) unless this estimator takes `n` readings per
  /// configuration: any count for the mean, at most kMaxRobustReadings for the others.
  void CheckCount(int n) const;

  /// The largest count of readings a median or trimmed mean takes (the factor's simulation grows
  /// with the count).
  static constexpr int kMaxRobustReadings = 1000;
};

}  // namespace lrcal
