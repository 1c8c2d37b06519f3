// The calibration record: what it says of the fit, the calibrated robot file written from it
// reads back as the solved model, and the record's covariance is reordered to a parameter set.
#include "lrcal/io/calibration_record.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "lrcal/core/error.h"
#include "lrcal/measurement/simulation.h"
#include "test_util.h"

namespace lrcal {
namespace {

TEST(CalibrationRecord, SaysWhichSigmaTheCovarianceAssumes) {
  IdentificationSummary s;
  s.names = {"a", "b"};
  s.estimate = Eigen::Vector2d(1, 2);
  s.sigma_hat = 3e-4;
  s.covariance_given = Eigen::Matrix2d::Identity();
  s.covariance_residual = 2 * Eigen::Matrix2d::Identity();
  const std::string data = testing::TempDir("record") + "/m.csv";
  std::ofstream(data) << "q1,h\n0,1\n";
  IdentificationOptions given;
  given.sigma = 2e-4;
  const CalibrationRecord g = MakeCalibrationRecord(DataSource::File(data), s, given);
  EXPECT_EQ(g.sigma, 2e-4);
  EXPECT_EQ(g.sigma_source, "given (--sigma-mm)");
  EXPECT_THAT(g.covariance, testing::EigenNear(s.covariance_given, 0.0));
  const CalibrationRecord r =
      MakeCalibrationRecord(DataSource::File(data), s, IdentificationOptions{});
  EXPECT_EQ(r.sigma, 3e-4);
  EXPECT_EQ(r.sigma_source, "residual (sigma_hat)");
  EXPECT_THAT(r.covariance, testing::EigenNear(s.covariance_residual, 0.0));
  EXPECT_EQ(r.data_fnv1a, g.data_fnv1a);
  EXPECT_EQ(r.data_fnv1a.size(), 16u);
  EXPECT_THAT(r.date, ::testing::MatchesRegex("[0-9]{4}-[0-9]{2}-[0-9]{2}T.*Z"));
}

TEST(CalibrationRecord, CovarianceIsReorderedToTheParameterSet) {
  const RobotModel& robot = testing::PaperRobot();
  const ParameterSet ps = MakeParameterSet(robot, PlaneTerms{});
  CalibrationRecord r;
  const int n = ps.size();
  r.parameters.assign(ps.names.rbegin(), ps.names.rend());  // reversed
  r.covariance = Eigen::MatrixXd(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) r.covariance(a, b) = 100 * a + b;
  const Eigen::MatrixXd C = RecordCovariance(r, ps, "cal.yaml");
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) EXPECT_EQ(C(a, b), r.covariance(n - 1 - a, n - 1 - b));
  r.parameters[0] = "nonsense";
  EXPECT_THROW(RecordCovariance(r, ps, "cal.yaml"), InputError);
  // The record names the set: RecordParameterSet gives it back, in MakeParameterSet's order.
  r.parameters.assign(ps.names.rbegin(), ps.names.rend());
  EXPECT_EQ(RecordParameterSet(robot, r, 1, "cal.yaml").names, ps.names);
}

TEST(CalibrationRecord, TheWrittenRobotIsTheSolvedModel) {
  const RobotFile& rig = testing::PaperRig();
  const MeasurementModel model(rig.robot, *rig.planes, MakeParameterSet(rig.robot, PlaneTerms{}));
  IdentificationSummary s;
  s.names = model.parameters().names;
  s.delta = Eigen::VectorXd::LinSpaced(model.num_parameters(), -1e-3, 1e-3);
  s.estimate = s.delta;
  s.sigma_hat = 1e-4;
  s.covariance_residual = Eigen::MatrixXd::Identity(s.delta.size(), s.delta.size()) * 1e-8;
  const std::string dir = testing::TempDir("record_robot");
  std::ofstream(dir + "/m.csv") << "q1\n";
  WriteCalibratedRobot(dir + "/cal.yaml", DataSource::File(dir + "/m.csv"), rig, model, s,
                       IdentificationOptions{});
  const RobotFile back = LoadRobotFile(dir + "/cal.yaml");
  EXPECT_THAT(back.robot.nominal_values(),
              testing::EigenNear(model.LinkValues(s.delta.data()), 0.0));
  ASSERT_TRUE(back.calibration.has_value());
  EXPECT_EQ(back.calibration->parameters, s.names);
}

}  // namespace
}  // namespace lrcal
