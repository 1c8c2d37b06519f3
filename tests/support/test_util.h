// Shared helpers for lrcal's tests.
#pragma once

#include <gmock/gmock.h>

#include <Eigen/Core>
#include <random>
#include <string>
#include <utility>

#include "lrcal/io/robot_file.h"
#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_model.h"
#include "lrcal/study/runner.h"

namespace lrcal::testing {

/// Named tolerances: what each kind of agreement is held to, in one place.
namespace tolerance {
/// Two computations of the same formula in a different order (rounding only): rotations composed
/// from the same angles, exported and re-read kinematics (m, rad).
inline constexpr double kRounding = 1e-15;
/// lrcal's kinematics against a URDF composed independently in the test (m, rad).
inline constexpr double kUrdf = 1e-12;
/// An analytic Jacobian against Ceres' autodiff of the same model.
inline constexpr double kAutodiff = 1e-11;
/// An analytic Jacobian against central differences (step ~1e-6: truncation ~1e-10 plus
/// rounding).
inline constexpr double kCentralDifference = 1e-8;
/// A noise-free identification against the truth it was simulated from (SI).
inline constexpr double kRoundTrip = 1e-9;
}  // namespace tolerance

/// Matches an Eigen vector or matrix of `expected`'s shape whose every entry lies within
/// `tolerance` of `expected`'s (the max-norm of the difference); on failure it says the largest
/// deviation and where it is. Non-finite entries never match.
MATCHER_P2(EigenNear, expected, tolerance,
           std::string(negation ? "is not" : "is") + " within " +
               ::testing::PrintToString(tolerance) + " of the expected matrix entry by entry") {
  if (arg.rows() != expected.rows() || arg.cols() != expected.cols()) {
    *result_listener << "whose shape is " << arg.rows() << "x" << arg.cols() << ", not "
                     << expected.rows() << "x" << expected.cols();
    return false;
  }
  const Eigen::MatrixXd difference = (Eigen::MatrixXd(arg) - Eigen::MatrixXd(expected)).cwiseAbs();
  if (!difference.allFinite()) {
    *result_listener << "which has a non-finite entry";
    return false;
  }
  Eigen::Index row = 0, col = 0;
  const double largest = difference.size() ? difference.maxCoeff(&row, &col) : 0.0;
  *result_listener << "whose largest deviation is " << largest << " at (" << row << ", " << col
                   << ")";
  return largest <= tolerance;
}

/// Path of a file in the source tree (e.g. "studies/robots/paper.yaml").
std::string SourcePath(const std::string& relative);
/// Path of the built lrcal program.
std::string LrcalBinary();
/// The paper's robot file (studies/robots/paper.yaml): the arm, its plane and its ranger.
const RobotFile& PaperRig();
/// The paper's arm and plane.
const RobotModel& PaperRobot();
/// The paper's simulated arm (its robot file's true_errors): the errors (5N, SI) and the true
/// link values, nominal + errors. PaperRobotWithFrames has the same links and the same truth.
const Eigen::VectorXd& PaperTrueErrors();
const Eigen::VectorXd& PaperTrueValues();
const Plane& PaperPlane();
/// The paper's arm on a tilted, shifted base with the ranger mounted off the flange (a tool
/// transform of 3–10 cm and 0.1–0.3 rad): the base and tool frames of a real rig.
const RobotModel& PaperRobotWithFrames();
/// The geometric Jacobian of `robot` at its nominal values and q (6 joints) against central
/// differences (step 1e-6) of its forward kinematics: the largest deviation of a column's linear
/// part (m/rad) and of its angular part (the skew part of dR·Rᵀ, rad/rad).
std::pair<double, double> GeometricJacobianDeviation(const RobotModel& robot, const double* q);
/// `count` random configurations of `robot` whose beam meets `plane` at |n·b| ≥ 0.2 (any sign of
/// the distance): for checks of formulas, not of readings.
TargetedConfigurations ConfigurationsFacing(const RobotModel& robot, const Plane& plane, int count,
                                            unsigned seed = 1);
/// `count` configurations of the paper's arm whose nominal beam hits `plane` (a usable reading),
/// drawn from a fixed std::mt19937 seed (test data only; the library uses counter-based streams).
TargetedConfigurations HittingConfigurations(const Plane& plane, int count, unsigned seed = 1);
/// The same for the paper's own plane.
TargetedConfigurations PaperHittingConfigurations(int count, unsigned seed = 1);
/// Writes a candidate pool (`pool` configurations whose beam hits the paper's plane) and a
/// validation set (`validation` configurations anywhere) of the paper's arm to DIR/pool.csv and
/// DIR/val.csv, drawn with the given seeds: a user's own configuration files for a study.
void WritePaperConfigurationFiles(const std::string& dir, int pool, int validation,
                                  std::uint64_t pool_seed, std::uint64_t validation_seed);
/// Runs (or resumes) the study file at `study` into `out` quietly and writes its tables, with
/// small batches (several transactions even in small runs).
RunResult RunStudyFile(const std::string& study, const std::string& out, int threads,
                       int shard_index = 0, int shard_count = 1, long long max_new = 0,
                       int batch_size = 7);
/// Runs a shell command, returns its exit code and captures stdout+stderr into `output`.
int RunCommand(const std::string& command, std::string* output);
/// The bytes of a file ("" if it cannot be read).
std::string ReadFile(const std::string& path);
/// A fresh empty temporary directory for one test.
std::string TempDir(const std::string& name);

}  // namespace lrcal::testing
