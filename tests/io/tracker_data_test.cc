// A tracker's measurement files (tracker_data.h): what simulation writes reads back to the same
// values (a pose's orientation through its quaternion), and bad cells are errors naming the
// file, line and column.
#include "lrcal/io/tracker_data.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "lrcal/core/error.h"
#include "lrcal/measurement/pose_measurement.h"
#include "test_util.h"
#include "tracker_fixtures.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Values written with 17 digits and a quaternion's round trip through a rotation: rounding only.
constexpr double kFileRoundTrip = 1e-12;

PointSetup TwoProbes() { return testing::TrackerSetup(true); }

TargetedConfigurations SomeConfigurations(int count) {
  return testing::RandomTrackerConfigurations(6, count, 2, 4);
}

class TrackerData : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::TempDir("TrackerData"); }
  std::string Write(const std::string& text) const {
    const std::string path = dir_ + "/m.csv";
    std::ofstream(path) << text;
    return path;
  }
  std::string dir_;
};

TEST_F(TrackerData, WhatSimulationWritesReadsBackToTheSameValues) {
  const RobotModel& robot = testing::PaperRobot();
  const PoseMeasurement pose(robot, TwoProbes());
  PointSetup positions = TwoProbes();
  positions.target_orientations.clear();
  const PointMeasurement point(robot, positions);
  NoiseModel noise;
  noise.repetitions = 3;
  noise.draw_mean = true;
  for (const PointMeasurement* kind : {static_cast<const PointMeasurement*>(&point),
                                       static_cast<const PointMeasurement*>(&pose)}) {
    MeasuredValues written;
    SimulateMeasurements(*kind, SomeConfigurations(20), noise,
                         RandomStream(2, 0, 0, RandomPurpose::kNoise), &written);
    const std::string path = dir_ + "/" + kind->name() + ".csv";
    WriteTrackerMeasurements(path, *kind, written);
    const MeasuredValues read = ReadTrackerMeasurements(path, *kind);
    ASSERT_EQ(read.size(), written.size());
    EXPECT_EQ(read.repetitions, written.repetitions);
    for (int i = 0; i < read.size(); ++i) EXPECT_EQ(read.configs.target(i), i % 2);
    ASSERT_EQ(read.y.size(), written.y.size());
    for (std::size_t r = 0; r < read.y.size(); ++r)
      EXPECT_NEAR(read.y[r], written.y[r], kFileRoundTrip) << kind->name() << " value " << r;
  }
}

TEST_F(TrackerData, BadCellsNameTheFileLineAndColumn) {
  const RobotModel& robot = testing::PaperRobot();
  const PoseMeasurement pose(robot, TwoProbes());
  const std::string joints = "q1,q2,q3,q4,q5,q6,";
  const std::string q = "0.1,0.2,0.3,0.4,0.5,0.6,";
  EXPECT_THAT(
      [&] {
        ReadTrackerMeasurements(
            Write(joints + "target,x,y,z,qx,qy,qz,qw\n" + q + "1,1,2,3,0,0,0.6,0.6\n"), pose);
      },
      ThrowsMessage<InputError>(
          HasSubstr("m.csv:2 columns qx,qy,qz,qw: expected a unit quaternion (norm 1 within "
                    "1e-6), got norm 0.848")));
  EXPECT_THAT(
      [&] {
        ReadTrackerMeasurements(Write(joints + "target,x,y,z,qx,qy,qz\n" + q + "1,1,2,3,0,0,0\n"),
                                pose);
      },
      ThrowsMessage<InputError>(
          HasSubstr("m.csv:1 column 'qw': missing: expected the target's orientation")));
  EXPECT_THAT(
      [&] {
        ReadTrackerMeasurements(Write(joints + "x,y,z,qx,qy,qz,qw\n" + q + "1,2,3,0,0,0,1\n"),
                                pose);
      },
      ThrowsMessage<InputError>(HasSubstr("m.csv:1 column 'target': missing: 2 targets")));
  EXPECT_THAT(
      [&] {
        ReadTrackerMeasurements(
            Write(joints + "target,x,y,z,qx,qy,qz,qw,readings\n" + q + "2,1,2,3,0,0,0,1,0\n"),
            pose);
      },
      ThrowsMessage<InputError>(
          HasSubstr("m.csv:2 column 'readings': expected a whole number of readings from 1 to "
                    "1,000,000, got '0'")));
  EXPECT_THAT(
      [&] {
        ReadTrackerMeasurements(
            Write(joints + "target,x,y,z,qx,qy,qz,qw\n" + q + "1,1,nan,3,0,0,0,1\n"), pose);
      },
      ThrowsMessage<InputError>(HasSubstr("m.csv:2 column 'y'")));
  EXPECT_THAT(
      [&] {
        ReadTrackerMeasurements(
            Write(joints + "target,x,y,z,qx,qy,qz,qw\n" + "10,0,0,0,0,0,1,1,2,3,0,0,0,1\n"), pose);
      },
      ThrowsMessage<InputError>(HasSubstr("m.csv")));
}

}  // namespace
}  // namespace lrcal
