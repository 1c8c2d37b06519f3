#include "lrcal/measurement/plane.h"

#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/measurement/parameter_set.h"

namespace lrcal {

Plane Plane::FromCoefficients(double nx, double ny, double nz, double f,
                              const std::string& source) {
  Eigen::Vector3d n(nx, ny, nz);
  if (!n.allFinite() || !std::isfinite(f))
    throw InputError(source, "plane coefficients must be finite numbers");
  // Components so large that |n|² overflows (or so small that it underflows) are scaled first;
  // ordinary normals are normalised as they are (the same bits as ever).
  const double largest = n.cwiseAbs().maxCoeff();
  if (largest > 1e150 || (largest > 0 && largest < 1e-150)) {
    n /= largest;
    f /= largest;
  }
  const double norm = n.norm();
  if (!(norm >= 1e-12))
    throw InputError(source, "plane normal (nx, ny, nz) is zero; expected a non-zero vector");
  Plane p;
  p.normal = n / norm;
  p.offset = f / norm;
  if (!std::isfinite(p.offset))
    throw InputError(source, "plane offset f is too large for its normal (|f|/|n| overflows)");
  return p;
}

Plane Plane::Parse(const std::string& text, const std::string& source) {
  std::vector<std::string> parts = SplitList(text);
  if (parts.size() != 4)
    throw InputError(source, "expected four numbers nx,ny,nz,f; got '" + text + "'");
  double v[4];
  for (int i = 0; i < 4; ++i) {
    if (!ParseDecimal(parts[i], &v[i]))
      throw InputError(source, "'" + parts[i] + "' is not a number (expected nx,ny,nz,f)");
  }
  return FromCoefficients(v[0], v[1], v[2], v[3], source);
}

PlaneSet::PlaneSet(std::vector<Plane> planes, std::vector<std::string> names,
                   const std::string& source)
    : planes_(std::move(planes)), names_(std::move(names)) {
  if (planes_.empty()) throw InputError(source, "expected at least one plane");
  if (size() > kMaxPlanes)
    throw InputError(source, "expected at most " + std::to_string(kMaxPlanes) + " planes, got " +
                                 std::to_string(size()));
  if (names_.empty()) names_.assign(planes_.size(), "");
  if (names_.size() != planes_.size()) throw InputError(source, "expected one name per plane");
  for (int p = 0; p < size(); ++p) {
    if (names_[p].empty()) continue;
    bool digits = true;
    for (char c : names_[p]) digits = digits && c >= '0' && c <= '9';
    if (digits)
      throw InputError(source, "plane name '" + names_[p] +
                                   "' is a number; a name must not read as a plane's index");
    for (int k = 0; k < p; ++k)
      if (names_[k] == names_[p])
        throw InputError(source, "two planes are named '" + names_[p] + "'");
  }
}

std::string PlaneSet::Label(int p) const {
  return names_[p].empty() ? "plane " + std::to_string(p + 1) : names_[p];
}

int PlaneSet::Find(const std::string& ref) const {
  for (int p = 0; p < size(); ++p)
    if (!names_[p].empty() && names_[p] == ref) return p;
  int number = 0;
  for (char c : ref) {
    if (c < '0' || c > '9' || number > kMaxPlanes) return -1;
    number = 10 * number + (c - '0');
  }
  return !ref.empty() && number >= 1 && number <= size() ? number - 1 : -1;
}

void TangentBasis(const Eigen::Vector3d& n0, Eigen::Vector3d* t1, Eigen::Vector3d* t2) {
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::fabs(n0[k]) < std::fabs(n0[axis])) axis = k;
  Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
  *t1 = (e - e.dot(n0) * n0).normalized();
  *t2 = n0.cross(*t1);
}

NormalChart::NormalChart(const Eigen::Vector3d& nominal_normal) : n0(nominal_normal) {
  TangentBasis(n0, &t1, &t2);
}

void NormalChart::NormalAndJacobian(double u1, double u2, Eigen::Vector3d* n,
                                    Eigen::Matrix<double, 3, 2>* dn_du) const {
  Eigen::Vector3d v = n0 + u1 * t1 + u2 * t2;
  double norm = v.norm();
  *n = v / norm;
  Eigen::Matrix3d P = (Eigen::Matrix3d::Identity() - (*n) * n->transpose()) / norm;
  dn_du->col(0) = P * t1;
  dn_du->col(1) = P * t2;
}

const std::vector<SettingField<RangerSpec>>& RangerSpec::Settings() {
  using R = RangerSpec;
  static const std::vector<SettingField<R>> fields = {
      {{"ranger", "min_range", "min_range", "m", 1, "m", 0, 1e6, false, false, "", "",
        "shortest usable reading"},
       &R::min_range},
      {{"ranger", "max_range", "max_range", "m", 1, "m", 0, 1e6, true, false, "", "",
        "longest usable reading"},
       &R::max_range},
      {{"ranger", "max_incidence", "max_incidence_deg", "deg", M_PI / 180, "rad", 0, 90, true,
        false, "", "", "largest angle between the beam and the plane normal"},
       &R::max_incidence},
  };
  return fields;
}

void RangerSpec::Validate() const {
  CheckSettings(*this, Settings());
  if (!(min_range < max_range))
    throw SettingError(Settings()[1].spec, "expected a value above min_range (" +
                                               FormatExact(min_range) + " m), got " +
                                               FormatExact(max_range));
}

BeamMiss ClassifyReading(double h, double n_dot_b, const RangerSpec& ranger) {
  if (!(std::fabs(n_dot_b) > kParallelBeamThreshold) || !std::isfinite(h))
    return BeamMiss::kParallel;
  if (h <= 0) return BeamMiss::kBehind;
  if (h < ranger.min_range || h > ranger.max_range) return BeamMiss::kOutOfRange;
  if (std::fabs(n_dot_b) < std::cos(ranger.max_incidence)) return BeamMiss::kGrazing;
  return BeamMiss::kNone;
}

}  // namespace lrcal
