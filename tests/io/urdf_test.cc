// URDF in and out: lrcal's D-H + β model of a URDF chain against the URDF's own forward
// kinematics, computed independently here from the joint origins and axes (urdfdom parses, Eigen
// composes), on four arms; URDF → lrcal → URDF round trips; bad URDFs named by file and joint.
#include "lrcal/io/urdf.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <fstream>
#include <map>
#include <random>

#include "lrcal/core/error.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "test_util.h"
#include "urdf_kinematics.h"

namespace lrcal {
namespace {

// Chains of O(1 m) and O(1) rotations composed in two different ways: rounding only.
constexpr double kTolerance = testing::tolerance::kUrdf;  // m, rad

std::vector<double> RandomConfiguration(const RobotModel& robot, std::mt19937* rng) {
  std::vector<double> q;
  for (const Link& link : robot.links())
    q.push_back(std::uniform_real_distribution<double>(link.q_min, link.q_max)(*rng));
  return q;
}

// lrcal's reference and fast forward kinematics of `robot` against `expected(q)` (the URDF's,
// composed here) at 200 random configurations.
template <typename Expected>
void ExpectKinematicsOf(const RobotModel& robot, unsigned seed, const Expected& expected,
                        const std::string& what) {
  std::mt19937 rng(seed);
  ChainPoint point;
  PrepareChainPoint(robot, robot.nominal_values().data(), &point);
  for (int trial = 0; trial < 200; ++trial) {
    const std::vector<double> q = RandomConfiguration(robot, &rng);
    const Eigen::Isometry3d want = expected(q);
    const Pose<double> ref =
        ForwardKinematics<double>(robot, robot.nominal_values().data(), q.data());
    TargetedConfigurations one(robot.num_links());
    one.Add(q);
    const Pose<double> fast = ToolPose(point, one, 0);
    for (const Pose<double>* pose : {&ref, &fast}) {
      EXPECT_LT((pose->p_BT - want.translation()).norm(), kTolerance) << what;
      EXPECT_THAT(pose->R_BT, testing::EigenNear(want.linear(), kTolerance)) << what;
    }
  }
}

void ExpectSameKinematics(const RobotModel& robot, const std::string& urdf,
                          const std::string& tool_link) {
  ExpectKinematicsOf(
      robot, 17,
      [&](const std::vector<double>& q) {
        return testing::UrdfForwardKinematics(urdf, tool_link, q);
      },
      urdf);
}

std::string Example(const std::string& name) {
  return testing::SourcePath("examples/urdf/" + name);
}

TEST(Urdf, Puma560MatchesTheUrdfsOwnKinematics) {
  const RobotFile rig = LoadRobotFile(Example("puma560.urdf"));
  EXPECT_EQ(rig.robot.name(), "puma560_ranger");
  EXPECT_EQ(rig.robot.num_links(), 6);
  EXPECT_FALSE(rig.planes.has_value());
  ExpectSameKinematics(rig.robot, Example("puma560.urdf"), "ranger");
  // Axes 2 and 3 are parallel: link 2 is Hayati's (β a parameter, d fixed at 0).
  EXPECT_TRUE(rig.robot.links()[1].is_parameter[kBeta]);
  EXPECT_FALSE(rig.robot.links()[1].is_parameter[kD]);
  EXPECT_EQ(rig.robot.links()[1].nominal[kD], 0.0);
  EXPECT_TRUE(rig.robot.links()[2].is_parameter[kD]);
  // Limits: revolute from <limit>, continuous ±π.
  EXPECT_EQ(rig.robot.links()[0].q_min, -2.79);
  EXPECT_EQ(rig.robot.links()[5].q_max, M_PI);
}

TEST(Urdf, Ur5WithAnOffsetRangerMatchesWithAChosenToolLink) {
  const RobotFile rig = LoadRobotFile(Example("ur5_ranger.urdf"), "ranger");
  ExpectSameKinematics(rig.robot, Example("ur5_ranger.urdf"), "ranger");
  // Shoulder lift, elbow and wrist 1 are parallel: links 2 and 3 carry β.
  for (int i : {1, 2}) EXPECT_TRUE(rig.robot.links()[i].is_parameter[kBeta]) << "link " << i + 1;
  for (int i : {0, 3, 4, 5}) EXPECT_FALSE(rig.robot.links()[i].is_parameter[kBeta]);
  EXPECT_FALSE(rig.robot.base().IsIdentity());  // the world joint's offset
  EXPECT_FALSE(rig.robot.tool().IsIdentity());
  // The camera link is the other end: the same chain up to the flange, another tool.
  const RobotFile camera = LoadRobotFile(Example("ur5_ranger.urdf"), "camera");
  ExpectSameKinematics(camera.robot, Example("ur5_ranger.urdf"), "camera");
}

TEST(Urdf, ScaraWithAPrismaticJointMatches) {
  const RobotFile rig = LoadRobotFile(Example("scara_ranger.urdf"));
  EXPECT_EQ(rig.robot.links()[2].joint, JointType::kPrismatic);
  ExpectSameKinematics(rig.robot, Example("scara_ranger.urdf"), "ranger");
}

TEST(Urdf, PaperArmExportedMatchesAndReadsBack) {
  const RobotModel& paper = testing::PaperRobotWithFrames();
  const std::string path = testing::TempDir("urdf_paper") + "/paper.urdf";
  std::ofstream(path) << UrdfText(paper, paper.nominal_values());
  ExpectSameKinematics(paper, path, "tool");
  const RobotFile back = LoadRobotFile(path);
  ExpectSameKinematics(back.robot, path, "tool");
  // The calibrated values, not the nominal ones, are what an export writes.
  const Eigen::VectorXd truth = testing::PaperTrueValues();
  std::ofstream(path) << UrdfText(paper, truth);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<double> q = RandomConfiguration(paper, &rng);
    const Pose<double> pose = ForwardKinematics<double>(paper, truth.data(), q.data());
    const Eigen::Isometry3d urdf = testing::UrdfForwardKinematics(path, "tool", q);
    EXPECT_LT((pose.p_BT - urdf.translation()).norm(), kTolerance);
    EXPECT_THAT(pose.R_BT, testing::EigenNear(urdf.linear(), kTolerance));
  }
}

TEST(Urdf, RoundTripKeepsTheKinematics) {
  // URDF → lrcal → URDF: the written URDF's own kinematics equal the original's.
  const std::string original = Example("ur5_ranger.urdf");
  const RobotFile rig = LoadRobotFile(original, "ranger");
  const std::string written = testing::TempDir("urdf_round_trip") + "/ur5.urdf";
  std::ofstream(written) << UrdfText(rig.robot, rig.robot.nominal_values());
  std::mt19937 rng(23);
  for (int trial = 0; trial < 200; ++trial) {
    const std::vector<double> q = RandomConfiguration(rig.robot, &rng);
    const Eigen::Isometry3d a = testing::UrdfForwardKinematics(original, "ranger", q);
    const Eigen::Isometry3d b = testing::UrdfForwardKinematics(written, "tool", q);
    EXPECT_LT((a.translation() - b.translation()).norm(), kTolerance);
    EXPECT_THAT(a.linear(), testing::EigenNear(b.linear(), kTolerance));
  }
  // And lrcal → YAML → lrcal keeps the model to the last digit.
  const std::string yaml = testing::TempDir("urdf_round_trip") + "/ur5.yaml";
  std::ofstream(yaml) << RobotFileText(rig, rig.robot.nominal_values(), std::nullopt, "ur5");
  const RobotFile from_yaml = LoadRobotFile(yaml);
  EXPECT_EQ(from_yaml.robot.nominal_values(), rig.robot.nominal_values());
  ExpectSameKinematics(from_yaml.robot, original, "ranger");
}

TEST(Urdf, DhTableListsEveryLinkAndTheFrames) {
  const RobotFile rig = LoadRobotFile(Example("puma560.urdf"));
  const std::string table = DhTableText(rig.robot, rig.robot.nominal_values());
  EXPECT_THAT(table, ::testing::HasSubstr("# base xyz_m:"));
  EXPECT_THAT(table, ::testing::HasSubstr("# tool xyz_m:"));
  EXPECT_THAT(table,
              ::testing::HasSubstr(
                  "link,joint,theta0_rad,d_m,a_m,alpha_rad,beta_rad,q_min,q_max,parameters"));
  EXPECT_THAT(table, ::testing::HasSubstr("\n2,revolute,"));
  EXPECT_THAT(table, ::testing::HasSubstr("theta alpha a beta\n"));  // link 2, Hayati
  EXPECT_THAT(table, ::testing::HasSubstr("\n6,revolute,"));
}

void ExpectInputError(const std::string& urdf_body, const std::string& tool_link,
                      const std::string& expected) {
  const std::string path = testing::TempDir("urdf_bad") + "/bad.urdf";
  std::ofstream(path) << "<?xml version=\"1.0\"?>\n<robot name=\"bad\">\n"
                      << urdf_body << "</robot>\n";
  try {
    LoadRobotFile(path, tool_link);
    ADD_FAILURE() << "no error for " << expected;
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr(path)) << e.what();
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr(expected)) << e.what();
  }
}

const char kTwoLinks[] = "<link name=\"a\"/><link name=\"b\"/>\n";

TEST(Urdf, BadUrdfsAreNamedByFileJointOrLink) {
  const std::string joint =
      "<joint name=\"j\" type=\"TYPE\"><parent link=\"a\"/>"
      "<child link=\"b\"/>LIMIT</joint>\n";
  const auto with = [&](const std::string& type, const std::string& limit) {
    std::string j = joint;
    j.replace(j.find("TYPE"), 4, type);
    j.replace(j.find("LIMIT"), 5, limit);
    return kTwoLinks + j;
  };
  ExpectInputError(with("floating", ""), "", "joint 'j': lrcal handles revolute");
  ExpectInputError(with("revolute", "<limit lower=\"1\" upper=\"1\" effort=\"0\" velocity=\"0\"/>"),
                   "", "joint 'j': expected <limit lower=... upper=...> with lower < upper");
  ExpectInputError(with("fixed", ""), "", "no movable joint between the root link 'a'");
  ExpectInputError(with("continuous", ""), "c", "no link named 'c' (--tool-link");
  ExpectInputError(std::string(kTwoLinks) + "<link name=\"c\"/>" +
                       with("continuous", "").substr(sizeof(kTwoLinks) - 1) +
                       "<joint name=\"k\" type=\"fixed\"><parent link=\"a\"/><child link=\"c\"/>"
                       "</joint>\n",
                   "", "2 end links (b, c): give the ranger's link with --tool-link");
  ExpectInputError("<link name=\"a\"", "", "not a URDF that urdfdom can read");
  ExpectInputError(kTwoLinks + std::string("<link name=\"c\"/>") +
                       with("continuous", "").substr(sizeof(kTwoLinks) - 1) +
                       "<joint name=\"m\" type=\"continuous\"><parent link=\"b\"/>"
                       "<child link=\"c\"/><mimic joint=\"j\"/></joint>\n",
                   "", "joint 'm' mimics another");
}

// Issue 31: a tree checked before urdfdom builds it. A cycle through the tool link looped until
// memory ran out, a joint that is its own parent likewise, and 150,000 chained links overflowed
// urdfdom's recursion (a signal, in the CLI and in Python): each is now a clear error.
TEST(Urdf, CyclesOwnParentsAndVeryDeepTreesAreRefused) {
  const auto revolute = [](const std::string& name, const std::string& parent,
                           const std::string& child) {
    return "<joint name=\"" + name + "\" type=\"revolute\"><parent link=\"" + parent +
           "\"/><child link=\"" + child +
           "\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
           "velocity=\"1\"/></joint>\n";
  };
  const std::string links =
      "<link name=\"base\"/><link name=\"a\"/><link name=\"b\"/>"
      "<link name=\"c\"/>\n";
  ExpectInputError(
      links + revolute("j1", "base", "a") + revolute("j2", "c", "b") + revolute("j3", "b", "c"),
      "c", "the joints form a cycle: 'b' -> 'c' -> 'b'");
  ExpectInputError(links + revolute("j1", "base", "a") + revolute("j2", "a", "a"), "a",
                   "joint 'j2' has link 'a' as both its parent and its child");
  std::string deep = "<link name=\"l0\"/>\n";
  for (int i = 1; i <= kMaxUrdfLinks; ++i)
    deep += "<link name=\"l" + std::to_string(i) + "\"/>" +
            revolute("j" + std::to_string(i), "l" + std::to_string(i - 1), "l" + std::to_string(i));
  ExpectInputError(deep, "l1000", "the URDF has 1001 links; lrcal reads at most 1000");
}

// Found by fuzzing: a truncated UTF-8 sequence at the end of a file made TinyXML (urdfdom's XML
// reader) read past its buffer. Bytes that are not UTF-8 are refused first, naming the line.
TEST(Urdf, BytesThatAreNotUtf8AreRefusedNamingTheLine) {
  ExpectInputError(kTwoLinks + std::string("<!-- \xc4 -->\n"), "",
                   "bad.urdf:4: not UTF-8 text (an invalid or truncated byte sequence");
  const std::string path = testing::TempDir("urdf_utf8") + "/end.urdf";
  std::ofstream(path, std::ios::binary)
      << "<?xml version=\"1.0\"?>\n<robot name=\"r\">" << kTwoLinks << "</robot>\xeb";
  try {
    LoadRobotFile(path, "");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr(path + ":3: not UTF-8 text"));
  }
  // UTF-8 text is read as before (a comment in Chinese).
  ExpectInputError(kTwoLinks + std::string("<!-- \xe6\x9c\xba\xe5\x99\xa8 -->\n") +
                       "<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/>"
                       "<child link=\"b\"/></joint>\n",
                   "", "no movable joint between the root link 'a'");
}

// Issue 30: a chain between any two links of a tree, against the URDF's pose of the tool link
// relative to the base link composed from the root here, at random configurations.
void ExpectSameKinematicsBetween(const RobotModel& robot, const std::string& urdf,
                                 const std::string& base_link, const std::string& tool_link) {
  ExpectKinematicsOf(
      robot, 29,
      [&](const std::vector<double>& q) {
        std::map<std::string, double> by_name;
        for (int i = 0; i < robot.num_links(); ++i) by_name[robot.links()[i].joint_name] = q[i];
        return testing::UrdfPoseBetween(urdf, base_link, tool_link, by_name);
      },
      tool_link);
}

std::vector<std::string> JointNames(const RobotModel& robot) {
  std::vector<std::string> names;
  for (const Link& link : robot.links()) names.push_back(link.joint_name);
  return names;
}

TEST(Urdf, AFootToHandChainRunsUpTheLegAgainstTheUrdf) {
  const std::string urdf = Example("humanoid_like.urdf");
  const RobotFile rig = LoadRobotFile(urdf, "left_gripper", "left_sole");
  // Up the leg from the ankle (each joint reversed), the torso, down the arm: 6 + 2 + 6 joints.
  EXPECT_THAT(
      JointNames(rig.robot),
      ::testing::ElementsAre("left_ankle_roll", "left_ankle_pitch", "left_knee", "left_hip_pitch",
                             "left_hip_roll", "left_hip_yaw", "torso_yaw", "torso_pitch",
                             "left_shoulder_pitch", "left_shoulder_roll", "left_shoulder_yaw",
                             "left_elbow", "left_wrist_yaw", "left_wrist_pitch"));
  // A reversed joint keeps its URDF range (the knee bends 0 … 2.2 rad).
  EXPECT_EQ(rig.robot.links()[2].q_min, 0.0);
  EXPECT_EQ(rig.robot.links()[2].q_max, 2.2);
  ExpectSameKinematicsBetween(rig.robot, urdf, "left_sole", "left_gripper");
  // From one sole to the other (the walking robot's swap of ends), from a hand to the other hand,
  // a chain that only climbs (a gripper to the pelvis) and one that starts inside the tree.
  for (const auto& [base, tool] :
       std::vector<std::pair<std::string, std::string>>{{"right_sole", "left_sole"},
                                                        {"left_gripper", "right_gripper"},
                                                        {"left_gripper", "pelvis"},
                                                        {"torso", "right_gripper"},
                                                        {"left_sole", "right_finger_a"}}) {
    const RobotFile chain = LoadRobotFile(urdf, tool, base);
    ExpectSameKinematicsBetween(chain.robot, urdf, base, tool);
  }
  // Without a base link the chain starts at the root, as before: the same model as the root named.
  EXPECT_EQ(LoadRobotFile(urdf, "left_gripper").robot.nominal_values(),
            LoadRobotFile(urdf, "left_gripper", "pelvis").robot.nominal_values());
}

TEST(Urdf, TheDualArmsChainsShareTheTorsosLinks) {
  const std::string urdf = Example("dual_arm_torso.urdf");
  const RobotFile left = LoadRobotFile(urdf, "left_tool");
  const RobotFile right = LoadRobotFile(urdf, "right_tool");
  ExpectSameKinematicsBetween(left.robot, urdf, "base_link", "left_tool");
  ExpectSameKinematicsBetween(right.robot, urdf, "base_link", "right_tool");
  // The head's mimic joint is off both chains; the torso's links before the branch (joints 1 and
  // 2 to the next axis) are the same D-H links in both.
  EXPECT_TRUE(left.robot.base().translation.isApprox(right.robot.base().translation));
  for (int i = 0; i < 2; ++i)
    EXPECT_EQ(left.robot.links()[i].nominal, right.robot.links()[i].nominal) << "link " << i + 1;
  EXPECT_NE(left.robot.links()[2].nominal, right.robot.links()[2].nominal);
}

TEST(Urdf, BadChainEndsAreNamed) {
  const std::string urdf = Example("humanoid_like.urdf");
  const auto message = [&](const std::string& tool, const std::string& base) {
    try {
      LoadRobotFile(urdf, tool, base);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message("left_gripper", "left_heel"),
              ::testing::HasSubstr("no link named 'left_heel' (--base-link, or a study's "
                                   "base_link); the links are "));
  EXPECT_THAT(message("torso", "torso"),
              ::testing::HasSubstr("the base link and the tool link are both 'torso'"));
  EXPECT_THAT(message("left_foot", "left_sole"),
              ::testing::HasSubstr("no movable joint between the base link 'left_sole' and the "
                                   "tool link 'left_foot'"));
  // Several end links other than the base: the tool link must be named.
  EXPECT_THAT(message("", "left_sole"),
              ::testing::HasSubstr("5 end links (left_finger_a, left_finger_b, right_finger_a"));
  // A mimic joint on the chain is refused by name (off the chain it is not read).
  EXPECT_THAT(message("left_finger_b", "left_sole"),
              ::testing::HasSubstr("joint 'left_finger_b_joint' mimics another"));
}

TEST(Urdf, ToolLinkIsForUrdfsOnly) {
  try {
    LoadRobotFile(testing::SourcePath("studies/robots/paper.yaml"), "ranger");
    ADD_FAILURE() << "no error";
  } catch (const SettingError& e) {
    EXPECT_EQ(e.where(), "setup.tool_link");
    EXPECT_EQ(e.Respelled(Frontend::kCommandLine).where(), "--tool-link");
    EXPECT_EQ(e.Respelled(Frontend::kPython).where(), "tool_link=");
  }
  try {
    LoadRobotFile(testing::SourcePath("studies/robots/paper.yaml"), "", "world");
    ADD_FAILURE() << "no error";
  } catch (const SettingError& e) {
    EXPECT_EQ(e.Respelled(Frontend::kCommandLine).where(), "--base-link");
  }
}

}  // namespace
}  // namespace lrcal
