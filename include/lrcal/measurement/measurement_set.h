// Readings of a laser ranger at a set of configurations, as an identification consumes them.
#pragma once

#include <vector>

#include "lrcal/kinematics/configuration_set.h"

namespace lrcal {

/// Readings to identify from: one entry per configuration.
struct MeasurementSet {
  ConfigurationSet configs;
  std::vector<double> mean_h;    ///< m, mean of the readings at each configuration
  std::vector<int> repetitions;  ///< number of readings averaged (the residual weight)
  int size() const { return configs.size(); }
};

}  // namespace lrcal
