// The seam between what a sensor measures and everything that uses measurements.
//
// A measurement kind (a ranger reading the distance to a plane, a tracker reading a point on the
// tool, ...) gives, for a set of configurations and an estimate e of its terms:
//  - the predicted measurements y(e): `rows_per_configuration()` values per configuration, in
//    SI units, configuration-major (row i·k + c is component c of configuration i);
//  - their Jacobian ∂y/∂e with respect to every estimated term (robot link values, the sensor's
//    own terms), analytic, column-major;
//  - why a configuration has no measurement (a beam that misses its plane), by name;
//  - its simulation (`SimulateMeasurements`: the kind built on the true geometry predicts the
//    exact values, the noise is added per component).
// e is the deviation of every estimated term from its nominal value (SI: rad, m, or
// dimensionless), laid out as `parameter_names()`; e = 0 is the nominal model.
//
// The identification (identification.h: `Identify(const MeasurementKind&, ...)`), its
// Levenberg–Marquardt solver and the identifiability analysis work against this interface. The
// ranger (ranger_measurement.h) is its first implementation and keeps its structure-of-arrays
// fast path behind `Bind`; the tracker's point (point_measurement.h) is the second.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/core/random.h"
#include "lrcal/measurement/noise_model.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

/// A kind's predictions at one fixed set of configurations, reused across a solver's
/// iterations. It may keep per-configuration work and scratch space, so it is not thread-safe:
/// one evaluator per thread. The configurations it was bound to must outlive it.
class MeasurementEvaluator {
 public:
  virtual ~MeasurementEvaluator() = default;
  /// Rows of y and J: configurations × the kind's rows per configuration.
  virtual int num_rows() const = 0;
  /// Columns of J: the kind's estimated terms.
  virtual int num_parameters() const = 0;
  /// The predicted measurements y(e) (num_rows() values, SI) at estimate e (num_parameters()
  /// values), and, if J is not null, ∂y/∂e into the column-major num_rows() × num_parameters()
  /// matrix J (leading dimension num_rows()). Returns false when some prediction is undefined at
  /// e (a ranger's beam parallel to its plane): y is then not finite there.
  virtual bool Predict(const double* e, double* y, double* J) = 0;
  /// Asks the following Predict calls for J with its rows weighted: J(i, k) · row_scale[i]
  /// (num_rows() values, kept by the caller until the next call; null: unweighted), the one
  /// multiplication a separate pass over J would make, so the same bits. Returns false when this
  /// evaluator does not weight rows (the caller then does); the ranger's batch kernel does, as
  /// it stores J.
  virtual bool WeightJacobianRows(const double* row_scale) {
    (void)row_scale;
    return false;
  }
};

/// One kind of measurement, built on a robot and the kind's nominal geometry (the sensor's
/// frame, planes, targets) with the set of terms it estimates.
class MeasurementKind {
 public:
  virtual ~MeasurementKind() = default;
  /// The kind's name as users write it: "ranger", "point".
  virtual const char* name() const = 0;
  /// Measured values per configuration: 1 for a distance, 3 for a point, 6 for a pose.
  virtual int rows_per_configuration() const = 0;
  /// True when component `component` (0 ≤ component < rows_per_configuration()) is an angle
  /// (rad, a pose's orientation) rather than a length (m): its noise is NoiseModel::sigma_angle.
  virtual bool RowIsAngle(int component) const {
    (void)component;
    return false;
  }
  /// The estimated terms, in the order of e. Units follow the name (DisplayUnitOf in
  /// parameter_set.h: angles in rad, lengths in m).
  virtual const std::vector<std::string>& parameter_names() const = 0;
  int num_parameters() const { return static_cast<int>(parameter_names().size()); }
  /// The nominal values of the estimated terms (SI): what e = 0 stands for. Terms whose nominal
  /// value is a chart origin (a plane normal's u) are 0.
  virtual Eigen::VectorXd NominalValues() const = 0;
  /// An evaluator bound to `configs`. Throws InputError when a configuration does not fit the
  /// kind (a plane or target index it does not have, a wrong number of joints).
  virtual std::unique_ptr<MeasurementEvaluator> Bind(
      const TargetedConfigurations& configs) const = 0;
  /// Bind, the values read in the frames of reference of `chart_configs` (as many as `configs`)
  /// where the kind has any: a coupled chain's evaluator (chain_measurement.h) moves a coupled
  /// joint with its gain while the measured orientations stay written in the charts of the
  /// nominal configurations (pose_measurement.h). A kind without charts binds `configs`.
  virtual std::unique_ptr<MeasurementEvaluator> BindInChartsOf(
      const TargetedConfigurations& configs, const TargetedConfigurations& chart_configs) const {
    (void)chart_configs;
    return Bind(configs);
  }
  /// Why each configuration has no measurement at estimate e ("ok" where it has one). Used by
  /// simulation: a configuration that misses is left out of the data, never filled with a NaN.
  virtual std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                               const double* e) const = 0;
  /// The configurations the rank analysis (identifiability.h) linearises at, for measurements
  /// at `configs`: `configs` themselves, except for a kind whose measured values are constraints
  /// (the socket kind: the tool point at its socket) — there real data leave residuals, along
  /// which a symmetry of the constraints (turning the arm and its sockets together about the base
  /// z axis) is not exact, so the analysis takes the configurations moved until the nominal
  /// model satisfies the constraints, where every symmetry shows as a deficiency.
  virtual TargetedConfigurations LinearisationConfigurations(
      const TargetedConfigurations& configs) const {
    return configs;
  }
  /// The same kind with the terms `names` held at nominal (what identifiability suggests to fix).
  /// Throws InputError naming an unknown term.
  virtual std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const = 0;
};

/// The measurement kinds lrcal models, as users name them (--sensor, a file's `sensor` column,
/// a study's sensor.kind): the one list the front ends and readers check names against.
inline constexpr const char* kMeasurementKindNames[] = {"ranger", "scanner", "point",
                                                        "pose",   "socket",  "contact"};
/// True for a name of kMeasurementKindNames.
bool IsMeasurementKindName(const std::string& name);
/// The names for messages: "ranger, scanner, point, pose, socket or contact".
std::string MeasurementKindNameList();

/// Measured values of one kind, as the identification consumes them: configuration i has
/// rows_per_configuration values y[i·k .. i·k + k) (SI), each the mean of repetitions[i] readings
/// (its residual weight).
struct MeasuredValues {
  TargetedConfigurations configs;
  std::vector<double> y;
  std::vector<int> repetitions;
  int size() const { return configs.size(); }
  /// Per measured value (rows_per_configuration per configuration), weights that replace the
  /// repetitions when not empty: σ²/var_i for a value whose variance is var_i (errors in
  /// variables, identification.h), in units of single readings.
  std::vector<double> weights{};
  /// Each measured value's weight: `weights` if given, else its configuration's repetitions on
  /// each of its `rows_per_configuration` values (what the solvers weigh the residuals by).
  std::vector<double> RowWeights(int rows_per_configuration) const;
};

/// Simulated measurements: `truth` (the kind built on the true geometry) predicts the exact
/// values at e = 0; configurations it misses are left out (their reasons in `misses`, if
/// given, one per configuration). Each component of each reading carries independent noise
/// N(0, noise.sigma²) (N(0, noise.sigma_angle²) for an angle, RowIsAngle, whose values are then
/// weighed (sigma/sigma_angle)² per reading in data->weights); a configuration's value is the mean
/// (or noise.average's median or trimmed mean, each component on its own, with weights
/// R/VarianceFactor(R)) of noise.repetitions readings. Reading r of component c of configuration i
/// draws the standard normal at index (i·R + r)·k + c of `stream` (R repetitions, k rows per
/// configuration), so a configuration's noise does not depend on the others; with noise.draw_mean
/// the mean's error is drawn directly as σ/√R·z, z at index i·k + c (the same distribution). The
/// rig disturbances of NoiseModel (encoder noise, plane form, outliers, ranger errors) are the
/// ranger's (simulation.h): for another kind they are refused with an InputError rather than
/// ignored. Returns the number of missed configurations.
int SimulateMeasurements(const MeasurementKind& truth, const TargetedConfigurations& configs,
                         const NoiseModel& noise, const RandomStream& stream, MeasuredValues* data,
                         std::vector<std::string>* misses = nullptr);

/// The noise half of SimulateMeasurements: the truth's exact values `exact` at `configs`
/// (rows_per_configuration per configuration, SI) and its MissReasons `reasons` given, computed
/// once for many noise draws (a study's fixed truth). SimulateMeasurements is this on the truth's
/// own predictions, bit for bit. Throws std::invalid_argument when the sizes do not match.
int AddMeasurementNoise(const MeasurementKind& truth, const std::vector<double>& exact,
                        const std::vector<std::string>& reasons,
                        const TargetedConfigurations& configs, const NoiseModel& noise,
                        const RandomStream& stream, MeasuredValues* data);

/// The Jacobian ∂y/∂e (num_rows × num_parameters) of `kind` at `configs` and estimate e
/// (nullptr: nominal). Throws InputError when a prediction is undefined there.
Eigen::MatrixXd MeasurementJacobian(const MeasurementKind& kind,
                                    const TargetedConfigurations& configs,
                                    const double* e = nullptr);

}  // namespace lrcal
