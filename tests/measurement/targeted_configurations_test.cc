// TargetedConfigurations: joint values tagged with the target their measurement is of.
#include "lrcal/measurement/targeted_configurations.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace lrcal {
namespace {

using ::testing::ElementsAre;

TEST(TargetedConfigurations, KeepsOneTagPerConfigurationThroughSubsetsAndCopies) {
  TargetedConfigurations c(2);
  c.Add(std::vector<double>{0.1, 0.2}, 1);
  c.Add(std::vector<double>{0.3, 0.4});  // target 0 by default
  c.Add(std::vector<double>{0.5, 0.6}, 2);
  EXPECT_EQ(c.size(), 3);
  EXPECT_THAT(c.targets(), ElementsAre(1, 0, 2));
  EXPECT_EQ(c.num_targets_referenced(), 3);

  const TargetedConfigurations s = c.Subset({2, 0});
  EXPECT_THAT(s.targets(), ElementsAre(2, 1));
  EXPECT_EQ(s.q(0)[1], 0.6);
  EXPECT_EQ(s.cos_q(1)[0], std::cos(0.1));  // copied, not recomputed: the same bits

  TargetedConfigurations t(2);
  t.AddFrom(c, 2);
  t.AddFrom(static_cast<const ConfigurationSet&>(c), 0, 4);  // untagged joint values, tagged 4
  EXPECT_THAT(t.targets(), ElementsAre(2, 4));
  t.Clear();
  EXPECT_EQ(t.size(), 0);
  EXPECT_EQ(t.num_targets_referenced(), 0);
}

TEST(TargetedConfigurations, UntaggedJointValuesTakeOneTargetAndKinematicsSeesOnlyJoints) {
  ConfigurationSet joints(1);
  joints.Add(std::vector<double>{0.7});
  joints.Add(std::vector<double>{-0.7});
  const TargetedConfigurations on_second(joints, 1);
  EXPECT_THAT(on_second.targets(), ElementsAre(1, 1));
  const ConfigurationSet& as_joints = on_second;  // what the kinematics layer takes
  EXPECT_EQ(as_joints.size(), 2);
  EXPECT_EQ(as_joints.q(1)[0], -0.7);
  // The kinematics layer's subset is joint values only; the tags stay with the measurement type.
  EXPECT_EQ(as_joints.Subset({1}).size(), 1);
}

}  // namespace
}  // namespace lrcal
