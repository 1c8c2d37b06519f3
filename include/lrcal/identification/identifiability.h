// Identifiability of a parameter set from laser-plane readings at a set of configurations.
//
// The identification Jacobian G (m×n, m configurations) is evaluated at a model point (the
// nominal model by default). Its columns are scaled to unit norm so that metres and radians
// compare (an exact dependence is unit-free; a near one is judged relative to the columns' own
// size). Then:
//  - a column whose norm is below `zero_column_tolerance` × the largest column norm is a
//    parameter that does not affect the reading at all: *unidentifiable*. It is set aside
//    *before* scaling, so that rounding noise in a column that is zero in exact arithmetic is
//    never blown up into a fake dependence;
//  - the numerical rank of the scaled remaining columns is the number of singular values above
//    `rank_tolerance` × σ_max;
//  - QR with column pivoting on the scaled columns picks a well-conditioned full-rank subset;
//    each parameter left out is *dependent*, and its dependence is written as the named linear
//    combination  e_j − Σ_k c_k·e_k  (SI coefficients) along which the readings do not change;
//  - suggested_fixed = unidentifiable ∪ dependent: fixing those at nominal gives a full-rank set.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "lrcal/core/settings.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/measurement_model.h"

namespace lrcal {

struct IdentifiabilityOptions {
  /// Relative singular value (of the column-scaled G) below which a direction counts as
  /// unobservable. Rounding gives ~1e-15; a real but weak direction is far above 1e-8.
  double rank_tolerance = 1e-8;
  /// Relative column norm below which a parameter has no effect on the readings.
  double zero_column_tolerance = 1e-10;
  /// Coefficients of a dependence smaller than this (in the scaled problem) are dropped.
  double coefficient_tolerance = 1e-7;
  /// The settings (settings.h): rank_tolerance (--rank-tolerance, rank_tolerance=),
  /// zero_column_tolerance and coefficient_tolerance, each a relative tolerance in [0, 1).
  static const std::vector<SettingField<IdentifiabilityOptions>>& Settings();
  /// Throws SettingError naming the library field (identifiability.rank_tolerance, ...).
  void Validate() const;
};

/// One exact dependence among parameters: moving the parameters along the direction whose
/// components are the coefficients (Δ(name_k) = t·coefficient_k, SI) leaves every reading
/// unchanged to first order, so only the combinations orthogonal to it are identifiable.
struct Dependency {
  std::vector<std::pair<std::string, double>> terms;  ///< (name, SI coefficient); first has 1
  std::string ToString() const;
};

struct IdentifiabilityReport {
  std::vector<std::string> names;  ///< the parameter set analysed
  int num_configurations = 0;
  int rank = 0;                     ///< numerical rank of G (zero columns count as rank-less)
  Eigen::VectorXd column_norms;     ///< ‖G_j‖ in SI (m/rad or m/m)
  Eigen::VectorXd singular_values;  ///< of the column-scaled non-zero columns, descending
  double condition_number = 0;      ///< σ_max/σ_min of those (infinite when rank-deficient)
  std::vector<std::string> unidentifiable;   ///< parameters with a zero column
  std::vector<Dependency> dependencies;      ///< one per dependent parameter
  std::vector<std::string> suggested_fixed;  ///< fix these to obtain a full-rank set
  /// In words, why a non-geometric term (environment_measurement.h) in `unidentifiable` or a
  /// dependence is lost: "c1: joint 1 carries no gravity torque in these measurements ...".
  std::vector<std::string> explanations{};
  int num_params() const { return static_cast<int>(names.size()); }
  bool full_rank() const { return rank == num_params(); }
  std::string ToString() const;
};

/// Analyses G at estimate `e` (nullptr: the nominal model, e = 0).
IdentifiabilityReport AnalyzeIdentifiability(const MeasurementModel& model,
                                             const TargetedConfigurations& configs,
                                             const double* e = nullptr,
                                             const IdentifiabilityOptions& options = {});

/// The same for any measurement kind (measurement_kind.h): its Jacobian's rows are every measured
/// component (rows_per_configuration per configuration). For the ranger this is the overload
/// above (the same report, tested).
IdentifiabilityReport AnalyzeIdentifiability(const MeasurementKind& kind,
                                             const TargetedConfigurations& configs,
                                             const double* e = nullptr,
                                             const IdentifiabilityOptions& options = {});

/// The analysis of a Jacobian G (rows: measured values, SI; columns: the terms `names`) taken at
/// `num_configurations` configurations: what both overloads above compute.
IdentifiabilityReport AnalyzeJacobian(const Eigen::MatrixXd& G,
                                      const std::vector<std::string>& names, int num_configurations,
                                      const IdentifiabilityOptions& options = {});

/// The directions (columns, SI) along which G's readings do not change, by the same rules as
/// AnalyzeIdentifiability: a unit vector per zero column, and the right singular vectors of the
/// column-scaled live columns below the rank tolerance, unscaled. n × (n − rank).
Eigen::MatrixXd UnobservableDirections(const Eigen::MatrixXd& G,
                                       const IdentifiabilityOptions& options = {});

/// The identification Jacobian G (m×n) at `e` (nullptr: nominal). Readings that miss the
/// plane still give their row (the formula is finite unless the beam is parallel).
Eigen::MatrixXd IdentificationJacobian(const MeasurementModel& model,
                                       const TargetedConfigurations& configs,
                                       const double* e = nullptr);

}  // namespace lrcal
