#include "measurement/batch_point.h"

#include <cstddef>

#include "measurement/batch_chain.h"

namespace lrcal {

void BatchPointEvaluator::SetConfigurations(const TargetedConfigurations& configs) {
  m_ = configs.size();
  joints_ = configs.num_joints();
  q_.resize(static_cast<std::size_t>(joints_) * m_);
  cq_.resize(q_.size());
  sq_.resize(q_.size());
  target_.resize(static_cast<std::size_t>(m_));
  for (int i = 0; i < m_; ++i) {
    for (int j = 0; j < joints_; ++j) {
      q_[j * m_ + i] = configs.q(i)[j];
      cq_[j * m_ + i] = configs.cos_q(i)[j];
      sq_[j * m_ + i] = configs.sin_q(i)[j];
    }
    target_[static_cast<std::size_t>(i)] = configs.target(i);
  }
  state_.resize(12 * static_cast<std::size_t>(m_));
  frames_.resize(static_cast<std::size_t>(batch::kFrameArrays) * joints_ * m_);
  scratch_.resize(kScratchArrays * static_cast<std::size_t>(m_));
}

namespace {

// The target point P (base frame) and what the instrument's rotation columns need, per
// configuration: 12 arrays of m (args.scratch).
enum : int { kP = 0, kU2 = 3, kU1 = 6, kValue = 9 };

struct PointArgs {
  int m;
  const PointMeasurement* kind;
  const PointMeasurement::State* state;
  const ChainPoint* chain;
  const double* q;
  const double* cq;
  const double* sq;
  const int* target;
  double* frames_state;
  double* frames;
  double* scratch;
  double* y;
  double* J;
};

// Eigen's a × b for 3-vectors, term for term (its scalar path, which lrcal's builds use).
struct Vec3 {
  double v0, v1, v2;
};
[[gnu::always_inline]] inline Vec3 Cross(double a0, double a1, double a2, double b0, double b1,
                                         double b2) {
  return {a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0};
}
// M·v and Mᵀ·v for a 3×3 M, summed in Eigen's order (column 0, 1, 2).
[[gnu::always_inline]] inline Vec3 Times(const Eigen::Matrix3d& M, const Vec3& v) {
  return {M(0, 0) * v.v0 + M(0, 1) * v.v1 + M(0, 2) * v.v2,
          M(1, 0) * v.v0 + M(1, 1) * v.v1 + M(1, 2) * v.v2,
          M(2, 0) * v.v0 + M(2, 1) * v.v1 + M(2, 2) * v.v2};
}
[[gnu::always_inline]] inline Vec3 TransposeTimes(const Eigen::Matrix3d& M, const Vec3& v) {
  return {M(0, 0) * v.v0 + M(1, 0) * v.v1 + M(2, 0) * v.v2,
          M(0, 1) * v.v0 + M(1, 1) * v.v1 + M(2, 1) * v.v2,
          M(0, 2) * v.v0 + M(1, 2) * v.v1 + M(2, 2) * v.v2};
}

// y = R_BIᵀ·(P − p_BI), P = p_BT + R_BT·t; keeps P and (Jacobian) the instrument's u2, u1 and
// value (point_measurement.cc's FillRows). Each configuration's target offset is gathered first
// (into the arrays P will overwrite), so that the main loop runs on contiguous arrays.
template <bool kJacobian>
[[gnu::always_inline]] inline void Values(const PointArgs& a, const batch::FrameArrays& s) {
  const PointMeasurement::State& st = *a.state;
  const int m = a.m;
  double* __restrict P0 = a.scratch + (kP + 0) * m;
  double* __restrict P1 = a.scratch + (kP + 1) * m;
  double* __restrict P2 = a.scratch + (kP + 2) * m;
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector3d& t = st.targets[static_cast<std::size_t>(a.target[i])];
    P0[i] = t[0];
    P1[i] = t[1];
    P2[i] = t[2];
  }
  const Eigen::Matrix3d& R = st.R_BI;
  const Eigen::Matrix3d& R0 = st.R_BI0;
  const Eigen::Matrix3d& Rz = st.Rz;
  const Eigen::Matrix3d& Ry = st.Ry;
  const Eigen::Matrix3d& Rx = st.Rx;
  const double p0 = st.p_BI[0], p1 = st.p_BI[1], p2 = st.p_BI[2];
  double* __restrict y = a.y;
  double* __restrict w = a.scratch;
  for (int i = 0; i < m; ++i) {
    const double t0 = P0[i], t1 = P1[i], t2 = P2[i];
    const double q0 = s.o0[i] + (s.x0[i] * t0 + s.y0[i] * t1 + s.z0[i] * t2);
    const double q1 = s.o1[i] + (s.x1[i] * t0 + s.y1[i] * t1 + s.z1[i] * t2);
    const double q2 = s.o2[i] + (s.x2[i] * t0 + s.y2[i] * t1 + s.z2[i] * t2);
    const Vec3 d{q0 - p0, q1 - p1, q2 - p2};
    const Vec3 value = TransposeTimes(R, d);
    y[3 * i] = value.v0;
    y[3 * i + 1] = value.v1;
    y[3 * i + 2] = value.v2;
    P0[i] = q0;
    P1[i] = q1;
    P2[i] = q2;
    if constexpr (kJacobian) {
      const Vec3 u2 = TransposeTimes(Rz, TransposeTimes(R0, d));
      const Vec3 u1 = TransposeTimes(Ry, u2);
      const Vec3 v = TransposeTimes(Rx, u1);
      w[(kU2 + 0) * m + i] = u2.v0;
      w[(kU2 + 1) * m + i] = u2.v1;
      w[(kU2 + 2) * m + i] = u2.v2;
      w[(kU1 + 0) * m + i] = u1.v0;
      w[(kU1 + 1) * m + i] = u1.v1;
      w[(kU1 + 2) * m + i] = u1.v2;
      w[(kValue + 0) * m + i] = v.v0;
      w[(kValue + 1) * m + i] = v.v1;
      w[(kValue + 2) * m + i] = v.v2;
    }
  }
}

// Link value `index`'s column: R_BIᵀ·∂P/∂v (chain.h's LinkValuePointMotion).
[[gnu::always_inline]] inline void LinkColumn(const PointArgs& a, int index,
                                              double* __restrict col) {
  const int m = a.m;
  const int l = index / kValuesPerLink, v = index % kValuesPerLink;
  const double* f = a.frames + static_cast<std::size_t>(l) * batch::kFrameArrays * m;
  const Eigen::Matrix3d& R = a.state->R_BI;
  const double* __restrict P0 = a.scratch + (kP + 0) * m;
  const double* __restrict P1 = a.scratch + (kP + 1) * m;
  const double* __restrict P2 = a.scratch + (kP + 2) * m;
  // θ: z_prev about o_prev; α: x_common about o; β: y_twist about o; d: z_prev; a: x_common.
  const int axis = v == kTheta || v == kD   ? batch::kZPrev
                   : v == kA || v == kAlpha ? batch::kXCommon
                                            : batch::kYTwist;
  const double* __restrict a0 = f + axis * m;
  const double* __restrict a1 = a0 + m;
  const double* __restrict a2 = a1 + m;
  const double* __restrict c0 = f + (v == kTheta ? batch::kOPrev : batch::kO) * m;
  const double* __restrict c1 = c0 + m;
  const double* __restrict c2 = c1 + m;
  const bool shift = v == kD || v == kA;
  for (int i = 0; i < m; ++i) {
    const Vec3 motion =
        shift ? Vec3{a0[i], a1[i], a2[i]}
              : Cross(a0[i], a1[i], a2[i], P0[i] - c0[i], P1[i] - c1[i], P2[i] - c2[i]);
    const Vec3 rows = TransposeTimes(R, motion);
    col[3 * i] = rows.v0;
    col[3 * i + 1] = rows.v1;
    col[3 * i + 2] = rows.v2;
  }
}

// The instrument's six columns: −R_BIᵀ·e_c for its shifts; its rotations through u2, u1 and the
// value (point_measurement.cc's FillRows).
[[gnu::always_inline]] inline void InstrumentColumns(const PointArgs& a) {
  const int m = a.m, rows = 3 * m;
  const PointMeasurement& kind = *a.kind;
  const PointMeasurement::State& st = *a.state;
  for (int c = 0; c < 3; ++c) {
    const int column = kind.instrument_column(c);
    if (column < 0) continue;
    double* __restrict col = a.J + static_cast<std::size_t>(column) * rows;
    const double r0 = -st.R_BI(c, 0), r1 = -st.R_BI(c, 1), r2 = -st.R_BI(c, 2);
    for (int i = 0; i < m; ++i) {
      col[3 * i] = r0;
      col[3 * i + 1] = r1;
      col[3 * i + 2] = r2;
    }
  }
  const double* w = a.scratch;
  for (int k = 0; k < 3; ++k) {
    const int column = kind.instrument_column(3 + k);
    if (column < 0) continue;
    double* __restrict col = a.J + static_cast<std::size_t>(column) * rows;
    for (int i = 0; i < m; ++i) {
      Vec3 g;
      if (k == 0) {  // −e_x × value
        g = Cross(1, 0, 0, w[(kValue + 0) * m + i], w[(kValue + 1) * m + i],
                  w[(kValue + 2) * m + i]);
      } else if (k == 1) {  // −Rxᵀ·(e_y × u1)
        g = TransposeTimes(st.Rx, Cross(0, 1, 0, w[(kU1 + 0) * m + i], w[(kU1 + 1) * m + i],
                                        w[(kU1 + 2) * m + i]));
      } else {  // −Rxᵀ·Ryᵀ·(e_z × u2)
        g = TransposeTimes(
            st.Rx, TransposeTimes(st.Ry, Cross(0, 0, 1, w[(kU2 + 0) * m + i], w[(kU2 + 1) * m + i],
                                               w[(kU2 + 2) * m + i])));
      }
      col[3 * i] = -g.v0;
      col[3 * i + 1] = -g.v1;
      col[3 * i + 2] = -g.v2;
    }
  }
}

// Target t's column along the tool axis e (three arrays of m): R_BIᵀ·e on the configurations
// that see t, zero elsewhere.
[[gnu::always_inline]] inline void TargetColumn(const PointArgs& a, int t, const double* e0,
                                                const double* e1, const double* e2,
                                                double* __restrict col) {
  const Eigen::Matrix3d& R = a.state->R_BI;
  for (int i = 0; i < a.m; ++i) {
    const Vec3 g = TransposeTimes(R, {e0[i], e1[i], e2[i]});
    const bool own = a.target[i] == t;
    col[3 * i] = own ? g.v0 : 0.0;
    col[3 * i + 1] = own ? g.v1 : 0.0;
    col[3 * i + 2] = own ? g.v2 : 0.0;
  }
}

// Each target's three columns: R_BIᵀ·R_BT·e_c (the tool's axis c).
[[gnu::always_inline]] inline void TargetColumns(const PointArgs& a, const batch::FrameArrays& s) {
  const std::size_t rows = 3 * static_cast<std::size_t>(a.m);
  const double* const axes[3][3] = {{s.x0, s.x1, s.x2}, {s.y0, s.y1, s.y2}, {s.z0, s.z1, s.z2}};
  const int targets = static_cast<int>(a.state->targets.size());
  for (int t = 0; t < targets; ++t) {
    for (int c = 0; c < 3; ++c) {
      const int column = a.kind->target_column(t, c);
      if (column >= 0)
        TargetColumn(a, t, axes[c][0], axes[c][1], axes[c][2],
                     a.J + static_cast<std::size_t>(column) * rows);
    }
  }
}

template <bool kJacobian>
[[gnu::always_inline]] inline void PointKernelBody(const PointArgs& a) {
  const int m = a.m;
  const ChainPoint& chain = *a.chain;
  const batch::FrameArrays s = batch::FrameArraysOf(a.frames_state, m);
  batch::StartAtBase(chain, m, s);
  const batch::ChainArrays arrays{m, &chain, a.q, a.cq, a.sq, a.frames};
  for (int l = 0; l < chain.num_links; ++l) batch::PropagateLink<kJacobian>(arrays, l, s);
  if (chain.has_tool) batch::ApplyTool(chain, m, s);
  Values<kJacobian>(a, s);
  if constexpr (!kJacobian) return;
  const std::vector<int>& values = a.kind->robot_values();
  for (int k = 0; k < static_cast<int>(values.size()); ++k)
    LinkColumn(a, values[static_cast<std::size_t>(k)], a.J + static_cast<std::size_t>(k) * 3 * m);
  InstrumentColumns(a);
  TargetColumns(a, s);
}

void PointKernelDefault(const PointArgs& a) {
  a.J ? PointKernelBody<true>(a) : PointKernelBody<false>(a);
}
#if defined(__x86_64__)
__attribute__((target("avx2"))) void PointKernelAvx2(const PointArgs& a) {
  a.J ? PointKernelBody<true>(a) : PointKernelBody<false>(a);
}
__attribute__((target("avx512f"))) void PointKernelAvx512(const PointArgs& a) {
  a.J ? PointKernelBody<true>(a) : PointKernelBody<false>(a);
}
#endif

}  // namespace

void BatchPointEvaluator::Evaluate(const PointMeasurement& kind,
                                   const PointMeasurement::State& state, const ChainPoint& chain,
                                   double* y, double* J) {
  Evaluate(kind, state, chain, y, J, ActiveIsa());
}

void BatchPointEvaluator::Evaluate(const PointMeasurement& kind,
                                   const PointMeasurement::State& state, const ChainPoint& chain,
                                   double* y, double* J, Isa isa) {
  const PointArgs args{
      m_,         &kind,          &state,        &chain,         q_.data(),       cq_.data(),
      sq_.data(), target_.data(), state_.data(), frames_.data(), scratch_.data(), y,
      J};
  switch (isa) {
#if defined(__x86_64__)
    case Isa::kAvx512:
      PointKernelAvx512(args);
      break;
    case Isa::kAvx2:
      PointKernelAvx2(args);
      break;
#endif
    default:
      PointKernelDefault(args);
  }
}

}  // namespace lrcal
