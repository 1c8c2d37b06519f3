// Data files read for a robot (robot_data.h): a robot whose joints have names (a URDF's) reads
// files whose joint columns carry those names exactly as files with q1..qN; a missing name and a
// value out of range are named by column (and joint).
#include "lrcal/io/robot_data.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/io/socket_data.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;

// MUKCa's Panda (examples/mukca): joints panda_joint1 … panda_joint7.
const RobotFile& Panda() {
  static const RobotFile rig =
      LoadRobotFile(testing::SourcePath("examples/mukca/panda.urdf"), "ball_link");
  return rig;
}

// `text` with its first line's q1..q7 replaced by `names` (comma-joined).
std::string WithHeader(const std::string& text, const std::string& names) {
  return names + text.substr(text.find('\n'));
}

const char* const kPandaNames =
    "panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,panda_joint6,panda_joint7";

TEST(RobotData, JointColumnsMayBeTheRobotsJointNames) {
  for (std::size_t j = 0; j < 7; ++j)
    EXPECT_EQ(Panda().robot.links()[j].joint_name, "panda_joint" + std::to_string(j + 1));
  const std::string original =
      testing::ReadFile(testing::SourcePath("examples/mukca/panda_1_front.csv"));  // q1..q7, socket
  const std::string dir = testing::TempDir("robot_data_names");
  // The joint columns by name, in another order, beside the socket column.
  std::istringstream in(original);
  std::ostringstream renamed;
  std::string line;
  std::getline(in, line);
  renamed << "socket,panda_joint7,panda_joint1,panda_joint2,panda_joint3,panda_joint4,"
             "panda_joint5,panda_joint6\n";
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    renamed << cells[7] << "," << cells[6];
    for (int k = 0; k < 6; ++k) renamed << "," << cells[static_cast<std::size_t>(k)];
    renamed << "\n";
  }
  std::ofstream(dir + "/named.csv") << renamed.str();
  const SocketData a =
      ReadSocketData(testing::SourcePath("examples/mukca/panda_1_front.csv"), Panda().robot);
  const SocketData b = ReadSocketData(dir + "/named.csv", Panda().robot);
  ASSERT_EQ(a.values.size(), b.values.size());
  for (int i = 0; i < a.values.size(); ++i)
    for (int j = 0; j < 7; ++j) EXPECT_EQ(a.values.configs.q(i)[j], b.values.configs.q(i)[j]);
  EXPECT_EQ(a.ids, b.ids);
  EXPECT_EQ(ReadRobotPoses(dir + "/named.csv", Panda().robot).size(), a.values.size());

  // One joint's column missing: named; a value out of range: the column and the joint.
  std::ofstream(dir + "/short.csv")
      << WithHeader(original,
                    "panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,panda_joint6,"
                    "wrist,socket");
  EXPECT_THAT([&] { ReadRobotConfigurations(dir + "/short.csv", Panda().robot); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("short.csv:1 column 'panda_joint7': missing: the file names joints by "
                            "the robot's joint names")));
  std::ofstream(dir + "/far.csv") << kPandaNames << "\n0,3,0,-1,0,1,0\n";
  EXPECT_THAT([&] { ReadRobotConfigurations(dir + "/far.csv", Panda().robot); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("column 'q2' (joint 'panda_joint2'): 3 is outside the joint's range")));
  // A robot without joint names (the paper's YAML) still needs q1..qN.
  std::ofstream(dir + "/paper.csv") << "j1,j2,j3,j4,j5,j6\n0,0,0,0,0,0\n";
  EXPECT_THAT([&] { ReadRobotConfigurations(dir + "/paper.csv", testing::PaperRobot()); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("column 'q1'")));
}

}  // namespace
}  // namespace lrcal
