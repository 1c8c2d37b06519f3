// K-fold cross-validation of an identification over its configurations: the check a user can
// run on real data without a tracker.
//
// Configuration i (0-based, in the data's order) is in fold i mod K. For each fold the model is
// identified from the other folds with the same options, and each held-out configuration's mean
// reading h̄_i is predicted by that fit. The prediction error e_i = h̄_i − ĥ_i has, to first
// order, the variance
//     v_i = σ²/R_i + g_iᵀ C g_i,
// σ the per-reading noise (the given one when IdentificationOptions::sigma > 0, else the fold
// fit's residual estimate σ̂), R_i the readings averaged at configuration i, g_i its Jacobian row
// at the fold's estimate and C the fold fit's covariance (given σ, else residual-based). If the
// model and σ are right, z_i = e_i/√v_i is about N(0, 1), so the mean of z² is about 1 and the
// RMS of the errors about the RMS of √v_i; a model that misses something (a second plane, a
// ranger error, joint errors) or an understated σ predicts held-out readings worse than it says.
// For least squares with K = m (leave-one-out) and a linear model, e_i = r_i/(1 − H_ii) and
// v_i = σ²/(R_i(1 − H_ii)) with H the weighted hat matrix: the test's closed form.
#pragma once

#include <string>
#include <vector>

#include "lrcal/identification/identification.h"
#include "lrcal/measurement/measurement_set.h"

namespace lrcal {

struct HeldOutReading {
  int configuration = 0;     ///< 0-based, in the data's order
  int fold = 0;              ///< configuration mod K
  double error = 0;          ///< h̄_i − ĥ_i (m; rad for an angle value)
  double predicted_std = 0;  ///< √v_i (m; rad for an angle value)
  double z = 0;              ///< error / predicted_std
  /// A kind of several values per configuration: which of them (0 for the ranger), and whether
  /// it is an angle (MeasurementKind::RowIsAngle).
  int component = 0;
  bool angle = false;
};

struct CrossValidation {
  int folds = 0;
  /// One per configuration whose fold could be fitted, in the data's order.
  std::vector<HeldOutReading> predictions;
  /// Folds that could not be fitted (rank-deficient without them, no residual degrees of
  /// freedom and no σ given, ...), with the reason in words.
  std::vector<std::pair<int, std::string>> failed_folds;
  double rms_error = 0;      ///< RMS of the held-out errors of lengths (m)
  double rms_predicted = 0;  ///< RMS of their predicted standard deviations (m)
  /// The same over the angle values of a kind that has them (rad; 0 without any).
  double rms_error_angle = 0, rms_predicted_angle = 0;
  double mean_z2 = 0;  ///< mean of z²: about 1 when the fit predicts as well as it says
  /// Half-width of the range of mean z² expected by chance: 3·√(2/n) for n predictions
  /// (independent Gaussian z; the folds' fits share data, so this is a guide, not a test).
  double mean_z2_tolerance = 0;
  std::vector<int> beyond_4;  ///< configurations with |z| > 4
  /// True when mean_z2 is within 1 ± mean_z2_tolerance.
  bool consistent() const { return mean_z2 <= 1 + mean_z2_tolerance; }
  /// A few lines: the folds, the two RMS and their ratio, mean z², a verdict in words.
  std::string ToString() const;
};

/// Runs the K-fold cross-validation (2 ≤ K ≤ number of configurations). Throws InputError
/// (where = "--holdout") for a K out of range.
CrossValidation CrossValidate(const MeasurementModel& model, const MeasurementSet& data, int folds,
                              const IdentificationOptions& options);

/// The same for any measurement kind (a tracker's point or pose, a scanner, contacts, sockets):
/// each fold fitted by Identify(kind) from the others, every value of each held-out
/// configuration predicted (one HeldOutReading per value), its variance σ²/w + jᵀCj with w its
/// weight in `data` (MeasuredValues::RowWeights: an angle value's includes (σ/σ_angle)², so
/// σ²/w is in its own unit) and j its Jacobian row at the fold's estimate. A constraint kind's
/// value is the residual of the constraint (a held-out ball's offset from its socket).
CrossValidation CrossValidate(const MeasurementKind& kind, const MeasuredValues& data, int folds,
                              const IdentificationOptions& options);

}  // namespace lrcal
