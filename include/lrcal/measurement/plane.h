// The measured plane and the laser ranger's reading.
//
// The plane is n·p + f = 0 in the base frame B, n a unit normal. The ranger's beam starts at the
// tool origin p_BT and points along the tool's +Z axis b = R_BT·[0 0 1]ᵀ. It meets the plane at
// p_BJ = p_BT + h·b with (slide 'Identification Equation')
//     h = -(n·p_BT + f) / (n·b).
// A reading exists only if the beam actually hits the plane in front of the ranger within its
// range; otherwise the configuration is reported with a BeamMiss reason, never as a NaN.
//
// Estimating the plane: the unit normal is charted around its nominal value n0 by the gnomonic
// chart n(u) = (n0 + u1·t1 + u2·t2) / |n0 + u1·t1 + u2·t2|, with t1, t2 an orthonormal basis of the
// tangent plane at n0. The chart is regular at u = 0 for every n0 (unlike the paper's
// n_x = sqrt(1 - n_y² - n_z²), which is singular at the paper's own plane, n_x = 0), and covers
// every normal within 90° of n0. u is dimensionless (u ≈ tilt angle in rad for small tilts).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "lrcal/core/enum_names.h"
#include "lrcal/core/settings.h"
#include "lrcal/kinematics/forward_kinematics.h"

namespace lrcal {

struct Plane {
  Eigen::Vector3d normal{0, 0, 1};  ///< unit normal n in the base frame
  double offset = 0;                ///< f (m): the plane is n·p + f = 0

  /// Normalises (nx, ny, nz, f) by |n|. Throws InputError (where = `source`) for a zero or
  /// non-finite normal.
  static Plane FromCoefficients(double nx, double ny, double nz, double f,
                                const std::string& source = "plane");
  /// Parses "nx,ny,nz,f" (the --plane option).
  static Plane Parse(const std::string& text, const std::string& source = "--plane");
  /// Signed distance n·p + f (m) of a point from the plane.
  double SignedDistance(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
};

/// Most planes one set-up may have (a cube's faces and two more). Bounded so that a prepared
/// model point (measurement_model.h) stays a fixed-size, allocation-free value.
inline constexpr int kMaxPlanes = 8;

/// The planes of a set-up: the paper's one, or several (Zhuang, Motaghedi and Roth 1999: one plane
/// leaves directions unobservable; three are equivalent to point measurement). A configuration
/// set tags each configuration with the index of its plane (targeted_configurations.h). Implicitly
/// built from one Plane, so single-plane code reads as before.
class PlaneSet {
 public:
  PlaneSet() = default;
  PlaneSet(const Plane& plane)
      : planes_{plane}, names_{""} {}  // NOLINT(google-explicit-constructor)
  /// Throws InputError (where = `source`) for no plane, more than kMaxPlanes or a repeated name;
  /// `names` may be empty (no names) or one per plane ("" for an unnamed one).
  PlaneSet(std::vector<Plane> planes, std::vector<std::string> names,
           const std::string& source = "planes");
  int size() const { return static_cast<int>(planes_.size()); }
  const Plane& operator[](int p) const { return planes_[p]; }
  Plane& operator[](int p) { return planes_[p]; }
  std::vector<Plane>::const_iterator begin() const { return planes_.begin(); }
  std::vector<Plane>::const_iterator end() const { return planes_.end(); }
  /// The name of plane p, or "" if it has none.
  const std::string& name(int p) const { return names_[p]; }
  /// How users refer to plane p: its name, else its 1-based number ("plane 2").
  std::string Label(int p) const;
  /// The index of a plane given as a 1-based number or a name, or -1.
  int Find(const std::string& ref) const;

 private:
  std::vector<Plane> planes_;
  std::vector<std::string> names_;
};

/// Orthonormal tangent basis (t1, t2) at unit vector n0, deterministic: t1 is the coordinate axis
/// least aligned with n0 projected on the tangent plane, t2 = n0 × t1. For the paper's plane
/// (n_x = 0) t1 is the base x axis.
void TangentBasis(const Eigen::Vector3d& n0, Eigen::Vector3d* t1, Eigen::Vector3d* t2);

/// The gnomonic chart of the unit normal around n0 (see the file comment).
struct NormalChart {
  Eigen::Vector3d n0, t1, t2;
  explicit NormalChart(const Eigen::Vector3d& nominal_normal);
  template <typename T>
  Eigen::Matrix<T, 3, 1> Normal(const T& u1, const T& u2) const {
    Eigen::Matrix<T, 3, 1> v = n0.cast<T>() + u1 * t1.cast<T>() + u2 * t2.cast<T>();
    return v / v.norm();  // |v| ≥ 1: never singular
  }
  /// n(u) and ∂n/∂u (3×2).
  void NormalAndJacobian(double u1, double u2, Eigen::Vector3d* n,
                         Eigen::Matrix<double, 3, 2>* dn_du) const;
};

/// Why a configuration gives no reading.
enum class BeamMiss {
  kNone = 0,    ///< the beam hits the plane: h is a valid reading
  kParallel,    ///< n·b is (numerically) zero: the beam runs along the plane
  kBehind,      ///< h ≤ 0: the plane is behind the ranger
  kOutOfRange,  ///< h outside [min_range, max_range]
  kGrazing,     ///< incidence angle above the ranger's limit
};
inline constexpr EnumName<BeamMiss> kBeamMissNames[] = {
    {BeamMiss::kNone, "ok"},
    {BeamMiss::kParallel, "beam_parallel_to_plane"},
    {BeamMiss::kBehind, "plane_behind_ranger"},
    {BeamMiss::kOutOfRange, "out_of_range"},
    {BeamMiss::kGrazing, "grazing_incidence"}};
inline const char* BeamMissName(BeamMiss miss) { return NameOf(kBeamMissNames, miss); }

/// The laser ranger's usable readings.
struct RangerSpec {
  double min_range = 0.05;        ///< m; shorter readings are rejected
  double max_range = 3.0;         ///< m; longer readings are out of range
  double max_incidence = 1.2217;  ///< rad (70°); angle between the beam and the plane normal
  /// The settings (settings.h), as a robot file's `ranger:` section spells them: min_range (≥ 0
  /// m), max_range (> 0 m, finite) and max_incidence_deg (in (0, 90] degrees).
  static const std::vector<SettingField<RangerSpec>>& Settings();
  /// Throws SettingError naming the library field (ranger.min_range, ...) unless each is in its
  /// range and min_range < max_range.
  void Validate() const;
};

/// Numerically parallel beam: |n·b| at or below this, the beam runs along the plane and h is not
/// a reading. The one threshold used by the model, the batch kernel and the solver.
inline constexpr double kParallelBeamThreshold = 1e-12;

/// Classifies a reading against the ranger (BeamMiss::kNone if usable).
BeamMiss ClassifyReading(double h, double n_dot_b, const RangerSpec& ranger);

/// The laser reading h = -(n·p + f)/(n·b) of a beam starting at p with unit direction b, for the
/// plane n·x + f = 0 (no miss checks: callers classify). Templated for autodiff; every reading
/// lrcal computes goes through this one formula.
template <typename T>
T LaserDistance(const Eigen::Matrix<T, 3, 1>& p, const Eigen::Matrix<T, 3, 1>& b,
                const Eigen::Matrix<T, 3, 1>& n, const T& f) {
  return -(n.dot(p) + f) / n.dot(b);
}

/// The reading of the beam of tool pose `pose` (origin p_BT, direction the tool's +Z) on
/// `plane`; `*n_dot_b` gets n·b for ClassifyReading.
inline double BeamReading(const Pose<double>& pose, const Plane& plane, double* n_dot_b) {
  const Eigen::Vector3d b = pose.R_BT.col(2);
  *n_dot_b = plane.normal.dot(b);
  return LaserDistance<double>(pose.p_BT, b, plane.normal, plane.offset);
}

}  // namespace lrcal
