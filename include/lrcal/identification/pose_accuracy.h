// How accurate a calibrated arm will be at given poses: the parameter covariance of an
// identification propagated, to first order, to the tool pose.
//
// For a configuration q, J(q) = ∂(pose error)/∂e (6 × n, by central differences of the model's
// link values: position in the base frame, m, then the rotation vector, rad, as in
// pose_errors.h) and the pose covariance is J·C·Jᵀ for the estimate's covariance C. Reported per
// pose: the standard deviation of each position and orientation component and the radius that
// contains the position error with 95 % probability (the 0.95 quantile of |x| for x ~ N(0, Σ_p):
// a weighted sum of χ²₁ variables, evaluated from 20,000 fixed draws, ~0.5 % accurate).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/kinematics/configuration_set.h"
#include "lrcal/measurement/measurement_model.h"

namespace lrcal {

struct PoseAccuracy {
  Eigen::Vector3d position_std = Eigen::Vector3d::Zero();     ///< m, base x, y, z
  Eigen::Vector3d orientation_std = Eigen::Vector3d::Zero();  ///< rad, rotation vector x, y, z
  double position_radius_95 = 0;                              ///< m
  /// The total (total_accuracy.h): the data part above plus everything the calibration held at
  /// nominal, propagated from its prior. Equal to the data part when nothing is held.
  Eigen::Vector3d position_std_total = Eigen::Vector3d::Zero();     ///< m
  Eigen::Vector3d orientation_std_total = Eigen::Vector3d::Zero();  ///< rad
  double position_radius_95_total = 0;                              ///< m
};

/// A pose's accuracy from its 6 × 6 pose covariances (position m, then rotation vector rad): the
/// data part `data` and the total `total` (pass `data` twice when nothing is held).
PoseAccuracy PoseAccuracyFromCovariance(const Eigen::Matrix<double, 6, 6>& data,
                                        const Eigen::Matrix<double, 6, 6>& total);

/// Over a set of poses: the RMS of the predicted position error (√ of the mean of tr Σ_p), the
/// 95th percentile of the per-pose 95 % radius, and the pose where that radius is largest.
struct PoseAccuracySummary {
  double rms_position = 0;   ///< m
  double p95_radius_95 = 0;  ///< m
  int worst = -1;            ///< index of the pose with the largest 95 % radius
};

/// ∂(pose)/∂e at estimate e for every configuration: 6M × n, rows 6j..6j+2 position,
/// 6j+3..6j+5 orientation of configuration j.
Eigen::MatrixXd PoseJacobian(const MeasurementModel& model, const double* e,
                             const ConfigurationSet& configs);

/// The position rows of a PoseJacobian (6M × n): 3M × n, rows 3j..3j+2 of configuration j.
Eigen::MatrixXd PositionRows(const Eigen::MatrixXd& pose_jacobian);

/// The predicted accuracy at every configuration for an estimate e with covariance C (n × n,
/// SI). Throws InputError if C is not n × n.
std::vector<PoseAccuracy> PredictPoseAccuracy(const MeasurementModel& model, const double* e,
                                              const Eigen::MatrixXd& covariance,
                                              const ConfigurationSet& configs);

PoseAccuracySummary SummarizePoseAccuracy(const std::vector<PoseAccuracy>& poses);

}  // namespace lrcal
