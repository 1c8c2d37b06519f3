// Issue 30 as a user meets it: `lrcal identify` and `identifiability` on a tree — the dual-arm
// robot's two arms sharing its torso (--tool-link left_tool,right_tool, one file per arm) and a
// humanoid's chain from its sole up the leg to a gripper (--base-link left_sole). The truths are
// the URDFs with every joint origin moved (a physical robot), simulated by `lrcal simulate`;
// configurations are logged as a robot logs them, every joint by its URDF name.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "test_util.h"
#include "urdf_kinematics.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;
using Json = nlohmann::json;

class TreeCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::TempDir("TreeCli"); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  int Run(const std::string& args, std::string* out) const {
    return testing::RunCommand(testing::LrcalBinary() + " " + args, out);
  }
  static Json JsonOf(const std::string& text) {
    return Json::parse(text.substr(text.find('{'), text.rfind('}') - text.find('{') + 1));
  }
  // A noise-free joint fit's JSON: nothing left over, and the estimate of `term`.
  static double ExactFitsDelta(const std::string& text, const std::string& term) {
    const Json fit = JsonOf(text);
    EXPECT_LT(fit["residual_rms"].get<double>(), 1e-12);
    for (const Json& p : fit["parameters"])
      if (p["name"] == term) return p["delta"].get<double>();
    ADD_FAILURE() << "no term " << term;
    return 0;
  }
  std::string dir_;
};

const char kDualArm[] = "examples/urdf/dual_arm_torso.urdf";
const char kTracker[] = " --sensor point --instrument 2.5,0.3,0.2,0,0,3";

// Every joint of the dual-arm robot by name (a log of the whole robot), within its range.
void WriteWholeRobotLog(const std::string& path, int count) {
  const std::vector<std::string> torso = {"torso_yaw", "torso_pitch_1", "torso_pitch_2"};
  const std::vector<std::string> arm = {"shoulder_pitch", "shoulder_roll", "shoulder_yaw",
                                        "elbow",          "wrist_yaw",     "wrist_pitch"};
  std::vector<std::string> names = torso;
  for (const char* side : {"right", "left"})  // not the order the chains list them
    for (const std::string& j : arm) names.push_back(std::string(side) + "_" + j);
  std::ofstream out(path);
  for (std::size_t k = 0; k < names.size(); ++k) out << (k ? "," : "") << names[k];
  out << "\n";
  std::mt19937 rng(3);
  for (int i = 0; i < count; ++i) {
    for (std::size_t k = 0; k < names.size(); ++k) {
      const bool elbow = names[k].find("elbow") != std::string::npos;
      out << (k ? "," : "")
          << std::uniform_real_distribution<double>(elbow ? -2.0 : -0.55, elbow ? 0.05 : 0.55)(rng);
    }
    out << "\n";
  }
}

TEST_F(TreeCli, TwoArmsSharingATorsoAreCalibratedTogether) {
  const std::string nominal = testing::SourcePath(kDualArm);
  const std::string truth = testing::UrdfWithMovedOrigins(nominal, 4, Path("true.urdf"));
  WriteWholeRobotLog(Path("log.csv"), 50);
  std::string out;
  for (const char* arm : {"left", "right"})
    ASSERT_EQ(Run("simulate --robot " + truth + " --tool-link " + arm + "_tool" + kTracker +
                      " --sigma-mm 0 --configs " + Path("log.csv") + " --out " +
                      Path(std::string(arm) + ".csv"),
                  &out),
              0)
        << out;
  const std::string tree = " --robot " + nominal + " --tool-link left_tool,right_tool" + kTracker;
  ASSERT_EQ(Run("identifiability" + tree + " --configs " + Path("left.csv") + " --configs " +
                    Path("right.csv"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("tree: 2 chains (left_tool, right_tool) over 15 joints"));
  EXPECT_THAT(out, HasSubstr("shared: theta1, alpha1, a1, d1, theta2, alpha2, a2, beta2, "
                             "instrument_x"));
  ASSERT_EQ(Run("identify --auto-fix --format json" + tree + " --data " + Path("left.csv") +
                    " --data " + Path("right.csv"),
                &out),
            0)
      << out;
  const Json fit = JsonOf(out);
  EXPECT_EQ(fit["tree"]["tool_links"], Json::array({"left_tool", "right_tool"}));
  EXPECT_EQ(fit["tree"]["joints"].size(), 15u);
  EXPECT_THAT(fit["tree"]["own_terms"]["right_tool"].get<std::vector<std::string>>(),
              ::testing::Contains("right_tool.theta3"));
  // The union's model holds the moved robot: nothing left over.
  EXPECT_LT(fit["residual_rms"].get<double>(), 1e-12);

  // A design over the whole robot: every chain measured at each chosen configuration, written by
  // joint name, which each chain's simulate reads as its own.
  ASSERT_EQ(Run("design --generate 150 --select 20 --method greedy --format json" + tree +
                    " --out " + Path("chosen.csv"),
                &out),
            0)
      << out;
  const Json design = JsonOf(out);
  EXPECT_EQ(design["tree"]["values_per_configuration"], 6);
  EXPECT_EQ(design["selected"].size(), 20u);
  std::ifstream chosen(Path("chosen.csv"));
  std::string header;
  std::getline(chosen, header);
  EXPECT_EQ(header.substr(0, 34), "torso_yaw,torso_pitch_1,torso_pitc");
  EXPECT_EQ(Run("design --generate 50 --select 10 --criterion I" + tree, &out), 2);
  EXPECT_THAT(out, HasSubstr("--criterion: I weighs one chain's tool poses"));

  // What a tree's run refuses, by option.
  const std::string files = " --data " + Path("left.csv") + " --data " + Path("right.csv");
  EXPECT_EQ(Run("identify" + tree + " --data " + Path("left.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("--data: given 1 time(s) for the 2 chains of --tool-link"));
  EXPECT_EQ(Run("identify" + tree + files + " --write-robot " + Path("cal.yaml"), &out), 2);
  EXPECT_THAT(out, HasSubstr("--write-robot: writes one chain's robot file"));
  EXPECT_EQ(Run("identify" + tree + files + " --holdout 5", &out), 2);
  EXPECT_THAT(out, HasSubstr("--holdout: is not taken by a calibration from a tree's chains"));
  EXPECT_EQ(Run("identify --robot paper --tool-link a,b --data x.csv", &out), 2);
  EXPECT_THAT(out, HasSubstr("--tool-link: several tool links are a tree's chains: --robot must "
                             "be a URDF"));
  EXPECT_EQ(Run("identify --robot " + nominal +
                    " --tool-link left_tool,right_tool --sensor point,pose,point" + files,
                &out),
            2);
  EXPECT_THAT(out, HasSubstr("--sensor: expected one kind for every chain, or one per tool link"));
}

// The head tilts with the last torso joint (a mimic joint): a coupled link whose gain is a term.
// The log has no head_tilt column (robots do not always log mimic joints): it follows its joint.
TEST_F(TreeCli, AMimicJointOnAChainIsACoupledLinkWithItsGain) {
  const std::string nominal = testing::SourcePath(kDualArm);
  WriteWholeRobotLog(Path("log.csv"), 40);
  const std::string tracker = std::string(kTracker) + " --target 0.05,0.02,0.1";
  std::string out;
  ASSERT_EQ(Run("identifiability --robot " + nominal + " --tool-link head" + tracker +
                    " --configs " + Path("log.csv"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("chain to head over 3 joints, coupled: head_tilt = -1 x "
                             "torso_pitch_2 + 0"));
  ASSERT_EQ(
      Run("identifiability --format json --robot " + nominal +
              " --tool-link left_tool,right_tool,head" + tracker + " --configs " + Path("log.csv") +
              " --configs " + Path("log.csv") + " --configs " + Path("log.csv"),
          &out),
      0)
      << out;
  const Json j = JsonOf(out);
  const auto names = j["tree"]["own_terms"]["head"].get<std::vector<std::string>>();
  EXPECT_THAT(names, ::testing::Contains("head.coupling4_gain"));
  EXPECT_THAT(j["suggested_fixed"].get<std::vector<std::string>>(),
              ::testing::Not(::testing::Contains("head.coupling4_gain")));
  // A tracker on the head of the true robot (origins moved, the tilt's multiplier -1.003): its
  // simulated points are calibrated back, gain included, with nothing left over.
  const std::string truth = testing::UrdfWithMovedOrigins(nominal, 8, Path("true.urdf"));
  {
    std::ifstream in(truth);
    std::stringstream text;
    text << in.rdbuf();
    std::string urdf = text.str();
    urdf.replace(urdf.find("multiplier=\"-1.0\""), 17, "multiplier=\"-1.003\"");
    std::ofstream(truth) << urdf;
  }
  for (const char* chain : {"left_tool", "right_tool", "head"})
    ASSERT_EQ(Run("simulate --robot " + truth + " --tool-link " + chain + tracker +
                      " --sigma-mm 0 --configs " + Path("log.csv") + " --out " +
                      Path(std::string(chain) + ".csv"),
                  &out),
              0)
        << out;
  ASSERT_EQ(Run("identify --auto-fix --format json --robot " + nominal +
                    " --tool-link left_tool,right_tool,head" + tracker + " --data " +
                    Path("left_tool.csv") + " --data " + Path("right_tool.csv") + " --data " +
                    Path("head.csv"),
                &out),
            0)
      << out;
  EXPECT_NEAR(ExactFitsDelta(out, "head.coupling4_gain"), -3e-3, 1e-9);
  // simulate writes one chain's file; the one-chain commands refuse a coupled chain by name.
  EXPECT_EQ(Run("simulate --robot " + nominal + " --tool-link left_tool,head" + tracker +
                    " --configs " + Path("log.csv") + " --out " + Path("x.csv"),
                &out),
            2);
  EXPECT_THAT(out, HasSubstr("--tool-link: simulate writes one chain's file"));
  EXPECT_EQ(Run("accuracy --robot " + nominal + " --tool-link head --workspace 10", &out), 2);
  EXPECT_THAT(out, HasSubstr("joint 'head_tilt' mimics another; a chain with a coupled joint"));
}

TEST_F(TreeCli, ACoupledLinkOfARobotFileIsCalibratedWithItsGain) {
  // examples/robots/parallelogram_arm.yaml: the paper's arm with q3 = -q2 (couple:). Its true
  // robot has other link values (none of those a tracker cannot separate: d1, d4 against a3, a1
  // when q3 = -q2 exactly) and a linkage ratio of -1.003; a log of its five joints (q3 left out)
  // is simulated noise-free and calibrated back, the gain to 1e-9.
  const std::string nominal = testing::SourcePath("examples/robots/parallelogram_arm.yaml");
  std::string text;
  {
    std::ifstream in(nominal);
    std::stringstream all;
    all << in.rdbuf();
    text = all.str();
  }
  for (const auto& [from, to] :
       std::vector<std::pair<std::string, std::string>>{{"multiplier: -1,", "multiplier: -1.003,"},
                                                        {"theta: pi,", "theta: 3.1426,"},
                                                        {"a: 1.0,", "a: 1.0012,"},
                                                        {"a: -0.12,", "a: -0.1195,"}}) {
    ASSERT_NE(text.find(from), std::string::npos) << from;
    text.replace(text.find(from), from.size(), to);
  }
  std::ofstream(Path("true.yaml")) << text;
  {
    std::ofstream log(Path("log.csv"));
    log << "q1,q2,q4,q5,q6\n";
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> q(-1.1, 1.1);
    for (int i = 0; i < 40; ++i)
      log << q(rng) << "," << q(rng) << "," << q(rng) << "," << q(rng) << "," << q(rng) << "\n";
  }
  const std::string tracker = std::string(kTracker) + " --target 0.05,0.02,0.1";
  std::string out;
  ASSERT_EQ(Run("simulate --robot " + Path("true.yaml") + tracker + " --sigma-mm 0 --configs " +
                    Path("log.csv") + " --out " + Path("points.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("identify --auto-fix --format json --robot " + nominal + tracker + " --data " +
                    Path("points.csv"),
                &out),
            0)
      << out;
  EXPECT_NEAR(ExactFitsDelta(out, "coupling3_gain"), -3e-3, 1e-9);
  // The one-chain commands refuse it at its line; a YAML robot takes no tool link.
  EXPECT_EQ(Run("accuracy --robot " + nominal + " --workspace 10", &out), 2);
  EXPECT_THAT(out, HasSubstr("parallelogram_arm.yaml:14 key 'links[2].couple': a coupled link"));
  EXPECT_EQ(Run("identify --robot " + nominal + " --tool-link tool" + tracker + " --data " +
                    Path("points.csv"),
                &out),
            2);
  EXPECT_THAT(out, HasSubstr("applies to a URDF robot"));
}

TEST_F(TreeCli, ASoleToGripperChainIsCalibratedUpTheLeg) {
  const std::string nominal = testing::SourcePath("examples/urdf/humanoid_like.urdf");
  const std::string truth = testing::UrdfWithMovedOrigins(nominal, 6, Path("true.urdf"));
  const std::string chain = " --base-link left_sole --tool-link left_gripper";
  std::string out;
  // The tracker's design needs no plane (the URDF has none).
  ASSERT_EQ(Run("design --robot " + nominal + chain + kTracker +
                    " --generate 90 --select 60 --method greedy --out " + Path("c.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("simulate --robot " + truth + chain + kTracker + " --sigma-mm 0 --configs " +
                    Path("c.csv") + " --out " + Path("points.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("identify --auto-fix --format json --robot " + nominal + chain + kTracker +
                    " --data " + Path("points.csv"),
                &out),
            0)
      << out;
  EXPECT_LT(JsonOf(out)["residual_rms"].get<double>(), 1e-12);
  EXPECT_EQ(Run("identify --robot " + nominal + " --base-link left_heel --tool-link left_gripper" +
                    kTracker + " --data " + Path("points.csv"),
                &out),
            2);
  EXPECT_THAT(out, HasSubstr("no link named 'left_heel' (--base-link"));
}

}  // namespace
}  // namespace lrcal
