#include "lrcal/measurement/simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "lrcal/core/error.h"

namespace lrcal {

void ExactReadings(const RobotModel& robot, const Eigen::VectorXd& link_values,
                   const PlaneSet& planes, const RangerSpec& ranger,
                   const TargetedConfigurations& configs, std::vector<double>* h,
                   std::vector<BeamMiss>* misses) {
  CheckPlanesReferenced(configs, planes);
  ModelPoint point;
  PrepareModelPoint(robot, link_values.data(), planes, &point);
  h->resize(configs.size());
  if (misses) misses->resize(configs.size());
  for (int i = 0; i < configs.size(); ++i) {
    const Pose<double> pose = ToolPose(point, configs, i);
    double nb;
    (*h)[i] = BeamReading(pose, planes[configs.target(i)], &nb);
    if (misses) (*misses)[i] = ClassifyReading((*h)[i], nb, ranger);
  }
}

void CheckPlanesReferenced(const TargetedConfigurations& configs, const PlaneSet& planes) {
  if (configs.num_targets_referenced() > planes.size())
    throw InputError("planes", "a configuration is aimed at plane " +
                                   std::to_string(configs.num_targets_referenced()) +
                                   " but the set-up has " + std::to_string(planes.size()) +
                                   " plane(s)");
}

namespace {

// The exact readings under encoder noise and form error: per configuration (draw_mean, at the
// mean joint error) or per reading. Misses are those of the recorded configuration.
void DisturbedReadings(const RobotModel& robot, const Eigen::VectorXd& link_values,
                       const PlaneSet& planes, const TargetedConfigurations& configs,
                       const NoiseModel& noise, const RandomStream& stream,
                       const std::vector<int>* noise_slots, std::vector<double>* out) {
  const int R = noise.repetitions, per = noise.DrawsMean() ? 1 : R, nj = configs.num_joints();
  const RandomStream encoder = stream.WithPurpose(RandomPurpose::kEncoder);
  const RandomStream form = stream.WithPurpose(RandomPurpose::kPlaneForm);
  const double sigma_q = noise.DrawsMean() ? noise.encoder_sigma / std::sqrt(static_cast<double>(R))
                                           : noise.encoder_sigma;
  TargetedConfigurations disturbed(nj);
  disturbed.Reserve(configs.size() * per);
  std::vector<double> q(nj);
  for (int i = 0; i < configs.size(); ++i) {
    const std::uint64_t slot = noise_slots ? (*noise_slots)[i] : i;
    for (int r = 0; r < per; ++r) {
      for (int j = 0; j < nj; ++j)
        q[j] = configs.q(i)[j] +
               (sigma_q > 0 ? sigma_q * encoder.Normal((slot * R + r) * nj + j) : 0.0);
      disturbed.Add(q.data(), configs.target(i));
    }
  }
  ModelPoint point;
  PrepareModelPoint(robot, link_values.data(), planes, &point);
  out->resize(disturbed.size());
  for (int k = 0; k < disturbed.size(); ++k) {
    const std::uint64_t slot = noise_slots ? (*noise_slots)[k / per] : k / per;
    Plane local = planes[disturbed.target(k)];
    if (noise.form_sigma > 0) local.offset += noise.form_sigma * form.Normal(slot);
    double nb;
    (*out)[k] = BeamReading(ToolPose(point, disturbed, k), local, &nb);
  }
}

// The gross errors' contribution to reading r of slot (raw), or to the mean of R (draw_mean).
// Reading k owns the block of four words at draws 4k..4k+3: word 0 decides whether it is an
// outlier, words 2 and 3 give its gross error (Box-Muller). The decision and the error never
// share a word: a shared word would tie the error's sign to the decision (every gross error
// positive when the decision's word also sets the Box-Muller angle).
double OutlierError(const NoiseModel& noise, const RandomStream& outliers, std::uint64_t slot,
                    int r) {
  const int R = noise.repetitions;
  if (!noise.DrawsMean()) {
    const std::uint64_t k = slot * R + r;
    return outliers.Uniform(4 * k) <= noise.outlier_fraction
               ? noise.outlier_sigma * outliers.Normal(4 * k + 2)
               : 0.0;
  }
  int count = 0;
  for (int rr = 0; rr < R; ++rr)
    count += outliers.Uniform(4 * (slot * R + rr)) <= noise.outlier_fraction;
  return count ? std::sqrt(static_cast<double>(count)) * noise.outlier_sigma *
                     outliers.Normal(4 * slot * R + 2) / R
               : 0.0;
}

// The value (noise.average: mean, median, trimmed mean) of R single readings of a configuration
// (each appended to `raw`): the exact reading (per reading when `per_reading`, else `exact`)
// through the ranger, noise, outliers.
double MeanOfReadings(const NoiseModel& noise, const RandomStream& stream,
                      const RandomStream& outliers, std::uint64_t slot, const double* per_reading,
                      double exact, std::vector<double>* z, std::vector<double>* raw) {
  const int R = noise.repetitions;
  stream.Normals(slot * R, R, z->data());
  for (int r = 0; r < R; ++r) {
    double reading = (1 + noise.ranger_scale) * (per_reading ? per_reading[r] : exact) +
                     noise.ranger_offset + noise.sigma * (*z)[r];
    if (noise.outlier_fraction > 0) reading += OutlierError(noise, outliers, slot, r);
    (*z)[r] = reading;
    if (raw) raw->push_back(reading);
  }
  return noise.average.Combine(z->data(), R);
}

}  // namespace

int SimulateReadings(const RobotModel& robot, const Eigen::VectorXd& true_link_values,
                     const PlaneSet& true_planes, const RangerSpec& ranger,
                     const TargetedConfigurations& configs, const NoiseModel& noise,
                     const RandomStream& stream, MeasurementSet* data,
                     std::vector<BeamMiss>* misses, std::vector<double>* raw,
                     const std::vector<int>* noise_slots) {
  noise.Validate();
  std::vector<double> h;
  std::vector<BeamMiss> local;
  std::vector<BeamMiss>* m = misses ? misses : &local;
  ExactReadings(robot, true_link_values, true_planes, ranger, configs, &h, m);
  if (!noise.DisturbsGeometry())
    return AddNoise(h, *m, configs, noise, stream, data, raw, noise_slots);
  std::vector<double> disturbed;
  DisturbedReadings(robot, true_link_values, true_planes, configs, noise, stream, noise_slots,
                    &disturbed);
  if (noise.DrawsMean())
    return AddNoise(disturbed, *m, configs, noise, stream, data, raw, noise_slots);
  return AddNoise(h, *m, configs, noise, stream, data, raw, noise_slots, &disturbed);
}

int AddNoise(const std::vector<double>& h, const std::vector<BeamMiss>& misses,
             const TargetedConfigurations& configs, const NoiseModel& noise,
             const RandomStream& stream, MeasurementSet* data, std::vector<double>* raw,
             const std::vector<int>* noise_slots, const std::vector<double>* per_reading) {
  // Reuse the buffers of `data` (the Monte-Carlo workspace calls this once per trial); when no
  // beam misses, the configurations are copied whole.
  const bool every_beam_hits = std::all_of(misses.begin(), misses.begin() + configs.size(),
                                           [](BeamMiss miss) { return miss == BeamMiss::kNone; });
  if (every_beam_hits) {
    data->configs = configs;
  } else {
    if (data->configs.num_joints() != configs.num_joints())
      data->configs = TargetedConfigurations(configs.num_joints());
    data->configs.Clear();
    data->configs.Reserve(configs.size());
  }
  data->mean_h.clear();
  data->repetitions.clear();
  data->variance_factor.clear();
  const double factor =
      noise.average.IsMean() ? 1 : noise.average.VarianceFactor(noise.repetitions);
  const int R = noise.repetitions;
  const double sigma_mean = noise.sigma / std::sqrt(static_cast<double>(R));
  std::vector<double> z(noise.DrawsMean() ? 1 : R);
  if (raw) raw->clear();
  const bool outliers = noise.outlier_fraction > 0;
  const RandomStream outlier_stream = stream.WithPurpose(RandomPurpose::kOutlier);
  NormalDraws normal(stream);  // neighbouring slots share their counter block and pair
  int missed = 0;
  for (int i = 0; i < configs.size(); ++i) {
    const std::uint64_t slot = noise_slots ? (*noise_slots)[i] : i;
    if (misses[i] != BeamMiss::kNone) {
      ++missed;
      continue;
    }
    double mean;
    if (noise.DrawsMean()) {
      mean = (1 + noise.ranger_scale) * h[i] + noise.ranger_offset + sigma_mean * normal(slot);
      if (outliers) mean += OutlierError(noise, outlier_stream, slot, 0);
    } else {
      mean = MeanOfReadings(noise, stream, outlier_stream, slot,
                            per_reading ? &(*per_reading)[i * R] : nullptr, h[i], &z, raw);
    }
    if (!every_beam_hits) data->configs.AddFrom(configs, i);
    data->mean_h.push_back(mean);
    data->repetitions.push_back(R);
    if (!noise.average.IsMean()) data->variance_factor.push_back(factor);
  }
  return missed;
}

}  // namespace lrcal
