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

BeamMiss BeamOf(const ModelPoint& point, const TargetedConfigurations& one,
                const RangerSpec& ranger) {
  const Pose<double> pose = ToolPose(point, one, 0);
  double nb;
  const double h = BeamReading(pose, point.planes[one.target(0)], &nb);
  return ClassifyReading(h, nb, ranger);
}

// The error when the attempt budget for plane p ran out with `accepted` of `wanted` drawn.
InputError SamplingExhausted(const PlaneSet& planes, int p, int accepted, int wanted,
                             long long attempts, const SamplingReport& rep) {
  return InputError("configuration sampling",
                    "could only accept " + std::to_string(accepted) + " of " +
                        std::to_string(wanted) + " configurations" +
                        (planes.size() > 1 ? " on " + planes.Label(p) : std::string()) + " in " +
                        std::to_string(attempts) + " attempts (" + rep.ToString() +
                        "); check the plane, the ranger's range and the joint limits");
}

// Why a drawn configuration (one row, tagged with its plane) is rejected: "" when it is usable.
// `truth` is null when the true rig is not checked.
std::string RejectionOf(const RobotModel& robot, const ModelPoint& nominal, const ModelPoint* truth,
                        const TargetedConfigurations& one, const SamplingOptions& options) {
  if (options.require_beam_hit) {
    BeamMiss miss = BeamOf(nominal, one, options.ranger);
    if (miss == BeamMiss::kNone && truth) miss = BeamOf(*truth, one, options.ranger);
    if (miss != BeamMiss::kNone) return BeamMissName(miss);
  }
  if (!IsWellConditioned(robot, one.q(0), options.min_jacobian_singular_value)) return "singular";
  return "";
}

}  // namespace

bool IsWellConditioned(const RobotModel& robot, const double* q, double min_singular_value) {
  if (!(min_singular_value > 0)) return true;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(GeometricJacobian(robot, robot.nominal_values(), q));
  return !(svd.singularValues().minCoeff() < min_singular_value);
}

TargetedConfigurations SampleConfigurations(const RobotModel& robot, const Plane& plane, int count,
                                            const RandomStream& stream,
                                            const SamplingOptions& options,
                                            SamplingReport* report) {
  return SampleConfigurations(robot, PlaneSet(plane), std::vector<int>{count}, stream, options,
                              report);
}

TargetedConfigurations SampleConfigurations(const RobotModel& robot, const PlaneSet& planes,
                                            const std::vector<int>& counts,
                                            const RandomStream& stream,
                                            const SamplingOptions& options,
                                            SamplingReport* report) {
  options.Validate();
  if (static_cast<int>(counts.size()) != planes.size())
    throw InputError("configuration sampling", "expected one count per plane");
  SamplingReport local;
  SamplingReport& rep = report ? *report : local;
  rep = SamplingReport{};
  for (int c : counts) rep.requested += c;
  const int N = robot.num_links();
  ModelPoint nominal, truth;
  PrepareModelPoint(robot, robot.nominal_values().data(), planes, &nominal);
  const bool check_truth = options.true_link_values.has_value();
  if (check_truth) {
    const PlaneSet& true_planes = options.true_planes ? *options.true_planes : planes;
    if (true_planes.size() != planes.size())
      throw InputError("configuration sampling", "expected one true plane per plane");
    PrepareModelPoint(robot, options.true_link_values->data(), true_planes, &truth);
  }
  TargetedConfigurations out(N);
  out.Reserve(rep.requested);
  std::vector<double> q(N);
  long long a = 0;  // attempts so far, over all planes: draw a·N + j is joint j of attempt a
  for (int p = 0; p < planes.size(); ++p) {
    const int target = out.size() + counts[p];
    const long long budget =
        a + static_cast<long long>(options.max_attempts_per_configuration) * std::max(counts[p], 1);
    for (; out.size() < target; ++a) {
      if (a >= budget) {
        throw SamplingExhausted(planes, p, out.size() - (target - counts[p]), counts[p], a, rep);
      }
      ++rep.attempts;
      for (int j = 0; j < N; ++j) {
        const Link& link = robot.links()[j];
        q[j] = link.q_min + (link.q_max - link.q_min) * stream.Uniform(a * N + j);
      }
      TargetedConfigurations one(N);
      one.Add(q, p);
      const std::string rejection =
          RejectionOf(robot, nominal, check_truth ? &truth : nullptr, one, options);
      if (!rejection.empty()) {
        ++rep.rejected[rejection];
        continue;
      }
      out.Add(q, p);
    }
  }
  rep.accepted = out.size();
  return out;
}

CandidatePool UsableCandidates(const RobotModel& robot, const PlaneSet& planes,
                               const RangerSpec& ranger, const TargetedConfigurations& pool) {
  CandidatePool out;
  out.configs = TargetedConfigurations(pool.num_joints());
  std::vector<double> h;
  ExactReadings(robot, robot.nominal_values(), planes, ranger, pool, &h, &out.misses);
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

const SettingSpec& WorkspacePosesSetting() {
  static const SettingSpec spec{"workspace",
                                "count",
                                "workspace",
                                "",
                                1,
                                "",
                                1,
                                1e5,
                                false,
                                true,
                                "poses",
                                "",
                                "poses drawn over the joint ranges"};
  return spec;
}

ConfigurationSet WorkspacePoses(const RobotModel& robot, int count, std::uint64_t seed) {
  WorkspacePosesSetting().Check(count);
  SamplingOptions o;
  o.require_beam_hit = false;
  return SampleConfigurations(robot, Plane{}, count,
                              RandomStream(seed, 0, 0, RandomPurpose::kValidation), o);
}

}  // namespace lrcal
