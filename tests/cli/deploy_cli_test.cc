// Deploying a calibration as a user does it: the shipped Panda (meshes, a gripper branch with a
// mimic joint) calibrated from MUKCa's socket seatings by `lrcal identify --write-robot`, then
// written into the user's own URDF by `lrcal export --like`; read back, the written URDF's tool
// poses equal the calibrated robot file's to 1e-12 at held-out configurations, and its bad
// requests are refused by option.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;
using Json = nlohmann::json;

class DeployCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::TempDir("DeployCli"); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  static std::string Example(const std::string& name) {
    return testing::SourcePath("examples/mukca/" + name);
  }
  int Run(const std::string& args, std::string* out) const {
    return testing::RunCommand(testing::LrcalBinary() + " " + args, out);
  }
  // The tool poses `lrcal kinematics` gives for `robot` at the held-out placement's configurations.
  Json ToolPoses(const std::string& robot) const {
    std::string out;
    EXPECT_EQ(Run("kinematics --format json --plane 0,0,1,-5 --configs " +
                      Example("panda_1_right.csv") + " --robot " + robot,
                  &out),
              0)
        << out;
    return Json::parse(out.substr(out.find('['), out.rfind(']') - out.find('[') + 1));
  }
  std::string dir_;
};

TEST_F(DeployCli, ACalibratedPandaGoesIntoTheUsersOwnUrdf) {
  std::string out;
  ASSERT_EQ(Run("identify --sensor socket --robot " + Example("panda.urdf") +
                    " --tool-link ball_link --socket-distance 0,1=0.05 --fix "
                    "target_x,target_y,target_z --auto-fix --sigma-mm 0.3 --prior-sigma "
                    "theta=10mrad,alpha=10mrad,a=2mm,d=2mm --data " +
                    Example("panda_1_front.csv") + " --write-robot " + Path("cal.yaml"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("export --robot " + Path("cal.yaml") + " --like " + Example("panda.urdf") +
                    " --tool-link ball_link --out " + Path("panda_calibrated.urdf"),
                &out),
            0)
      << out;
  const Json calibrated = ToolPoses(Path("cal.yaml"));
  const Json written = ToolPoses(Path("panda_calibrated.urdf") + " --tool-link ball_link");
  const Json nominal = ToolPoses(Example("panda.urdf") + " --tool-link ball_link");
  ASSERT_EQ(calibrated.size(), written.size());
  constexpr double kExact = testing::tolerance::kUrdf;
  double moved = 0;
  for (std::size_t i = 0; i < calibrated.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(written[i]["position"][c].get<double>(),
                  calibrated[i]["position"][c].get<double>(), kExact);
      for (int r = 0; r < 3; ++r)
        EXPECT_NEAR(written[i]["rotation"][r][c].get<double>(),
                    calibrated[i]["rotation"][r][c].get<double>(), kExact);
      moved = std::max(moved, std::abs(written[i]["position"][c].get<double>() -
                                       nominal[i]["position"][c].get<double>()));
    }
  // The calibration moved the ball by millimetres (not nothing, not metres).
  EXPECT_GT(moved, 1e-4);
  EXPECT_LT(moved, 0.05);
  // The branch off the chain is the user's, byte for byte in its elements.
  std::ifstream in(Path("panda_calibrated.urdf"));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_THAT(text, HasSubstr("<mimic joint=\"panda_finger_joint1\""));
  EXPECT_THAT(text, HasSubstr("<mesh filename=\"../meshes/panda/hand.dae\""));

  EXPECT_EQ(Run("export --robot " + Path("cal.yaml") + " --like " + Example("panda.urdf") +
                    " --format dh-table",
                &out),
            2);
  EXPECT_THAT(out, HasSubstr("--like: writes into a URDF: give --format urdf"));
  EXPECT_EQ(
      Run("export --robot paper --like " + Example("panda.urdf") + " --tool-link ball_link", &out),
      2);
  EXPECT_THAT(out, HasSubstr("has 7 movable joints but the model has 6 links"));
}

}  // namespace
}  // namespace lrcal
