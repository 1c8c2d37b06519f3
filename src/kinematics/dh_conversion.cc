#include "lrcal/kinematics/dh_conversion.h"

#include <Eigen/SVD>
#include <cmath>
#include <initializer_list>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/forward_kinematics.h"

namespace lrcal {

namespace {

// The angle (rad) that turns unit vector `from` into `to` about `axis` (both ⊥ axis).
double AngleAbout(const Eigen::Vector3d& axis, const Eigen::Vector3d& from,
                  const Eigen::Vector3d& to) {
  return std::atan2(from.cross(to).dot(axis), from.dot(to));
}

// `v` without its component along unit `axis`, normalised; zero if too short.
Eigen::Vector3d Across(const Eigen::Vector3d& axis, const Eigen::Vector3d& v) {
  const Eigen::Vector3d w = v - v.dot(axis) * axis;
  return w.norm() > 1e-9 ? Eigen::Vector3d(w.normalized()) : Eigen::Vector3d::Zero();
}

// A unit x axis ⊥ `z`: the first of `candidates` not along z.
Eigen::Vector3d XAxis(const Eigen::Vector3d& z, std::initializer_list<Eigen::Vector3d> candidates) {
  for (const Eigen::Vector3d& c : candidates)
    if (const Eigen::Vector3d x = Across(z, c); x.squaredNorm() > 0) return x;
  return Across(z, z.unitOrthogonal());
}

// Frame 0: z on joint 1's axis, origin its point nearest the base origin, x the base x across z.
RigidTransform FirstFrame(const JointAxis& first) {
  const Eigen::Vector3d z = first.direction;
  const Eigen::Vector3d x = XAxis(z, {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()});
  RigidTransform f;
  f.rotation << x, z.cross(x), z;
  f.translation = first.point - first.point.dot(z) * z;
  return f;
}

// Link values from frame `f` (its z on this joint's axis) to a frame whose z is on `next`.
// Sets is_parameter: θ, α, a and d (D-H) or β (Hayati, nearly parallel axes).
void LinkToNextAxis(const RigidTransform& f, const JointAxis& next, double parallel_tolerance,
                    Link* link) {
  const Eigen::Vector3d o = f.translation, x0 = f.rotation.col(0), z = f.rotation.col(2);
  const Eigen::Vector3d u = next.direction;
  auto& v = link->nominal;
  const Eigen::Vector3d n = z.cross(u);
  if (n.norm() > std::sin(parallel_tolerance)) {
    // The common normal: P on this axis, Q on the next, PQ ⊥ both.
    const Eigen::Vector3d w = o - next.point;
    const double b = z.dot(u), dz = z.dot(w), du = u.dot(w), denom = 1 - b * b;
    const double t_here = (b * du - dz) / denom, t_next = (du - b * dz) / denom;
    const Eigen::Vector3d pq = next.point + t_next * u - (o + t_here * z);
    Eigen::Vector3d x = n.normalized();
    if (pq.dot(x) < 0) x = -x;
    v[kTheta] = AngleAbout(z, x0, x);
    v[kD] = t_here;
    v[kA] = pq.dot(x);
    v[kAlpha] = AngleAbout(x, z, u);
    v[kBeta] = 0;
    link->is_parameter = {true, true, true, true, false};
    return;
  }
  // Hayati: d = 0; x towards where the next axis crosses the plane ⊥ z through o.
  const double t = (o - next.point).dot(z) / u.dot(z);
  const Eigen::Vector3d across = next.point + t * u - o;
  const Eigen::Vector3d x = across.norm() > 1e-12 ? Eigen::Vector3d(across.normalized()) : x0;
  v[kTheta] = AngleAbout(z, x0, x);
  v[kD] = 0;
  v[kA] = across.dot(x);
  // Rx(α)·Ry(β) turns z into u: u in the frame (x, z × x, z) is (sin β, −sin α cos β, cos α cos β).
  const Eigen::Vector3d y = z.cross(x);
  const double u0 = u.dot(x), u1 = u.dot(y), u2 = u.dot(z);
  v[kAlpha] = std::atan2(-u1, u2);
  v[kBeta] = std::atan2(u0, std::hypot(u1, u2));
  link->is_parameter = {true, true, true, false, true};
}

// The last link: origin at the tool origin (d along the axis, a across it), α = β = 0.
void LinkToTool(const RigidTransform& f, const RigidTransform& tool, Link* link) {
  const Eigen::Vector3d o = f.translation, x0 = f.rotation.col(0), z = f.rotation.col(2);
  const Eigen::Vector3d r = tool.translation - o;
  const double d = r.dot(z);
  const Eigen::Vector3d across = r - d * z;
  const Eigen::Vector3d x = across.norm() > 1e-12
                                ? Eigen::Vector3d(across.normalized())
                                : XAxis(z, {tool.rotation.col(0), tool.rotation.col(1), x0});
  auto& v = link->nominal;
  v[kTheta] = AngleAbout(z, x0, x);
  v[kD] = d;
  v[kA] = across.dot(x);
  v[kAlpha] = 0;
  v[kBeta] = 0;
  link->is_parameter = {true, true, true, true, false};
}

}  // namespace

RobotModel RobotFromJointAxes(const std::string& name, const std::vector<JointAxis>& axes,
                              const RigidTransform& tool_at_zero, const std::string& source,
                              double parallel_tolerance) {
  if (axes.empty()) throw InputError(source, "the chain has no movable joint");
  if (axes.size() > static_cast<std::size_t>(kMaxLinks))
    throw InputError(source, "the chain has " + std::to_string(axes.size()) +
                                 " movable joints; at most " + std::to_string(kMaxLinks) +
                                 " are supported");
  std::vector<JointAxis> unit = axes;
  for (std::size_t i = 0; i < unit.size(); ++i) {
    const double norm = unit[i].direction.norm();
    if (!(norm > 1e-12) || !unit[i].point.allFinite())
      throw InputError(source, "joint " + std::to_string(i + 1) + ": the axis has no direction");
    unit[i].direction /= norm;
  }
  const RigidTransform base = FirstFrame(unit[0]);
  RigidTransform frame = base;  // frame i-1 in B
  std::vector<Link> links(unit.size());
  for (std::size_t i = 0; i < unit.size(); ++i) {
    links[i].joint = unit[i].joint;
    links[i].q_min = unit[i].q_min;
    links[i].q_max = unit[i].q_max;
    links[i].joint_name = unit[i].name;
    if (i + 1 < unit.size())
      LinkToNextAxis(frame, unit[i + 1], parallel_tolerance, &links[i]);
    else
      LinkToTool(frame, tool_at_zero, &links[i]);
    frame = frame * LinkRigidTransform(links[i].nominal.data());
  }
  RigidTransform tool = frame.Inverse() * tool_at_zero;
  // Re-orthonormalise the rounding of the products (a rotation within ~1e-16).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(tool.rotation,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  tool.rotation = svd.matrixU() * svd.matrixV().transpose();
  return RobotModel(name, std::move(links), source, base, tool);
}

}  // namespace lrcal
