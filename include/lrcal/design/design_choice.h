// Choosing a design from a pool, the whole of `lrcal design` and of Python's lrcal.design(): the
// selection by a criterion (E, D, A, O1–O5, or the task criterion I), its certificate of
// near-optimality, its standing against random designs and how it spreads over the planes.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/design/design_certificate.h"
#include "lrcal/design/experiment_design.h"
#include "lrcal/design/random_baseline.h"
#include "lrcal/design/task_criterion.h"

namespace lrcal {

/// What to choose and how.
struct DesignRequest {
  int count = 0;  ///< configurations to choose (k)
  /// The criterion and method; with a task (TaskPoses::count > 0) the criterion is A on the
  /// task-weighted G: criterion I.
  SelectionOptions selection;
  DesignScaling scaling = DesignScaling::kSI;  ///< columns of G (ignored by criterion I)
  double expected_angle = 1e-3;   ///< rad, the column weight of angles for kExpectedErrors
  double expected_length = 1e-3;  ///< m, the column weight of lengths for kExpectedErrors
  int baseline = 1000;            ///< random designs to compare with (RandomBaselineSetting)
  std::uint64_t seed = 1;         ///< exchange kicks (stream 1) and the baseline (stream 2)
  TaskPoses task;                 ///< criterion I's poses; count 0 for the other criteria
  /// Criterion I without poses of the user's: the front ends draw this many workspace poses
  /// (WorkspacePoses, with `seed`) to build `task` from.
  int workspace = 200;

  /// "I" for the task criterion, else the criterion's name.
  std::string CriterionName() const;
  /// The numeric settings (settings.h), their defaults this struct's: expected_angle_mrad
  /// (`design.expected_angle`, > 0 mrad), expected_length_mm (`design.expected_length`, > 0 mm)
  /// baseline (1 to 1,000,000 random designs; RandomBaselineSetting) and workspace (1 to
  /// 100,000 poses; WorkspacePosesSetting). The command line and Python take them as
  /// --expected-angle-mrad, expected_angle_mrad=, ...
  static const std::vector<SettingField<DesignRequest>>& Settings();
  /// Throws SettingError or InputError naming the field and what was expected.
  void Validate() const;
};

/// The chosen design and what it is worth.
struct DesignChoice {
  SelectionResult chosen;               ///< pool indices, ascending, with the criterion's score
  double seconds = 0;                   ///< the selection's wall time
  std::vector<BaselineIndex> baseline;  ///< every index against the random designs
  DesignCertificate certificate;
  std::string certificate_statement;  ///< DesignCertificate::ToString
  std::vector<int> per_plane;         ///< chosen configurations aimed at each plane
  /// Criterion I: the predicted RMS position error at the task poses per unit reading σ.
  std::optional<double> task_rms_per_sigma;
};

/// Chooses request.count of `pool` for measurements of `kind` (at its nominal terms); per_plane
/// counts the chosen configurations per target. A kind of several values per configuration (a
/// tracker's 3 or 6) is chosen by blocks (block_selection.h; exhaustive refused there), its
/// baseline of random designs of as many configurations, and has no certificate (the relaxation
/// weighs single rows). Throws InputError for an impossible request (count above the pool, too
/// few values for the terms).
DesignChoice ChooseDesign(const MeasurementKind& kind, const TargetedConfigurations& pool,
                          const DesignRequest& request);
/// The ranger's: ChooseDesign of RangerMeasurement(model), per_plane over the model's planes.
DesignChoice ChooseDesign(const MeasurementModel& model, const TargetedConfigurations& pool,
                          const DesignRequest& request);

/// "I (predicted RMS position error at 200 workspace poses: 0.61 mm per mm of reading noise)"
/// or "E = 0.0123": the criterion and the chosen design's value of it, for text output.
std::string CriterionText(const DesignRequest& request, const DesignChoice& choice);

/// `lrcal design`'s text: the choice, its criterion, the chosen indices, how they spread over
/// `planes`, the certificate and the table against the random designs.
std::string DesignChoiceText(const DesignRequest& request, const DesignChoice& choice,
                             const PlaneSet& planes, int pool_size);

}  // namespace lrcal
