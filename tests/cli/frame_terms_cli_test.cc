// The base and tool transforms estimated from the command line: `identify --estimate-base
// --estimate-tool --auto-fix` on readings of an arm whose base and tool really moved, the
// calibrated robot file (its base: and tool: carry the estimate), and that file reading what the
// moved arm reads at poses the calibration never saw.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "lrcal/core/strings.h"
#include "lrcal/io/robot_file.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;
using Json = nlohmann::json;

// Readings of a file that reproduces the truth's at poses it never saw: rounding only.
constexpr double kSameReadings = 1e-9;  // m

// The paper's arm without its true errors, three planes; `frames` adds base: and tool: lines.
std::string RigText(const std::string& frames) {
  return R"(name: frames
links:
  - {theta: pi/2,  alpha: -pi/2, a: 0,     d: 0.5,  beta: 0, parameters: [theta, alpha, a, d]}
  - {theta: 0,     alpha: 0,     a: 1.0,   d: 0,    beta: 0, parameters: [theta, alpha, a, beta]}
  - {theta: -pi/2, alpha: pi/2,  a: 0,     d: 0,    beta: 0, parameters: [theta, alpha, a, d]}
  - {theta: 0,     alpha: -pi/2, a: 0,     d: -0.8, beta: 0, parameters: [theta, alpha, a, d]}
  - {theta: pi,    alpha: pi/2,  a: 0,     d: 0,    beta: 0, parameters: [theta, alpha, a, d]}
  - {theta: 0,     alpha: 0,     a: -0.12, d: 0.4,  beta: 0, parameters: [theta, alpha, a, d, beta]}
planes:
  - {normal: [0, 1, 4.6], offset: -0.69}
  - {normal: [1, 0.1, 0], offset: 0.9}
  - {normal: [0, -1, 0.3], offset: 1.1}
ranger: {min_range: 0.05, max_range: 3.0, max_incidence_deg: 70}
)" + frames;
}

class FrameTermsCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::TempDir("FrameTermsCli"); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
    return Path(name);
  }
  int Run(const std::string& args, std::string* out) const {
    return testing::RunCommand(testing::LrcalBinary() + " " + args, out);
  }
  std::vector<double> Readings(const std::string& file) const {
    std::ifstream in(file);
    std::string header, line;
    std::getline(in, header);
    const std::vector<std::string> names = SplitList(header);
    const auto h = std::find(names.begin(), names.end(), "h") - names.begin();
    std::vector<double> out;
    while (std::getline(in, line)) out.push_back(std::stod(SplitList(line)[h]));
    return out;
  }
  std::string dir_;
};

TEST_F(FrameTermsCli, IdentifyEstimatesTheFramesAndWritesThemToTheCalibratedFile) {
  // The truth: the base shifted by (2, 1, -2) mm and tilted by (1, -2) mrad roll and pitch, the
  // ranger shifted by (3, -2, 4) mm on the flange.
  const std::string truth =
      Write("truth.yaml", RigText("base: {xyz: [0.002, 0.001, -0.002], rpy: [0.001, -0.002, 0]}\n"
                                  "tool: {xyz: [0.003, -0.002, 0.004], rpy: [0, 0, 0]}\n"));
  const std::string nominal = Write("nominal.yaml", RigText(""));
  std::string out;
  ASSERT_EQ(Run("sample --robot " + nominal + " --count 30 --seed 3 --out " + Path("c.csv"), &out),
            0)
      << out;
  ASSERT_EQ(Run("simulate --robot " + truth + " --configs " + Path("c.csv") +
                    " --sigma-mm 0 --seed 2 --out " + Path("m.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("identify --robot " + nominal + " --data " + Path("m.csv") +
                    " --estimate-base all --estimate-tool all --auto-fix --format json "
                    "--write-robot " +
                    Path("cal.yaml"),
                &out),
            0)
      << out;
  const Json j = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  std::map<std::string, double> delta;
  for (const Json& p : j["parameters"])
    delta[p["name"].get<std::string>()] = p["delta"].get<double>();
  const auto fixed = j["fixed_for_rank"].get<std::vector<std::string>>();
  // What identifiability finds on this arm: a turn about the beam moves no reading; the base's
  // yaw and height are joint 1's θ1 and d1; the ranger's shifts are link 6's θ6, a6 and d6 (α6
  // is 0: z6 is z5, so d6 moves the ranger along its beam exactly as tool_z does).
  for (const char* name : {"tool_yaw", "base_yaw", "base_z", "tool_x", "tool_y", "tool_z"})
    EXPECT_THAT(fixed, Contains(name));
  // A tilt of joint 1's axis is in no link's parameters: the base's roll and pitch are estimated.
  ASSERT_EQ(delta.count("base_roll"), 1u) << out;
  EXPECT_NEAR(delta["base_roll"], 0.001, 1e-9);
  EXPECT_NEAR(delta["base_pitch"], -0.002, 1e-9);
  EXPECT_NEAR(delta["d6"], 0.004, 1e-9);
  // d1 takes the base's height along the tilted z0: 2 mm·(1 − cos) ≈ 5e-9 m from −2 mm.
  EXPECT_NEAR(delta["d1"], -0.002, 1e-8);
  EXPECT_LT(j["residual_rms"].get<double>(), 1e-10);

  // The calibrated file carries the estimated base and reads what the moved arm reads.
  const RobotFile cal = LoadRobotFile(Path("cal.yaml"));
  EXPECT_NEAR(cal.robot.base().Rpy()[0], 0.001, 1e-9);
  EXPECT_NEAR(cal.robot.base().Rpy()[1], -0.002, 1e-9);
  ASSERT_EQ(Run("sample --robot " + nominal + " --validation --count 20 --seed 1 --out " +
                    Path("val.csv"),
                &out),
            0)
      << out;
  for (const std::string& who : {std::string("truth"), std::string("cal")}) {
    ASSERT_EQ(Run("simulate --robot " + Path(who + ".yaml") + " --configs " + Path("val.csv") +
                      " --sigma-mm 0 --out " + Path(who + "_val.csv"),
                  &out),
              0)
        << out;
  }
  const std::vector<double> a = Readings(Path("truth_val.csv")), b = Readings(Path("cal_val.csv"));
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 20u);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], kSameReadings) << i;
}

TEST_F(FrameTermsCli, BadFrameTermsAreRefusedNamingTheOption) {
  std::string out;
  Write("c.csv", "q1,q2,q3,q4,q5,q6\n0,-0.7,0,0,0,0\n");
  EXPECT_EQ(
      Run("identifiability --robot paper --configs " + Path("c.csv") + " --estimate-tool x,twist",
          &out),
      2);
  EXPECT_THAT(out, HasSubstr("--estimate-tool"));
  EXPECT_THAT(out, HasSubstr("unknown frame term 'twist'"));
  EXPECT_EQ(Run("identifiability --robot paper --configs " + Path("c.csv") +
                    " --estimate-base all --fix base_q",
                &out),
            2);
  EXPECT_THAT(out, HasSubstr("base_q"));
}

}  // namespace
}  // namespace lrcal
