// Readings of a laser ranger at a set of configurations, as an identification consumes them.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "lrcal/measurement/averaging.h"
#include "lrcal/measurement/plane.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

/// Readings to identify from: one entry per configuration.
struct MeasurementSet {
  TargetedConfigurations configs;
  std::vector<double> mean_h;    ///< m, mean of the readings at each configuration
  std::vector<int> repetitions;  ///< number of readings averaged
  /// Each configuration's variance factor c (averaging.h): its value's variance is c·σ²/R.
  /// Empty for means (c = 1 everywhere).
  std::vector<double> variance_factor;
  /// Each configuration's label (a measurement file's `configuration` column), in order; empty
  /// when the readings were grouped by their joint values. Messages name configurations by it.
  std::vector<std::string> labels{};
  int size() const { return configs.size(); }
  /// The residual weight of configuration i: R/c (exactly R for a mean).
  double Weight(int i) const {
    const double r = repetitions[static_cast<std::size_t>(i)];
    return variance_factor.empty() ? r : r / variance_factor[static_cast<std::size_t>(i)];
  }
  /// Every configuration's Weight, in order, into `w` (its buffer reused: the Monte-Carlo
  /// workspace fills it once per trial).
  void FillWeights(std::vector<double>* w) const {
    w->resize(repetitions.size());
    for (int i = 0; i < static_cast<int>(w->size()); ++i)
      (*w)[static_cast<std::size_t>(i)] = Weight(i);
  }
  /// Every configuration's Weight, in order.
  std::vector<double> Weights() const {
    std::vector<double> w;
    FillWeights(&w);
    return w;
  }
};

/// Groups individual readings into a MeasurementSet: reading r was taken at joint values
/// `q.q(r)` (rad or m) and read `h[r]` (m). Readings at identical joint values are one
/// configuration (in order of first appearance) whose mean_h is their sum divided by their
/// count, summed in reading order. Throws InputError, located by `where(r)` (e.g. "file.csv:12"),
/// for a reading that is not a positive distance, or one outside `ranger`'s range if given.
/// What `lrcal identify` does with a measurement CSV and the Python module with arrays.
///
/// With `labels` (one per reading: a measurement file's `configuration` column), readings are
/// grouped by label instead: a configuration is the readings that share a label, whatever
/// their recorded joint values (encoders that jitter between readings of one pose); its joint
/// values are those of its first reading if all agree, else their mean.
///
/// With `average` other than the mean, each configuration's value is the median or trimmed mean
/// of its readings and variance_factor holds the factor each count of readings implies.
MeasurementSet GroupReadings(const TargetedConfigurations& q, const std::vector<double>& h,
                             const RangerSpec* ranger, const std::function<std::string(int)>& where,
                             const std::vector<std::string>* labels = nullptr,
                             const Averaging& average = {});

}  // namespace lrcal
