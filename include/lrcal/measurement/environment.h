// Where and when a measurement was taken: the gravity the arm hangs in and its temperature —
// what the non-geometric terms (environment_measurement.h) read.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

namespace lrcal {

/// Standard gravity (m/s²) as the defaults write it: an upright arm on the ground.
inline constexpr double kStandardGravity = 9.81;

/// One measurement's environment. A field that is NaN was not given (a data file without the
/// columns): it takes the robot's default (Or).
struct Environment {
  /// The acceleration of free fall in the robot's base frame B (m/s²): (0, 0, −9.81) upright on
  /// the ground, (0, 0, 9.81) ceiling-mounted, 0 on orbit, a fraction on an offloading rig.
  Eigen::Vector3d gravity = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The arm's temperature (°C), uniform over the arm.
  double temperature_c = std::numeric_limits<double>::quiet_NaN();

  /// Upright on the ground at 20 °C: the defaults of a robot file without `environment:`.
  static Environment Ground() {
    Environment e;
    e.gravity = Eigen::Vector3d(0, 0, -kStandardGravity);
    e.temperature_c = 20;
    return e;
  }
  /// This environment with the fields it does not give taken from `defaults`.
  Environment Or(const Environment& defaults) const {
    Environment e = *this;
    if (!e.gravity.allFinite()) e.gravity = defaults.gravity;
    if (!(e.temperature_c == e.temperature_c)) e.temperature_c = defaults.temperature_c;
    return e;
  }
  /// True when both fields are given.
  bool complete() const { return gravity.allFinite() && temperature_c == temperature_c; }
  /// Exact equality of given fields (NaN equals NaN: both not given).
  bool operator==(const Environment& o) const;
  /// "gravity (0, 0, -9.81) m/s², 20 °C".
  std::string ToString() const;
};

}  // namespace lrcal
