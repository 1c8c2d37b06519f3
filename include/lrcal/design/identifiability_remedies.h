// What would make a rank-deficient set-up identifiable, and the cheapest way there.
//
// An identifiability analysis (lrcal/identification/identifiability.h) names the directions in
// parameter space that no reading sees: a parameter with no effect, or a dependence such as
// θ1 + plane2_u1 − plane3_u1 (a common spin of the planes about z0). For each such *lost
// direction* this analysis tries the remedies a user has, in order of what they cost on the rig:
//   1. fix a parameter (no new hardware; the parameter keeps its nominal value, so its true error
//      is not corrected: right when it only sets the frame, as θ1 and d1 do against estimated
//      planes, or when it is known from elsewhere);
//   2. know a plane's offset (one measurement of the fixture: planeK_f leaves the set);
//   3. add a plane of a given orientation (a fixture and more poses; its terms estimated like
//      those of the planes already there);
//   4. add a known distance (readings against a reference surface whose position in the base
//      frame is known, e.g. measured by a CMM: a plane whose terms are not estimated).
// A remedy *recovers* a lost direction v when, after it, no direction the readings cannot see
// projects onto v (the new null space, restricted to the old parameters, no longer contains v).
// Every test is exact linear algebra on the identification Jacobian at the nominal model: no
// remedy is assumed to work because it usually does.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/identification/identifiability.h"
#include "lrcal/measurement/plane.h"

namespace lrcal {

struct Remedy {
  enum class Kind { kFixParameter, kKnowPlaneOffset, kAddPlane, kAddKnownDistance };
  Kind kind = Kind::kFixParameter;
  /// What to do, in words ("fix theta1", "add a plane facing x0 (normal (1, 0, 0))").
  std::string action;
  /// The parameter fixed (kFixParameter, kKnowPlaneOffset), else "".
  std::string parameter;
  /// The plane tried (kAddPlane, kAddKnownDistance): unit normal and offset in the base frame.
  Plane plane;
  /// Indices (into RemedyReport::lost) of the lost directions this remedy recovers.
  std::vector<int> recovers;
};

/// The JSON/CLI name of a remedy kind: "fix_parameter", "know_plane_offset", "add_plane",
/// "add_known_distance".
const char* RemedyKindName(Remedy::Kind kind);

struct RemedyReport {
  /// Each lost direction in words: a dependence ("theta1 + 1*plane2_u1 - 1*plane3_u1") or
  /// "a1 (no effect on any reading)".
  std::vector<std::string> lost;
  /// Every remedy tried, cheapest kind first (within a kind, in the order found).
  std::vector<Remedy> remedies;
  /// For each lost direction, the index in `remedies` of the cheapest one that recovers it, or
  /// -1 when none of those tried does.
  std::vector<int> cheapest;
  /// Orientations for which no reachable plane was found (a sampling budget ran out), in words.
  std::vector<std::string> unreachable;
  std::string ToString() const;
};

struct RemedyOptions {
  /// Configurations drawn on each added plane (at least the number of parameters is used).
  int configurations_per_added_plane = 40;
  /// Seed of the draws on added planes (the analysis is deterministic for a seed).
  std::uint64_t seed = 1;
  /// The ranger whose limits the added planes' readings must meet.
  RangerSpec ranger;
  IdentifiabilityOptions identifiability;
};

/// The remedies for the lost directions in `report` (the analysis of `model` at `configs`).
/// Empty when the set is full rank.
RemedyReport FindRemedies(const MeasurementModel& model, const TargetedConfigurations& configs,
                          const IdentifiabilityReport& report, const RemedyOptions& options = {});

}  // namespace lrcal
