#include "measurement/batch_evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/cpu_dispatch.h"

namespace lrcal {

namespace {
// Per link: z_prev (3), o_prev (3), x_common (3), y_twist (3), o (3).
constexpr int kFrameArrays = 15;
enum : int { kZPrev = 0, kOPrev = 3, kXCommon = 6, kYTwist = 9, kO = 12 };
}  // namespace

void BatchEvaluator::SetConfigurations(const ConfigurationSet& configs) {
  m_ = configs.size();
  joints_ = configs.num_joints();
  q_.resize(static_cast<std::size_t>(joints_) * m_);
  cq_.resize(q_.size());
  sq_.resize(q_.size());
  for (int i = 0; i < m_; ++i) {
    for (int j = 0; j < joints_; ++j) {
      q_[j * m_ + i] = configs.q(i)[j];
      cq_[j * m_ + i] = configs.cos_q(i)[j];
      sq_[j * m_ + i] = configs.sin_q(i)[j];
    }
  }
  plane_.clear();
  num_planes_referenced_ = configs.num_planes_referenced();
  if (num_planes_referenced_ > 1) {
    plane_.resize(m_);
    for (int i = 0; i < m_; ++i) plane_[i] = configs.plane(i);
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

// The vectorised kernel: structure-of-arrays loops over all configurations, inlined into one
// variant per instruction set (cpu_dispatch.h). Kept in one function on purpose: the compiler
// vectorises and inlines it whole, and the variants must give the same bits.
// Several planes: each configuration's plane normal and offset are gathered into arrays.
template <bool kJacobian, bool kSeveralPlanes>
// NOLINTNEXTLINE(readability-function-size,readability-function-cognitive-complexity)
[[gnu::always_inline]] inline bool KernelBody(const KernelArgs& args) {
  const int m = args.m;
  const ModelPoint& point = *args.point;
  double* __restrict h = args.h;
  double* __restrict J = args.J;
  double* __restrict x0 = args.state;
  double* __restrict x1 = x0 + m;
  double* __restrict x2 = x1 + m;
  double* __restrict y0 = x2 + m;
  double* __restrict y1 = y0 + m;
  double* __restrict y2 = y1 + m;
  double* __restrict z0 = y2 + m;
  double* __restrict z1 = z0 + m;
  double* __restrict z2 = z1 + m;
  double* __restrict o0 = z2 + m;
  double* __restrict o1 = o0 + m;
  double* __restrict o2 = o1 + m;
  // The chain starts at frame 0: the base transform's axes and origin (the identity without one).
  const Eigen::Matrix3d& rb = point.base.rotation;
  const Eigen::Vector3d& pb = point.base.translation;
  double* const start[12] = {x0, x1, x2, y0, y1, y2, z0, z1, z2, o0, o1, o2};
  for (int k = 0; k < 12; ++k)
    std::fill(start[k], start[k] + m, k < 9 ? rb(k % 3, k / 3) : pb(k - 9));

  for (int l = 0; l < point.num_links; ++l) {
    const ModelPoint::LinkTrig& t = point.links[l];
    const double* __restrict cq = args.cq + l * m;
    const double* __restrict sq = args.sq + l * m;
    const double* __restrict q = args.q + l * m;
    double* f = args.frames + static_cast<std::size_t>(l) * kFrameArrays * m;
    double* __restrict fz0 = f + (kZPrev + 0) * m;
    double* __restrict fz1 = f + (kZPrev + 1) * m;
    double* __restrict fz2 = f + (kZPrev + 2) * m;
    double* __restrict fp0 = f + (kOPrev + 0) * m;
    double* __restrict fp1 = f + (kOPrev + 1) * m;
    double* __restrict fp2 = f + (kOPrev + 2) * m;
    double* __restrict fx0 = f + (kXCommon + 0) * m;
    double* __restrict fx1 = f + (kXCommon + 1) * m;
    double* __restrict fx2 = f + (kXCommon + 2) * m;
    double* __restrict fy0 = f + (kYTwist + 0) * m;
    double* __restrict fy1 = f + (kYTwist + 1) * m;
    double* __restrict fy2 = f + (kYTwist + 2) * m;
    double* __restrict fo0 = f + (kO + 0) * m;
    double* __restrict fo1 = f + (kO + 1) * m;
    double* __restrict fo2 = f + (kO + 2) * m;
    const double ct0 = t.cos_theta0, st0 = t.sin_theta0, ca = t.cos_alpha, sa = t.sin_alpha,
                 cb = t.cos_beta, sb = t.sin_beta, a = t.a, d0 = t.d;
    const double revolute = t.prismatic ? 0.0 : 1.0;
#pragma GCC ivdep
    for (int i = 0; i < m; ++i) {
      // cos/sin(θ0 + q) by the addition theorem (revolute); θ0 alone and d0 + q (prismatic).
      const double ct = revolute * (ct0 * cq[i] - st0 * sq[i]) + (1 - revolute) * ct0;
      const double st = revolute * (st0 * cq[i] + ct0 * sq[i]) + (1 - revolute) * st0;
      const double d = d0 + (1 - revolute) * q[i];
      const double xc0 = ct * x0[i] + st * y0[i];
      const double xc1 = ct * x1[i] + st * y1[i];
      const double xc2 = ct * x2[i] + st * y2[i];
      const double yr0 = ct * y0[i] - st * x0[i];
      const double yr1 = ct * y1[i] - st * x1[i];
      const double yr2 = ct * y2[i] - st * x2[i];
      const double yt0 = ca * yr0 + sa * z0[i];
      const double yt1 = ca * yr1 + sa * z1[i];
      const double yt2 = ca * yr2 + sa * z2[i];
      const double za0 = ca * z0[i] - sa * yr0;
      const double za1 = ca * z1[i] - sa * yr1;
      const double za2 = ca * z2[i] - sa * yr2;
      if constexpr (kJacobian) {
        fz0[i] = z0[i];
        fz1[i] = z1[i];
        fz2[i] = z2[i];
        fp0[i] = o0[i];
        fp1[i] = o1[i];
        fp2[i] = o2[i];
        fx0[i] = xc0;
        fx1[i] = xc1;
        fx2[i] = xc2;
        fy0[i] = yt0;
        fy1[i] = yt1;
        fy2[i] = yt2;
      }
      o0[i] += a * xc0 + d * z0[i];
      o1[i] += a * xc1 + d * z1[i];
      o2[i] += a * xc2 + d * z2[i];
      if constexpr (kJacobian) {
        fo0[i] = o0[i];
        fo1[i] = o1[i];
        fo2[i] = o2[i];
      }
      x0[i] = cb * xc0 - sb * za0;
      x1[i] = cb * xc1 - sb * za1;
      x2[i] = cb * xc2 - sb * za2;
      z0[i] = sb * xc0 + cb * za0;
      z1[i] = sb * xc1 + cb * za1;
      z2[i] = sb * xc2 + cb * za2;
      y0[i] = yt0;
      y1[i] = yt1;
      y2[i] = yt2;
    }
  }

  if (point.has_tool) {  // the tool frame: p ← p + R·t, R ← R·R_tool
    const Eigen::Matrix3d& rt = point.tool.rotation;
    const Eigen::Vector3d& pt = point.tool.translation;
#pragma GCC ivdep
    for (int i = 0; i < m; ++i) {
      const double r[3][3] = {{x0[i], y0[i], z0[i]}, {x1[i], y1[i], z1[i]}, {x2[i], y2[i], z2[i]}};
      double* const axes[3][3] = {{x0, y0, z0}, {x1, y1, z1}, {x2, y2, z2}};
      double* const origin[3] = {o0, o1, o2};
      for (int row = 0; row < 3; ++row) {
        origin[row][i] += r[row][0] * pt(0) + r[row][1] * pt(1) + r[row][2] * pt(2);
        for (int col = 0; col < 3; ++col)
          axes[row][col][i] =
              r[row][0] * rt(0, col) + r[row][1] * rt(1, col) + r[row][2] * rt(2, col);
      }
    }
  }

  // Readings: h = -(n·p + f)/(n·b); keep -1/(n·b) and the hit point for the Jacobian. With one
  // plane its normal n and offset are scalars; with several, arrays over the configurations.
  double* __restrict inv = args.scratch;
  double* __restrict ph0 = inv + m;
  double* __restrict ph1 = ph0 + m;
  double* __restrict ph2 = ph1 + m;
  double* __restrict nbs = ph2 + m;
  double* __restrict pn0 = nbs + m;
  double* __restrict pn1 = pn0 + m;
  double* __restrict pn2 = pn1 + m;
  double* __restrict pf = pn2 + m;
  const Plane& plane0 = point.planes[0];
  const double s0 = plane0.normal.x(), s1 = plane0.normal.y(), s2 = plane0.normal.z(),
               sf = plane0.offset;
  if constexpr (kSeveralPlanes) {
    for (int i = 0; i < m; ++i) {
      const Plane& p = point.planes[args.plane[i]];
      pn0[i] = p.normal.x();
      pn1[i] = p.normal.y();
      pn2[i] = p.normal.z();
      pf[i] = p.offset;
    }
  }
  // n at configuration i: the one plane's, or configuration i's plane's.
  const auto n0 = [&](int i) { return kSeveralPlanes ? pn0[i] : s0; };
  const auto n1 = [&](int i) { return kSeveralPlanes ? pn1[i] : s1; };
  const auto n2 = [&](int i) { return kSeveralPlanes ? pn2[i] : s2; };
  const auto fo = [&](int i) { return kSeveralPlanes ? pf[i] : sf; };
#pragma GCC ivdep
  for (int i = 0; i < m; ++i) {
    const double nb = n0(i) * z0[i] + n1(i) * z1[i] + n2(i) * z2[i];
    const double hi = -(n0(i) * o0[i] + n1(i) * o1[i] + n2(i) * o2[i] + fo(i)) / nb;
    nbs[i] = nb;
    h[i] = hi;
    inv[i] = -1.0 / nb;
    ph0[i] = o0[i] + hi * z0[i];
    ph1[i] = o1[i] + hi * z1[i];
    ph2[i] = o2[i] + hi * z2[i];
  }
  int parallel = 0;  // beams along the plane (|n·b| ≤ kParallelBeamThreshold): no reading
  for (int i = 0; i < m; ++i) parallel += std::fabs(nbs[i]) <= kParallelBeamThreshold;
  if constexpr (!kJacobian) return parallel == 0;

  const ParameterSet& ps = *args.parameters;
  for (int k = 0; k < ps.num_robot(); ++k) {
    const int index = ps.robot_values[k];
    const int l = index / kValuesPerLink;
    const double* f = args.frames + static_cast<std::size_t>(l) * kFrameArrays * m;
    double* __restrict col = J + static_cast<std::size_t>(k) * m;
    const int v = index % kValuesPerLink;
    if (v == kD || v == kA) {
      const double* __restrict a0 = f + (v == kD ? kZPrev : kXCommon) * m;
      const double* __restrict a1 = a0 + m;
      const double* __restrict a2 = a1 + m;
#pragma GCC ivdep
      for (int i = 0; i < m; ++i) col[i] = (n0(i) * a0[i] + n1(i) * a1[i] + n2(i) * a2[i]) * inv[i];
      continue;
    }
    // θ: axis z_prev through o_prev; α: x_common through o; β: y_twist through o.
    const double* __restrict c0 = f + (v == kTheta ? kOPrev : kO) * m;
    const double* __restrict c1 = c0 + m;
    const double* __restrict c2 = c1 + m;
    const double* __restrict a0 = f + (v == kTheta ? kZPrev : v == kAlpha ? kXCommon : kYTwist) * m;
    const double* __restrict a1 = a0 + m;
    const double* __restrict a2 = a1 + m;
#pragma GCC ivdep
    for (int i = 0; i < m; ++i) {
      const double r0 = ph0[i] - c0[i], r1 = ph1[i] - c1[i], r2 = ph2[i] - c2[i];
      // (r × n)·axis
      const double g = (r1 * n2(i) - r2 * n1(i)) * a0[i] + (r2 * n0(i) - r0 * n2(i)) * a1[i] +
                       (r0 * n1(i) - r1 * n0(i)) * a2[i];
      col[i] = g * inv[i];
    }
  }
  for (int p = 0; p < ps.num_planes(); ++p) {
    const PlaneColumns& pc = ps.plane_columns[p];
    // 1 on the configurations aimed at plane p, 0 elsewhere (all are aimed at plane 0 in the
    // single-plane kernel).
    const double all_own = p == 0 ? 1.0 : 0.0;
    const auto own = [&](int i) {
      return kSeveralPlanes ? (args.plane[i] == p ? 1.0 : 0.0) : all_own;
    };
    for (int c = 0; c < 2; ++c) {
      if (pc.u[c] < 0) continue;
      double* __restrict col = J + static_cast<std::size_t>(pc.u[c]) * m;
      const double d0 = point.dn_du[p](0, c), d1 = point.dn_du[p](1, c), d2 = point.dn_du[p](2, c);
#pragma GCC ivdep
      for (int i = 0; i < m; ++i)
        col[i] = own(i) * ((ph0[i] * d0 + ph1[i] * d1 + ph2[i] * d2) * inv[i]);
    }
    if (pc.f >= 0) {
      double* __restrict col = J + static_cast<std::size_t>(pc.f) * m;
#pragma GCC ivdep
      for (int i = 0; i < m; ++i) col[i] = own(i) * inv[i];
    }
  }
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
  if (num_planes_referenced_ > model.num_planes())
    throw std::invalid_argument("BatchEvaluator: a configuration is aimed at plane " +
                                std::to_string(num_planes_referenced_) + " of " +
                                std::to_string(model.num_planes()));
  const KernelArgs args{m_,
                        &point,
                        &model.parameters(),
                        q_.data(),
                        cq_.data(),
                        sq_.data(),
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
