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
  // The tool poses `lrcal kinematics` gives for `robot` at `configs` (default: the held-out
  // placement's configurations).
  Json ToolPoses(const std::string& robot, const std::string& configs = "") const {
    std::string out;
    EXPECT_EQ(
        Run("kinematics --format json --plane 0,0,1,-5 --configs " +
                (configs.empty() ? Example("panda_1_right.csv") : configs) + " --robot " + robot,
            &out),
        0)
        << out;
    return Json::parse(out.substr(out.find('['), out.rfind(']') - out.find('[') + 1));
  }
  // cal.yaml: the Panda calibrated from MUKCa's front placement (README "Sockets").
  void CalibratePanda() const {
    std::string out;
    ASSERT_EQ(Run("identify --sensor socket --robot " + Example("panda.urdf") +
                      " --tool-link ball_link --socket-distance 0,1=0.05 --fix "
                      "target_x,target_y,target_z --auto-fix --sigma-mm 0.3 --prior-sigma "
                      "theta=10mrad,alpha=10mrad,a=2mm,d=2mm --data " +
                      Example("panda_1_front.csv") + " --write-robot " + Path("cal.yaml"),
                  &out),
              0)
        << out;
  }
  std::string dir_;
};

TEST_F(DeployCli, ACalibratedPandaGoesIntoTheUsersOwnUrdf) {
  std::string out;
  ASSERT_NO_FATAL_FAILURE(CalibratePanda());
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

// Compensation as a controller would use it: the held-out placement's commands, planned on the
// nominal URDF, corrected for the calibrated Panda; the calibrated model's tool poses at the
// corrected commands (lrcal kinematics) are the nominal plan's to 1e-9.
TEST_F(DeployCli, CompensatedCommandsReachTheNominalPlansPoses) {
  std::string out;
  ASSERT_NO_FATAL_FAILURE(CalibratePanda());
  ASSERT_EQ(Run("compensate --robot " + Path("cal.yaml") + " --nominal " + Example("panda.urdf") +
                    " --tool-link ball_link --targets " + Example("panda_1_right.csv") + " --out " +
                    Path("commands.csv"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("60 targets (tool poses)"));
  EXPECT_THAT(out, HasSubstr("60 reached"));
  // The compensated commands as a configurations file for lrcal kinematics.
  std::ifstream in(Path("commands.csv"));
  std::string line;
  std::getline(in, line);
  std::ofstream configs(Path("q.csv"));
  configs << "q1,q2,q3,q4,q5,q6,q7\n";
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 12u) << line;
    EXPECT_EQ(cells[9], "1") << line;   // converged
    EXPECT_EQ(cells[10], "1") << line;  // within_limits
    for (int j = 0; j < 7; ++j) configs << (j ? "," : "") << cells[static_cast<std::size_t>(j)];
    configs << "\n";
    ++rows;
  }
  configs.close();
  EXPECT_EQ(rows, 60);
  const Json reached = ToolPoses(Path("cal.yaml"), Path("q.csv"));
  const Json planned =
      ToolPoses(Example("panda.urdf") + " --tool-link ball_link", Example("panda_1_right.csv"));
  ASSERT_EQ(reached.size(), planned.size());
  constexpr double kReached = testing::tolerance::kRoundTrip;  // m
  for (std::size_t i = 0; i < reached.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(reached[i]["position"][c].get<double>(), planned[i]["position"][c].get<double>(),
                  kReached);
      for (int r = 0; r < 3; ++r)
        EXPECT_NEAR(reached[i]["rotation"][r][c].get<double>(),
                    planned[i]["rotation"][r][c].get<double>(), kReached);
    }

  EXPECT_EQ(
      Run("compensate --robot " + Path("cal.yaml") + " --targets " + Example("panda_1_right.csv"),
          &out),
      2);
  EXPECT_THAT(out, HasSubstr("--nominal: missing"));
  std::ofstream(Path("bad.csv")) << "q1,q2,q3,q4,q5,q6,q7,x,y,z,qx,qy,qz,qw\n"
                                 << "0,0,0,-1,0,1,0,0.3,0,0.5,0,0,0,2\n";
  EXPECT_EQ(Run("compensate --robot " + Path("cal.yaml") + " --targets " + Path("bad.csv"), &out),
            2);
  EXPECT_THAT(out, HasSubstr("bad.csv:2 columns qx, qy, qz, qw: expected a unit quaternion"));
}

// The presets and classes a controller's user asks for instead of typing names: --estimate
// offsets is each joint's zero offset (θ1 … θ6 on the paper's arm), lengths a and d, --fix alpha
// every α; a preset lrcal does not have is refused by name.
TEST_F(DeployCli, PresetsAndClassesNameTheTermsForTheUser) {
  std::string out;
  ASSERT_EQ(Run("sample --count 40 --seed 3 --out " + Path("c.csv"), &out), 0) << out;
  const auto terms = [&](const std::string& options) {
    std::string text;
    EXPECT_EQ(
        Run("identifiability --format json --configs " + Path("c.csv") + " " + options, &text), 0)
        << text;
    const Json j = Json::parse(text.substr(text.find('{'), text.rfind('}') - text.find('{') + 1));
    return j["parameters"].get<std::vector<std::string>>();
  };
  EXPECT_THAT(terms("--estimate offsets"),
              ::testing::ElementsAre("theta1", "theta2", "theta3", "theta4", "theta5", "theta6"));
  for (const std::string& name : terms("--estimate lengths"))
    EXPECT_TRUE(name[0] == 'a' || name[0] == 'd') << name;
  const std::vector<std::string> all = terms(""), no_alpha = terms("--fix alpha,d1");
  EXPECT_EQ(all.size(), 25u);
  EXPECT_EQ(no_alpha.size(), 25u - 6 - 1);
  for (const std::string& name : no_alpha) EXPECT_NE(name.rfind("alpha", 0), 0u) << name;
  EXPECT_EQ(Run("identifiability --estimate joints --configs " + Path("c.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("--estimate: 'joints' is not a preset"));
}

// Joint offsets for a controller that takes nothing else: the calibrated Panda against its URDF,
// one offset per joint by name, and the error of that simplification stated beside the nominal
// model's (smaller, not zero: a calibration is more than offsets).
TEST_F(DeployCli, JointOffsetsStateWhatTheSimplificationCosts) {
  std::string out;
  ASSERT_NO_FATAL_FAILURE(CalibratePanda());
  ASSERT_EQ(Run("export --format joint-offsets --robot " + Path("cal.yaml") + " --nominal " +
                    Example("panda.urdf") + " --tool-link ball_link --count 300 --out " +
                    Path("offsets.csv"),
                &out),
            0)
      << out;
  std::ifstream in(Path("offsets.csv"));
  std::string line, error_line;
  std::vector<std::string> rows;
  while (std::getline(in, line)) {
    if (line.rfind("# The simplification's error", 0) == 0) error_line = line;
    if (!line.empty() && line[0] != '#') rows.push_back(line);
  }
  ASSERT_EQ(rows.size(), 8u);
  EXPECT_EQ(rows[0], "joint,name,offset,unit");
  EXPECT_EQ(rows[4].rfind("4,panda_joint4,", 0), 0u) << rows[4];
  const auto number_after = [&](const std::string& label) {
    return std::stod(error_line.substr(error_line.find(label) + label.size()));
  };
  const double rms = number_after("tool position RMS "), nominal = number_after("alone: RMS ");
  EXPECT_GT(rms, 0.01);
  EXPECT_LT(rms, nominal / 2);
  EXPECT_EQ(Run("export --format joint-offsets --robot " + Path("cal.yaml"), &out), 2);
  EXPECT_THAT(out, HasSubstr("--nominal: missing"));
}

// identify --only-significant K: the corrections within K standard deviations of zero are held at
// nominal and the rest refitted, and both models' predicted accuracy is stated.
TEST_F(DeployCli, OnlySignificantCorrectionsAreKept) {
  std::string out;
  ASSERT_EQ(Run("sample --count 40 --seed 3 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv"), &out), 0) << out;
  ASSERT_EQ(
      Run("identify --format json --sigma-mm 0.2 --only-significant 2 --data " + Path("m.csv"),
          &out),
      0)
      << out;
  const Json fit = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  const Json& filter = fit["only_significant"];
  ASSERT_FALSE(filter["held"].empty());
  std::vector<std::string> estimated;
  for (const Json& p : fit["parameters"]) estimated.push_back(p["name"]);
  for (const Json& h : filter["held"]) {
    EXPECT_LT(h["ratio"].get<double>(), 2.0);
    EXPECT_THAT(estimated, ::testing::Not(::testing::Contains(h["name"].get<std::string>())));
  }
  EXPECT_EQ(estimated.size() + filter["held"].size(), 25u);
  EXPECT_GT(filter["predicted_rms_filtered_mm"].get<double>(), 0);
  EXPECT_GT(filter["predicted_rms_full_mm"].get<double>(), 0);
  EXPECT_EQ(Run("identify --only-significant -1 --data " + Path("m.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("--only-significant: expected a positive number"));
}

}  // namespace
}  // namespace lrcal
