#include "lrcal/measurement/measurement_kind.h"

#include <cmath>
#include <iterator>
#include <stdexcept>

#include "lrcal/core/error.h"
#include "lrcal/measurement/environment_measurement.h"

namespace lrcal {

bool IsMeasurementKindName(const std::string& name) {
  for (const char* kind : kMeasurementKindNames)
    if (name == kind) return true;
  return false;
}

std::string MeasurementKindNameList() {
  std::string out;
  const std::size_t n = std::size(kMeasurementKindNames);
  for (std::size_t k = 0; k < n; ++k)
    out += (k == 0 ? "" : k + 1 == n ? " or " : ", ") + std::string(kMeasurementKindNames[k]);
  return out;
}

namespace {

// The rig disturbances NoiseModel describes for the ranger: refused, not ignored, elsewhere.
void CheckNoiseFitsKind(const MeasurementKind& kind, const NoiseModel& noise) {
  noise.Validate();
  // The ranger's own disturbances are simulated on its geometric path (simulation.h); inside the
  // non-geometric model it takes sigma and repetitions like the other kinds.
  if (std::string(kind.name()) == "ranger" && !dynamic_cast<const EnvironmentMeasurement*>(&kind))
    return;
  const char* term = noise.encoder_sigma > 0                                 ? "encoder noise"
                     : noise.form_sigma > 0                                  ? "plane form error"
                     : noise.outlier_fraction > 0                            ? "outliers"
                     : (noise.ranger_offset != 0 || noise.ranger_scale != 0) ? "ranger errors"
                                                                             : nullptr;
  if (term)
    throw InputError("noise", std::string(term) + " is simulated for the ranger only; the " +
                                  kind.name() + " measurement takes sigma and repetitions");
}

}  // namespace

std::vector<double> MeasuredValues::RowWeights(int rows_per_configuration) const {
  if (!this->weights.empty()) return this->weights;
  std::vector<double> weights;
  weights.reserve(static_cast<std::size_t>(rows_per_configuration) * repetitions.size());
  for (int r : repetitions) weights.insert(weights.end(), rows_per_configuration, r);
  return weights;
}

int SimulateMeasurements(const MeasurementKind& truth, const TargetedConfigurations& configs,
                         const NoiseModel& noise, const RandomStream& stream, MeasuredValues* data,
                         std::vector<std::string>* misses) {
  CheckNoiseFitsKind(truth, noise);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(truth.num_parameters());
  std::unique_ptr<MeasurementEvaluator> evaluator = truth.Bind(configs);
  std::vector<double> exact(evaluator->num_rows());
  evaluator->Predict(zero.data(), exact.data(), nullptr);
  const std::vector<std::string> reasons = truth.MissReasons(configs, zero.data());
  if (misses) *misses = reasons;
  return AddMeasurementNoise(truth, exact, reasons, configs, noise, stream, data);
}

int AddMeasurementNoise(const MeasurementKind& truth, const std::vector<double>& exact,
                        const std::vector<std::string>& reasons,
                        const TargetedConfigurations& configs, const NoiseModel& noise,
                        const RandomStream& stream, MeasuredValues* data) {
  CheckNoiseFitsKind(truth, noise);
  const int k = truth.rows_per_configuration(), R = noise.repetitions;
  if (exact.size() != static_cast<std::size_t>(configs.size()) * k ||
      reasons.size() != static_cast<std::size_t>(configs.size()))
    throw std::invalid_argument(
        "AddMeasurementNoise: exact values or reasons do not match the "
        "configurations");
  *data = MeasuredValues{TargetedConfigurations(configs.num_joints()), {}, {}};
  // Each component's σ, and its weight in single readings of σ (an angle's (σ/σ_angle)² per
  // reading: the variance ratio, measurement_kind.h MeasuredValues::weights).
  std::vector<double> sigma(static_cast<std::size_t>(k), noise.sigma);
  std::vector<double> weight(static_cast<std::size_t>(k),
                             noise.average.IsMean() ? R : R / noise.average.VarianceFactor(R));
  bool weighted = !noise.average.IsMean();
  for (int c = 0; c < k; ++c) {
    if (!truth.RowIsAngle(c)) continue;
    const auto u = static_cast<std::size_t>(c);
    sigma[u] = noise.sigma_angle;
    if (noise.sigma > 0 && noise.sigma_angle > 0) {
      weight[u] *= (noise.sigma / noise.sigma_angle) * (noise.sigma / noise.sigma_angle);
      weighted = true;
    }
  }
  int missed = 0;
  std::vector<double> z(static_cast<std::size_t>(R) * k);
  std::vector<double> readings(static_cast<std::size_t>(R));  // one component's R readings
  NormalDraws normal(stream);  // neighbouring configurations share counter blocks
  for (int i = 0; i < configs.size(); ++i) {
    if (reasons[i] != "ok" || !std::isfinite(exact[static_cast<std::size_t>(i) * k])) {
      ++missed;
      continue;
    }
    data->configs.AddFrom(configs, i);
    data->repetitions.push_back(R);
    if (weighted) data->weights.insert(data->weights.end(), weight.begin(), weight.end());
    if (noise.DrawsMean()) {
      for (int c = 0; c < k; ++c)
        data->y.push_back(exact[static_cast<std::size_t>(i) * k + c] +
                          sigma[static_cast<std::size_t>(c)] / std::sqrt(static_cast<double>(R)) *
                              normal(static_cast<std::uint64_t>(i) * k + c));
      continue;
    }
    stream.Normals(static_cast<std::uint64_t>(i) * R * k, R * k, z.data());
    for (int c = 0; c < k; ++c) {
      for (int r = 0; r < R; ++r)
        readings[static_cast<std::size_t>(r)] = exact[static_cast<std::size_t>(i) * k + c] +
                                                sigma[static_cast<std::size_t>(c)] * z[r * k + c];
      data->y.push_back(noise.average.Combine(readings.data(), R));
    }
  }
  return missed;
}

Eigen::MatrixXd MeasurementJacobian(const MeasurementKind& kind,
                                    const TargetedConfigurations& configs, const double* e) {
  std::unique_ptr<MeasurementEvaluator> evaluator = kind.Bind(configs);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(kind.num_parameters());
  Eigen::MatrixXd G(evaluator->num_rows(), kind.num_parameters());
  std::vector<double> y(evaluator->num_rows());
  if (!evaluator->Predict(e ? e : zero.data(), y.data(), G.data()))
    throw InputError(std::string(kind.name()) + " measurement",
                     "a prediction is undefined at this estimate (a beam parallel to its plane)");
  return G;
}

}  // namespace lrcal
