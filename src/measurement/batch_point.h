// The point and pose kinds' values and Jacobian (point_measurement.h, pose_measurement.h) for a
// whole set of configurations at once: the chain through batch_chain.h's structure-of-arrays
// steps, then the target's position in the instrument's frame and each term's rows, every step a
// loop over the configurations; a pose's orientation (a rotation logarithm per configuration) in
// a loop of Eigen's 3 × 3 arithmetic, its Jacobian rows again over arrays. Every instruction-set
// variant (cpu_dispatch.h) gives the same bits (batch_point_test.cc); point_measurement_test.cc
// and pose_measurement_test.cc check the Jacobian against autodiff and central differences. The
// Jacobian is column-major (Km rows, K = 3 or 6 values a configuration, row Ki + c the value c of
// configuration i), as MeasurementEvaluator::Predict writes it.
#pragma once

#include <vector>

#include "core/cpu_dispatch.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/measurement/targeted_configurations.h"
#include "measurement/batch_chain.h"

namespace lrcal {

class BatchPointEvaluator {
 public:
  /// Takes the configurations' joint values, their cos/sin and their targets.
  void SetConfigurations(const TargetedConfigurations& configs);
  int size() const { return m_; }

  /// The values y[0..Km) of `kind` at the geometry `state` and its prepared chain; if `J` is not
  /// null also ∂y/∂e into the column-major Km×n matrix J (every entry written). A pose kind
  /// (K = 6) needs each configuration's chart centre (PoseMeasurement::ChartCentre), a point kind
  /// none (null); std::invalid_argument otherwise.
  void Evaluate(const PointMeasurement& kind, const PointMeasurement::State& state,
                const ChainPoint& chain, const Eigen::Matrix3d* chart_centres, double* y,
                double* J);
  /// The same with a chosen instruction-set variant: identical bits.
  void Evaluate(const PointMeasurement& kind, const PointMeasurement::State& state,
                const ChainPoint& chain, const Eigen::Matrix3d* chart_centres, double* y, double* J,
                Isa isa);

 private:
  int m_ = 0, joints_ = 0;
  batch::JointArrays joint_arrays_;
  std::vector<int> target_;  // each configuration's target
  // Chain state, per-link frames and the per-configuration arrays of the values' and the
  // Jacobian's steps (kScratchArrays of m).
  static constexpr int kScratchArrays = 40;
  std::vector<double> state_, frames_, scratch_;
};

}  // namespace lrcal
