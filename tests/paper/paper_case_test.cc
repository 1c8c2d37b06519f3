// The paper's two cases as lrcal reproduces them, and the consistency of the published tables
// with the paper's robot file.
#include "lrcal/paper/paper_case.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "lrcal/core/error.h"
#include "test_util.h"

namespace lrcal {
namespace {

// The published identified errors exist exactly for the paper arm's 25 parameters.
TEST(PaperTables, PublishedParametersAreThePaperArmsParameters) {
  const RobotModel& robot = testing::PaperRobot();
  ASSERT_EQ(robot.num_links(), 6);
  for (int c = 0; c < 2; ++c)
    for (int l = 0; l < 6; ++l)
      for (int v = 0; v < kValuesPerLink; ++v)
        EXPECT_EQ(std::isnan(kPaperIdentified[c][l][v]), !robot.links()[l].is_parameter[v])
            << "case " << c + 1 << " " << robot.ValueName(kValuesPerLink * l + v);
}

// Case 1 (backward elimination, 50 of 101) and case 2 (leave-one-out, 100 of 101): both
// converge, the identified errors are within 5 predicted standard deviations of the robot
// file's truth, and the calibrated arm is better than the nominal one on every validation axis.
TEST(PaperCases, BothCasesIdentifyTheTruthAndBeatTheNominalArm) {
  const RobotFile& rig = testing::PaperRig();
  PaperCaseOptions options;
  options.sampling.ranger = rig.ranger;
  const PaperCasesResult r = RunPaperCases(rig.robot, rig.truth, (*rig.planes)[0], options);
  EXPECT_EQ(r.pool.size(), 101);
  EXPECT_EQ(r.validation.size(), 20);
  ASSERT_EQ(r.cases.size(), 2u);
  const int expected_counts[2] = {50, 100};
  for (int c = 0; c < 2; ++c) {
    const PaperCase& pc = r.cases[c];
    EXPECT_EQ(static_cast<int>(pc.selection.indices.size()), expected_counts[c]);
    ASSERT_TRUE(pc.summary.IsSolutionUsable()) << pc.summary.message;
    for (std::size_t k = 0; k < pc.summary.names.size(); ++k) {
      const int index = rig.robot.FindValue(pc.summary.names[k]);
      ASSERT_GE(index, 0);
      EXPECT_NEAR(pc.summary.delta[k], rig.truth.LinkErrors(rig.robot)[index],
                  5 * pc.summary.std_given[k])
          << pc.label << " " << pc.summary.names[k];
    }
    for (int a = 0; a < 3; ++a)
      EXPECT_LT(pc.validation.stats.rms_position[a], r.nominal_validation.stats.rms_position[a])
          << pc.label << " axis " << a;
  }
  // The tables lrcal prints beside the paper's.
  EXPECT_EQ(PaperValidationTable(r).num_rows(), 9);
  EXPECT_GT(PaperParameterTable(rig.robot, r).num_rows(), 0);
}

// On a robot file: the file's arm, truth, plane and ranger, and a file of another number of
// planes is refused by its path.
TEST(PaperCases, OnARobotFileAreTheCasesOfItsArmPlaneAndRanger) {
  const RobotFile& rig = testing::PaperRig();
  PaperCaseOptions options;
  options.case1_selection.method = SelectionMethod::kGreedy;
  const PaperCasesResult from_file = RunPaperCases(rig, options);
  options.sampling.ranger = rig.ranger;
  const PaperCasesResult direct = RunPaperCases(rig.robot, rig.truth, (*rig.planes)[0], options);
  ASSERT_EQ(from_file.cases.size(), 2u);
  for (int c = 0; c < 2; ++c) {
    EXPECT_EQ(from_file.cases[c].selection.indices, direct.cases[c].selection.indices);
    EXPECT_EQ(from_file.cases[c].summary.delta, direct.cases[c].summary.delta);
  }
  RobotFile two = rig;
  two.planes = PlaneSet({(*rig.planes)[0], Plane::FromCoefficients(1, 0, 0, 2.0)}, {});
  EXPECT_THAT([&] { RunPaperCases(two, options); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(
                  rig.path + ": the robot file has 2 planes; the paper's study uses exactly one")));
}

}  // namespace
}  // namespace lrcal
