#include "lrcal/measurement/simulation.h"

#include <cmath>

#include "lrcal/core/error.h"

namespace lrcal {

void ExactReadings(const RobotModel& robot, const Eigen::VectorXd& link_values, const Plane& plane,
                   const RangerSpec& ranger, const ConfigurationSet& configs,
                   std::vector<double>* h, std::vector<BeamMiss>* misses) {
  ModelPoint point;
  PrepareModelPoint(robot, link_values.data(), plane, &point);
  h->resize(configs.size());
  if (misses) misses->resize(configs.size());
  for (int i = 0; i < configs.size(); ++i) {
    const Pose<double> pose = ToolPose(point, configs, i);
    double nb;
    (*h)[i] = BeamReading(pose, plane, &nb);
    if (misses) (*misses)[i] = ClassifyReading((*h)[i], nb, ranger);
  }
}

void NoiseModel::Validate(const std::string& source) const {
  if (!(std::isfinite(sigma) && sigma >= 0))
    throw InputError(source, "sigma: expected a finite standard deviation >= 0 (m), got " +
                                 std::to_string(sigma));
  if (repetitions < 1)
    throw InputError(source, "repetitions: expected at least 1 reading per configuration");
}

int SimulateReadings(const RobotModel& robot, const Eigen::VectorXd& true_link_values,
                     const Plane& true_plane, const RangerSpec& ranger,
                     const ConfigurationSet& configs, const NoiseModel& noise,
                     const RandomStream& stream, MeasurementSet* data,
                     std::vector<BeamMiss>* misses, std::vector<double>* raw,
                     const std::vector<int>* noise_slots) {
  noise.Validate();
  std::vector<double> h;
  std::vector<BeamMiss> local;
  std::vector<BeamMiss>* m = misses ? misses : &local;
  ExactReadings(robot, true_link_values, true_plane, ranger, configs, &h, m);
  return AddNoise(h, *m, configs, noise, stream, data, raw, noise_slots);
}

int AddNoise(const std::vector<double>& h, const std::vector<BeamMiss>& misses,
             const ConfigurationSet& configs, const NoiseModel& noise, const RandomStream& stream,
             MeasurementSet* data, std::vector<double>* raw, const std::vector<int>* noise_slots) {
  // Reuse the buffers of `data` (the Monte-Carlo workspace calls this once per trial).
  if (data->configs.num_joints() != configs.num_joints())
    data->configs = ConfigurationSet(configs.num_joints());
  data->configs.Clear();
  data->configs.Reserve(configs.size());
  data->mean_h.clear();
  data->repetitions.clear();
  const int R = noise.repetitions;
  const double sigma_mean = noise.sigma / std::sqrt(static_cast<double>(R));
  std::vector<double> z(noise.draw_mean ? 1 : R);
  if (raw) raw->clear();
  int missed = 0;
  for (int i = 0; i < configs.size(); ++i) {
    const std::uint64_t slot = noise_slots ? (*noise_slots)[i] : i;
    if (misses[i] != BeamMiss::kNone) {
      ++missed;
      continue;
    }
    double mean;
    if (noise.draw_mean) {
      mean = h[i] + sigma_mean * stream.Normal(slot);
    } else {
      stream.Normals(slot * R, R, z.data());
      double sum = 0;
      for (int r = 0; r < R; ++r) {
        const double reading = h[i] + noise.sigma * z[r];
        sum += reading;
        if (raw) raw->push_back(reading);
      }
      mean = sum / R;
    }
    data->configs.AddFrom(configs, i);
    data->mean_h.push_back(mean);
    data->repetitions.push_back(R);
  }
  return missed;
}

}  // namespace lrcal
