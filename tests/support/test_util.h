// Shared helpers for lrcal's tests.
#pragma once

#include <random>
#include <string>
#include <utility>

#include "lrcal/io/robot_file.h"
#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_model.h"
#include "lrcal/study/runner.h"

namespace lrcal::testing {

/// Path of a file in the source tree (e.g. "studies/robots/paper.yaml").
std::string SourcePath(const std::string& relative);
/// Path of the built lrcal program.
std::string LrcalBinary();
/// The paper's robot file (studies/robots/paper.yaml): the arm, its plane and its ranger.
const RobotFile& PaperRig();
/// The paper's arm and plane.
const RobotModel& PaperRobot();
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
ConfigurationSet ConfigurationsFacing(const RobotModel& robot, const Plane& plane, int count,
                                      unsigned seed = 1);
/// `count` configurations of the paper's arm whose nominal beam hits `plane` (a usable reading),
/// drawn from a fixed std::mt19937 seed (test data only; the library uses counter-based streams).
ConfigurationSet HittingConfigurations(const Plane& plane, int count, unsigned seed = 1);
/// The same for the paper's own plane.
ConfigurationSet PaperHittingConfigurations(int count, unsigned seed = 1);
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
