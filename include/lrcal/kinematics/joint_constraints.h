// Moving an arm's joints until its tool satisfies constraints: a ball seated in a socket, a
// probe on a plane, a flange flat on a face. What simulations of constraint measurements use
// (socket_measurement.h, contact_measurement.h) and what their rank analysis linearises at.
#pragma once

#include <Eigen/Core>
#include <functional>

#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

/// The constraints' residual r (their count of rows) at a tool pose and its joint Jacobian J
/// (rows × N), given the tool pose and the geometric Jacobian G (6 × N: the tool origin's linear
/// velocity, then the angular velocity, in the base frame; chain.h).
using JointConstraints =
    std::function<void(const Pose<double>& pose, const Eigen::Matrix<double, 6, Eigen::Dynamic>& G,
                       Eigen::VectorXd* r, Eigen::MatrixXd* J)>;

/// Gauss–Newton steps of minimum norm on the joints q (rad or m, `robot`'s N, its nominal model)
/// until |r| < 1e-12, so the arm's remaining freedom keeps the starting posture as far as it can;
/// a step of more than 0.5 rad is shortened. Returns false (q at the last iterate) when that is
/// not reached in 100 steps: out of reach, or at a singularity.
bool SolveJointConstraints(const RobotModel& robot, int rows, const JointConstraints& constraints,
                           double* q);

/// Brings each revolute joint of q into its range (Link::q_min, q_max) by whole turns where it
/// can; true when every joint is then within its range.
bool WrapIntoJointRanges(const RobotModel& robot, double* q);

}  // namespace lrcal
