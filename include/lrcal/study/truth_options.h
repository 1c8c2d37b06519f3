// The simulated truth of a study's trials: the arm, ranger and errors the readings come from.
//
// Two modes. robot_file: every trial's truth is the robot file's `true_errors` (link values and
// the ranger's offset and scale) times `scale`, the same in every trial. random: each trial
// draws an error for every link value the robot file marks as a parameter, N(0, angle_sigma²)
// for θ, α, β and N(0, length_sigma²) for a and d (the trial's own random stream); the ranger's
// errors are then the robot file's, unscaled. In either mode `ranger_offset` and `ranger_scale`,
// when given, replace the ranger's true errors.
//
// A study file spells it as the `truth:` section (docs/STUDIES.md): mode, scale,
// angle_sigma_mrad, length_sigma_mm, ranger_offset_mm and ranger_scale_ppm ("robot_file" for the
// file's). The angle and length sigmas are also the truth's magnitudes for expected-error design
// scaling and for identification.prior_sigma: truth.
#pragma once

#include <optional>
#include <vector>

#include "lrcal/core/settings.h"

namespace lrcal {

struct TruthOptions {
  bool random = false;         ///< truth.mode: random (drawn per trial); else robot_file
  double scale = 1.0;          ///< robot_file: the file's errors × this (≥ 0)
  double angle_sigma = 1e-3;   ///< rad, random: σ of each drawn angle error (θ, α, β)
  double length_sigma = 1e-3;  ///< m, random: σ of each drawn length error (a, d)
  /// The true ranger's zero offset (m) and scale error (dimensionless: it reads (1 + s)·h + o);
  /// empty: the robot file's (× scale in robot_file mode).
  std::optional<double> ranger_offset, ranger_scale;

  /// The numeric settings (settings.h), their defaults this struct's: scale (≥ 0),
  /// angle_sigma_mrad (≥ 0 mrad), length_sigma_mm (≥ 0 mm).
  static const std::vector<SettingField<TruthOptions>>& Settings();
  /// The ranger's scale error in ppm must be below 500,000 in magnitude (a reading that keeps its
  /// sign).
  static constexpr double kMaxRangerScale = 0.5;
  /// Throws SettingError naming the library field (truth.scale, ...) and what was expected.
  void Validate() const;
};

}  // namespace lrcal
