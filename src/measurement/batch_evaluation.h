// Laser readings and the identification Jacobian for a whole set of configurations at once.
//
// The same mathematics as MeasurementModel::Evaluate (measurement_model.h), laid out as
// structure-of-arrays: every quantity of the chain (rotation columns, origins, the axes the
// Jacobian needs) is an array over the configurations, and each step of the chain is a loop over
// contiguous arrays that the compiler vectorises. The Jacobian is written column-major (m×n),
// ready for the normal equations' rank-k update. batch_evaluation_test.cc checks it against the
// per-configuration path. The Monte-Carlo hot path (LevenbergMarquardt) uses it.
#pragma once

#include <vector>

#include "core/cpu_dispatch.h"
#include "lrcal/measurement/measurement_model.h"
#include "measurement/batch_chain.h"

namespace lrcal {

class BatchEvaluator {
 public:
  /// Takes the configurations' joint values and their cos/sin (transposed to arrays per joint).
  void SetConfigurations(const TargetedConfigurations& configs);
  int size() const { return m_; }

  /// Readings h[0..m) at `point`; if `J` is not null also ∂h/∂e into the column-major m×n
  /// matrix J (leading dimension m). Returns false if some beam runs parallel to the plane
  /// (|n·b| ≤ 1e-12), whose h is then not finite.
  bool Evaluate(const MeasurementModel& model, const ModelPoint& point, double* h, double* J);
  /// The same with a chosen instruction-set variant (cpu_dispatch.h): identical bits.
  bool Evaluate(const MeasurementModel& model, const ModelPoint& point, double* h, double* J,
                Isa isa);

 private:
  int m_ = 0, joints_ = 0, num_targets_referenced_ = 0;
  batch::JointArrays joint_arrays_;
  // Each configuration's plane; empty when every configuration is aimed at plane 0 (the
  // single-plane kernel, which keeps the plane's normal in registers).
  std::vector<int> plane_;
  // Chain state and per-link frames: [(link·kFrameArrays + k)·m + i].
  std::vector<double> state_, frames_, scratch_;
};

}  // namespace lrcal
