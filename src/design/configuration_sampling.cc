#include "lrcal/design/configuration_sampling.h"

#include <Eigen/SVD>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/measurement/simulation.h"

namespace lrcal {

std::string SamplingReport::ToString() const {
  std::ostringstream out;
  out << accepted << " of " << requested << " configurations accepted after " << attempts
      << " attempts";
  if (!rejected.empty()) {
    out << "; rejected:";
    for (const auto& [reason, n] : rejected) out << " " << reason << "=" << n;
  }
  return out.str();
}

namespace {

BeamMiss BeamOf(const ModelPoint& point, const ConfigurationSet& one, const RangerSpec& ranger) {
  const Pose<double> pose = ToolPose(point, one, 0);
  double nb;
  const double h = BeamReading(pose, point.plane, &nb);
  return ClassifyReading(h, nb, ranger);
}

}  // namespace

void SamplingOptions::Validate(const std::string& source) const {
  if (!(std::isfinite(min_jacobian_singular_value) && min_jacobian_singular_value >= 0))
    throw InputError(source, "min_jacobian_singular_value: expected a finite value >= 0");
  if (max_attempts_per_configuration < 1)
    throw InputError(source, "max_attempts_per_configuration: expected at least 1");
  ranger.Validate(source + " ranger");
}

ConfigurationSet SampleConfigurations(const RobotModel& robot, const Plane& plane, int count,
                                      const RandomStream& stream, const SamplingOptions& options,
                                      SamplingReport* report) {
  options.Validate();
  SamplingReport local;
  SamplingReport& rep = report ? *report : local;
  rep = SamplingReport{};
  rep.requested = count;
  const int N = robot.num_links();
  ModelPoint nominal, truth;
  PrepareModelPoint(robot, robot.nominal_values().data(), plane, &nominal);
  const bool check_truth = options.true_link_values.has_value();
  if (check_truth)
    PrepareModelPoint(robot, options.true_link_values->data(),
                      options.true_plane ? *options.true_plane : plane, &truth);
  ConfigurationSet out(N);
  out.Reserve(count);
  const long long budget =
      static_cast<long long>(options.max_attempts_per_configuration) * std::max(count, 1);
  std::vector<double> q(N);
  for (long long a = 0; out.size() < count; ++a) {
    if (a >= budget) {
      throw InputError("configuration sampling",
                       "could only accept " + std::to_string(out.size()) + " of " +
                           std::to_string(count) + " configurations in " + std::to_string(a) +
                           " attempts (" + rep.ToString() +
                           "); check the plane, the ranger's range and the joint limits");
    }
    ++rep.attempts;
    for (int j = 0; j < N; ++j) {
      const Link& link = robot.links()[j];
      q[j] = link.q_min + (link.q_max - link.q_min) * stream.Uniform(a * N + j);
    }
    ConfigurationSet one(N);
    one.Add(q);
    if (options.require_beam_hit) {
      BeamMiss miss = BeamOf(nominal, one, options.ranger);
      if (miss == BeamMiss::kNone && check_truth) miss = BeamOf(truth, one, options.ranger);
      if (miss != BeamMiss::kNone) {
        ++rep.rejected[BeamMissName(miss)];
        continue;
      }
    }
    if (options.min_jacobian_singular_value > 0) {
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(
          GeometricJacobian(robot, robot.nominal_values(), q.data()));
      if (svd.singularValues().minCoeff() < options.min_jacobian_singular_value) {
        ++rep.rejected["singular"];
        continue;
      }
    }
    out.Add(q);
  }
  rep.accepted = out.size();
  return out;
}

CandidatePool UsableCandidates(const RobotModel& robot, const Plane& plane,
                               const RangerSpec& ranger, const ConfigurationSet& pool) {
  CandidatePool out;
  out.configs = ConfigurationSet(pool.num_joints());
  std::vector<double> h;
  ExactReadings(robot, robot.nominal_values(), plane, ranger, pool, &h, &out.misses);
  out.report.requested = out.report.attempts = pool.size();
  for (int i = 0; i < pool.size(); ++i) {
    if (out.misses[i] != BeamMiss::kNone) {
      ++out.report.rejected[BeamMissName(out.misses[i])];
      continue;
    }
    out.configs.AddFrom(pool, i);
    out.kept.push_back(i);
  }
  out.report.accepted = out.configs.size();
  return out;
}

}  // namespace lrcal
