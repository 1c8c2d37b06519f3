#include "lrcal/identification/pose_accuracy.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/core/random.h"
#include "lrcal/core/text_table.h"
#include "lrcal/kinematics/pose_errors.h"

namespace lrcal {

Eigen::MatrixXd PoseJacobian(const MeasurementModel& model, const double* e,
                             const ConfigurationSet& configs) {
  const int n = model.num_parameters(), m = configs.size();
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(e, n);
  // The poses of the model at x: its link values and, where estimated, its base and tool.
  const bool frames = model.parameters().EstimatesFrames();
  const auto compare = [&](const std::vector<Pose<double>>& reference) {
    return frames ? ComparePoses(model.RobotAt(x.data()), reference, model.LinkValues(x.data()),
                                 configs)
                  : ComparePoses(model.robot(), reference, model.LinkValues(x.data()), configs);
  };
  const std::vector<Pose<double>> poses = ToolPoses(
      frames ? model.RobotAt(x.data()) : model.robot(), model.LinkValues(x.data()), configs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6 * m, n);
  constexpr double kStep = 1e-6;  // m or rad: truncation O(step²), rounding O(1e-16/step)
  for (int k = 0; k < n; ++k) {
    const double x0 = x[k];
    x[k] = x0 + kStep;
    const PoseErrors plus = compare(poses);
    x[k] = x0 - kStep;
    const PoseErrors minus = compare(poses);
    x[k] = x0;
    // ComparePoses gives reference − model: the pose moves by minus that.
    for (int j = 0; j < m; ++j)
      for (int a = 0; a < 3; ++a) {
        J(6 * j + a, k) = -(plus.position(a, j) - minus.position(a, j)) / (2 * kStep);
        J(6 * j + 3 + a, k) = -(plus.orientation(a, j) - minus.orientation(a, j)) / (2 * kStep);
      }
  }
  return J;
}

Eigen::MatrixXd PositionRows(const Eigen::MatrixXd& pose_jacobian) {
  const Eigen::Index m = pose_jacobian.rows() / 6;
  Eigen::MatrixXd P(3 * m, pose_jacobian.cols());
  for (Eigen::Index j = 0; j < m; ++j) P.middleRows(3 * j, 3) = pose_jacobian.middleRows(6 * j, 3);
  return P;
}

namespace {

// The 0.95 quantile of |x|, x ~ N(0, Σ) in 3-D: |x|² = Σ λ_i z_i², from fixed draws.
double Radius95(const Eigen::Matrix3d& sigma, const Eigen::MatrixXd& z) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(sigma, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0);
  std::vector<double> r2(z.cols());
  for (Eigen::Index d = 0; d < z.cols(); ++d) r2[d] = lambda.dot(z.col(d).cwiseAbs2());
  const std::size_t k = static_cast<std::size_t>(0.95 * r2.size());
  std::nth_element(r2.begin(), r2.begin() + k, r2.end());
  return std::sqrt(r2[k]);
}

// Fixed standard normal draws for Radius95 (made once; read-only afterwards, so thread-safe).
const Eigen::MatrixXd& RadiusDraws() {
  static const Eigen::MatrixXd z = [] {
    constexpr int kDraws = 20000;
    Eigen::MatrixXd d(3, kDraws);
    RandomStream(0, 0, 0, RandomPurpose::kPrediction).Normals(0, 3 * kDraws, d.data());
    return d;
  }();
  return z;
}

}  // namespace

PoseAccuracy PoseAccuracyFromCovariance(const Eigen::Matrix<double, 6, 6>& data,
                                        const Eigen::Matrix<double, 6, 6>& total) {
  PoseAccuracy a;
  a.position_std = data.diagonal().head<3>().cwiseMax(0.0).cwiseSqrt();
  a.orientation_std = data.diagonal().tail<3>().cwiseMax(0.0).cwiseSqrt();
  a.position_radius_95 = Radius95(data.topLeftCorner<3, 3>(), RadiusDraws());
  if (total == data) {
    a.position_std_total = a.position_std;
    a.orientation_std_total = a.orientation_std;
    a.position_radius_95_total = a.position_radius_95;
    return a;
  }
  a.position_std_total = total.diagonal().head<3>().cwiseMax(0.0).cwiseSqrt();
  a.orientation_std_total = total.diagonal().tail<3>().cwiseMax(0.0).cwiseSqrt();
  a.position_radius_95_total = Radius95(total.topLeftCorner<3, 3>(), RadiusDraws());
  return a;
}

std::vector<PoseAccuracy> PredictPoseAccuracy(const MeasurementModel& model, const double* e,
                                              const Eigen::MatrixXd& covariance,
                                              const ConfigurationSet& configs) {
  const int n = model.num_parameters();
  if (covariance.rows() != n || covariance.cols() != n)
    throw InputError("covariance", "expected " + std::to_string(n) + " x " + std::to_string(n) +
                                       " (one row and column per estimated parameter)");
  const Eigen::MatrixXd J = PoseJacobian(model, e, configs);
  std::vector<PoseAccuracy> out(configs.size());
  for (int j = 0; j < configs.size(); ++j) {
    const Eigen::MatrixXd Jj = J.middleRows(6 * j, 6);
    const Eigen::Matrix<double, 6, 6> S = Jj * covariance * Jj.transpose();
    out[j] = PoseAccuracyFromCovariance(S, S);
  }
  return out;
}

PoseAccuracySummary SummarizePoseAccuracy(const std::vector<PoseAccuracy>& poses) {
  PoseAccuracySummary s;
  if (poses.empty()) return s;
  double sum = 0;
  std::vector<double> radii;
  for (std::size_t j = 0; j < poses.size(); ++j) {
    sum += poses[j].position_std.squaredNorm();
    radii.push_back(poses[j].position_radius_95);
    if (s.worst < 0 || poses[j].position_radius_95 > poses[s.worst].position_radius_95)
      s.worst = static_cast<int>(j);
  }
  s.rms_position = std::sqrt(sum / poses.size());
  std::sort(radii.begin(), radii.end());
  s.p95_radius_95 = radii[std::min(radii.size() - 1,
                                   static_cast<std::size_t>(std::ceil(0.95 * radii.size())) - 1)];
  return s;
}

}  // namespace lrcal
