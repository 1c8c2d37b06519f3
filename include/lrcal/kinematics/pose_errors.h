// Validation: how far a model's tool pose is from the true robot's over a configuration set.
//
// Per configuration, in the base frame B: position error p_true − p_model (m) and orientation
// error φ = rotation vector of R_true·R_modelᵀ (rad). Per axis x, y, z: the RMS over the
// configurations and the maximum absolute value (the paper's validation table, which is in mm
// and mrad: conversion happens only in tables).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "lrcal/kinematics/chain.h"

namespace lrcal {

struct PoseErrorStats {
  Eigen::Vector3d rms_position = Eigen::Vector3d::Zero();     ///< m, per base axis
  Eigen::Vector3d max_position = Eigen::Vector3d::Zero();     ///< m, max |error| per axis
  Eigen::Vector3d rms_orientation = Eigen::Vector3d::Zero();  ///< rad
  Eigen::Vector3d max_orientation = Eigen::Vector3d::Zero();  ///< rad
};

/// Per-configuration errors (3×M each, columns = configurations) and their statistics.
struct PoseErrors {
  Eigen::Matrix3Xd position;     ///< m
  Eigen::Matrix3Xd orientation;  ///< rad
  PoseErrorStats stats;
};

/// Compares two sets of link values (5N, SI) of the same robot at every configuration.
PoseErrors ComparePoses(const RobotModel& robot, const Eigen::VectorXd& true_values,
                        const Eigen::VectorXd& model_values, const ConfigurationSet& configs);

/// The true robot's tool poses at every configuration (for ComparePoses below).
std::vector<Pose<double>> ToolPoses(const RobotModel& robot, const Eigen::VectorXd& link_values,
                                    const ConfigurationSet& configs);
/// The same as ComparePoses with the true poses computed beforehand.
PoseErrors ComparePoses(const RobotModel& robot, const std::vector<Pose<double>>& true_poses,
                        const Eigen::VectorXd& model_values, const ConfigurationSet& configs);

/// The same with both sets of poses given (as many true poses as model poses): a model whose poses
/// are not its link values' (compliance, thermal growth: environment_measurement.h).
PoseErrors ComparePoses(const std::vector<Pose<double>>& true_poses,
                        const std::vector<Pose<double>>& model_poses);

/// Rotation vector (axis·angle, rad) of a rotation matrix; exact near 0 and π.
Eigen::Vector3d RotationVector(const Eigen::Matrix3d& R);

}  // namespace lrcal
