// `lrcal identifiability --sensor`: what a laser ranger, a tracker's reflector and a 6-D probe can
// identify on the paper's arm, as a user asks it. The slides' 25 for the ranger and Everett's
// 4R + 2P + 6 = 30 for a full-pose measurement with the instrument's frame estimated (27 with
// positions only) are computed by the rank analysis here, in text and JSON.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;
using Json = nlohmann::json;

class SensorCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::TempDir("SensorCli");
    std::string out;
    ASSERT_EQ(Run("sample --count 40 --seed 3 --out " + Path("c.csv"), &out), 0) << out;
  }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  int Run(const std::string& args, std::string* out) const {
    return testing::RunCommand(testing::LrcalBinary() + " " + args, out);
  }
  Json Identifiability(const std::string& options) const {
    std::string out;
    EXPECT_EQ(Run("identifiability --configs " + Path("c.csv") + " --format json " + options, &out),
              0)
        << out;
    return Json::parse(out);
  }
  std::string dir_;
};

TEST_F(SensorCli, CountsTheSlidesAndEverettsIdentifiableTerms) {
  const Json ranger = Identifiability("");
  EXPECT_EQ(ranger["rank"], 25);
  EXPECT_EQ(ranger["n_params"], 25);
  EXPECT_FALSE(ranger.contains("sensor"));  // the ranger's output is what it always was
  const Json point = Identifiability("--sensor point --instrument 2.5,0.3,0.2,0,0,3");
  EXPECT_EQ(point["sensor"], "point");
  EXPECT_EQ(point["values_per_configuration"], 3);
  EXPECT_EQ(point["n_params"], 25 + 6 + 3);
  EXPECT_EQ(point["rank"], 27);
  const Json pose = Identifiability("--sensor pose --instrument 2.5,0.3,0.2,0,0,3");
  EXPECT_EQ(pose["sensor"], "pose");
  EXPECT_EQ(pose["values_per_configuration"], 6);
  EXPECT_EQ(pose["n_params"], 25 + 6 + 6);
  EXPECT_EQ(pose["rank"], 30);
  EXPECT_EQ(pose["suggested_fixed"].size(), 7u);

  std::string text;
  ASSERT_EQ(Run("identifiability --configs " + Path("c.csv") + " --sensor pose", &text), 0);
  EXPECT_THAT(text, HasSubstr("sensor: pose (x, y, z in m and an orientation in rad"));
  EXPECT_THAT(text, HasSubstr("parameters: 37, configurations: 40, rank: 30 (DEFICIENT)"));
  EXPECT_THAT(text, HasSubstr("suggested to fix:"));
}

TEST_F(SensorCli, ASecondProbeAddsItsSixTermsWhenTheTargetColumnSaysWhichIsSeen) {
  // The same configurations, alternately seeing probe 1 and probe 2.
  std::ifstream in(Path("c.csv"));
  std::ostringstream tagged;
  std::string line;
  std::getline(in, line);
  tagged << line << ",target\n";
  for (int i = 0; std::getline(in, line); ++i) tagged << line << "," << 1 + i % 2 << "\n";
  std::ofstream(Path("c.csv")) << tagged.str();
  const Json pose = Identifiability("--sensor pose --target 0,0,0.1 --target 0.05,0,0.1,0,0.5,0");
  EXPECT_EQ(pose["n_params"], 25 + 6 + 12);
  EXPECT_EQ(pose["rank"], 36);
}

// simulate --sensor pose writes the true arm's probe poses (the robot file's true errors);
// identify --sensor pose --auto-fix reads them back and finds those errors: noise-free to
// rounding, with noise consistently with the stated σ's (exit 0, not 4).
TEST_F(SensorCli, SimulatedTrackerDataCalibratesTheArm) {
  const std::string tracker = " --instrument 2.5,0.3,0.2,0,0,3";
  std::string out;
  ASSERT_EQ(Run("simulate --sensor pose --configs " + Path("c.csv") + tracker +
                    " --sigma-mm 0 --sigma-mrad 0 --repetitions 1 --out " + Path("exact.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("identify --sensor pose --data " + Path("exact.csv") + tracker +
                    " --auto-fix --format json",
                &out),
            0)
      << out;
  const Json exact = Json::parse(out.substr(out.find('{')));
  EXPECT_EQ(exact["sensor"], "pose");
  const auto at = [&](const std::string& name) {
    for (const Json& p : exact["parameters"])
      if (p["name"] == name) return p["delta"].get<double>();
    ADD_FAILURE() << name << " not estimated";
    return 0.0;
  };
  // The paper's true errors (studies/robots/paper.yaml), SI; d1's 0.73 mm goes to the
  // instrument's height, β6's −3.36 mrad to the probe's pitch (the dependences of the README).
  constexpr double kExact = 1e-9;
  EXPECT_NEAR(at("theta1"), -7.23e-3, kExact);
  EXPECT_NEAR(at("a2"), 1.94e-3, kExact);
  EXPECT_NEAR(at("instrument_z"), -0.73e-3, kExact);
  EXPECT_NEAR(at("target_pitch"), -3.36e-3, kExact);

  ASSERT_EQ(Run("simulate --sensor point --configs " + Path("c.csv") + tracker +
                    " --sigma-mm 0.05 --repetitions 4 --seed 7 --out " + Path("noisy.csv"),
                &out),
            0)
      << out;
  EXPECT_EQ(Run("identify --sensor point --data " + Path("noisy.csv") + tracker +
                    " --auto-fix --sigma-mm 0.05",
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("consistent with the stated noise"));
  // --holdout 5: every held-out point predicted (3 values each), as the fit says it would be.
  ASSERT_EQ(Run("identify --sensor point --data " + Path("noisy.csv") + tracker +
                    " --auto-fix --sigma-mm 0.05 --holdout 5 --format json",
                &out),
            0)
      << out;
  const Json cv = Json::parse(out.substr(out.find('{')))["holdout"];
  EXPECT_EQ(cv["folds"], 5);
  EXPECT_EQ(cv["predictions"].size(), 3u * 40u);
  EXPECT_EQ(cv["predictions"][2]["component"], 2);
  EXPECT_TRUE(cv["consistent"].get<bool>()) << cv.dump();
  ASSERT_EQ(Run("simulate --sensor pose --configs " + Path("c.csv") + tracker +
                    " --sigma-mm 0.05 --sigma-mrad 0.3 --repetitions 4 --seed 7 --out " +
                    Path("poses.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("identify --sensor pose --data " + Path("poses.csv") + tracker +
                    " --auto-fix --sigma-mm 0.05 --sigma-mrad 0.3 --holdout 4",
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("40 held-out configurations predicted (240 values)"));
  EXPECT_THAT(out, HasSubstr("held-out angle error RMS"));
  EXPECT_THAT(out, HasSubstr("predicted as well as the fit says"));
  // --report DIR: the calibration report of the tracker's fit; its calibrated robot file is
  // --write-robot's, byte for byte, and its cross-validation predicts every value. --measured:
  // 30 tracker points the fit never saw, judged in the report as accuracy --measured judges them.
  ASSERT_EQ(Run("sample --validation --count 30 --seed 5 --out " + Path("v.csv"), &out), 0);
  ASSERT_EQ(Run("simulate --sensor point --configs " + Path("v.csv") + tracker +
                    " --sigma-mm 0 --repetitions 1 --out " + Path("held.csv"),
                &out),
            0);
  const std::string measured = " --measured " + Path("held.csv");
  EXPECT_EQ(Run("identify --sensor point --data " + Path("noisy.csv") + tracker + measured, &out),
            2);
  EXPECT_THAT(out, HasSubstr("--measured: goes into the calibration report: give --report"));
  ASSERT_EQ(Run("identify --sensor point --data " + Path("noisy.csv") + tracker +
                    " --auto-fix --sigma-mm 0.05 --report " + Path("report") + " --write-robot " +
                    Path("written.yaml") + measured,
                &out),
            0)
      << out;
  const auto text = [](const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const Json report = Json::parse(text(Path("report/calibration.json")));
  EXPECT_EQ(report["sensor"], "point");
  EXPECT_EQ(report["values_per_configuration"], 3);
  EXPECT_EQ(report["n_values"], 120);
  EXPECT_EQ(report["holdout"]["predictions"].size(), 120u);
  EXPECT_FALSE(report["workspace_accuracy"]["poses"].empty());
  // The same file but for the record's date (the two writes may fall in different seconds).
  const auto undated = [&](const std::string& path) {
    return std::regex_replace(text(path), std::regex("\n  date: \"[^\"]*\"\n"), "\n");
  };
  EXPECT_EQ(undated(Path("report/calibrated.yaml")), undated(Path("written.yaml")));
  EXPECT_NE(undated(Path("written.yaml")), text(Path("written.yaml")));  // a date was there
  EXPECT_THAT(text(Path("report/report.html")), HasSubstr("over the values"));
  ASSERT_EQ(
      Run("accuracy --robot " + Path("written.yaml") + " --format json" + measured + tracker, &out),
      0)
      << out;
  ASSERT_TRUE(report.contains("measured_points"));
  EXPECT_EQ(report["measured_points"]["points"], 30);
  EXPECT_EQ(report["measured_points"]["rms"].get<double>(), Json::parse(out)["rms"].get<double>());
  EXPECT_GT(report["measured_points"]["rms"].get<double>(), 0);  // the fit had noise
  EXPECT_LT(report["measured_points"]["rms"].get<double>(), 0.2e-3);
  EXPECT_THAT(text(Path("report/report.html")),
              HasSubstr("30 points a tracker measured, not used in the fit"));
  // --predict-at: the calibrated arm's predicted accuracy at poses, the numbers lrcal accuracy
  // gives from --write-robot's file.
  ASSERT_EQ(Run("identify --sensor point --data " + Path("noisy.csv") + tracker +
                    " --auto-fix --sigma-mm 0.05 --format json --predict-at " + Path("v.csv"),
                &out),
            0)
      << out;
  const Json predicted = Json::parse(out.substr(out.find('{')))["accuracy"];
  ASSERT_EQ(
      Run("accuracy --robot " + Path("written.yaml") + " --format json --configs " + Path("v.csv"),
          &out),
      0)
      << out;
  const Json stated = Json::parse(out.substr(out.find('{')));
  ASSERT_EQ(predicted["poses"].size(), 30u);
  EXPECT_EQ(predicted["poses"], stated["poses"]);
  EXPECT_EQ(predicted["rms_position_total"], stated["rms_position_total"]);
  EXPECT_GT(predicted["poses"][0]["position_radius_95"].get<double>(), 0);
  ASSERT_EQ(Run("identify --sensor point --data " + Path("noisy.csv") + tracker +
                    " --auto-fix --sigma-mm 0.05 --predict-at " + Path("v.csv"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("Predicted accuracy of the calibrated arm"));
  // A ranger-only option is refused by name.
  EXPECT_EQ(
      Run("identify --sensor point --data " + Path("noisy.csv") + " --only-significant 2", &out),
      2);
  EXPECT_THAT(out,
              HasSubstr("--only-significant: is the ranger's; --sensor point does not take it"));
}

// identify --sensor point --write-robot writes a robot file every command takes: its link values
// are the fit's, so tracker points the fit never saw are predicted exactly (noise-free), the
// tracker's frame registered.
TEST_F(SensorCli, ATrackerCalibrationIsARobotFileOtherCommandsTake) {
  const std::string tracker = " --instrument 2.5,0.3,0.2,0,0,3 --target 0.02,0,0.05";
  std::string out;
  ASSERT_EQ(Run("simulate --sensor point --configs " + Path("c.csv") + tracker +
                    " --sigma-mm 0 --repetitions 1 --out " + Path("fit.csv"),
                &out),
            0);
  ASSERT_EQ(Run("identify --sensor point --data " + Path("fit.csv") + tracker +
                    " --auto-fix --write-robot " + Path("cal.yaml"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("calibrated robot written to"));
  ASSERT_EQ(Run("sample --validation --count 30 --seed 5 --out " + Path("v.csv"), &out), 0);
  ASSERT_EQ(Run("simulate --sensor point --configs " + Path("v.csv") + tracker +
                    " --sigma-mm 0 --repetitions 1 --out " + Path("points.csv"),
                &out),
            0);
  ASSERT_EQ(Run("accuracy --robot " + Path("cal.yaml") + " --format json --measured " +
                    Path("points.csv") + tracker,
                &out),
            0)
      << out;
  EXPECT_LT(Json::parse(out)["worst"].get<double>(), 1e-9);
  // Its record names the arm's terms only, with their covariance: accuracy predicts from it.
  std::ifstream file(Path("cal.yaml"));
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_THAT(text, HasSubstr("calibration:"));
  EXPECT_THAT(text, ::testing::Not(HasSubstr("instrument_x")));
}

// accuracy --measured judges a model with tracker points it was not calibrated on: the nominal
// model is millimetres off the true arm; a noise-free ranger calibration is exact, even with the
// tracker's frame given 1 cm and 10 mrad off (it is registered to the points).
TEST_F(SensorCli, MeasuredPointsJudgeARangerCalibration) {
  std::string out;
  ASSERT_EQ(Run("sample --validation --count 30 --seed 5 --out " + Path("v.csv"), &out), 0);
  ASSERT_EQ(Run("simulate --sensor point --configs " + Path("v.csv") +
                    " --instrument 2.5,0.3,0.2,0,0,3 --target 0.02,0,0.05 --sigma-mm 0 "
                    "--repetitions 1 --out " +
                    Path("points.csv"),
                &out),
            0)
      << out;
  const std::string measured = " --measured " + Path("points.csv") +
                               " --instrument 2.51,0.29,0.2,0,0,3.01 --target 0.02,0,0.05";
  ASSERT_EQ(Run("accuracy --robot paper --format json" + measured, &out), 0) << out;
  const Json nominal = Json::parse(out);
  EXPECT_EQ(nominal["points"], 30);
  EXPECT_GT(nominal["rms"].get<double>(), 1e-3);  // the paper's errors: millimetres at the tool
  EXPECT_GE(nominal["worst"].get<double>(), nominal["rms"].get<double>());

  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --sigma-mm 0 --repetitions 1 --out " +
                    Path("m.csv"),
                &out),
            0);
  ASSERT_EQ(Run("identify --data " + Path("m.csv") + " --write-robot " + Path("cal.yaml"), &out), 0)
      << out;
  ASSERT_EQ(Run("accuracy --robot " + Path("cal.yaml") + " --format json" + measured, &out), 0)
      << out;
  const Json calibrated = Json::parse(out);
  EXPECT_LT(calibrated["worst"].get<double>(), 1e-9);
  // The registered instrument is the one the points were taken with.
  EXPECT_NEAR(calibrated["instrument"]["xyz"][0].get<double>(), 2.5, 1e-9);
  EXPECT_NEAR(calibrated["instrument"]["rpy"][2].get<double>(), 3.0, 1e-9);

  ASSERT_EQ(Run("accuracy --robot paper" + measured, &out), 0);
  EXPECT_THAT(out, HasSubstr("error at the measured points: RMS"));

  // The same judgement in the calibration report (identify --report --measured), with noise.
  ASSERT_EQ(
      Run("simulate --configs " + Path("c.csv") + " --seed 4 --out " + Path("noisy.csv"), &out), 0);
  ASSERT_EQ(Run("identify --data " + Path("noisy.csv") + " --sigma-mm 0.2 --report " +
                    Path("cal_report") + measured,
                &out),
            0)
      << out;
  ASSERT_EQ(
      Run("accuracy --robot " + Path("cal_report/calibrated.yaml") + " --format json" + measured,
          &out),
      0)
      << out;
  const Json judged = Json::parse(out);
  std::ifstream report_json(Path("cal_report/calibration.json"));
  const Json report = Json::parse(report_json);
  ASSERT_TRUE(report.contains("measured_points"));
  EXPECT_EQ(report["measured_points"]["rms"].get<double>(), judged["rms"].get<double>());
  EXPECT_EQ(report["measured_points"]["points"], 30);
  EXPECT_GT(judged["rms"].get<double>(), 0);
  std::ifstream page_in(Path("cal_report/report.html"));
  const std::string page((std::istreambuf_iterator<char>(page_in)),
                         std::istreambuf_iterator<char>());
  EXPECT_THAT(page, HasSubstr("<h2>Measured points</h2>"));
  EXPECT_THAT(page, HasSubstr("30 points a tracker measured, not used in the fit"));
  EXPECT_EQ(Run("identify --data " + Path("noisy.csv") + measured, &out), 2);
  EXPECT_THAT(out, HasSubstr("--measured: goes into the calibration report: give --report"));
}

// Sockets as a user meets them: the 40 configurations, alternately in two sockets 50 mm apart, are
// seated by `simulate --sensor socket` on the true arm; the analysis finds the README's 26;
// noise-free, `identify --sensor socket --auto-fix --write-robot` finds the true errors where
// they are identifiable alone and its robot file puts the ball at one point per socket, 50 mm
// apart, where the nominal arm does not.
TEST_F(SensorCli, SocketSeatingsCalibrateTheArmWithALengthReference) {
  std::ifstream in(Path("c.csv"));
  std::ostringstream tagged;
  std::string line;
  std::getline(in, line);
  tagged << line << ",socket\n";
  for (int i = 0; std::getline(in, line); ++i) tagged << line << "," << i % 2 << "\n";
  std::ofstream(Path("starts.csv")) << tagged.str();
  const std::string sockets = " --socket-distance 0,1=0.05";
  std::string out;
  ASSERT_EQ(Run("simulate --sensor socket --configs " + Path("starts.csv") +
                    " --socket 0.8,0.3,0.4 --socket 0.8,0.35,0.4 --sigma-mm 0 --out " +
                    Path("seated.csv"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("40 socket seatings written"));
  ASSERT_EQ(
      Run("identifiability --sensor socket --format json --configs " + Path("seated.csv") + sockets,
          &out),
      0)
      << out;
  const Json analysis = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  EXPECT_EQ(analysis["sensor"], "socket");
  EXPECT_EQ(analysis["n_params"], 25 + 3 + 5);
  EXPECT_EQ(analysis["rank"], 26);
  EXPECT_THAT(analysis["suggested_fixed"].get<std::vector<std::string>>(),
              ::testing::IsSupersetOf({"socket0_z", "alpha6", "beta6"}));

  ASSERT_EQ(Run("identify --sensor socket --format json --auto-fix --data " + Path("seated.csv") +
                    sockets + " --write-robot " + Path("cal.yaml"),
                &out),
            0)
      << out;
  const Json fit = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  const auto at = [&](const std::string& name) {
    for (const Json& p : fit["parameters"])
      if (p["name"] == name) return p["delta"].get<double>();
    ADD_FAILURE() << name << " not estimated";
    return 0.0;
  };
  // The paper's true errors (studies/robots/paper.yaml), SI, where no held term is confounded
  // with them (θ1 and d1 take up the sockets' turn about and height along the base z axis).
  constexpr double kExact = 1e-9;
  EXPECT_NEAR(at("a2"), 1.94e-3, kExact);
  EXPECT_NEAR(at("beta2"), 1.45e-3, kExact);
  EXPECT_NEAR(at("alpha5"), -4.83e-3, kExact);
  EXPECT_NEAR(at("d6"), 0.85e-3, kExact);
  // With priors nothing needs holding: the gauge directions are set by the priors, and a
  // robot file is still written with the arm's terms.
  ASSERT_EQ(Run("identify --sensor socket --data " + Path("seated.csv") + sockets +
                    " --sigma-mm 0.1 --prior-sigma theta=5mrad,alpha=5mrad,beta=5mrad,a=1mm,d=1mm,"
                    "target_x=1mm,target_y=1mm,target_z=1mm,socket_z=10mm,socket_u=20mrad "
                    "--write-robot " +
                    Path("prior.yaml"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("set by the prior (posterior/prior std above 0.9):"));
  EXPECT_THAT(out, ::testing::Not(HasSubstr("fixed at nominal because of rank deficiency")));
  for (const std::string& model : {std::string("paper"), Path("cal.yaml")}) {
    ASSERT_EQ(Run("accuracy --format json --robot " + model + " --sockets " + Path("seated.csv") +
                      sockets,
                  &out),
              0)
        << out;
    const Json j = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
    if (model == "paper") {
      EXPECT_GT(j["rms_spread"].get<double>(), 1e-3);  // the nominal arm: millimetres
    } else {
      EXPECT_LT(j["rms_spread"].get<double>(), 1e-9);
      EXPECT_NEAR(j["distances"][0]["error"].get<double>(), 0.0, 1e-9);
    }
  }
}

// Plane contacts as a user meets them: the 40 configurations, alternately on a tilted floor and a
// wall, are seated on the true arm by `simulate --sensor contact`; the analysis counts what the
// contacts identify with both planes estimated; noise-free, `identify --sensor contact
// --auto-fix` leaves no residual and finds the true errors its held terms do not touch.
TEST_F(SensorCli, PlaneContactsCalibrateTheArmWithThePlanesEstimated) {
  std::ifstream in(Path("c.csv"));
  std::ostringstream tagged;
  std::string line;
  std::getline(in, line);
  tagged << line << ",plane\n";
  for (int i = 0; std::getline(in, line); ++i) tagged << line << "," << 1 + i % 2 << "\n";
  std::ofstream(Path("starts.csv")) << tagged.str();
  const std::string planes = " --plane 0.1,0.2,1,-0.3 --plane 1,0,0.2,-0.9";
  std::string out;
  ASSERT_EQ(Run("simulate --sensor contact --configs " + Path("starts.csv") + planes +
                    " --sigma-mm 0 --out " + Path("contacts.csv"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("40 contacts written"));
  ASSERT_EQ(Run("identifiability --sensor contact --format json --estimate-plane normal,offset "
                "--configs " +
                    Path("contacts.csv") + planes,
                &out),
            0)
      << out;
  const Json analysis = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  EXPECT_EQ(analysis["sensor"], "contact");
  EXPECT_EQ(analysis["values_per_configuration"], 1);
  EXPECT_EQ(analysis["n_params"], 25 + 3 + 6);
  EXPECT_EQ(analysis["rank"], 26);
  ASSERT_EQ(Run("identify --sensor contact --format json --auto-fix --estimate-plane "
                "normal,offset --data " +
                    Path("contacts.csv") + planes,
                &out),
            0)
      << out;
  const Json fit = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  EXPECT_LT(fit["residual_rms"].get<double>(), 1e-12);
  const auto at = [&](const std::string& name) {
    for (const Json& p : fit["parameters"])
      if (p["name"] == name) return p["delta"].get<double>();
    ADD_FAILURE() << name << " not estimated";
    return 0.0;
  };
  constexpr double kExact = 1e-9;  // studies/robots/paper.yaml's true errors, SI
  EXPECT_NEAR(at("beta2"), 1.45e-3, kExact);
  EXPECT_NEAR(at("alpha5"), -4.83e-3, kExact);
  // A flush file says so in its flush column; a file mixing both is refused by line.
  ASSERT_EQ(Run("simulate --sensor contact --flush --configs " + Path("starts.csv") + planes +
                    " --sigma-mm 0.01 --sigma-mrad 0.05 --out " + Path("flush.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("identify --sensor contact --auto-fix --sigma-mm 0.01 --sigma-mrad 0.05 --data " +
                    Path("flush.csv") + planes,
                &out),
            0)
      << out;
  EXPECT_THAT(out, HasSubstr("flush contacts on 2 plane(s)"));
  EXPECT_THAT(out, HasSubstr("consistent with the stated noise"));
}

// A line scanner as a user meets it: five beams spread ±10° in a frame turned on the tool,
// simulated noise-free by `simulate --sensor scanner` at the 40 configurations (those with a beam
// out of range or grazing the plane left out, and said so); the analysis counts what the fan
// identifies with the plane estimated; `identify --sensor scanner --auto-fix` leaves no residual
// and finds the true errors its held terms do not touch; the data file's errors are located.
TEST_F(SensorCli, ALineScannerCalibratesTheArmWithThePlaneEstimated) {
  const std::string geometry =
      " --sensor scanner --beams 5 --fan-deg 10 --scanner 0.03,-0.01,0.02,0.1,0.2,0.3";
  const std::string scanner = geometry + " --estimate-plane normal,offset";
  std::string out;
  ASSERT_EQ(Run("simulate" + geometry + " --sigma-mm 0 --configs " + Path("c.csv") + " --out " +
                    Path("scans.csv"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, ::testing::ContainsRegex("[0-9]+ scans of 5 beam\\(s\\) written"));
  ASSERT_EQ(
      Run("identifiability --format json" + scanner + " --configs " + Path("scans.csv"), &out), 0)
      << out;
  const Json analysis = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  EXPECT_EQ(analysis["sensor"], "scanner");
  EXPECT_EQ(analysis["values_per_configuration"], 5);
  EXPECT_EQ(analysis["n_params"], 25 + 3 + 3 + 3);  // arm, origin, orientation, plane
  EXPECT_EQ(analysis["rank"], 27);
  ASSERT_EQ(
      Run("identify --format json --auto-fix" + scanner + " --data " + Path("scans.csv"), &out), 0)
      << out;
  const Json fit = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  EXPECT_LT(fit["residual_rms"].get<double>(), 1e-12);
  const auto at = [&](const std::string& name) {
    for (const Json& p : fit["parameters"])
      if (p["name"] == name) return p["delta"].get<double>();
    ADD_FAILURE() << name << " not estimated";
    return 0.0;
  };
  constexpr double kExact = 1e-9;  // studies/robots/paper.yaml's true errors, SI
  EXPECT_NEAR(at("beta2"), 1.45e-3, kExact);
  EXPECT_NEAR(at("alpha5"), -4.83e-3, kExact);

  // A configuration without one of its beams, a beam number beyond the fan, the ranger's options.
  std::ifstream in(Path("scans.csv"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::ofstream(Path("short.csv")) << lines[0] << "\n" << lines[1] << "\n" << lines[2] << "\n";
  EXPECT_EQ(Run("identify" + scanner + " --data " + Path("short.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("short.csv:2 column 'beam': the configuration starting here has no "
                             "reading of beam 3"));
  EXPECT_EQ(Run("identify --sensor scanner --beams 4 --data " + Path("scans.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("column 'beam': expected a beam number from 1 to 4"));
  EXPECT_EQ(Run("identify --fan-deg 5 --data " + Path("scans.csv"), &out), 2);
  EXPECT_THAT(out,
              HasSubstr("--fan-deg: is the scanner sensor's; --sensor ranger does not take it"));
  EXPECT_EQ(
      Run("identify" + scanner + " --estimate-ranger offset --data " + Path("scans.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("are the scanner's frame and the planes"));
}

}  // namespace
}  // namespace lrcal

namespace lrcal {
namespace {

// `lrcal design --sensor point|pose`: a tracker's configurations chosen as blocks, anywhere in
// the workspace (a pool of c.csv's configurations, none filtered by a beam), with the terms the
// pool cannot separate held at nominal and named; the chosen CSV is what `simulate --sensor`
// reads; the ranger's options are refused for a tracker and a tracker's for the ranger.
TEST(SensorDesignCli, ATrackersDesignIsChosenAsBlocksAndNamesWhatItHolds) {
  const std::string dir = testing::TempDir("sensor_design");
  std::string out;
  ASSERT_EQ(
      testing::RunCommand(
          testing::LrcalBinary() + " sample --count 60 --seed 3 --out " + dir + "/c.csv", &out),
      0)
      << out;
  const std::string design = testing::LrcalBinary() + " design --pool " + dir +
                             "/c.csv --select 12 --method backward --baseline 50" +
                             " --instrument 2.5,0.3,0.2,0,0,3";
  ASSERT_EQ(
      testing::RunCommand(design + " --sensor pose --format json --out " + dir + "/d.csv", &out), 0)
      << out;
  const Json j = Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  EXPECT_EQ(j["sensor"], "pose");
  EXPECT_EQ(j["held_at_nominal"].size(), 7u);  // 37 terms, rank 30
  EXPECT_EQ(j["pool"]["size"], 60);
  ASSERT_EQ(
      testing::RunCommand(testing::LrcalBinary() + " simulate --sensor pose --configs " + dir +
                              "/d.csv --instrument 2.5,0.3,0.2,0,0,3 --out " + dir + "/p.csv",
                          &out),
      0)
      << out;
  EXPECT_EQ(testing::RunCommand(design + " --sensor point --estimate-plane offset", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("--estimate-plane: is the ranger's"));
  EXPECT_EQ(testing::RunCommand(design + " --sensor ranger,pose", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("lrcal design chooses for one sensor at a time"));
  EXPECT_EQ(testing::RunCommand(design, &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("--instrument: is a tracker's"));
}

// `lrcal design --sensor scanner|contact|socket --generate`: candidates where the kind measures
// (every beam of the fan on the plane; the probe's tip on the plane; the ball in its socket, the
// sockets in turn), chosen as blocks; each chosen CSV is what `simulate` and `identify` of that
// sensor read, and the socket design keeps its socket column.
TEST(SensorDesignCli, ScannerContactAndSocketDesignsFeedTheirCampaigns) {
  const std::string dir = testing::TempDir("sensor_design_kinds");
  const std::string lrcal = testing::LrcalBinary();
  const std::string design =
      lrcal + " design --generate 60 --select 25 --method backward --seed 4 --format json";
  const auto json = [](const std::string& out) {
    return Json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  };
  std::string out;
  const std::string scanner = " --sensor scanner --beams 5 --fan-deg 10";
  ASSERT_EQ(testing::RunCommand(design + scanner + " --out " + dir + "/s.csv", &out), 0) << out;
  Json j = json(out);
  EXPECT_EQ(j["sensor"], "scanner");
  EXPECT_EQ(j["pool"]["size"], 60);
  EXPECT_EQ(j["selected"].size(), 25u);
  ASSERT_EQ(testing::RunCommand(lrcal + " simulate --configs " + dir + "/s.csv" + scanner +
                                    " --out " + dir + "/scans.csv",
                                &out),
            0)
      << out;
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("left out")));  // every beam hits
  const std::string contact = " --sensor contact --target 0,0,0.05";
  ASSERT_EQ(testing::RunCommand(design + contact + " --out " + dir + "/c.csv", &out), 0) << out;
  EXPECT_EQ(json(out)["sensor"], "contact");
  ASSERT_EQ(testing::RunCommand(lrcal + " simulate --configs " + dir + "/c.csv" + contact +
                                    " --out " + dir + "/contacts.csv",
                                &out),
            0)
      << out;
  const std::string sockets =
      " --sensor socket --target 0,0,0.05 --socket-distance 0,1=0.05 --socket 1,0.5,0.3 "
      "--socket 1,0.55,0.3 --socket 0.8,-0.6,0.4";
  ASSERT_EQ(testing::RunCommand(design + sockets + " --out " + dir + "/k.csv", &out), 0) << out;
  j = json(out);
  EXPECT_EQ(j["sensor"], "socket");
  EXPECT_FALSE(j["held_at_nominal"].empty());  // the sockets turn with the arm about z1, ...
  std::string held;
  for (const Json& name : j["held_at_nominal"])
    held += (held.empty() ? "" : ",") + name.get<std::string>();
  std::string header;
  std::getline(std::ifstream(dir + "/k.csv") >> std::ws, header);
  EXPECT_THAT(header, ::testing::HasSubstr(",socket"));
  ASSERT_EQ(testing::RunCommand(lrcal + " simulate --configs " + dir + "/k.csv" + sockets +
                                    " --sigma-mm 0.01 --out " + dir + "/seated.csv",
                                &out),
            0)
      << out;
  ASSERT_EQ(testing::RunCommand(lrcal +
                                    " identify --sensor socket --target 0,0,0.05 "
                                    "--socket-distance 0,1=0.05 --fix " +
                                    held + " --data " + dir + "/seated.csv",
                                &out),
            0)
      << out;
  // A socket design draws its candidates in the sockets it is given; a file's are its own.
  EXPECT_EQ(testing::RunCommand(design + " --sensor socket --target 0,0,0.05", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("--socket: --sensor socket with --generate needs"));
  EXPECT_EQ(testing::RunCommand(design + " --sensor point --socket 1,0,0", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("--socket: is the socket sensor's"));
  EXPECT_EQ(testing::RunCommand(design + " --sensor socket --socket 1,0", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("'1,0': expected x,y,z (m)"));
}

}  // namespace
}  // namespace lrcal

namespace lrcal {
namespace {

// A study with a sensor section as a user runs it (`lrcal run`): the cells table names each
// cell's sensor, its campaign (configurations × readings bought by the budget, and their cost),
// the terms it estimates (the rank analysis: 25 for the ranger, 27 for a reflector, 30 for a
// probe) and the terms it holds at nominal.
TEST(SensorStudyCli, TheCellsTableStatesEachSensorsCampaignAndTerms) {
  const std::string dir = testing::TempDir("sensor_study");
  std::ofstream(dir + "/s.yaml")
      << "name: s\nseed: 3\ntrials: 20\nrobot: paper\nnoise: {sigma_mm: 0.1, repetitions: 5}\n"
         "pool: {size: 60}\nvalidation: {size: 8}\nidentification: {on_rank_deficient: fix}\n"
         "sensor: {budget: 200, instrument: [2.5, 0.3, 0.2, 0, 0, 3]}\n"
         "sweep:\n  axes:\n    - key: sensor.kind\n      values: [ranger, point, pose]\n";
  std::string out;
  ASSERT_EQ(testing::RunCommand(testing::LrcalBinary() + " run " + dir + "/s.yaml --out " + dir +
                                    "/run --threads 2",
                                &out),
            0)
      << out;
  const std::string summary = testing::ReadFile(dir + "/run/tables/summary.md");
  EXPECT_THAT(summary, ::testing::HasSubstr("| sensor | configurations × readings | campaign "
                                            "cost | terms estimated | held at nominal (rank) |"));
  EXPECT_THAT(summary, ::testing::ContainsRegex("\\| ranger \\| 40 × 5 \\| 200 \\| 25 \\| — \\|"));
  EXPECT_THAT(summary,
              ::testing::ContainsRegex("\\| point \\| 40 × 5 \\| 200 \\| 27 \\| [a-z0-9_ ]+ \\|"));
  EXPECT_THAT(summary,
              ::testing::ContainsRegex("\\| pose \\| 40 × 5 \\| 200 \\| 30 \\| [a-z0-9_ ]+ \\|"));
}

// Several kinds at once, as a user meets it: a tracker's reflector and flush plane contacts of the
// same true arm, each simulated on its own (`simulate --sensor point`, `--sensor contact`), then
// `identifiability` and `identify --sensor point,contact` with one file per kind: the union sees
// more than either alone, the flush probe's in-plane offset is named as unseen, and noise-free the
// fit leaves no residual and finds the true errors (studies/robots/paper.yaml) to 1e-9.
TEST_F(SensorCli, ATrackerAndPlaneContactsCalibrateTheArmTogether) {
  std::ifstream in(Path("c.csv"));
  std::ostringstream tagged;
  std::string line;
  std::getline(in, line);
  tagged << line << ",plane\n";
  for (int i = 0; std::getline(in, line); ++i) tagged << line << "," << 1 + i % 2 << "\n";
  std::ofstream(Path("starts.csv")) << tagged.str();
  const std::string planes = " --plane 0.1,0.2,1,-0.3 --plane 1,0,0.2,-0.9";
  const std::string tracker = " --instrument 2.5,0.3,0.2,0,0,3";
  std::string out;
  ASSERT_EQ(Run("simulate --sensor point --sigma-mm 0 --configs " + Path("c.csv") + tracker +
                    " --out " + Path("points.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("simulate --sensor contact --flush --sigma-mm 0 --sigma-mrad 0 --target "
                "0.01,0,0.1 --configs " +
                    Path("starts.csv") + planes + " --out " + Path("contacts.csv"),
                &out),
            0)
      << out;
  const std::string both = " --sensor point,contact" + tracker + planes +
                           " --probe 0.01,0,0.1 --estimate-plane normal,offset --format json";
  const auto json = [](const std::string& text) {
    return Json::parse(text.substr(text.find('{'), text.rfind('}') - text.find('{') + 1));
  };
  ASSERT_EQ(Run("identifiability" + both + " --configs " + Path("c.csv") + " --configs " +
                    Path("contacts.csv"),
                &out),
            0)
      << out;
  const Json analysis = json(out);
  EXPECT_EQ(analysis["sensor"], "mixed");
  ASSERT_EQ(analysis["parts"].size(), 2u);
  EXPECT_EQ(analysis["parts"][1]["sensor"], "contact");
  EXPECT_EQ(analysis["parts"][1]["values_per_configuration"], 3);
  // The arm's 25 terms once, the tracker's 6 + 3, the probe's 3, the planes' 6.
  EXPECT_EQ(analysis["n_params"], 25 + 9 + 3 + 6);
  const Json points_alone = Identifiability("--sensor point" + tracker);
  EXPECT_GT(analysis["rank"].get<int>(), points_alone["rank"].get<int>());
  std::vector<std::string> unseen = analysis["unidentifiable"];
  EXPECT_THAT(unseen, ::testing::ElementsAre("contact.target_x", "contact.target_y"));

  ASSERT_EQ(Run("identify --auto-fix" + both + " --data " + Path("points.csv") + " --data " +
                    Path("contacts.csv"),
                &out),
            0)
      << out;
  const Json fit = json(out);
  EXPECT_EQ(fit["sensor"], "mixed");
  EXPECT_LT(fit["residual_rms"].get<double>(), 1e-12);
  const auto at = [&](const std::string& name) {
    for (const Json& p : fit["parameters"])
      if (p["name"] == name) return p["delta"].get<double>();
    ADD_FAILURE() << name << " not estimated";
    return 0.0;
  };
  constexpr double kExact = 1e-9;  // studies/robots/paper.yaml's true errors, SI
  EXPECT_NEAR(at("beta2"), 1.45e-3, kExact);
  EXPECT_NEAR(at("alpha5"), -4.83e-3, kExact);
  EXPECT_NEAR(at("d4"), 1.35e-3, kExact);

  // What a mixed run refuses, by option.
  const std::string files = " --data " + Path("points.csv") + " --data " + Path("contacts.csv");
  EXPECT_EQ(Run("identify --sensor point,contact" + tracker + planes + files, &out), 2);
  EXPECT_THAT(out, HasSubstr("--probe: missing: with --sensor point,contact --target is the "
                             "tracker's"));
  EXPECT_EQ(Run("identify" + both + " --data " + Path("points.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("--data: given 1 time(s) for the 2 kinds of --sensor point,contact"));
  EXPECT_EQ(Run("identify" + both + files + " --fix target_x", &out), 2);
  EXPECT_THAT(out, HasSubstr("--fix: 'target_x' is not a term of this calibration"));
  EXPECT_EQ(Run("identify" + both + files + " --holdout 5", &out), 2);
  EXPECT_THAT(out, HasSubstr("--holdout: is not taken by a calibration from several kinds"));
  EXPECT_EQ(Run("identify --sensor point" + tracker + files, &out), 2);
  EXPECT_THAT(out, HasSubstr("--data: given 2 times"));
  EXPECT_EQ(
      Run("simulate --sensor point,contact --configs " + Path("c.csv") + " --out " + Path("x.csv"),
          &out),
      2);
  EXPECT_THAT(out, HasSubstr("simulate writes one kind's file"));
  EXPECT_EQ(Run("identify --sensor point,laser" + files, &out), 2);
  EXPECT_THAT(out, HasSubstr("--sensor: 'laser' is not a sensor lrcal models"));

  // One file of both kinds, each row's kind in its sensor column (--sensor mixed): the same fit.
  const auto cells = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) out.push_back(cell);
    if (!line.empty() && line.back() == ',') out.emplace_back();
    return out;
  };
  std::ifstream points_in(Path("points.csv")), contacts_in(Path("contacts.csv"));
  std::getline(points_in, line);  // q1..q6,x,y,z,readings
  ASSERT_EQ(cells(line).size(), 10u) << line;
  std::getline(contacts_in, line);  // q1..q6,plane,flush,readings
  ASSERT_EQ(cells(line).size(), 9u) << line;
  std::ofstream mixed(Path("mixed.csv"));
  mixed << "sensor,q1,q2,q3,q4,q5,q6,x,y,z,readings,plane,flush\n";
  while (std::getline(points_in, line)) mixed << "point," << line << ",,\n";
  while (std::getline(contacts_in, line)) {
    const std::vector<std::string> c = cells(line);
    mixed << "contact";
    for (int j = 0; j < 6; ++j) mixed << "," << c[static_cast<std::size_t>(j)];
    mixed << ",,,," << c[8] << "," << c[6] << "," << c[7] << "\n";
  }
  mixed << "laser,0,0,0,0,0,0,,,,1,,\n";
  mixed.close();
  const std::string one_file = " --sensor mixed" + tracker + planes +
                               " --probe 0.01,0,0.1 --estimate-plane normal,offset --format json";
  EXPECT_EQ(Run("identify --auto-fix" + one_file + " --data " + Path("mixed.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("mixed.csv:82 column 'sensor': 'laser' is not a kind lrcal models"));
  {
    std::ifstream in(Path("mixed.csv"));
    std::ostringstream kept;
    for (std::string l; std::getline(in, l);)
      if (l.rfind("laser", 0) != 0) kept << l << "\n";
    std::ofstream(Path("mixed.csv")) << kept.str();
  }
  ASSERT_EQ(Run("identify --auto-fix" + one_file + " --data " + Path("mixed.csv"), &out), 0) << out;
  const Json from_one = json(out);
  ASSERT_EQ(from_one["parameters"].size(), fit["parameters"].size());
  for (std::size_t k = 0; k < fit["parameters"].size(); ++k) {
    EXPECT_EQ(from_one["parameters"][k]["name"], fit["parameters"][k]["name"]);
    EXPECT_NEAR(from_one["parameters"][k]["delta"].get<double>(),
                fit["parameters"][k]["delta"].get<double>(), 1e-15);
  }
  EXPECT_EQ(Run("identify --auto-fix" + one_file + " --data " + Path("points.csv"), &out), 2);
  EXPECT_THAT(out, HasSubstr("points.csv:1 column 'sensor': missing"));
}

}  // namespace
}  // namespace lrcal
