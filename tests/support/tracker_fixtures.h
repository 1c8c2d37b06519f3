// Shared set-ups for the tracker kinds' tests (point_measurement_test.cc, pose_measurement_test.cc,
// tracker_data_test.cc): a tracker in front of the paper's arm, random configurations, every
// term's value from an estimate, the truth kind of a simulation and central differences.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "lrcal/identification/identification.h"
#include "lrcal/measurement/contact_measurement.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/measurement/pose_measurement.h"
#include "lrcal/measurement/truth.h"
#include "test_util.h"

namespace lrcal::testing {

/// A tracker 2 m in front of the arm, turned and tilted, seeing two targets on the tool; with
/// `orientations`, two 6-D probes, the second turned against the tool's axes.
inline PointSetup TrackerSetup(bool orientations = false) {
  PointSetup setup;
  setup.instrument =
      RigidTransform::FromXyzRpy(Eigen::Vector3d(2.0, -0.4, 0.3), Eigen::Vector3d(0.1, -0.2, 2.8));
  setup.targets = {Eigen::Vector3d(0.05, 0.0, 0.10), Eigen::Vector3d(-0.03, 0.04, 0.12)};
  if (orientations)
    setup.target_orientations = {
        Eigen::Matrix3d::Identity(),
        RigidTransform::FromXyzRpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.4, -1.1, 2.0))
            .rotation};
  return setup;
}

/// `count` configurations with joints uniform in ±2.5 rad, configuration i seeing target
/// i mod `targets`.
inline TargetedConfigurations RandomTrackerConfigurations(int num_joints, int count, int targets,
                                                          unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(-2.5, 2.5);
  TargetedConfigurations configs(num_joints);
  for (int i = 0; i < count; ++i) {
    std::vector<double> q(static_cast<std::size_t>(num_joints));
    for (double& v : q) v = angle(rng);
    configs.Add(q, i % targets);
  }
  return configs;
}

/// Every term's deviation (AllTermNames order) from the estimate e of `kind` (0 where fixed): any
/// kind with AllTermNames (point, pose, socket, contact).
template <typename Kind, typename T>
std::vector<T> AllTrackerTerms(const Kind& kind, const std::vector<T>& e) {
  const std::vector<std::string> names = kind.AllTermNames();
  std::vector<T> all(names.size(), T(0));
  for (int k = 0; k < kind.num_parameters(); ++k) {
    const auto it = std::find(names.begin(), names.end(), kind.parameter_names()[k]);
    all[static_cast<std::size_t>(it - names.begin())] = e[static_cast<std::size_t>(k)];
  }
  return all;
}

/// The kind a simulation reads from when `kind`'s terms are off nominal by `truth` (its layout):
/// the true arm (`*true_robot`, which must outlive it), instrument and targets, estimating the
/// same terms; a pose written in `kind`'s chart.
inline std::unique_ptr<PointMeasurement> TrueTrackerKind(const PointMeasurement& kind,
                                                         const Eigen::VectorXd& truth,
                                                         RobotModel* true_robot) {
  const RobotModel& robot = kind.robot();
  Truth errors;
  errors.link_errors = Eigen::VectorXd::Zero(robot.num_values());
  for (std::size_t k = 0; k < kind.robot_values().size(); ++k)
    errors.link_errors[kind.robot_values()[k]] = truth[static_cast<Eigen::Index>(k)];
  *true_robot = errors.TrueRobot(robot);
  PointMeasurement::State state;
  kind.StateAt(truth.data(), &state);
  PointSetup setup = kind.setup();
  setup.instrument.rotation = state.R_BI;
  setup.instrument.translation = state.p_BI;
  setup.targets = state.targets;
  if (const auto* pose = dynamic_cast<const PoseMeasurement*>(&kind)) {
    setup.target_orientations = state.R_TM;
    auto true_kind = std::make_unique<PoseMeasurement>(*true_robot, setup, kind.fixed());
    true_kind->UseChartOf(*pose);
    return true_kind;
  }
  return std::make_unique<PointMeasurement>(*true_robot, setup, kind.fixed());
}

/// The contact kind a campaign reads from when `kind`'s terms are off nominal by `truth` (its
/// layout): the true arm (`*true_robot`, which must outlive it), tool point and planes; tilts are
/// measured in the nominal planes' charts, as the data are recorded.
inline std::unique_ptr<ContactMeasurement> TrueContactKind(const ContactMeasurement& kind,
                                                           const Eigen::VectorXd& truth,
                                                           RobotModel* true_robot) {
  const RobotModel& robot = kind.robot();
  Truth errors;
  errors.link_errors = Eigen::VectorXd::Zero(robot.num_values());
  for (std::size_t c = 0; c < kind.arm().robot_values().size(); ++c)
    errors.link_errors[kind.arm().robot_values()[c]] = truth[static_cast<Eigen::Index>(c)];
  *true_robot = errors.TrueRobot(robot);
  PointMeasurement::State arm;
  kind.arm().StateAt(truth.data(), &arm);
  ContactSetup setup = kind.setup();
  setup.tool_point = arm.targets[0];
  for (int p = 0; p < setup.planes.size(); ++p) {
    const ContactMeasurement::PlaneState plane = kind.PlaneAt(truth.data(), p);
    setup.planes[p].normal = plane.normal;
    setup.planes[p].offset = plane.offset;
  }
  return std::make_unique<ContactMeasurement>(*true_robot, setup, kind.fixed());
}

/// Every term of `kind` off nominal by 1–3 mm or 1–3 mrad, alternating in sign.
inline Eigen::VectorXd SomeTruth(const MeasurementKind& kind, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> size(1e-3, 3e-3);
  Eigen::VectorXd truth(kind.num_parameters());
  for (Eigen::Index k = 0; k < truth.size(); ++k) truth[k] = (k % 2 ? 1 : -1) * size(rng);
  return truth;
}

/// Noise-free values of `kind` at `configs` when its terms are off nominal by `truth`
/// (TrueTrackerKind), and both solvers' fits of them, which must recover `truth` to the round
/// trip's tolerance with no residual.
inline MeasuredValues ExpectNoiseFreeRoundTrip(const PointMeasurement& kind,
                                               const TargetedConfigurations& configs,
                                               const Eigen::VectorXd& truth) {
  RobotModel true_robot;
  const std::unique_ptr<PointMeasurement> true_kind = TrueTrackerKind(kind, truth, &true_robot);
  NoiseModel exact;
  exact.sigma = 0;
  exact.sigma_angle = 0;
  exact.repetitions = 1;
  MeasuredValues data;
  EXPECT_EQ(SimulateMeasurements(*true_kind, configs, exact,
                                 RandomStream(1, 0, 0, RandomPurpose::kNoise), &data),
            0);
  for (auto solver : {IdentificationOptions::Solver::kLevenbergMarquardt,
                      IdentificationOptions::Solver::kCeres}) {
    IdentificationOptions options;
    options.solver = solver;
    const IdentificationSummary s = Identify(kind, data, options);
    EXPECT_TRUE(s.IsSolutionUsable()) << s.message;
    if (!s.IsSolutionUsable()) continue;
    EXPECT_THAT(s.delta, EigenNear(truth, tolerance::kRoundTrip)) << s.solver;
    EXPECT_LT(s.residual_rms, 1e-12);
  }
  return data;
}

/// ∂y/∂e of `evaluator` at e by central differences of step 1e-6.
inline Eigen::MatrixXd CentralDifferences(MeasurementEvaluator& evaluator,
                                          const std::vector<double>& e) {
  constexpr double kStep = 1e-6;
  const int m = evaluator.num_rows(), n = evaluator.num_parameters();
  Eigen::MatrixXd central(m, n);
  std::vector<double> yp(static_cast<std::size_t>(m)), ym(static_cast<std::size_t>(m));
  for (int k = 0; k < n; ++k) {
    std::vector<double> ep = e, em = e;
    ep[static_cast<std::size_t>(k)] += kStep;
    em[static_cast<std::size_t>(k)] -= kStep;
    evaluator.Predict(ep.data(), yp.data(), nullptr);
    evaluator.Predict(em.data(), ym.data(), nullptr);
    for (int r = 0; r < m; ++r) central(r, k) = (yp[r] - ym[r]) / (2 * kStep);
  }
  return central;
}

/// An estimate away from nominal: rotation terms of ±0.05 rad, lengths of ±5 mm, alternating.
inline std::vector<double> OffNominalEstimate(const MeasurementKind& kind) {
  std::vector<double> e(static_cast<std::size_t>(kind.num_parameters()));
  for (std::size_t k = 0; k < e.size(); ++k)
    e[k] = (k % 2 ? 1 : -1) * (IsAngularName(kind.parameter_names()[k]) ? 0.05 : 0.005);
  return e;
}

}  // namespace lrcal::testing
