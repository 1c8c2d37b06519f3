// ChooseDesign: the choice equals SelectConfigurations' on the same G, criterion I is A on the
// task-weighted G, the per-plane counts add up, and bad settings name themselves.
#include "lrcal/design/design_choice.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numeric>

#include "lrcal/core/random.h"
#include "lrcal/design/block_selection.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "test_util.h"

namespace lrcal {
namespace {

class DesignChoiceTest : public ::testing::Test {
 protected:
  MeasurementModel model_{testing::PaperRobot(), testing::PaperPlane(),
                          MakeParameterSet(testing::PaperRobot(), PlaneTerms{})};
  TargetedConfigurations pool_ =
      testing::ConfigurationsFacing(testing::PaperRobot(), testing::PaperPlane(), 45, 11);
};

TEST_F(DesignChoiceTest, ChoosesWhatTheSelectionChoosesOnTheSameJacobian) {
  DesignRequest request;
  request.count = 30;
  request.baseline = 20;
  request.seed = 4;
  request.selection.criterion = DesignCriterion::kD;
  request.selection.method = SelectionMethod::kGreedy;
  const DesignChoice choice = ChooseDesign(model_, pool_, request);
  const SelectionResult direct =
      SelectConfigurations(DesignJacobian(model_, pool_, DesignScaling::kSI, 1e-3, 1e-3), 30,
                           request.selection, RandomStream(4, 1, 0, RandomPurpose::kSelection));
  EXPECT_EQ(choice.chosen.indices, direct.indices);
  EXPECT_EQ(choice.chosen.score, direct.score);
  EXPECT_EQ(std::accumulate(choice.per_plane.begin(), choice.per_plane.end(), 0), 30);
  EXPECT_FALSE(choice.task_rms_per_sigma.has_value());
  EXPECT_EQ(request.CriterionName(), "D");
  EXPECT_THAT(CriterionText(request, choice), ::testing::StartsWith("D = "));
  EXPECT_EQ(choice.baseline.size(), std::size(kBaselineCriteria));
}

TEST_F(DesignChoiceTest, CriterionIIsAOnTheTaskWeightedJacobian) {
  DesignRequest request;
  request.count = 28;
  request.baseline = 10;
  request.selection.method = SelectionMethod::kBackward;
  request.task = TaskPosesAt(model_, WorkspacePoses(model_.robot(), 15, 2), "workspace");
  const DesignChoice choice = ChooseDesign(model_, pool_, request);
  SelectionOptions a = request.selection;
  a.criterion = DesignCriterion::kA;
  const SelectionResult direct =
      SelectConfigurations(TaskDesignJacobian(model_, pool_, request.task), 28, a,
                           RandomStream(1, 1, 0, RandomPurpose::kSelection));
  EXPECT_EQ(choice.chosen.indices, direct.indices);
  EXPECT_EQ(request.CriterionName(), "I");
  ASSERT_TRUE(choice.task_rms_per_sigma.has_value());
  EXPECT_EQ(*choice.task_rms_per_sigma,
            TaskRmsPositionPerUnitSigma(model_, pool_.Subset(choice.chosen.indices), request.task));
  EXPECT_THAT(CriterionText(request, choice),
              ::testing::HasSubstr("I (predicted RMS position error at 15 workspace poses"));
}

TEST_F(DesignChoiceTest, RefusesANonPositiveExpectedErrorInEachFrontEndsWords) {
  DesignRequest request;
  request.count = 30;
  request.expected_length = 0;
  try {
    ChooseDesign(model_, pool_, request);
    FAIL() << "no error";
  } catch (const SettingError& e) {
    EXPECT_THAT(e.Respelled(Frontend::kCommandLine).what(),
                ::testing::HasSubstr("--expected-length-mm: expected a finite value > 0 (mm)"));
    EXPECT_THAT(e.Respelled(Frontend::kPython).what(), ::testing::HasSubstr("expected_length_mm="));
  }
}

// Design works against the measurement interface: the ranger's route through it keeps the
// identification Jacobian's bits, so the choice is the model overload's exactly.
TEST_F(DesignChoiceTest, TheRangerAsAMeasurementKindChoosesWhatTheModelChooses) {
  EXPECT_EQ(DesignJacobian(model_, pool_, DesignScaling::kSI, 0, 0),
            IdentificationJacobian(model_, pool_));
  DesignRequest request;
  request.count = 30;
  request.baseline = 10;
  request.selection.method = SelectionMethod::kExchange;
  const RangerMeasurement ranger(model_);
  const DesignChoice by_kind = ChooseDesign(ranger, pool_, request);
  const DesignChoice by_model = ChooseDesign(model_, pool_, request);
  EXPECT_EQ(by_kind.chosen.indices, by_model.chosen.indices);
  EXPECT_EQ(by_kind.chosen.score, by_model.chosen.score);
  request.task = TaskPosesAt(model_, WorkspacePoses(model_.robot(), 12, 5), "workspace");
  EXPECT_EQ(ChooseDesign(ranger, pool_, request).task_rms_per_sigma,
            ChooseDesign(model_, pool_, request).task_rms_per_sigma);
}

// Another kind's terms: its Jacobian's columns are weighed by their own units, the task's pose
// rows reach its link terms by name and leave the instrument's and targets' at zero, and a
// kind of three values per configuration is refused by name rather than chosen row by row.
TEST_F(DesignChoiceTest, AnyKindsJacobianScalesAndWeighsByItsOwnTerms) {
  PointSetup setup;
  setup.instrument =
      RigidTransform::FromXyzRpy(Eigen::Vector3d(2.0, -0.4, 0.3), Eigen::Vector3d(0.1, -0.2, 2.8));
  const PointMeasurement tracker(model_.robot(), setup);
  const TargetedConfigurations some = pool_.Subset({0, 1, 2, 3, 4});
  const Eigen::MatrixXd G = DesignJacobian(tracker, some, DesignScaling::kSI, 0, 0);
  EXPECT_EQ(G, MeasurementJacobian(tracker, some));
  EXPECT_EQ(G.rows(), 15);
  const std::vector<std::string>& names = tracker.parameter_names();
  const Eigen::MatrixXd scaled =
      DesignJacobian(tracker, some, DesignScaling::kExpectedErrors, 2e-3, 5e-4);
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    EXPECT_EQ(scaled.col(j), G.col(j) * (IsAngularName(names[k]) ? 2e-3 : 5e-4)) << names[k];
  }
  const TaskPoses task = TaskPosesAt(model_, WorkspacePoses(model_.robot(), 4, 9), "workspace");
  const Eigen::MatrixXd P = PositionRowsFor(task, names);
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto in_task = std::find(task.names.begin(), task.names.end(), names[k]);
    if (in_task == task.names.end())
      EXPECT_TRUE(P.col(static_cast<Eigen::Index>(k)).isZero()) << names[k];
    else
      EXPECT_EQ(P.col(static_cast<Eigen::Index>(k)),
                task.position_rows.col(in_task - task.names.begin()))
          << names[k];
  }
  EXPECT_EQ(std::count(names.begin(), names.end(), "instrument_x"), 1);
}

// A tracker's configurations are chosen as blocks of their three values: what SelectBlocks
// chooses on the same Jacobian, the baseline's random designs of as many configurations (their
// scores from the blocks' rows, computed here), and no certificate.
TEST_F(DesignChoiceTest, ATrackersConfigurationsAreChosenAsBlocks) {
  PointSetup setup;
  setup.instrument =
      RigidTransform::FromXyzRpy(Eigen::Vector3d(2.0, -0.4, 0.3), Eigen::Vector3d(0.1, -0.2, 2.8));
  const PointMeasurement full(model_.robot(), setup);
  const std::unique_ptr<MeasurementKind> tracker =
      full.Without(AnalyzeIdentifiability(full, pool_).suggested_fixed);
  DesignRequest request;
  request.count = 15;
  request.baseline = 30;
  request.seed = 6;
  request.selection.criterion = DesignCriterion::kE;
  request.selection.method = SelectionMethod::kBackward;
  const DesignChoice choice = ChooseDesign(*tracker, pool_, request);
  const Eigen::MatrixXd G = DesignJacobian(*tracker, pool_, DesignScaling::kSI, 1e-3, 1e-3);
  const SelectionResult direct =
      SelectBlocks(G, 3, 15, request.selection, RandomStream(6, 1, 0, RandomPurpose::kSelection));
  EXPECT_EQ(choice.chosen.indices, direct.indices);
  EXPECT_GT(choice.chosen.score, 0);
  EXPECT_FALSE(choice.certificate.available);
  EXPECT_THAT(choice.certificate_statement,
              ::testing::HasSubstr("no certificate for configurations of 3 values"));
  Eigen::MatrixXd chosen_rows(45, G.cols());
  for (int t = 0; t < 15; ++t)
    chosen_rows.middleRows(3 * t, 3) = G.middleRows(3 * choice.chosen.indices[t], 3);
  const Eigen::MatrixXd A = chosen_rows.transpose() * chosen_rows;
  ASSERT_EQ(choice.baseline[0].criterion, DesignCriterion::kE);
  EXPECT_NEAR(choice.baseline[0].chosen, CriterionScore(A, 15, DesignCriterion::kE),
              1e-12 * choice.baseline[0].chosen);
  EXPECT_EQ(choice.baseline[0].random.n, 30);
  EXPECT_GT(choice.baseline[0].percentile, 50);  // the E-optimal design beats most random ones
  request.selection.method = SelectionMethod::kExhaustive;
  EXPECT_THAT([&] { ChooseDesign(*tracker, pool_, request); },
              ::testing::ThrowsMessage<InputError>(
                  ::testing::HasSubstr("for 3 values per configuration use backward")));
}

}  // namespace
}  // namespace lrcal
