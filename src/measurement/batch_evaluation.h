// Laser readings and the identification Jacobian for a whole set of configurations at once.
//
// The same mathematics as MeasurementModel::Evaluate (measurement_model.h), vectorised over the
// configurations: the kernel takes them a block at a time (2, 4 or 8, the variant's vector
// width), follows the block through the chain with the running frame in registers, and writes
// its readings and its rows of the Jacobian (column-major m×n, ready for the normal equations)
// before the next block. batch_evaluation_test.cc checks it against the per-configuration path
// and cpu_dispatch_test.cc checks that every variant gives the same bits. The Monte-Carlo hot
// path (LevenbergMarquardt) uses it.
#pragma once

#include <vector>

#include "core/cpu_dispatch.h"
#include "lrcal/measurement/measurement_model.h"

namespace lrcal {

class BatchEvaluator {
 public:
  /// Takes the configurations' joint values and their cos/sin (transposed to arrays per joint).
  /// The configurations already taken (the same joint values, bit for bit, and the same
  /// targets: a Monte-Carlo trial on its cell's design) are kept as they are: cos and sin are
  /// functions of q (ConfigurationSet::Add), so the arrays would not change.
  void SetConfigurations(const TargetedConfigurations& configs);
  int size() const { return m_; }

  /// Readings h[0..m) at `point`; if `J` is not null also ∂h/∂e into the column-major m×n
  /// matrix J (leading dimension m). Returns false if some beam runs parallel to the plane
  /// (|n·b| ≤ 1e-12), whose h is then not finite.
  /// With `row_scale` (m values), J's rows come weighted: J(i, k) · row_scale[i], as the one
  /// multiplication of a separate pass (the kernel multiplies as it stores, or, when the ranger's
  /// terms change J after it, a pass at the end).
  bool Evaluate(const MeasurementModel& model, const ModelPoint& point, double* h, double* J,
                const double* row_scale = nullptr);
  /// The same with a chosen instruction-set variant (cpu_dispatch.h): identical bits.
  bool Evaluate(const MeasurementModel& model, const ModelPoint& point, double* h, double* J,
                Isa isa, const double* row_scale = nullptr);

 private:
  // The widest block the kernel takes (AVX-512: eight doubles).
  static constexpr int kMaxLanes = 8;
  int m_ = 0, joints_ = 0, num_targets_referenced_ = 0, stride_ = 0;
  // The configurations' joint values and their cos/sin, one array per joint
  // ([joint·stride + i], padded to whole blocks by repeating the last configuration).
  std::vector<double> q_, cq_, sq_;
  // Each configuration's plane; empty when every configuration is aimed at plane 0 (the
  // single-plane kernel, which keeps the plane's normal in registers).
  std::vector<int> plane_;
  // The configurations taken, as given (row-major q and the targets), to recognise them.
  std::vector<double> taken_q_;
  std::vector<int> taken_targets_;
};

}  // namespace lrcal
