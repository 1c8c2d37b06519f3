#include "test_util.h"

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "lrcal/core/random.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/io/csv.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/report/run_tables.h"

namespace lrcal::testing {

std::string SourcePath(const std::string& relative) {
  return std::string(LRCAL_SOURCE_DIR) + "/" + relative;
}

std::string LrcalBinary() { return std::string(LRCAL_BINARY_DIR) + "/lrcal"; }

const RobotFile& PaperRig() {
  static const RobotFile rig = LoadRobotFile(SourcePath("studies/robots/paper.yaml"));
  return rig;
}

const RobotModel& PaperRobot() { return PaperRig().robot; }
const Eigen::VectorXd& PaperTrueErrors() {
  static const Eigen::VectorXd errors = PaperRig().truth.LinkErrors(PaperRobot());
  return errors;
}
const Eigen::VectorXd& PaperTrueValues() {
  static const Eigen::VectorXd values = PaperRig().truth.LinkValues(PaperRobot());
  return values;
}

const Plane& PaperPlane() { return (*PaperRig().planes)[0]; }

std::pair<double, double> GeometricJacobianDeviation(const RobotModel& robot, const double* q) {
  const auto J = GeometricJacobian(robot, robot.nominal_values(), q);
  const double step = 1e-6;
  double linear = 0, angular = 0;
  for (int j = 0; j < 6; ++j) {
    double qp[6], qm[6];
    std::copy(q, q + 6, qp);
    std::copy(q, q + 6, qm);
    qp[j] += step;
    qm[j] -= step;
    const auto pp = ForwardKinematics<double>(robot, robot.nominal_values().data(), qp);
    const auto pm = ForwardKinematics<double>(robot, robot.nominal_values().data(), qm);
    const Eigen::Vector3d v = (pp.p_BT - pm.p_BT) / (2 * step);
    const Eigen::Matrix3d dR = (pp.R_BT - pm.R_BT) / (2 * step) * pp.R_BT.transpose();
    const Eigen::Vector3d w(dR(2, 1), dR(0, 2), dR(1, 0));
    linear = std::max(linear, (J.col(j).head<3>() - v).norm());
    angular = std::max(angular, (J.col(j).tail<3>() - w).norm());
  }
  return {linear, angular};
}

const RobotModel& PaperRobotWithFrames() {
  static const RobotModel robot = [] {
    const RobotModel& paper = PaperRobot();
    const RigidTransform base = RigidTransform::FromXyzRpy(Eigen::Vector3d(0.2, -0.1, 0.3),
                                                           Eigen::Vector3d(0.05, -0.1, 0.7));
    const RigidTransform tool = RigidTransform::FromXyzRpy(Eigen::Vector3d(0.03, -0.05, 0.1),
                                                           Eigen::Vector3d(0.2, -0.3, 0.1));
    return RobotModel("paper with frames", paper.links(), "test", base, tool);
  }();
  return robot;
}

TargetedConfigurations ConfigurationsFacing(const RobotModel& robot, const Plane& plane, int count,
                                            unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-M_PI, M_PI);
  TargetedConfigurations out(robot.num_links());
  ModelPoint point;
  PrepareModelPoint(robot, robot.nominal_values().data(), plane, &point);
  std::vector<double> q(robot.num_links());
  while (out.size() < count) {
    for (double& v : q) v = u(rng);
    TargetedConfigurations one(robot.num_links());
    one.Add(q);
    if (std::fabs(plane.normal.dot(ToolPose(point, one, 0).R_BT.col(2))) >= 0.2) out.Add(q);
  }
  return out;
}

TargetedConfigurations HittingConfigurations(const Plane& plane, int count, unsigned seed) {
  const RobotModel& robot = PaperRobot();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-M_PI, M_PI);
  TargetedConfigurations out(robot.num_links());
  ModelPoint point;
  PrepareModelPoint(robot, robot.nominal_values().data(), plane, &point);
  while (out.size() < count) {
    double q[6];
    for (double& v : q) v = u(rng);
    TargetedConfigurations one(6);
    one.Add(q);
    const Pose<double> pose = ToolPose(point, one, 0);
    double nb;
    const double h = BeamReading(pose, plane, &nb);
    if (ClassifyReading(h, nb, PaperRig().ranger) == BeamMiss::kNone) out.Add(q);
  }
  return out;
}

TargetedConfigurations PaperHittingConfigurations(int count, unsigned seed) {
  return HittingConfigurations(PaperPlane(), count, seed);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int RunCommand(const std::string& command, std::string* output) {
  output->clear();
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe)) *output += buffer.data();
  int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string TempDir(const std::string& name) {
  namespace fs = std::filesystem;
  fs::path p = fs::temp_directory_path() / ("lrcal_test_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

void WritePaperConfigurationFiles(const std::string& dir, int pool, int validation,
                                  std::uint64_t pool_seed, std::uint64_t validation_seed) {
  const RobotFile& rig = PaperRig();
  SamplingOptions o;
  o.ranger = rig.ranger;
  WriteConfigurations(dir + "/pool.csv",
                      SampleConfigurations(rig.robot, (*rig.planes)[0], pool,
                                           RandomStream(pool_seed, 0, 0, RandomPurpose::kPool), o));
  o.require_beam_hit = false;
  WriteConfigurations(
      dir + "/val.csv",
      SampleConfigurations(rig.robot, (*rig.planes)[0], validation,
                           RandomStream(validation_seed, 0, 0, RandomPurpose::kValidation), o));
}

RunResult RunStudyFile(const std::string& study, const std::string& out, int threads,
                       int shard_index, int shard_count, long long max_new, int batch_size) {
  RunOptions o;
  o.out_dir = out;
  o.threads = threads;
  o.shard_index = shard_index;
  o.shard_count = shard_count;
  o.progress = false;
  o.max_new_trials = max_new;
  o.batch_size = batch_size;
  return RunStudyAndWriteTables(LoadStudy(study), o);
}

}  // namespace lrcal::testing
