// The laser ranger reading its distance to a plane — the paper's measurement — as the first
// MeasurementKind (measurement_kind.h).
//
// Its terms are MeasurementModel's (parameter_set.h: link values, plane terms, ranger offset and
// scale), its prediction and Jacobian MeasurementModel's formulas (measurement_model.h); its
// evaluator is the structure-of-arrays batch kernel that the Monte-Carlo trials run on, so
// solving through the interface gives the bits of the ranger's own path (tested).
#pragma once

#include <memory>

#include "lrcal/measurement/environment_measurement.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/measurement_model.h"
#include "lrcal/measurement/measurement_set.h"

namespace lrcal {

class BatchEvaluator;

/// The ranger's evaluator: the batch kernel, reusable across solves without allocation once
/// warm (the Monte-Carlo hot path keeps one per thread).
class RangerEvaluator : public MeasurementEvaluator {
 public:
  RangerEvaluator();
  ~RangerEvaluator() override;
  RangerEvaluator(const RangerEvaluator&) = delete;
  RangerEvaluator& operator=(const RangerEvaluator&) = delete;
  /// Binds to `model` at `configs` (each configuration aimed at its plane, configs.target(i));
  /// both must outlive the binding.
  void Bind(const MeasurementModel& model, const TargetedConfigurations& configs);
  int num_rows() const override;
  int num_parameters() const override { return model_ ? model_->num_parameters() : 0; }
  /// The readings (1 + s)·h + o at e and their Jacobian (measurement_model.h); false when a beam
  /// runs parallel to its plane at e.
  bool Predict(const double* e, double* y, double* J) override;
  bool WeightJacobianRows(const double* row_scale) override {
    row_scale_ = row_scale;
    return true;
  }

 private:
  const MeasurementModel* model_ = nullptr;
  std::unique_ptr<BatchEvaluator> batch_;
  ModelPoint point_;
  const double* row_scale_ = nullptr;
};

/// The ranger as a measurement kind: one reading per configuration, a configuration's plane is
/// configs.target(i). A configuration misses (MissReasons) when the beam at e does not give a
/// usable reading within `ranger`'s limits (BeamMiss names).
class RangerMeasurement : public MeasurementKind {
 public:
  /// `model`'s robot must outlive this kind.
  explicit RangerMeasurement(MeasurementModel model, RangerSpec ranger = {});
  const MeasurementModel& model() const { return model_; }
  const RangerSpec& ranger() const { return ranger_; }

  const char* name() const override { return "ranger"; }
  int rows_per_configuration() const override { return 1; }
  const std::vector<std::string>& parameter_names() const override {
    return model_.parameters().names;
  }
  /// Link values at nominal, each plane's offset f0 for plane_f, the base's and tool's translation
  /// for their shifts, 0 for chart, ranger and frame rotation terms.
  Eigen::VectorXd NominalValues() const override;
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

 private:
  MeasurementModel model_;
  RangerSpec ranger_;
};

/// The laser ranger inside the non-geometric model: the ranger on `arm` with every link value, its
/// offset and scale and `asked`'s plane and frame terms (what the model moves), the terms `asked`
/// does not estimate held; `robot` (the nominal arm, which must outlive the kind, as must `arm`)
/// carries the gravity torques. What identify --estimate-compliance, Python's
/// identify_in_environment and simulate use (simulation: `arm` the true arm, `asked` all terms,
/// nothing estimated).
std::unique_ptr<EnvironmentMeasurement> RangerInEnvironment(
    const RobotModel& arm, const RobotModel& robot, const PlaneSet& planes,
    const ParameterSet& asked, const RangerSpec& ranger, const NonGeometricModel& model,
    const NonGeometricTerms& terms, const std::string& source);

/// A ranger's MeasurementSet as the kind-neutral MeasuredValues (one value per configuration).
MeasuredValues ToMeasuredValues(const MeasurementSet& data);

}  // namespace lrcal
