// Sampling measurement and validation configurations.
//
// A candidate configuration is drawn uniformly within the joint ranges (robot file q_min..q_max)
// and accepted only if, for the nominal model (and, when given, the true one too):
//  - the beam hits the plane within the ranger's range and incidence limit (laser_plane.h);
//  - the arm is not near a singularity: the smallest singular value of its 6×N geometric
//    Jacobian (m/rad rows and rad/rad rows together, as is usual for arms of ~1 m reach) is at
//    least `min_jacobian_singular_value`.
// Draw a·N + j of the stream is joint j of attempt a, so the result depends only on the stream.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/core/random.h"
#include "lrcal/core/settings.h"
#include "lrcal/measurement/measurement_model.h"

namespace lrcal {

struct SamplingOptions {
  /// Reject configurations whose geometric Jacobian's σ_min is below this (non-singular arm).
  double min_jacobian_singular_value = 0.05;
  /// Require the beam to hit the plane (h > 0, in range, incidence): off for validation sets,
  /// which judge the pose over the whole workspace and need no reading.
  bool require_beam_hit = true;
  /// Also require the *true* model's beam to hit (simulation), if given.
  std::optional<Eigen::VectorXd> true_link_values;
  std::optional<PlaneSet> true_planes;
  /// The ranger whose limits a reading must meet (the robot file's `ranger:` section).
  RangerSpec ranger;
  /// Give up after this many attempts per requested configuration.
  int max_attempts_per_configuration = 10000;
  /// The numeric settings (settings.h): min_singular_value (≥ 0; a study's
  /// pool.min_singular_value, --min-singular-value, min_singular_value=) and max_attempts (at
  /// least 1 per configuration; the library's only).
  static const std::vector<SettingField<SamplingOptions>>& Settings();
  /// Throws SettingError naming the library field (pool.min_jacobian_singular_value, ...) and the
  /// range, or the ranger's (RangerSpec::Validate).
  void Validate() const;
};

struct SamplingReport {
  int requested = 0;
  int accepted = 0;
  int attempts = 0;
  std::map<std::string, int> rejected;  ///< reason → count ("singular", BeamMiss names)
  std::string ToString() const;
};

/// True when the nominal arm's geometric Jacobian at joint values `q` has no singular value below
/// `min_singular_value` (always when it is 0 or less): the sampler's test, whose rejects it
/// reports as "singular".
bool IsWellConditioned(const RobotModel& robot, const double* q, double min_singular_value);

/// Draws `count` accepted configurations. Throws InputError if the constraints reject so many
/// that `count` cannot be reached within the attempt budget (a plane the beam can never hit).
TargetedConfigurations SampleConfigurations(const RobotModel& robot, const Plane& plane, int count,
                                            const RandomStream& stream,
                                            const SamplingOptions& options,
                                            SamplingReport* report = nullptr);

/// Several planes: counts[p] configurations aimed at plane p (tagged p, targeted_configurations.h),
/// plane 0's first. Attempts are numbered on across the planes, so plane 0's configurations are
/// those of the one-plane call with the same stream.
TargetedConfigurations SampleConfigurations(const RobotModel& robot, const PlaneSet& planes,
                                            const std::vector<int>& counts,
                                            const RandomStream& stream,
                                            const SamplingOptions& options,
                                            SamplingReport* report = nullptr);

/// The candidates of a given pool whose nominal beam hits its plane within `ranger`'s limits (the
/// others cannot give a reading): the usable configurations, the pool index of each (`kept`,
/// ascending), every candidate's BeamMiss (`misses`, kNone when kept) and a report by reason.
struct CandidatePool {
  TargetedConfigurations configs;
  std::vector<int> kept;
  std::vector<BeamMiss> misses;
  SamplingReport report;
};
CandidatePool UsableCandidates(const RobotModel& robot, const PlaneSet& planes,
                               const RangerSpec& ranger, const TargetedConfigurations& pool);

/// The number of workspace poses (`workspace.count`: --workspace, workspace=): 1 to 100,000.
const SettingSpec& WorkspacePosesSetting();

/// `count` poses drawn over the joint ranges (non-singular, no beam needed) from `seed`'s
/// validation stream: the poses of an accuracy map over the workspace and of criterion I when no
/// task poses are given. Throws SettingError for a count out of WorkspacePosesSetting()'s range.
ConfigurationSet WorkspacePoses(const RobotModel& robot, int count, std::uint64_t seed);

}  // namespace lrcal
