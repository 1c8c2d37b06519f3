// ChooseDesign: the choice equals SelectConfigurations' on the same G, criterion I is A on the
// task-weighted G, the per-plane counts add up, and bad settings name themselves.
#include "lrcal/design/design_choice.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numeric>

#include "lrcal/core/random.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/measurement/parameter_set.h"
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

}  // namespace
}  // namespace lrcal
