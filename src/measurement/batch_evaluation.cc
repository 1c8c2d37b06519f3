#include "measurement/batch_evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/cpu_dispatch.h"
#include "core/dense_kernel_variants.h"
#include "core/lanes.h"

namespace lrcal {

void BatchEvaluator::SetConfigurations(const TargetedConfigurations& configs) {
  const std::size_t values = static_cast<std::size_t>(configs.size()) * configs.num_joints();
  const double* q = configs.size() > 0 ? configs.q(0) : nullptr;
  if (configs.size() == m_ && configs.num_joints() == joints_ && taken_q_.size() == values &&
      (values == 0 || std::memcmp(taken_q_.data(), q, values * sizeof(double)) == 0) &&
      configs.targets() == taken_targets_)
    return;
  taken_q_.assign(q, q + values);
  taken_targets_ = configs.targets();
  m_ = configs.size();
  joints_ = configs.num_joints();
  // Padded to whole blocks of kMaxLanes; the padding repeats the last configuration (finite
  // values whose results are never stored).
  stride_ = (m_ + kMaxLanes - 1) / kMaxLanes * kMaxLanes;
  const std::size_t size = static_cast<std::size_t>(joints_) * stride_;
  q_.resize(size);
  cq_.resize(size);
  sq_.resize(size);
  for (int i = 0; i < stride_; ++i) {
    const int from = std::min(i, m_ - 1);
    for (int j = 0; j < joints_; ++j) {
      const std::size_t at = static_cast<std::size_t>(j) * stride_ + i;
      q_[at] = from < 0 ? 0.0 : configs.q(from)[j];
      cq_[at] = from < 0 ? 1.0 : configs.cos_q(from)[j];
      sq_[at] = from < 0 ? 0.0 : configs.sin_q(from)[j];
    }
  }
  plane_.clear();
  num_targets_referenced_ = configs.num_targets_referenced();
  if (num_targets_referenced_ > 1) {
    plane_.resize(stride_);
    for (int i = 0; i < stride_; ++i) plane_[i] = configs.target(std::min(i, m_ - 1));
  }
}

namespace {

// The kernel runs on blocks of W configurations at once, each quantity a vector of W doubles
// (GCC's vector extension: elementwise IEEE arithmetic, lowered to the variant's registers), and
// follows one block through the whole chain, the readings and the Jacobian before the next: the
// chain's running frame stays in registers and the link frames the Jacobian needs stay in a few
// kilobytes of first-level cache. Each configuration's arithmetic is MeasurementModel's fast path
// operation for operation (the same expressions in the same order, and -ffp-contract=off forbids
// fused multiply-adds), so every variant and every block width gives the same bits.

using lanes::All;
using lanes::Load;
using lanes::Store;

struct KernelArgs {
  int m;       // configurations (J's leading dimension)
  int stride;  // of the joint arrays (m rounded up to whole blocks)
  const ModelPoint* point;
  const ParameterSet* parameters;
  const double* q;
  const double* cq;
  const double* sq;
  const int* plane;  // per configuration; null when all are aimed at plane 0
  double* h;
  double* J;
  const double* row_scale;  // J's row weights (m values); null: none
};

template <typename V>
struct BlockVec3 {
  V c0, c1, c2;
};

// A link's frames kept for the Jacobian (ChainFrames' o_prev, z_prev, x_common, y_twist, o).
template <typename V>
struct BlockLinkFrames {
  BlockVec3<V> z_prev, o_prev, x_common, y_twist, o;
};

// The running frame: axes x, y, z and origin o.
template <typename V>
struct BlockFrame {
  BlockVec3<V> x, y, z, o;
};

template <typename V>
[[gnu::always_inline]] inline BlockFrame<V> BlockAtBase(const ModelPoint& point) {
  const Eigen::Matrix3d& rb = point.base.rotation;
  const Eigen::Vector3d& pb = point.base.translation;
  const auto all = [](double x) { return All<V>(x); };
  return {{all(rb(0, 0)), all(rb(1, 0)), all(rb(2, 0))},
          {all(rb(0, 1)), all(rb(1, 1)), all(rb(2, 1))},
          {all(rb(0, 2)), all(rb(1, 2)), all(rb(2, 2))},
          {all(pb(0)), all(pb(1)), all(pb(2))}};
}

// Through link l (D-H + β): batch::PropagateLink's arithmetic.
template <typename V, bool kJacobian>
[[gnu::always_inline]] inline void PropagateBlock(const ChainPoint::LinkTrig& t, const V& q,
                                                  const V& cq, const V& sq, BlockFrame<V>* s,
                                                  BlockLinkFrames<V>* f) {
  const double ct0 = t.cos_theta0, st0 = t.sin_theta0, ca = t.cos_alpha, sa = t.sin_alpha,
               cb = t.cos_beta, sb = t.sin_beta, a = t.a, d0 = t.d;
  const double revolute = t.prismatic ? 0.0 : 1.0;
  const V ct = revolute * (ct0 * cq - st0 * sq) + (1 - revolute) * ct0;
  const V st = revolute * (st0 * cq + ct0 * sq) + (1 - revolute) * st0;
  const V d = d0 + (1 - revolute) * q;
  BlockVec3<V>& x = s->x;
  BlockVec3<V>& y = s->y;
  BlockVec3<V>& z = s->z;
  BlockVec3<V>& o = s->o;
  const BlockVec3<V> xc{ct * x.c0 + st * y.c0, ct * x.c1 + st * y.c1, ct * x.c2 + st * y.c2};
  const BlockVec3<V> yr{ct * y.c0 - st * x.c0, ct * y.c1 - st * x.c1, ct * y.c2 - st * x.c2};
  const BlockVec3<V> yt{ca * yr.c0 + sa * z.c0, ca * yr.c1 + sa * z.c1, ca * yr.c2 + sa * z.c2};
  const BlockVec3<V> za{ca * z.c0 - sa * yr.c0, ca * z.c1 - sa * yr.c1, ca * z.c2 - sa * yr.c2};
  if constexpr (kJacobian) {
    f->z_prev = z;
    f->o_prev = o;
    f->x_common = xc;
    f->y_twist = yt;
  }
  o.c0 += a * xc.c0 + d * z.c0;
  o.c1 += a * xc.c1 + d * z.c1;
  o.c2 += a * xc.c2 + d * z.c2;
  if constexpr (kJacobian) f->o = o;
  x = {cb * xc.c0 - sb * za.c0, cb * xc.c1 - sb * za.c1, cb * xc.c2 - sb * za.c2};
  z = {sb * xc.c0 + cb * za.c0, sb * xc.c1 + cb * za.c1, sb * xc.c2 + cb * za.c2};
  y = yt;
}

// The tool frame: p ← p + R·t, R ← R·R_tool (batch::ApplyTool's arithmetic).
template <typename V>
[[gnu::always_inline]] inline void ApplyToolToBlock(const ChainPoint& point, BlockFrame<V>* s) {
  const Eigen::Matrix3d& rt = point.tool.rotation;
  const Eigen::Vector3d& pt = point.tool.translation;
  const BlockFrame<V> r = *s;
  const auto row = [&](const V& xr, const V& yr, const V& zr, V* o, V* x, V* y, V* z) {
    *o += xr * pt(0) + yr * pt(1) + zr * pt(2);
    *x = xr * rt(0, 0) + yr * rt(1, 0) + zr * rt(2, 0);
    *y = xr * rt(0, 1) + yr * rt(1, 1) + zr * rt(2, 1);
    *z = xr * rt(0, 2) + yr * rt(1, 2) + zr * rt(2, 2);
  };
  row(r.x.c0, r.y.c0, r.z.c0, &s->o.c0, &s->x.c0, &s->y.c0, &s->z.c0);
  row(r.x.c1, r.y.c1, r.z.c1, &s->o.c1, &s->x.c1, &s->y.c1, &s->z.c1);
  row(r.x.c2, r.y.c2, r.z.c2, &s->o.c2, &s->x.c2, &s->y.c2, &s->z.c2);
}

// The reading and what the Jacobian needs of it: the plane's normal n and offset f, −1/(n·b),
// the hit point.
template <typename V>
struct BlockReading {
  BlockVec3<V> n;
  V f, h, inv, nb;
  BlockVec3<V> ph;
};

// (r × n)·axis / (−n·b) with r = ph − c: a rotation about an axis through c.
template <typename V>
[[gnu::always_inline]] inline V BlockTurnColumn(const BlockReading<V>& r, const BlockVec3<V>& c,
                                                const BlockVec3<V>& axis) {
  const V r0 = r.ph.c0 - c.c0, r1 = r.ph.c1 - c.c1, r2 = r.ph.c2 - c.c2;
  const BlockVec3<V>& n = r.n;
  const V g = (r1 * n.c2 - r2 * n.c1) * axis.c0 + (r2 * n.c0 - r0 * n.c2) * axis.c1 +
              (r0 * n.c1 - r1 * n.c0) * axis.c2;
  return g * r.inv;
}

// n·axis / (−n·b): a shift along an axis.
template <typename V>
[[gnu::always_inline]] inline V BlockShiftColumn(const BlockReading<V>& r,
                                                 const BlockVec3<V>& axis) {
  return (r.n.c0 * axis.c0 + r.n.c1 * axis.c1 + r.n.c2 * axis.c2) * r.inv;
}

// The column of link value `index`: d and a move the origin along an axis; θ, α and β turn
// about an axis through a point (θ: z_prev through o_prev; α: x_common through o; β: y_twist
// through o).
template <typename V>
[[gnu::always_inline]] inline V BlockLinkColumn(const BlockLinkFrames<V>* frames, int index,
                                                const BlockReading<V>& r) {
  const BlockLinkFrames<V>& f = frames[index / kValuesPerLink];
  switch (index % kValuesPerLink) {
    case kD:
      return BlockShiftColumn(r, f.z_prev);
    case kA:
      return BlockShiftColumn(r, f.x_common);
    case kTheta:
      return BlockTurnColumn(r, f.o_prev, f.z_prev);
    case kAlpha:
      return BlockTurnColumn(r, f.o, f.x_common);
    default:
      return BlockTurnColumn(r, f.o, f.y_twist);
  }
}

// One estimated base or tool term's column: a shift moves the hit point along v, a rotation
// turns it about v through a point; the base's v and point are fixed in B, the tool's v turns
// with the tool (R_BT·v) and its point is the beam's origin.
template <typename V, bool kTool, bool kShift>
[[gnu::always_inline]] inline V BlockFrameColumn(const ModelPoint& point, const BlockFrame<V>& s,
                                                 const BlockReading<V>& r,
                                                 const Eigen::Vector3d& v) {
  BlockVec3<V> w{All<V>(v[0]), All<V>(v[1]), All<V>(v[2])};
  if constexpr (kTool) {
    w = {s.x.c0 * v[0] + s.y.c0 * v[1] + s.z.c0 * v[2],
         s.x.c1 * v[0] + s.y.c1 * v[1] + s.z.c1 * v[2],
         s.x.c2 * v[0] + s.y.c2 * v[1] + s.z.c2 * v[2]};
  }
  if constexpr (kShift) {
    return BlockShiftColumn(r, w);
  } else {
    const Eigen::Vector3d& pb = point.base.translation;
    const BlockVec3<V> c = kTool ? s.o : BlockVec3<V>{All<V>(pb[0]), All<V>(pb[1]), All<V>(pb[2])};
    return BlockTurnColumn(r, c, w);
  }
}

// The reading of configurations i0 … from the block's final frame s: h = −(n·o + f)/(n·b), and
// what the Jacobian needs of it.
template <typename V>
[[gnu::always_inline]] inline BlockReading<V> BlockReadingOf(const KernelArgs& args, int i0,
                                                             const BlockFrame<V>& s) {
  const ModelPoint& point = *args.point;
  BlockReading<V> r;
  if (args.plane) {
    for (int k = 0; k < lanes::kWidth<V>; ++k) {
      const Plane& p = point.planes[args.plane[i0 + k]];
      r.n.c0[k] = p.normal.x();
      r.n.c1[k] = p.normal.y();
      r.n.c2[k] = p.normal.z();
      r.f[k] = p.offset;
    }
  } else {
    const Plane& p = point.planes[0];
    r.n = {All<V>(p.normal.x()), All<V>(p.normal.y()), All<V>(p.normal.z())};
    r.f = All<V>(p.offset);
  }
  const BlockVec3<V>& n = r.n;
  r.nb = n.c0 * s.z.c0 + n.c1 * s.z.c1 + n.c2 * s.z.c2;
  r.h = -(n.c0 * s.o.c0 + n.c1 * s.o.c1 + n.c2 * s.o.c2 + r.f) / r.nb;
  r.inv = -1.0 / r.nb;
  r.ph = {s.o.c0 + r.h * s.z.c0, s.o.c1 + r.h * s.z.c1, s.o.c2 + r.h * s.z.c2};
  return r;
}

// J's rows i0 … i0 + valid − 1 in column c.
[[gnu::always_inline]] inline double* BlockColumn(const KernelArgs& args, int c, int i0) {
  return args.J + static_cast<std::size_t>(c) * args.m + i0;
}

// Plane p's chart u (two) and offset f: nonzero on the configurations aimed at plane p.
template <typename V>
[[gnu::always_inline]] inline void BlockPlaneColumns(const KernelArgs& args, int i0, int valid,
                                                     const BlockReading<V>& r, const V& w) {
  const ParameterSet& ps = *args.parameters;
  for (int p = 0; p < ps.num_planes(); ++p) {
    const PlaneColumns& pc = ps.plane_columns[p];
    V own = All<V>(p == 0 ? 1.0 : 0.0);
    if (args.plane)
      for (int k = 0; k < lanes::kWidth<V>; ++k) own[k] = args.plane[i0 + k] == p ? 1.0 : 0.0;
    for (int c = 0; c < 2; ++c) {
      if (pc.u[c] < 0) continue;
      const Eigen::Matrix<double, 3, 2>& dn_du = args.point->dn_du[p];
      const double d0 = dn_du(0, c), d1 = dn_du(1, c), d2 = dn_du(2, c);
      Store(BlockColumn(args, pc.u[c], i0),
            own * ((r.ph.c0 * d0 + r.ph.c1 * d1 + r.ph.c2 * d2) * r.inv) * w, valid);
    }
    if (pc.f >= 0) Store(BlockColumn(args, pc.f, i0), own * r.inv * w, valid);
  }
}

// Every estimated base and tool term's column.
template <typename V>
[[gnu::always_inline]] inline void BlockFrameColumns(const KernelArgs& args, int i0, int valid,
                                                     const BlockFrame<V>& s,
                                                     const BlockReading<V>& r, const V& w) {
  const ModelPoint& point = *args.point;
  const int* base = args.parameters->frame_columns[0];
  const int* tool = args.parameters->frame_columns[1];
  for (int k = 0; k < 3; ++k) {
    if (base[k] >= 0)
      Store(BlockColumn(args, base[k], i0),
            BlockFrameColumn<V, false, true>(point, s, r, Eigen::Vector3d::Unit(k)) * w, valid);
    if (base[3 + k] >= 0)
      Store(BlockColumn(args, base[3 + k], i0),
            BlockFrameColumn<V, false, false>(point, s, r, point.base_axes.col(k)) * w, valid);
    if (tool[k] >= 0)
      Store(BlockColumn(args, tool[k], i0),
            BlockFrameColumn<V, true, true>(point, s, r, point.tool_shifts_T.col(k)) * w, valid);
    if (tool[3 + k] >= 0)
      Store(BlockColumn(args, tool[3 + k], i0),
            BlockFrameColumn<V, true, false>(point, s, r, point.tool_axes_T.col(k)) * w, valid);
  }
}

// Configurations i0 … i0 + valid − 1 (valid ≤ W): their readings into h and, with kJacobian,
// their rows of J. Returns how many beams run along their plane.
template <typename V, bool kJacobian>
[[gnu::always_inline]] inline int Block(const KernelArgs& args, int i0, int valid) {
  const ModelPoint& point = *args.point;
  BlockFrame<V> s = BlockAtBase<V>(point);
  BlockLinkFrames<V> frames[kJacobian ? kMaxLinks : 1];
  for (int l = 0; l < point.num_links; ++l) {
    const std::size_t at = static_cast<std::size_t>(l) * args.stride + i0;
    PropagateBlock<V, kJacobian>(point.links[l], Load<V>(args.q + at), Load<V>(args.cq + at),
                                 Load<V>(args.sq + at), &s, &frames[kJacobian ? l : 0]);
  }
  if (point.has_tool) ApplyToolToBlock(point, &s);
  const BlockReading<V> r = BlockReadingOf(args, i0, s);
  Store(args.h + i0, r.h, valid);
  int parallel = 0;
  for (int k = 0; k < valid; ++k) parallel += std::fabs(r.nb[k]) <= kParallelBeamThreshold;
  if constexpr (kJacobian) {
    // The rows' weights (1 without: x · 1 = x exactly), the last multiplication of each entry.
    V w = All<V>(1.0);
    if (args.row_scale) {
      if (valid == lanes::kWidth<V>)
        w = Load<V>(args.row_scale + i0);
      else
        for (int k = 0; k < valid; ++k) w[k] = args.row_scale[i0 + k];
    }
    const ParameterSet& ps = *args.parameters;
    for (int k = 0; k < ps.num_robot(); ++k)
      Store(BlockColumn(args, k, i0), BlockLinkColumn(frames, ps.robot_values[k], r) * w, valid);
    BlockPlaneColumns(args, i0, valid, r, w);
    if (ps.EstimatesFrames()) BlockFrameColumns(args, i0, valid, s, r, w);
  }
  return parallel;
}

template <int W>
[[gnu::always_inline]] inline bool KernelBody(const KernelArgs& args) {
  using V = typename lanes::VectorOf<W>::type;
  int parallel = 0;
  for (int i0 = 0; i0 < args.m; i0 += W) {
    const int valid = std::min(W, args.m - i0);
    parallel += args.J ? Block<V, true>(args, i0, valid) : Block<V, false>(args, i0, valid);
  }
  return parallel == 0;
}

bool KernelDefault(const KernelArgs& a) { return KernelBody<2>(a); }
#if defined(__x86_64__)
__attribute__((target("avx2"))) bool KernelAvx2(const KernelArgs& a) { return KernelBody<4>(a); }
__attribute__((target("avx512f"))) bool KernelAvx512(const KernelArgs& a) {
  return KernelBody<8>(a);
}
// The AVX-512 variant's blocks of eight on an AVX2 machine (cpu_dispatch.h, Isa::kAvx512OnAvx2).
__attribute__((target("avx2"))) bool KernelAvx512OnAvx2(const KernelArgs& a) {
  return KernelBody<8>(a);
}
#endif

}  // namespace

bool BatchEvaluator::Evaluate(const MeasurementModel& model, const ModelPoint& point, double* h,
                              double* J, const double* row_scale) {
  return Evaluate(model, point, h, J, ActiveIsa(), row_scale);
}

bool BatchEvaluator::Evaluate(const MeasurementModel& model, const ModelPoint& point, double* h,
                              double* J, Isa isa, const double* row_scale) {
  if (num_targets_referenced_ > model.num_planes())
    throw std::invalid_argument("BatchEvaluator: a configuration is aimed at plane " +
                                std::to_string(num_targets_referenced_) + " of " +
                                std::to_string(model.num_planes()));
  // The ranger's terms change J after the kernel (MeasurementModel::ApplyRanger): the rows are
  // weighted after them, in a pass of their own.
  const ParameterSet& ps = model.parameters();
  const bool ranger_changes_J = model.RangerChangesJacobian(point);
  const KernelArgs args{m_,
                        stride_,
                        &point,
                        &ps,
                        q_.data(),
                        cq_.data(),
                        sq_.data(),
                        plane_.empty() ? nullptr : plane_.data(),
                        h,
                        J,
                        ranger_changes_J ? nullptr : row_scale};
  bool ok;
  switch (isa) {
#if defined(__x86_64__)
    case Isa::kAvx512:
      ok = KernelAvx512(args);
      break;
    case Isa::kAvx512OnAvx2:
      ok = KernelAvx512OnAvx2(args);
      break;
    case Isa::kAvx2:
      ok = KernelAvx2(args);
      break;
#endif
    default:
      ok = KernelDefault(args);
  }
  model.ApplyRanger(point, m_, h, J);
  if (J && row_scale && ranger_changes_J) ScaleRows(row_scale, m_, model.num_parameters(), J, isa);
  return ok;
}

}  // namespace lrcal
