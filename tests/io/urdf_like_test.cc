// A calibration written into the user's own URDF (UrdfLikeText): on the shipped Panda with its
// meshes, gripper branch and mimic finger joint, the written file's forward kinematics to the tool
// link — composed independently here from its joint origins and axes — equals the calibrated
// model's to 1e-12, and an element-by-element walk of the two XML documents finds only the
// chain's joint origins changed; a tool link that turns with the last joint; models of another
// robot refused by name.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <fstream>
#include <random>
#include <set>

#include "lrcal/core/error.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/urdf.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "test_util.h"
#include "urdf_kinematics.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;
constexpr double kLikeTolerance = testing::tolerance::kUrdf;  // m, rad

std::string PandaUrdf() { return testing::SourcePath("examples/mukca/panda.urdf"); }

// The Panda's chain to `tool_link` with every link value 1–3 mm or mrad off, and its base and
// tool transforms moved too: a calibrated model.
struct Calibrated {
  RobotModel robot;
  Eigen::VectorXd values;
};
Calibrated CalibratedPanda(const std::string& tool_link, bool move_tool = true) {
  const RobotFile own = LoadRobotFile(PandaUrdf(), tool_link);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> size(1e-3, 3e-3);
  Calibrated c{own.robot, own.robot.nominal_values()};
  for (int index : own.robot.parameter_indices())
    c.values[index] += (index % 2 ? 1 : -1) * size(rng);
  const RigidTransform base = RigidTransform::FromXyzRpy(Eigen::Vector3d(1e-3, -2e-3, 1.5e-3),
                                                         Eigen::Vector3d(2e-3, -1e-3, 3e-3));
  const RigidTransform tool = RigidTransform::FromXyzRpy(Eigen::Vector3d(-1e-3, 2e-3, 0.5e-3),
                                                         Eigen::Vector3d(1e-3, 2e-3, -2e-3));
  c.robot = own.robot.WithFrames(own.robot.base() * base,
                                 move_tool ? own.robot.tool() * tool : own.robot.tool());
  return c;
}

std::string WriteLike(const std::string& name, const std::string& tool_link, const Calibrated& c) {
  const std::string path = testing::TempDir("urdf_like") + "/" + name;
  std::ofstream(path) << UrdfLikeText(PandaUrdf(), tool_link, c.robot, c.values);
  return path;
}

void ExpectModelKinematics(const Calibrated& c, const std::string& path,
                           const std::string& tool_link) {
  std::mt19937 rng(29);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> q;
    for (const Link& link : c.robot.links())
      q.push_back(std::uniform_real_distribution<double>(link.q_min, link.q_max)(rng));
    const Pose<double> model = ForwardKinematics<double>(c.robot, c.values.data(), q.data());
    const Eigen::Isometry3d urdf = testing::UrdfForwardKinematics(path, tool_link, q);
    EXPECT_LT((model.p_BT - urdf.translation()).norm(), kLikeTolerance);
    EXPECT_THAT(model.R_BT, testing::EigenNear(urdf.linear(), kLikeTolerance));
  }
}

// Walks two XML nodes in parallel: the same node types, element names, attributes and texts,
// except the <origin> attributes of the joints in `changed` (whose names are collected in
// `seen_changed` when they differ).
void ExpectSameXml(const TiXmlNode* a, const TiXmlNode* b, const std::string& joint,
                   std::set<std::string>* seen_changed) {
  ASSERT_EQ(a->Type(), b->Type());
  ASSERT_EQ(std::string(a->Value()), std::string(b->Value()));
  if (const TiXmlElement* ea = a->ToElement()) {
    const TiXmlElement* eb = b->ToElement();
    const std::string here = std::string(ea->Value()) == "joint" && ea->Attribute("name")
                                 ? ea->Attribute("name")
                                 : joint;
    std::vector<std::pair<std::string, std::string>> attributes_a, attributes_b;
    for (const TiXmlAttribute* t = ea->FirstAttribute(); t; t = t->Next())
      attributes_a.emplace_back(t->Name(), t->Value());
    for (const TiXmlAttribute* t = eb->FirstAttribute(); t; t = t->Next())
      attributes_b.emplace_back(t->Name(), t->Value());
    if (std::string(ea->Value()) == "origin" && attributes_a != attributes_b) {
      seen_changed->insert(joint);
    } else {
      EXPECT_EQ(attributes_a, attributes_b) << "element <" << ea->Value() << "> in " << here;
    }
    const TiXmlNode* ca = a->FirstChild();
    const TiXmlNode* cb = b->FirstChild();
    for (; ca && cb; ca = ca->NextSibling(), cb = cb->NextSibling())
      ExpectSameXml(ca, cb, here, seen_changed);
    EXPECT_EQ(ca == nullptr, cb == nullptr) << "children of <" << ea->Value() << "> in " << here;
  }
}

TEST(UrdfLike, ThePandaKeepsEverythingOffTheChainAndTakesTheCalibration) {
  const Calibrated c = CalibratedPanda("ball_link");
  const std::string path = WriteLike("panda.urdf", "ball_link", c);
  ExpectModelKinematics(c, path, "ball_link");
  // Read back, it is the same model (lrcal's D-H conversion of the written chain).
  const RobotFile back = LoadRobotFile(path, "ball_link");
  std::vector<double> q(7, 0.3);
  const Pose<double> a = ForwardKinematics<double>(c.robot, c.values.data(), q.data());
  const Pose<double> b =
      ForwardKinematics<double>(back.robot, back.robot.nominal_values().data(), q.data());
  EXPECT_LT((a.p_BT - b.p_BT).norm(), kLikeTolerance);

  TiXmlDocument original, written;
  ASSERT_TRUE(original.LoadFile(PandaUrdf().c_str()));
  ASSERT_TRUE(written.LoadFile(path.c_str()));
  std::set<std::string> changed;
  const TiXmlNode* x = original.FirstChild();
  const TiXmlNode* y = written.FirstChild();
  for (; x && y; x = x->NextSibling(), y = y->NextSibling()) ExpectSameXml(x, y, "", &changed);
  EXPECT_EQ(x == nullptr, y == nullptr);
  // The seven joints' origins and the flange's fixed joint (which carries the tool); the hand,
  // the fingers (one a mimic joint), the ball's joint and every mesh as they were.
  EXPECT_THAT(changed, ::testing::ElementsAre("panda_joint1", "panda_joint2", "panda_joint3",
                                              "panda_joint4", "panda_joint5", "panda_joint6",
                                              "panda_joint7", "panda_joint8"));
}

// The URDF's own model written into it gives it back: every joint frame keeps its place (so a
// calibration moves link frames, meshes and inertials only by what it moved), not just the tool.
TEST(UrdfLike, TheUrdfsOwnModelGivesEveryJointOriginBack) {
  const RobotFile own = LoadRobotFile(PandaUrdf(), "ball_link");
  const Calibrated nominal{own.robot, own.robot.nominal_values()};
  const std::string path = WriteLike("own.urdf", "ball_link", nominal);
  const urdf::ModelInterfaceSharedPtr a = urdf::parseURDFFile(PandaUrdf());
  const urdf::ModelInterfaceSharedPtr b = urdf::parseURDFFile(path);
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->joints_.size(), b->joints_.size());
  for (const auto& [name, joint] : a->joints_) {
    const urdf::Pose& x = joint->parent_to_joint_origin_transform;
    const urdf::Pose& y = b->joints_.at(name)->parent_to_joint_origin_transform;
    const Eigen::Quaterniond qx(x.rotation.w, x.rotation.x, x.rotation.y, x.rotation.z);
    const Eigen::Quaterniond qy(y.rotation.w, y.rotation.x, y.rotation.y, y.rotation.z);
    EXPECT_LT((Eigen::Vector3d(x.position.x, x.position.y, x.position.z) -
               Eigen::Vector3d(y.position.x, y.position.y, y.position.z))
                  .norm(),
              kLikeTolerance)
        << name;
    EXPECT_LT(qx.angularDistance(qy), kLikeTolerance) << name;
  }
}

TEST(UrdfLike, AToolLinkThatTurnsWithTheLastJointTakesOnlyAToolOnItsAxis) {
  // The URDF's own model, tool link panda_link7: the joint's frame slides along its axis.
  const RobotFile own = LoadRobotFile(PandaUrdf(), "panda_link7");
  const Calibrated nominal{own.robot, own.robot.nominal_values()};
  ExpectModelKinematics(nominal, WriteLike("link7.urdf", "panda_link7", nominal), "panda_link7");
  // A calibrated last link puts the tool off the axis: there is no element to carry it.
  const Calibrated c = CalibratedPanda("panda_link7");
  EXPECT_THAT([&] { UrdfLikeText(PandaUrdf(), "panda_link7", c.robot, c.values); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("'panda_link7' is the last movable joint's own child")));
}

TEST(UrdfLike, AModelOfAnotherChainIsRefused) {
  const RobotModel& paper = testing::PaperRobot();
  EXPECT_THAT([&] { UrdfLikeText(PandaUrdf(), "ball_link", paper, paper.nominal_values()); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("the chain to 'ball_link' has 7 movable joints but the model has 6")));
  Calibrated far = CalibratedPanda("ball_link");
  far.values[kValuesPerLink * 3 + kD] += 1.0;  // a metre: not a calibration of this arm
  EXPECT_THAT([&] { UrdfLikeText(PandaUrdf(), "ball_link", far.robot, far.values); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("is the model a calibration of this robot and tool link?")));
  EXPECT_THAT([&] { UrdfLikeText(PandaUrdf(), "no_link", far.robot, far.values); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("no link named 'no_link'")));
}

}  // namespace
}  // namespace lrcal
