// The point kind's values and Jacobian (point_measurement.h) for a whole set of configurations at
// once: the chain through batch_chain.h's structure-of-arrays steps, then the target's position
// in the instrument's frame and each term's three rows, every step a loop over the
// configurations. The arithmetic per configuration is the per-configuration evaluator's,
// operation for operation, so the values and the Jacobian have its bits (batch_point_test.cc),
// in every instruction-set variant (cpu_dispatch.h). The Jacobian is column-major (3m rows, row
// 3i + c the component c of configuration i), as MeasurementEvaluator::Predict writes it.
#pragma once

#include <vector>

#include "core/cpu_dispatch.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

class BatchPointEvaluator {
 public:
  /// Takes the configurations' joint values, their cos/sin and their targets.
  void SetConfigurations(const TargetedConfigurations& configs);
  int size() const { return m_; }

  /// The values y[0..3m) of `kind` (the point kind) at the geometry `state` and its prepared
  /// chain; if `J` is not null also ∂y/∂e into the column-major 3m×n matrix J.
  void Evaluate(const PointMeasurement& kind, const PointMeasurement::State& state,
                const ChainPoint& chain, double* y, double* J);
  /// The same with a chosen instruction-set variant: identical bits.
  void Evaluate(const PointMeasurement& kind, const PointMeasurement::State& state,
                const ChainPoint& chain, double* y, double* J, Isa isa);

 private:
  int m_ = 0, joints_ = 0;
  std::vector<double> q_, cq_, sq_;  // [joint·m + i]
  std::vector<int> target_;          // each configuration's target
  // Chain state, per-link frames and the target point's arrays (kScratchArrays of m).
  static constexpr int kScratchArrays = 12;
  std::vector<double> state_, frames_, scratch_;
};

}  // namespace lrcal
