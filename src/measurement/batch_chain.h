// The chain's forward kinematics over many configurations at once, as structure-of-arrays:
// the steps of the point kind's batch kernel (batch_point.h; the ranger's, batch_evaluation.h,
// walks blocks of configurations through the same arithmetic with its frame in registers). Every
// step is a loop over contiguous arrays of the m configurations that the compiler vectorises,
// force-inlined into each kernel's per-instruction-set variant (cpu_dispatch.h). The arithmetic per
// configuration is ToolPose's (chain.h), operation for operation, so with -ffp-contract=off every
// variant gives the same bits.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "lrcal/kinematics/chain.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal::batch {

// Per link: z_prev (3), o_prev (3), x_common (3), y_twist (3), o (3).
inline constexpr int kFrameArrays = 15;
enum : int { kZPrev = 0, kOPrev = 3, kXCommon = 6, kYTwist = 9, kO = 12 };

// The configurations' joint values and their cos/sin, one array of m per joint ([joint·m + i]):
// what the chain's steps read.
struct JointArrays {
  std::vector<double> q, cq, sq;
  void Set(const TargetedConfigurations& configs) {
    const int m = configs.size(), joints = configs.num_joints();
    q.resize(static_cast<std::size_t>(joints) * m);
    cq.resize(q.size());
    sq.resize(q.size());
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < joints; ++j) {
        q[j * m + i] = configs.q(i)[j];
        cq[j * m + i] = configs.cos_q(i)[j];
        sq[j * m + i] = configs.sin_q(i)[j];
      }
    }
  }
};

// What the chain's steps read and write: m configurations' joint values and their cos/sin
// ([joint·m + i]) and, for the Jacobian, every link's frames ([(link·kFrameArrays + k)·m + i]).
struct ChainArrays {
  int m;
  const ChainPoint* point;
  const double* q;
  const double* cq;
  const double* sq;
  double* frames;
};

// The chain's running frame, 12 arrays of m: the axes x, y, z and the origin o, each as three
// coordinate arrays.
struct FrameArrays {
  double* __restrict x0;
  double* __restrict x1;
  double* __restrict x2;
  double* __restrict y0;
  double* __restrict y1;
  double* __restrict y2;
  double* __restrict z0;
  double* __restrict z1;
  double* __restrict z2;
  double* __restrict o0;
  double* __restrict o1;
  double* __restrict o2;
};

[[gnu::always_inline]] inline FrameArrays FrameArraysOf(double* state, int m) {
  return {state,         state + m,     state + 2 * m,  state + 3 * m,
          state + 4 * m, state + 5 * m, state + 6 * m,  state + 7 * m,
          state + 8 * m, state + 9 * m, state + 10 * m, state + 11 * m};
}

// The chain starts at frame 0: the base transform's axes and origin (the identity without one).
[[gnu::always_inline]] inline void StartAtBase(const ChainPoint& point, int m,
                                               const FrameArrays& s) {
  const Eigen::Matrix3d& rb = point.base.rotation;
  const Eigen::Vector3d& pb = point.base.translation;
  double* const start[12] = {s.x0, s.x1, s.x2, s.y0, s.y1, s.y2,
                             s.z0, s.z1, s.z2, s.o0, s.o1, s.o2};
  for (int k = 0; k < 12; ++k)
    std::fill(start[k], start[k] + m, k < 9 ? rb(k % 3, k / 3) : pb(k - 9));
}

// Link l's frames saved for the Jacobian (kFrameArrays arrays of m, kZPrev ... kO).
struct LinkFrames {
  double* __restrict z0;
  double* __restrict z1;
  double* __restrict z2;
  double* __restrict p0;
  double* __restrict p1;
  double* __restrict p2;
  double* __restrict x0;
  double* __restrict x1;
  double* __restrict x2;
  double* __restrict y0;
  double* __restrict y1;
  double* __restrict y2;
  double* __restrict o0;
  double* __restrict o1;
  double* __restrict o2;
};

[[gnu::always_inline]] inline LinkFrames LinkFramesOf(double* frames, int l, int m) {
  double* f = frames + static_cast<std::size_t>(l) * kFrameArrays * m;
  return {f + (kZPrev + 0) * m,   f + (kZPrev + 1) * m,   f + (kZPrev + 2) * m,
          f + (kOPrev + 0) * m,   f + (kOPrev + 1) * m,   f + (kOPrev + 2) * m,
          f + (kXCommon + 0) * m, f + (kXCommon + 1) * m, f + (kXCommon + 2) * m,
          f + (kYTwist + 0) * m,  f + (kYTwist + 1) * m,  f + (kYTwist + 2) * m,
          f + (kO + 0) * m,       f + (kO + 1) * m,       f + (kO + 2) * m};
}

// The running frame through link l (D-H + β), saving the link's frames when the Jacobian is
// wanted.
template <bool kJacobian>
[[gnu::always_inline]] inline void PropagateLink(const ChainArrays& args, int l,
                                                 const FrameArrays& s) {
  const int m = args.m;
  const ChainPoint::LinkTrig& t = args.point->links[l];
  const double* __restrict cq = args.cq + l * m;
  const double* __restrict sq = args.sq + l * m;
  const double* __restrict q = args.q + l * m;
  const LinkFrames f = LinkFramesOf(args.frames, l, m);
  double* __restrict x0 = s.x0;
  double* __restrict x1 = s.x1;
  double* __restrict x2 = s.x2;
  double* __restrict y0 = s.y0;
  double* __restrict y1 = s.y1;
  double* __restrict y2 = s.y2;
  double* __restrict z0 = s.z0;
  double* __restrict z1 = s.z1;
  double* __restrict z2 = s.z2;
  double* __restrict o0 = s.o0;
  double* __restrict o1 = s.o1;
  double* __restrict o2 = s.o2;
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
      f.z0[i] = z0[i];
      f.z1[i] = z1[i];
      f.z2[i] = z2[i];
      f.p0[i] = o0[i];
      f.p1[i] = o1[i];
      f.p2[i] = o2[i];
      f.x0[i] = xc0;
      f.x1[i] = xc1;
      f.x2[i] = xc2;
      f.y0[i] = yt0;
      f.y1[i] = yt1;
      f.y2[i] = yt2;
    }
    o0[i] += a * xc0 + d * z0[i];
    o1[i] += a * xc1 + d * z1[i];
    o2[i] += a * xc2 + d * z2[i];
    if constexpr (kJacobian) {
      f.o0[i] = o0[i];
      f.o1[i] = o1[i];
      f.o2[i] = o2[i];
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

// The tool frame: p ← p + R·t, R ← R·R_tool.
[[gnu::always_inline]] inline void ApplyTool(const ChainPoint& point, int m, const FrameArrays& s) {
  const Eigen::Matrix3d& rt = point.tool.rotation;
  const Eigen::Vector3d& pt = point.tool.translation;
  double* __restrict x0 = s.x0;
  double* __restrict x1 = s.x1;
  double* __restrict x2 = s.x2;
  double* __restrict y0 = s.y0;
  double* __restrict y1 = s.y1;
  double* __restrict y2 = s.y2;
  double* __restrict z0 = s.z0;
  double* __restrict z1 = s.z1;
  double* __restrict z2 = s.z2;
  double* __restrict o0 = s.o0;
  double* __restrict o1 = s.o1;
  double* __restrict o2 = s.o2;
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

}  // namespace lrcal::batch
