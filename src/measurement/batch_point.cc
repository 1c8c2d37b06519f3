#include "measurement/batch_point.h"

#include <cstddef>
#include <stdexcept>

#include "lrcal/measurement/pose_measurement.h"
#include "measurement/batch_chain.h"

namespace lrcal {

void BatchPointEvaluator::SetConfigurations(const TargetedConfigurations& configs) {
  m_ = configs.size();
  joints_ = configs.num_joints();
  joint_arrays_.Set(configs);
  target_.resize(static_cast<std::size_t>(m_));
  for (int i = 0; i < m_; ++i) target_[static_cast<std::size_t>(i)] = configs.target(i);
  state_.resize(12 * static_cast<std::size_t>(m_));
  frames_.resize(static_cast<std::size_t>(batch::kFrameArrays) * joints_ * m_);
  scratch_.assign(kScratchArrays * static_cast<std::size_t>(m_), 0.0);
}

namespace {

// Per configuration, arrays of m (args.scratch): the target point P (base frame) and what the
// instrument's rotation columns need (u2, u1, value); for the pose kind, what its orientation rows
// need: the body-rate map J_r⁻¹·R_BMᵀ (9, row-major), and the orientation rows of the
// instrument's and the target's three rotation columns (3 × 3 each, column by column).
enum : int {
  kP = 0,
  kU2 = 3,
  kU1 = 6,
  kValue = 9,
  kToBody = 12,
  kInstrumentTurn = 21,
  kTargetTurn = 30,
  kZeros = 39  // zeros, never written: a length's (no) rotation axis
};

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
  const Eigen::Matrix3d* chart_centres;  // the pose kind's, one per configuration
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
// The sums of 3 × 3 products as Eigen 3.4 forms them in lrcal's portable build (SSE2), so that
// the kernel has the bits of the per-configuration Eigen code it replaced (and of the tables made
// with it): a stored matrix times a vector or a matrix sums rows 0 and 1 as (a₀ + a₁) + a₂ (a
// pair of rows per packet) and row 2 as a₀ + (a₁ + a₂) (its scalar reduction); a transposed
// matrix's product sums every row as (a₀ + a₁) + a₂. M·v for a stored M:
[[gnu::always_inline]] inline Vec3 Times(const Eigen::Matrix3d& M, const Vec3& v) {
  return {M(0, 0) * v.v0 + M(0, 1) * v.v1 + M(0, 2) * v.v2,
          M(1, 0) * v.v0 + M(1, 1) * v.v1 + M(1, 2) * v.v2,
          M(2, 0) * v.v0 + (M(2, 1) * v.v1 + M(2, 2) * v.v2)};
}
// ... and Mᵀ·v as a transposed expression.
[[gnu::always_inline]] inline Vec3 TransposeTimes(const Eigen::Matrix3d& M, const Vec3& v) {
  return {M(0, 0) * v.v0 + M(1, 0) * v.v1 + M(2, 0) * v.v2,
          M(0, 1) * v.v0 + M(1, 1) * v.v1 + M(2, 1) * v.v2,
          M(0, 2) * v.v0 + M(1, 2) * v.v1 + M(2, 2) * v.v2};
}

// y = R_BIᵀ·(P − p_BI), P = p_BT + R_BT·t; keeps P and (Jacobian) the instrument's u2, u1 and
// value (point_measurement.cc's FillRows). Each configuration's target offset is gathered first
// (into the arrays P will overwrite), so that the main loop runs on contiguous arrays.
template <bool kJacobian, int K>
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
    const double q2 = s.o2[i] + (s.x2[i] * t0 + (s.y2[i] * t1 + s.z2[i] * t2));
    const Vec3 d{q0 - p0, q1 - p1, q2 - p2};
    const Vec3 value = TransposeTimes(R, d);
    y[K * i] = value.v0;
    y[K * i + 1] = value.v1;
    y[K * i + 2] = value.v2;
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
template <int K>
[[gnu::always_inline]] inline void LinkColumn(const PointArgs& a, int index,
                                              double* __restrict col) {
  const int m = a.m;
  const int l = index / kValuesPerLink, v = index % kValuesPerLink;
  const double* f = a.frames + static_cast<std::size_t>(l) * batch::kFrameArrays * m;
  const Eigen::Matrix3d Rt = a.state->R_BI.transpose();  // stored, as FillRows had it
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
    const Vec3 rows = Times(Rt, motion);
    col[K * i] = rows.v0;
    col[K * i + 1] = rows.v1;
    col[K * i + 2] = rows.v2;
  }
}

// The instrument's six columns: −R_BIᵀ·e_c for its shifts; its rotations through u2, u1 and the
// value (point_measurement.cc's FillRows).
template <int K>
[[gnu::always_inline]] inline void InstrumentColumns(const PointArgs& a) {
  const int m = a.m, rows = K * m;
  const PointMeasurement& kind = *a.kind;
  const PointMeasurement::State& st = *a.state;
  for (int c = 0; c < 3; ++c) {
    const int column = kind.instrument_column(c);
    if (column < 0) continue;
    double* __restrict col = a.J + static_cast<std::size_t>(column) * rows;
    const double r0 = -st.R_BI(c, 0), r1 = -st.R_BI(c, 1), r2 = -st.R_BI(c, 2);
    for (int i = 0; i < m; ++i) {
      col[K * i] = r0;
      col[K * i + 1] = r1;
      col[K * i + 2] = r2;
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
      col[K * i] = -g.v0;
      col[K * i + 1] = -g.v1;
      col[K * i + 2] = -g.v2;
    }
  }
}

// Target t's column along the tool axis e (three arrays of m): R_BIᵀ·e on the configurations
// that see t, zero elsewhere.
template <int K>
[[gnu::always_inline]] inline void TargetColumn(const PointArgs& a, int t, const double* e0,
                                                const double* e1, const double* e2,
                                                double* __restrict col) {
  const Eigen::Matrix3d Rt = a.state->R_BI.transpose();  // R_BIᵀ·R_BT, stored as FillRows had it
  for (int i = 0; i < a.m; ++i) {
    const Vec3 g = Times(Rt, {e0[i], e1[i], e2[i]});
    const bool own = a.target[i] == t;
    col[K * i] = own ? g.v0 : 0.0;
    col[K * i + 1] = own ? g.v1 : 0.0;
    col[K * i + 2] = own ? g.v2 : 0.0;
  }
}

// Each target's three columns: R_BIᵀ·R_BT·e_c (the tool's axis c).
template <int K>
[[gnu::always_inline]] inline void TargetColumns(const PointArgs& a, const batch::FrameArrays& s) {
  const std::size_t rows = K * static_cast<std::size_t>(a.m);
  const double* const axes[3][3] = {{s.x0, s.x1, s.x2}, {s.y0, s.y1, s.y2}, {s.z0, s.z1, s.z2}};
  const int targets = static_cast<int>(a.state->targets.size());
  for (int t = 0; t < targets; ++t) {
    for (int c = 0; c < 3; ++c) {
      const int column = a.kind->target_column(t, c);
      if (column >= 0)
        TargetColumn<K>(a, t, axes[c][0], axes[c][1], axes[c][2],
                        a.J + static_cast<std::size_t>(column) * rows);
    }
  }
}

// The pose kind's orientation rows 3–5 of each configuration (pose_measurement.h): φ =
// log(Cᵀ·R_IM) into y and, for the Jacobian, the body-rate map J_r⁻¹(φ)·R_BMᵀ and the
// orientation rows of the instrument's and the target's rotation columns (scratch). Per
// configuration in Eigen's 3 × 3 arithmetic (a logarithm each: no loop to vectorise).
template <bool kJacobian>
[[gnu::always_inline]] inline void Orientations(const PointArgs& a, const batch::FrameArrays& s) {
  const PointMeasurement::State& st = *a.state;
  const int m = a.m;
  double* w = a.scratch;
  const auto put = [&](int first, int i, const Eigen::Vector3d& v) {
    for (int c = 0; c < 3; ++c) w[(first + c) * m + i] = v[c];
  };
  for (int i = 0; i < m; ++i) {
    const auto t = static_cast<std::size_t>(a.target[i]);
    Eigen::Matrix3d R_BT;
    R_BT << s.x0[i], s.y0[i], s.z0[i], s.x1[i], s.y1[i], s.z1[i], s.x2[i], s.y2[i], s.z2[i];
    const Eigen::Matrix3d R_BM = R_BT * st.R_TM[t];
    const Eigen::Matrix3d R_IM = st.R_BI.transpose() * R_BM;
    const Eigen::Vector3d phi = RotationLog(a.chart_centres[i].transpose() * R_IM);
    for (int c = 0; c < 3; ++c) a.y[6 * i + 3 + c] = phi[c];
    if constexpr (!kJacobian) continue;
    const Eigen::Matrix3d Jinv = InverseRightJacobian(phi);
    const Eigen::Matrix3d to_body = Jinv * R_BM.transpose();  // base-frame ω → rows
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) w[(kToBody + 3 * r + c) * m + i] = to_body(r, c);
    // The instrument's rotations turn R_IM on the left (frame I): ω_M = −R_IMᵀ·ω_I.
    const Eigen::Matrix3d from_instrument = -Jinv * R_IM.transpose();
    put(kInstrumentTurn, i, from_instrument * Eigen::Vector3d::UnitX());
    put(kInstrumentTurn + 3, i, from_instrument * (st.Rx.transpose() * Eigen::Vector3d::UnitY()));
    put(kInstrumentTurn + 6, i,
        from_instrument * (st.Rx.transpose() * (st.Ry.transpose() * Eigen::Vector3d::UnitZ())));
    // The target's rotations turn R_IM on the right (frame M).
    const Eigen::Matrix3d& Rx = st.target_Rx[t];
    const Eigen::Matrix3d& Ry = st.target_Ry[t];
    put(kTargetTurn, i, Jinv * Eigen::Vector3d::UnitX());
    put(kTargetTurn + 3, i, Jinv * (Rx.transpose() * Eigen::Vector3d::UnitY()));
    put(kTargetTurn + 6, i, Jinv * (Rx.transpose() * (Ry.transpose() * Eigen::Vector3d::UnitZ())));
  }
}

// Link value `index`'s orientation rows: J_r⁻¹·R_BMᵀ times the axis it turns about (chain.h's
// LinkValueRotation), zero for a length.
[[gnu::always_inline]] inline void LinkTurnRows(const PointArgs& a, int index,
                                                double* __restrict col) {
  const int m = a.m;
  const int l = index / kValuesPerLink, v = index % kValuesPerLink;
  const double* w = a.scratch;
  // A length turns about no axis: J_r⁻¹·R_BMᵀ·0, summed all the same (its zeros keep their signs).
  const bool length = v == kD || v == kA;
  const double* f = a.frames + static_cast<std::size_t>(l) * batch::kFrameArrays * m;
  const int axis = v == kTheta ? batch::kZPrev : v == kAlpha ? batch::kXCommon : batch::kYTwist;
  const double* __restrict a0 = length ? w + kZeros * m : f + axis * m;
  const double* __restrict a1 = length ? a0 : a0 + m;
  const double* __restrict a2 = length ? a0 : a1 + m;
  for (int r = 0; r < 3; ++r) {
    const double* __restrict t0 = w + (kToBody + 3 * r) * m;
    const double* __restrict t1 = t0 + m;
    const double* __restrict t2 = t1 + m;
    if (r < 2) {  // summed as Times sums a stored matrix's rows
      for (int i = 0; i < m; ++i)
        col[6 * i + 3 + r] = t0[i] * a0[i] + t1[i] * a1[i] + t2[i] * a2[i];
    } else {
      for (int i = 0; i < m; ++i)
        col[6 * i + 3 + r] = t0[i] * a0[i] + (t1[i] * a1[i] + t2[i] * a2[i]);
    }
  }
}

// The orientation rows of every column but the links': the instrument's and the targets' shifts
// (zero), their rotations (from Orientations), and the position rows of the targets' rotations
// (zero: a target's orientation does not move its point).
[[gnu::always_inline]] inline double* PoseColumn(const PointArgs& a, int column) {
  return a.J + static_cast<std::size_t>(column) * 6 * static_cast<std::size_t>(a.m);
}

// Zeros in rows first…first+2 of each configuration of a pose column.
[[gnu::always_inline]] inline void ZeroRows(const PointArgs& a, int column, int first) {
  double* __restrict col = PoseColumn(a, column);
  for (int i = 0; i < a.m; ++i)
    col[6 * i + first] = col[6 * i + first + 1] = col[6 * i + first + 2] = 0.0;
}

// Orientation rows from the scratch arrays first…first+2, on the configurations that see target
// t (t < 0: on every configuration), zero elsewhere.
[[gnu::always_inline]] inline void TurnRows(const PointArgs& a, int column, int first, int t) {
  double* __restrict col = PoseColumn(a, column);
  for (int c = 0; c < 3; ++c) {
    const double* __restrict g = a.scratch + (first + c) * a.m;
    for (int i = 0; i < a.m; ++i) col[6 * i + 3 + c] = t < 0 || a.target[i] == t ? g[i] : 0.0;
  }
}

[[gnu::always_inline]] inline void OtherTurnRows(const PointArgs& a) {
  const PointMeasurement& kind = *a.kind;
  for (int k = 0; k < 3; ++k) {
    if (kind.instrument_column(k) >= 0) ZeroRows(a, kind.instrument_column(k), 3);
    if (kind.instrument_column(3 + k) >= 0)
      TurnRows(a, kind.instrument_column(3 + k), kInstrumentTurn + 3 * k, -1);
  }
  const int targets = static_cast<int>(a.state->targets.size());
  for (int t = 0; t < targets; ++t) {
    for (int k = 0; k < 3; ++k) {
      if (kind.target_column(t, k) >= 0) ZeroRows(a, kind.target_column(t, k), 3);
      const int column = kind.target_rotation_column(t, k);
      if (column < 0) continue;
      ZeroRows(a, column, 0);
      TurnRows(a, column, kTargetTurn + 3 * k, t);
    }
  }
}

// K = 3: the point kind; K = 6: the pose kind (positions, then orientations).
template <bool kJacobian, int K>
[[gnu::always_inline]] inline void PointKernelBody(const PointArgs& a) {
  const int m = a.m;
  const ChainPoint& chain = *a.chain;
  const batch::FrameArrays s = batch::FrameArraysOf(a.frames_state, m);
  batch::StartAtBase(chain, m, s);
  const batch::ChainArrays arrays{m, &chain, a.q, a.cq, a.sq, a.frames};
  for (int l = 0; l < chain.num_links; ++l) batch::PropagateLink<kJacobian>(arrays, l, s);
  if (chain.has_tool) batch::ApplyTool(chain, m, s);
  Values<kJacobian, K>(a, s);
  if constexpr (K == 6) Orientations<kJacobian>(a, s);
  if constexpr (!kJacobian) return;
  const std::vector<int>& values = a.kind->robot_values();
  for (int k = 0; k < static_cast<int>(values.size()); ++k) {
    double* col = a.J + static_cast<std::size_t>(k) * K * m;
    LinkColumn<K>(a, values[static_cast<std::size_t>(k)], col);
    if constexpr (K == 6) LinkTurnRows(a, values[static_cast<std::size_t>(k)], col);
  }
  InstrumentColumns<K>(a);
  TargetColumns<K>(a, s);
  if constexpr (K == 6) OtherTurnRows(a);
}

template <int K>
[[gnu::always_inline]] inline void PointKernelRows(const PointArgs& a) {
  a.J ? PointKernelBody<true, K>(a) : PointKernelBody<false, K>(a);
}

void PointKernelDefault(const PointArgs& a) {
  a.chart_centres ? PointKernelRows<6>(a) : PointKernelRows<3>(a);
}
#if defined(__x86_64__)
__attribute__((target("avx2"))) void PointKernelAvx2(const PointArgs& a) {
  a.chart_centres ? PointKernelRows<6>(a) : PointKernelRows<3>(a);
}
__attribute__((target("avx512f"))) void PointKernelAvx512(const PointArgs& a) {
  a.chart_centres ? PointKernelRows<6>(a) : PointKernelRows<3>(a);
}
#endif

}  // namespace

void BatchPointEvaluator::Evaluate(const PointMeasurement& kind,
                                   const PointMeasurement::State& state, const ChainPoint& chain,
                                   const Eigen::Matrix3d* chart_centres, double* y, double* J) {
  Evaluate(kind, state, chain, chart_centres, y, J, ActiveIsa());
}

void BatchPointEvaluator::Evaluate(const PointMeasurement& kind,
                                   const PointMeasurement::State& state, const ChainPoint& chain,
                                   const Eigen::Matrix3d* chart_centres, double* y, double* J,
                                   Isa isa) {
  if ((chart_centres != nullptr) != kind.measures_orientation())
    throw std::invalid_argument("BatchPointEvaluator: a pose kind needs its chart centres");
  const PointArgs args{m_,
                       &kind,
                       &state,
                       &chain,
                       joint_arrays_.q.data(),
                       joint_arrays_.cq.data(),
                       joint_arrays_.sq.data(),
                       target_.data(),
                       state_.data(),
                       frames_.data(),
                       scratch_.data(),
                       chart_centres,
                       y,
                       J};
  switch (isa) {
#if defined(__x86_64__)
    case Isa::kAvx512:
      PointKernelAvx512(args);
      break;
    case Isa::kAvx2:
    case Isa::kAvx512OnAvx2:  // no lanes of its own: the AVX-512 variant is this code
      PointKernelAvx2(args);
      break;
#endif
    default:
      PointKernelDefault(args);
  }
}

}  // namespace lrcal
