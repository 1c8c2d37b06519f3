#include "measurement/batch_evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/cpu_dispatch.h"
#include "measurement/batch_chain.h"

namespace lrcal {

using batch::kFrameArrays;
using batch::kO;
using batch::kOPrev;
using batch::kXCommon;
using batch::kYTwist;
using batch::kZPrev;

void BatchEvaluator::SetConfigurations(const TargetedConfigurations& configs) {
  m_ = configs.size();
  joints_ = configs.num_joints();
  joint_arrays_.Set(configs);
  plane_.clear();
  num_targets_referenced_ = configs.num_targets_referenced();
  if (num_targets_referenced_ > 1) {
    plane_.resize(m_);
    for (int i = 0; i < m_; ++i) plane_[i] = configs.target(i);
  }
  state_.resize(12 * static_cast<std::size_t>(m_));
  frames_.resize(static_cast<std::size_t>(kFrameArrays) * joints_ * m_);
  scratch_.resize(12 * static_cast<std::size_t>(m_));
}

namespace {

struct KernelArgs {
  int m;
  const ModelPoint* point;
  const ParameterSet* parameters;
  const double* q;
  const double* cq;
  const double* sq;
  const int* plane;  // per configuration; null when all are aimed at plane 0
  double* state;
  double* frames;
  double* scratch;
  double* h;
  double* J;
};

// The vectorised kernel: structure-of-arrays loops over all configurations, in force-inlined
// steps that the compiler inlines into one function per instruction set (cpu_dispatch.h); every
// variant gives the same bits (each configuration's arithmetic is the same sequence of
// operations, and -ffp-contract=off forbids fused multiply-adds). The chain's steps are
// batch_chain.h's.
using batch::FrameArrays;
using batch::FrameArraysOf;

// What the readings leave for the Jacobian (args.scratch, 9 arrays of m): −1/(n·b), the hit
// point, n·b, and (several planes) each configuration's plane normal and offset.
struct ReadingArrays {
  double* __restrict inv;
  double* __restrict ph0;
  double* __restrict ph1;
  double* __restrict ph2;
  double* __restrict nbs;
  double* __restrict pn0;
  double* __restrict pn1;
  double* __restrict pn2;
  double* __restrict pf;
};

[[gnu::always_inline]] inline ReadingArrays ReadingArraysOf(double* scratch, int m) {
  return {scratch,         scratch + m,     scratch + 2 * m, scratch + 3 * m, scratch + 4 * m,
          scratch + 5 * m, scratch + 6 * m, scratch + 7 * m, scratch + 8 * m};
}

// The plane normal n and offset f at configuration i: the one plane's (scalars), or
// configuration i's plane's (gathered into arrays).
template <bool kSeveralPlanes>
struct PlaneAt {
  const ReadingArrays& r;
  double s0, s1, s2, sf;
  [[gnu::always_inline]] double n0(int i) const { return kSeveralPlanes ? r.pn0[i] : s0; }
  [[gnu::always_inline]] double n1(int i) const { return kSeveralPlanes ? r.pn1[i] : s1; }
  [[gnu::always_inline]] double n2(int i) const { return kSeveralPlanes ? r.pn2[i] : s2; }
  [[gnu::always_inline]] double f(int i) const { return kSeveralPlanes ? r.pf[i] : sf; }
};

template <bool kSeveralPlanes>
[[gnu::always_inline]] inline PlaneAt<kSeveralPlanes> GatherPlanes(const KernelArgs& args,
                                                                   const ReadingArrays& r) {
  const ModelPoint& point = *args.point;
  const Plane& plane0 = point.planes[0];
  if constexpr (kSeveralPlanes) {
    for (int i = 0; i < args.m; ++i) {
      const Plane& p = point.planes[args.plane[i]];
      r.pn0[i] = p.normal.x();
      r.pn1[i] = p.normal.y();
      r.pn2[i] = p.normal.z();
      r.pf[i] = p.offset;
    }
  }
  return {r, plane0.normal.x(), plane0.normal.y(), plane0.normal.z(), plane0.offset};
}

// Readings h = −(n·p + f)/(n·b); keeps −1/(n·b) and the hit point for the Jacobian. Returns the
// number of beams along the plane (|n·b| ≤ kParallelBeamThreshold: no reading).
template <bool kSeveralPlanes>
[[gnu::always_inline]] inline int Readings(const KernelArgs& args, const FrameArrays& s,
                                           const ReadingArrays& r,
                                           const PlaneAt<kSeveralPlanes>& n) {
  const int m = args.m;
  double* __restrict h = args.h;
  const double* __restrict z0 = s.z0;
  const double* __restrict z1 = s.z1;
  const double* __restrict z2 = s.z2;
  const double* __restrict o0 = s.o0;
  const double* __restrict o1 = s.o1;
  const double* __restrict o2 = s.o2;
  double* __restrict inv = r.inv;
  double* __restrict ph0 = r.ph0;
  double* __restrict ph1 = r.ph1;
  double* __restrict ph2 = r.ph2;
  double* __restrict nbs = r.nbs;
#pragma GCC ivdep
  for (int i = 0; i < m; ++i) {
    const double nb = n.n0(i) * z0[i] + n.n1(i) * z1[i] + n.n2(i) * z2[i];
    const double hi = -(n.n0(i) * o0[i] + n.n1(i) * o1[i] + n.n2(i) * o2[i] + n.f(i)) / nb;
    nbs[i] = nb;
    h[i] = hi;
    inv[i] = -1.0 / nb;
    ph0[i] = o0[i] + hi * z0[i];
    ph1[i] = o1[i] + hi * z1[i];
    ph2[i] = o2[i] + hi * z2[i];
  }
  int parallel = 0;
  for (int i = 0; i < m; ++i) parallel += std::fabs(nbs[i]) <= kParallelBeamThreshold;
  return parallel;
}

// The Jacobian column of the link value at `index`: d and a move the origin along an axis
// (n·axis/(−n·b)); θ, α and β turn about an axis through a point ((r × n)·axis/(−n·b), r from
// that point to the hit point).
template <bool kSeveralPlanes>
[[gnu::always_inline]] inline void LinkColumn(const KernelArgs& args, int index,
                                              const ReadingArrays& r,
                                              const PlaneAt<kSeveralPlanes>& n,
                                              double* __restrict col) {
  const int m = args.m;
  const int l = index / kValuesPerLink;
  const double* f = args.frames + static_cast<std::size_t>(l) * kFrameArrays * m;
  const double* __restrict inv = r.inv;
  const int v = index % kValuesPerLink;
  if (v == kD || v == kA) {
    const double* __restrict a0 = f + (v == kD ? kZPrev : kXCommon) * m;
    const double* __restrict a1 = a0 + m;
    const double* __restrict a2 = a1 + m;
#pragma GCC ivdep
    for (int i = 0; i < m; ++i)
      col[i] = (n.n0(i) * a0[i] + n.n1(i) * a1[i] + n.n2(i) * a2[i]) * inv[i];
    return;
  }
  // θ: axis z_prev through o_prev; α: x_common through o; β: y_twist through o.
  const double* __restrict c0 = f + (v == kTheta ? kOPrev : kO) * m;
  const double* __restrict c1 = c0 + m;
  const double* __restrict c2 = c1 + m;
  const double* __restrict a0 = f + (v == kTheta ? kZPrev : v == kAlpha ? kXCommon : kYTwist) * m;
  const double* __restrict a1 = a0 + m;
  const double* __restrict a2 = a1 + m;
  const double* __restrict ph0 = r.ph0;
  const double* __restrict ph1 = r.ph1;
  const double* __restrict ph2 = r.ph2;
#pragma GCC ivdep
  for (int i = 0; i < m; ++i) {
    const double r0 = ph0[i] - c0[i], r1 = ph1[i] - c1[i], r2 = ph2[i] - c2[i];
    // (r × n)·axis
    const double g = (r1 * n.n2(i) - r2 * n.n1(i)) * a0[i] + (r2 * n.n0(i) - r0 * n.n2(i)) * a1[i] +
                     (r0 * n.n1(i) - r1 * n.n0(i)) * a2[i];
    col[i] = g * inv[i];
  }
}

// The Jacobian columns of plane p's chart u (two) and offset f: nonzero only on the
// configurations aimed at plane p (all are aimed at plane 0 in the single-plane kernel).
template <bool kSeveralPlanes>
[[gnu::always_inline]] inline void PlaneColumnsOf(const KernelArgs& args, int p,
                                                  const ReadingArrays& r) {
  const int m = args.m;
  const PlaneColumns& pc = args.parameters->plane_columns[p];
  const double* __restrict inv = r.inv;
  const double* __restrict ph0 = r.ph0;
  const double* __restrict ph1 = r.ph1;
  const double* __restrict ph2 = r.ph2;
  const double all_own = p == 0 ? 1.0 : 0.0;
  const auto own = [&](int i) {
    return kSeveralPlanes ? (args.plane[i] == p ? 1.0 : 0.0) : all_own;
  };
  for (int c = 0; c < 2; ++c) {
    if (pc.u[c] < 0) continue;
    double* __restrict col = args.J + static_cast<std::size_t>(pc.u[c]) * m;
    const Eigen::Matrix<double, 3, 2>& dn_du = args.point->dn_du[p];
    const double d0 = dn_du(0, c), d1 = dn_du(1, c), d2 = dn_du(2, c);
#pragma GCC ivdep
    for (int i = 0; i < m; ++i)
      col[i] = own(i) * ((ph0[i] * d0 + ph1[i] * d1 + ph2[i] * d2) * inv[i]);
  }
  if (pc.f >= 0) {
    double* __restrict col = args.J + static_cast<std::size_t>(pc.f) * m;
#pragma GCC ivdep
    for (int i = 0; i < m; ++i) col[i] = own(i) * inv[i];
  }
}

// One Jacobian column of an estimated base or tool term (measurement_model.h): a shift moves the
// hit point along a direction v (n·v/(−n·b)), a rotation turns it about an axis v through a point
// ((r × n)·v/(−n·b)). The base's v and point are fixed in B; the tool's v turns with the tool
// (R_BT·v, from the state's axes) and its point is the beam's origin.
template <bool kSeveralPlanes, bool kTool, bool kShift>
[[gnu::always_inline]] inline void FrameColumn(const KernelArgs& args, const FrameArrays& s,
                                               const ReadingArrays& r,
                                               const PlaneAt<kSeveralPlanes>& n,
                                               const Eigen::Vector3d& v, double* __restrict col) {
  const Eigen::Vector3d& pb = args.point->base.translation;
  for (int i = 0; i < args.m; ++i) {
    double w0 = v[0], w1 = v[1], w2 = v[2];
    if constexpr (kTool) {
      w0 = s.x0[i] * v[0] + s.y0[i] * v[1] + s.z0[i] * v[2];
      w1 = s.x1[i] * v[0] + s.y1[i] * v[1] + s.z1[i] * v[2];
      w2 = s.x2[i] * v[0] + s.y2[i] * v[1] + s.z2[i] * v[2];
    }
    double g;
    if constexpr (kShift) {
      g = n.n0(i) * w0 + n.n1(i) * w1 + n.n2(i) * w2;
    } else {
      const double r0 = r.ph0[i] - (kTool ? s.o0[i] : pb[0]);
      const double r1 = r.ph1[i] - (kTool ? s.o1[i] : pb[1]);
      const double r2 = r.ph2[i] - (kTool ? s.o2[i] : pb[2]);
      g = (r1 * n.n2(i) - r2 * n.n1(i)) * w0 + (r2 * n.n0(i) - r0 * n.n2(i)) * w1 +
          (r0 * n.n1(i) - r1 * n.n0(i)) * w2;
    }
    col[i] = g * r.inv[i];
  }
}

// Every estimated base and tool term's column.
template <bool kSeveralPlanes>
[[gnu::always_inline]] inline void FrameColumnsOf(const KernelArgs& args, const FrameArrays& s,
                                                  const ReadingArrays& r,
                                                  const PlaneAt<kSeveralPlanes>& n) {
  const ModelPoint& point = *args.point;
  const auto column = [&](int f, int k) {
    const int c = args.parameters->frame_columns[f][k];
    return c < 0 ? nullptr : args.J + static_cast<std::size_t>(c) * args.m;
  };
  for (int k = 0; k < 3; ++k) {
    if (double* col = column(0, k))
      FrameColumn<kSeveralPlanes, false, true>(args, s, r, n, Eigen::Vector3d::Unit(k), col);
    if (double* col = column(0, 3 + k))
      FrameColumn<kSeveralPlanes, false, false>(args, s, r, n, point.base_axes.col(k), col);
    if (double* col = column(1, k))
      FrameColumn<kSeveralPlanes, true, true>(args, s, r, n, point.tool_shifts_T.col(k), col);
    if (double* col = column(1, 3 + k))
      FrameColumn<kSeveralPlanes, true, false>(args, s, r, n, point.tool_axes_T.col(k), col);
  }
}

// The kernel: frames through the chain, the readings and (kJacobian) the Jacobian's columns.
template <bool kJacobian, bool kSeveralPlanes>
[[gnu::always_inline]] inline bool KernelBody(const KernelArgs& args) {
  const int m = args.m;
  const ModelPoint& point = *args.point;
  const FrameArrays s = FrameArraysOf(args.state, m);
  batch::StartAtBase(point, m, s);
  const batch::ChainArrays chain{m, &point, args.q, args.cq, args.sq, args.frames};
  for (int l = 0; l < point.num_links; ++l) batch::PropagateLink<kJacobian>(chain, l, s);
  if (point.has_tool) batch::ApplyTool(point, m, s);
  const ReadingArrays r = ReadingArraysOf(args.scratch, m);
  const PlaneAt<kSeveralPlanes> n = GatherPlanes<kSeveralPlanes>(args, r);
  const int parallel = Readings<kSeveralPlanes>(args, s, r, n);
  if constexpr (!kJacobian) return parallel == 0;
  const ParameterSet& ps = *args.parameters;
  for (int k = 0; k < ps.num_robot(); ++k)
    LinkColumn<kSeveralPlanes>(args, ps.robot_values[k], r, n,
                               args.J + static_cast<std::size_t>(k) * m);
  for (int p = 0; p < ps.num_planes(); ++p) PlaneColumnsOf<kSeveralPlanes>(args, p, r);
  if (ps.EstimatesFrames()) FrameColumnsOf<kSeveralPlanes>(args, s, r, n);
  return parallel == 0;
}

template <bool kJacobian>
[[gnu::always_inline]] inline bool KernelPlanes(const KernelArgs& a) {
  return a.plane ? KernelBody<kJacobian, true>(a) : KernelBody<kJacobian, false>(a);
}

bool KernelDefault(const KernelArgs& a) {
  return a.J ? KernelPlanes<true>(a) : KernelPlanes<false>(a);
}
#if defined(__x86_64__)
__attribute__((target("avx2"))) bool KernelAvx2(const KernelArgs& a) {
  return a.J ? KernelPlanes<true>(a) : KernelPlanes<false>(a);
}
__attribute__((target("avx512f"))) bool KernelAvx512(const KernelArgs& a) {
  return a.J ? KernelPlanes<true>(a) : KernelPlanes<false>(a);
}
#endif

}  // namespace

bool BatchEvaluator::Evaluate(const MeasurementModel& model, const ModelPoint& point, double* h,
                              double* J) {
  return Evaluate(model, point, h, J, ActiveIsa());
}

bool BatchEvaluator::Evaluate(const MeasurementModel& model, const ModelPoint& point, double* h,
                              double* J, Isa isa) {
  if (num_targets_referenced_ > model.num_planes())
    throw std::invalid_argument("BatchEvaluator: a configuration is aimed at plane " +
                                std::to_string(num_targets_referenced_) + " of " +
                                std::to_string(model.num_planes()));
  const KernelArgs args{m_,
                        &point,
                        &model.parameters(),
                        joint_arrays_.q.data(),
                        joint_arrays_.cq.data(),
                        joint_arrays_.sq.data(),
                        plane_.empty() ? nullptr : plane_.data(),
                        state_.data(),
                        frames_.data(),
                        scratch_.data(),
                        h,
                        J};
  bool ok;
  switch (isa) {
#if defined(__x86_64__)
    case Isa::kAvx512:
      ok = KernelAvx512(args);
      break;
    case Isa::kAvx2:
      ok = KernelAvx2(args);
      break;
#endif
    default:
      ok = KernelDefault(args);
  }
  model.ApplyRanger(point, m_, h, J);
  return ok;
}

}  // namespace lrcal
