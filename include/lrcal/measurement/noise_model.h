// The noise of simulated readings and a real rig's disturbances: what SimulateReadings draws
// (simulation.h explains each term's law). SI inside; the settings schema (settings.h) gives each
// setting's name and unit at the interfaces (noise.sigma_mm, --sigma-mm, sigma_mm=).
#pragma once

#include <vector>

#include "lrcal/core/settings.h"
#include "lrcal/measurement/averaging.h"

namespace lrcal {

struct NoiseModel {
  double sigma = 0.2e-3;  ///< m, standard deviation of one reading
  int repetitions = 10;   ///< readings averaged per configuration
  /// Draw each configuration's mean reading error directly as σ/√R·z (z at index `slot`),
  /// instead of averaging R drawn readings. The distribution of the mean is exactly the same;
  /// the cost no longer grows with R. The Monte-Carlo trials use this; `lrcal simulate` writes
  /// every reading.
  bool draw_mean = false;
  double encoder_sigma = 0;     ///< rad, each joint, each reading
  double form_sigma = 0;        ///< m, flatness deviation at each configuration's hit point
  double outlier_fraction = 0;  ///< probability that a reading carries a gross error
  double outlier_sigma = 5e-3;  ///< m, standard deviation of a gross error
  /// The true ranger's errors: it reads (1 + ranger_scale)·h + ranger_offset (m) for a true
  /// geometric distance h, before the random errors above.
  double ranger_offset = 0;
  double ranger_scale = 0;
  /// How a configuration's R readings become its value (averaging.h): their mean (the default),
  /// median or trimmed mean; not a numeric setting (noise.average, --average, average=). A
  /// median or trimmed mean draws every reading even with draw_mean (its law is not normal).
  Averaging average{};
  /// rad, standard deviation of one reading of an orientation component (the pose kind's rows
  /// 3–5, measurement_kind.h RowIsAngle): a 6-D probe's or a camera marker's angular noise. Kept
  /// last so that aggregate initialisation {sigma, repetitions, draw_mean} keeps its meaning.
  double sigma_angle = 0.2e-3;
  /// Readings averaged per configuration as the identification weighs them: R for the mean,
  /// R / average.VarianceFactor(R) otherwise (the averaged value's variance is σ²/this).
  double EffectiveReadings() const;
  /// draw_mean, where it applies (the mean of the readings).
  bool DrawsMean() const { return draw_mean && average.IsMean(); }
  /// Encoder noise or form error: the readings need the kinematics, not only exact readings.
  bool DisturbsGeometry() const { return encoder_sigma > 0 || form_sigma > 0; }
  /// The user-facing settings (settings.h), in this order: sigma_mm (≥ 0), repetitions (1 to
  /// 1,000,000), encoder_sigma_mrad (≥ 0), form_sigma_mm (≥ 0), outlier_fraction ([0, 1]),
  /// outlier_sigma_mm (≥ 0). Their defaults are the initial values above. The ranger's errors
  /// are the truth's (a study's truth.ranger_offset_mm, the robot file's), not settings here.
  static const std::vector<SettingField<NoiseModel>>& Settings();
  /// Throws SettingError naming the library field (noise.sigma, ...) unless every setting is
  /// in range (a median or trimmed mean of at most Averaging::kMaxRobustReadings readings);
  /// InputError unless the ranger's offset is finite, |scale| < 0.5 and sigma_angle is finite and
  /// ≥ 0.
  void Validate() const;
};

}  // namespace lrcal
