#include "lrcal/measurement/ranger_measurement.h"

#include "lrcal/core/error.h"
#include "lrcal/measurement/simulation.h"
#include "measurement/batch_evaluation.h"

namespace lrcal {

RangerEvaluator::RangerEvaluator() : batch_(std::make_unique<BatchEvaluator>()) {}
RangerEvaluator::~RangerEvaluator() = default;

void RangerEvaluator::Bind(const MeasurementModel& model, const TargetedConfigurations& configs) {
  model_ = &model;
  batch_->SetConfigurations(configs);
}

int RangerEvaluator::num_rows() const { return batch_->size(); }

bool RangerEvaluator::Predict(const double* e, double* y, double* J) {
  model_->Prepare(e, &point_);
  return batch_->Evaluate(*model_, point_, y, J, row_scale_);
}

RangerMeasurement::RangerMeasurement(MeasurementModel model, RangerSpec ranger)
    : model_(std::move(model)), ranger_(ranger) {
  ranger_.Validate();
}

Eigen::VectorXd RangerMeasurement::NominalValues() const {
  const ParameterSet& ps = model_.parameters();
  Eigen::VectorXd nominal = Eigen::VectorXd::Zero(ps.size());
  for (int k = 0; k < ps.num_robot(); ++k)
    nominal[k] = model_.robot().nominal_values()[ps.robot_values[k]];
  for (int p = 0; p < ps.num_planes(); ++p)
    if (ps.plane_columns[p].f >= 0)
      nominal[ps.plane_columns[p].f] = model_.nominal_planes()[p].offset;
  // A frame's shifts start at its translation, its rotations at 0 (parameter_set.h FrameTerms).
  for (int f = 0; f < 2; ++f)
    for (int k = 0; k < 3; ++k)
      if (ps.frame_columns[f][k] >= 0)
        nominal[ps.frame_columns[f][k]] =
            (f == 0 ? model_.robot().base() : model_.robot().tool()).translation[k];
  return nominal;
}

std::unique_ptr<MeasurementEvaluator> RangerMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  CheckPlanesReferenced(configs, model_.nominal_planes());
  if (configs.num_joints() != model_.robot().num_links())
    throw InputError("configurations",
                     "the ranger's robot has " + std::to_string(model_.robot().num_links()) +
                         " joints, the configurations " + std::to_string(configs.num_joints()));
  auto evaluator = std::make_unique<RangerEvaluator>();
  evaluator->Bind(model_, configs);
  return evaluator;
}

std::vector<std::string> RangerMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                        const double* e) const {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model_.num_parameters());
  const double* at = e ? e : zero.data();
  std::vector<double> h;
  std::vector<BeamMiss> misses;
  ExactReadings(model_.parameters().EstimatesFrames() ? model_.RobotAt(at) : model_.robot(),
                model_.LinkValues(at), model_.PlanesAt(at), ranger_, configs, &h, &misses);
  std::vector<std::string> reasons;
  reasons.reserve(misses.size());
  for (BeamMiss miss : misses) reasons.emplace_back(BeamMissName(miss));
  return reasons;
}

std::unique_ptr<MeasurementKind> RangerMeasurement::Without(
    const std::vector<std::string>& names) const {
  return std::make_unique<RangerMeasurement>(
      MeasurementModel(model_.robot(), model_.nominal_planes(),
                       WithoutParameters(model_.robot(), model_.parameters(), names)),
      ranger_);
}

MeasuredValues ToMeasuredValues(const MeasurementSet& data) {
  MeasuredValues values{data.configs, data.mean_h, data.repetitions};
  if (!data.variance_factor.empty()) values.weights = data.Weights();  // one row each
  return values;
}

std::unique_ptr<EnvironmentMeasurement> RangerInEnvironment(
    const RobotModel& arm, const RobotModel& robot, const PlaneSet& planes,
    const ParameterSet& asked, const RangerSpec& ranger, const NonGeometricModel& model,
    const NonGeometricTerms& terms, const std::string& source) {
  const ParameterSet full = MakeParameterSet(
      arm, asked.plane_terms, {}, "fix", RangerTerms{true, true}, asked.frames[0], asked.frames[1]);
  auto inner = std::make_shared<RangerMeasurement>(MeasurementModel(arm, planes, full), ranger);
  std::vector<std::string> held;
  for (const std::string& name : inner->parameter_names())
    if (asked.Find(name) < 0) held.push_back(name);
  return std::make_unique<EnvironmentMeasurement>(std::move(inner), robot, model, terms, held,
                                                  source);
}

}  // namespace lrcal
