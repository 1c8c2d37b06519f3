// The lrcal program as a user runs it: JSON outputs, the sample → simulate → identify round
// trip, and error messages that name the file, line and field with exit code 2.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/cpu_dispatch.h"
#include "lrcal/core/strings.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_model.h"
#include "test_util.h"

namespace lrcal {
namespace {

using Json = nlohmann::json;
using testing::LrcalBinary;
using testing::RunCommand;

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::TempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
    return Path(name);
  }
  int Run(const std::string& args, std::string* out) const {
    return RunCommand(LrcalBinary() + " " + args, out);
  }
  std::string dir_;
};

TEST_F(CliTest, VersionNamesTheKernelsThatRunAndAForcedVariant) {
  std::string out;
  ASSERT_EQ(RunCommand("LRCAL_ISA= " + LrcalBinary() + " --version", &out), 0) << out;
  EXPECT_THAT(out, ::testing::MatchesRegex("lrcal [0-9.]+ \\(.*; kernels: "
                                           "(default|avx2|avx512)\\)\n"));
  // A forced variant the CPU has is the one named; one it lacks (or a misspelt one) is not.
  for (Isa isa : SupportedIsas()) {
    ASSERT_EQ(
        RunCommand(std::string("LRCAL_ISA=") + IsaName(isa) + " " + LrcalBinary() + " --version",
                   &out),
        0);
    EXPECT_THAT(out, ::testing::HasSubstr(std::string("kernels: ") + IsaName(isa) + ")"));
  }
  ASSERT_EQ(RunCommand("LRCAL_ISA=avx1024 " + LrcalBinary() + " --version", &out), 0);
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("avx1024")));
}

TEST_F(CliTest, KinematicsJsonHasThePoseBeamAndDistance) {
  // q = 0: tool at (0, 2.2, 0.62), beam +y0: the paper's plane is behind (h < 0 → no reading).
  // q2 = π/2: tool at (0, 0.12, -1.7), beam -z0: also behind; q = (0,-π/4,...) hits.
  Write("c.csv", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n0,1.5707963267948966,0,0,0,0\n");
  std::string out;
  ASSERT_EQ(Run("kinematics --robot paper --configs " + Path("c.csv") + " --jacobian --format json",
                &out),
            0)
      << out;
  Json j = Json::parse(out);
  ASSERT_EQ(j.size(), 2u);
  EXPECT_NEAR(j[0]["position"][1].get<double>(), 2.2, 1e-12);
  EXPECT_NEAR(j[0]["position"][2].get<double>(), 0.62, 1e-12);
  EXPECT_NEAR(j[0]["beam"][1].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(j[0]["rotation"][2][0].get<double>(), -1.0, 1e-12);
  EXPECT_TRUE(j[0]["h"].is_null());
  EXPECT_EQ(j[0]["status"], "plane_behind_ranger");
  EXPECT_EQ(j[0]["jacobian"].size(), 25u);
  EXPECT_TRUE(j[0]["jacobian"].contains("beta6"));
}

TEST_F(CliTest, KinematicsDistanceMatchesTheFormula) {
  Write("c.csv", "q1,q2,q3,q4,q5,q6\n0.3,-0.7,1.1,0.4,-0.9,0.2\n");
  std::string out;
  ASSERT_EQ(Run("kinematics --configs " + Path("c.csv") + " --plane 0,0,1,0.5 --format json", &out),
            0)
      << out;
  Json j = Json::parse(out)[0];
  // h = -(n·p + f)/(n·b) with n = e_z, f = 0.5.
  const double pz = j["position"][2], bz = j["beam"][2];
  const double h = -(pz + 0.5) / bz;
  if (h > 0.05 && h < 3.0 && std::fabs(bz) > std::cos(70 * M_PI / 180)) {
    EXPECT_NEAR(j["h"].get<double>(), h, 1e-12);
  } else {
    EXPECT_TRUE(j["h"].is_null());
  }
}

TEST_F(CliTest, KinematicsOfTheTrueModelReadsWhatNoiseFreeSimulationReads) {
  // A rig whose true ranger reads 0.3 mm long with a 150 ppm scale error, d6 fixed (its true
  // error still moves the true arm): --model true must include all of it.
  std::string robot = testing::ReadFile(testing::SourcePath("studies/robots/paper.yaml"));
  const std::string unit_line = "  length_unit: mm\n";
  robot.replace(robot.find(unit_line), unit_line.size(),
                unit_line + "  ranger_offset_mm: 0.3\n  ranger_scale_ppm: 150\n");
  const std::string rig = Write("rig.yaml", robot);
  std::string out;
  ASSERT_EQ(Run("sample --robot " + rig + " --count 6 --seed 3 --out " + Path("q.csv"), &out), 0)
      << out;
  ASSERT_EQ(Run("simulate --robot " + rig + " --configs " + Path("q.csv") +
                    " --sigma-mm 0 --repetitions 1 --out " + Path("m.csv"),
                &out),
            0)
      << out;
  for (const std::string fix : {"", " --fix d6", " --estimate-ranger offset,scale"}) {
    ASSERT_EQ(Run("kinematics --robot " + rig + " --configs " + Path("q.csv") +
                      " --model true --format json" + fix,
                  &out),
              0)
        << out;
    const Json rows = Json::parse(out);
    std::istringstream m(testing::ReadFile(Path("m.csv")));
    std::string line;
    std::getline(m, line);  // header: q1..q6,h,repetition
    for (const auto& row : rows) {
      if (row["h"].is_null()) continue;  // the true beam misses: simulate skips it too
      ASSERT_TRUE(std::getline(m, line));
      const std::vector<std::string> cells = SplitList(line);
      EXPECT_NEAR(row["h"].get<double>(), std::stod(cells.at(6)), testing::tolerance::kUrdf) << fix;
    }
  }
}

TEST_F(CliTest, SampleSimulateIdentifyRoundTrip) {
  std::string out;
  ASSERT_EQ(Run("sample --robot paper --count 60 --seed 3 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --robot paper --configs " + Path("c.csv") +
                    " --sigma-mm 0.2 --repetitions 5 --seed 9 --out " + Path("m.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(
      Run("identify --robot paper --data " + Path("m.csv") + " --sigma-mm 0.2 --format json", &out),
      0)
      << out;
  Json j = Json::parse(out);
  EXPECT_EQ(j["termination"], "converged");
  EXPECT_EQ(j["rank"], 25);
  ASSERT_EQ(j["parameters"].size(), 25u);
  EXPECT_EQ(j["covariance"].size(), 25u);
  const RobotModel& robot = testing::PaperRobot();
  for (const auto& p : j["parameters"]) {
    const double truth = testing::PaperTrueErrors()[robot.FindValue(p["name"])];
    // Within 5 predicted standard deviations of the truth.
    EXPECT_LT(std::fabs(p["delta"].get<double>() - truth), 5 * p["std_given_sigma"].get<double>())
        << p["name"];
    EXPECT_NEAR(p["estimate"].get<double>(), p["nominal"].get<double>() + p["delta"].get<double>(),
                1e-15);
  }
  // The residual RMS of means of 5 readings of 0.2 mm is about 0.2/√5·√(35/60) ≈ 0.07 mm.
  EXPECT_NEAR(j["residual_rms"].get<double>(), 0.068e-3, 0.03e-3);
}

// A URDF arm from end to end, as the README's "Your own arm: URDF" shows: sample, simulate,
// identify with --write-robot, export the calibrated model as URDF, and the exported URDF's
// kinematics equal the calibrated robot file's.
TEST_F(CliTest, UrdfArmCalibratesAndExportsWithTheSameKinematics) {
  const std::string urdf =
      "--robot " + testing::SourcePath("examples/urdf/ur5_ranger.urdf") + " --tool-link ranger";
  const std::string plane = " --plane 0,0,1,0";
  std::string out;
  ASSERT_EQ(Run("sample " + urdf + plane + " --count 60 --seed 3 --out " + Path("c.csv"), &out), 0)
      << out;
  ASSERT_EQ(Run("simulate " + urdf + plane + " --configs " + Path("c.csv") + " --seed 2 --out " +
                    Path("m.csv"),
                &out),
            0)
      << out;
  // The horizontal plane cannot see θ1, a1 or d4 of this arm (identifiability says so).
  ASSERT_EQ(
      Run("identifiability " + urdf + plane + " --configs " + Path("c.csv") + " --format json",
          &out),
      0)
      << out;
  EXPECT_EQ(Json::parse(out)["rank"], 21) << out;
  ASSERT_EQ(Run("identify " + urdf + plane + " --data " + Path("m.csv") +
                    " --fix theta1,a1,d4 --sigma-mm 0.2 --write-robot " + Path("cal.yaml"),
                &out),
            0)
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("consistent with the stated noise")) << out;
  EXPECT_THAT(testing::ReadFile(Path("cal.yaml")), ::testing::HasSubstr("tool: {xyz:"));
  ASSERT_EQ(
      Run("export --robot " + Path("cal.yaml") + " --format urdf --out " + Path("cal.urdf"), &out),
      0)
      << out;
  std::string from_yaml, from_urdf;
  ASSERT_EQ(Run("kinematics --robot " + Path("cal.yaml") + " --configs " + Path("c.csv") +
                    " --format json",
                &from_yaml),
            0);
  ASSERT_EQ(Run("kinematics --robot " + Path("cal.urdf") + plane + " --configs " + Path("c.csv") +
                    " --format json",
                &from_urdf),
            0)
      << from_urdf;
  const Json a = Json::parse(from_yaml), b = Json::parse(from_urdf);
  ASSERT_EQ(a.size(), 60u);
  ASSERT_EQ(b.size(), 60u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(a[i]["position"][k].get<double>(), b[i]["position"][k].get<double>(), 1e-12);
    EXPECT_NEAR(a[i]["h"].get<double>(), b[i]["h"].get<double>(), 1e-12);
  }
}

TEST_F(CliTest, IdentifiabilityFindsThePapersHorizontalPlaneRemark) {
  std::string out;
  ASSERT_EQ(Run("sample --robot paper --plane 0,0,1,0.3 --count 80 --seed 2 --out " + Path("c.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("identifiability --robot paper --plane 0,0,1,0.3 --configs " + Path("c.csv") +
                    " --format json",
                &out),
            0)
      << out;
  Json j = Json::parse(out);
  EXPECT_EQ(j["n_params"], 25);
  EXPECT_EQ(j["rank"], 22);
  std::vector<std::string> u = j["unidentifiable"];
  std::sort(u.begin(), u.end());
  EXPECT_EQ(u, (std::vector<std::string>{"a1", "d3", "theta1"}));
  EXPECT_TRUE(j["dependencies"].empty());
}

// --estimate-ranger offset,scale against one known plane: the analysis names the ranger offset
// with d6 (both translate along the beam) and the scale with the arm's lengths (a uniform
// scaling about the point where the plane meets the base z axis keeps every reading's ratio).
TEST_F(CliTest, IdentifiabilityNamesTheRangerDependences) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 3 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("identifiability --configs " + Path("c.csv") +
                    " --estimate-ranger offset,scale --format json",
                &out),
            0)
      << out;
  const Json j = Json::parse(out);
  EXPECT_EQ(j["n_params"], 27);
  EXPECT_EQ(j["rank"], 25);
  ASSERT_EQ(j["dependencies"].size(), 2u);
  const Json& offset = j["dependencies"][0];
  ASSERT_EQ(offset.size(), 2u);
  EXPECT_EQ(offset[0]["name"], "ranger_offset");
  EXPECT_EQ(offset[1]["name"], "d6");
  EXPECT_NEAR(offset[1]["coefficient"].get<double>(), 1.0, 1e-9);
  EXPECT_EQ(j["dependencies"][1][0]["name"], "ranger_scale");
  EXPECT_EQ(j["suggested_fixed"], Json::array({"ranger_offset", "ranger_scale"}));
  EXPECT_NE(Run("identifiability --configs " + Path("c.csv") + " --estimate-ranger zero", &out), 0);
  EXPECT_THAT(out, ::testing::HasSubstr("--estimate-ranger: unknown ranger term 'zero'")) << out;
}

// Issue 12's acceptance: three planes with normals and offsets estimated give 34 parameters,
// rank 32, the two lost combinations (the planes' common spin with θ1, a shift along z0 with
// d1) and the cheapest fix of each; with the planes known and the ranger's terms estimated,
// the ranger offset / d6 dependence.
TEST_F(CliTest, IdentifiabilityOnThreePlanesNamesTheLostCombinations) {
  const std::string planes = " --plane 0,0,1,0.3 --plane 1,0,0,0.9 --plane 0,1,0,0.9";
  std::string out;
  ASSERT_EQ(Run("sample --count 40 --seed 5 --out " + Path("c.csv") + planes, &out), 0) << out;
  const std::string csv = testing::ReadFile(Path("c.csv"));
  ASSERT_EQ(csv.substr(0, csv.find('\n')), "q1,q2,q3,q4,q5,q6,plane");
  ASSERT_EQ(Run("identifiability --configs " + Path("c.csv") + planes +
                    " --estimate-plane normal,offset --format json",
                &out),
            0)
      << out;
  Json j = Json::parse(out);
  EXPECT_EQ(j["n_params"], 34);
  EXPECT_EQ(j["n_configurations"], 120);
  EXPECT_EQ(j["rank"], 32);
  ASSERT_EQ(j["dependencies"].size(), 2u);
  std::set<std::string> members;
  for (const auto& d : j["dependencies"])
    for (const auto& t : d) members.insert(t["name"].get<std::string>());
  for (const char* name : {"theta1", "d1", "plane1_f"}) EXPECT_TRUE(members.count(name)) << name;
  ASSERT_EQ(j["remedies"]["lost"].size(), 2u);
  ASSERT_EQ(j["remedies"]["cheapest_fix"].size(), 2u);
  for (const auto& fix : j["remedies"]["cheapest_fix"])
    EXPECT_EQ(fix.get<std::string>().rfind("fix ", 0), 0u) << fix;
  // The text output says the same in words.
  ASSERT_EQ(
      Run("identifiability --configs " + Path("c.csv") + planes + " --estimate-plane normal,offset",
          &out),
      0);
  EXPECT_THAT(out, ::testing::HasSubstr("cheapest fix: fix")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("add a known distance")) << out;

  ASSERT_EQ(Run("identifiability --configs " + Path("c.csv") + planes +
                    " --estimate-ranger offset,scale --format json",
                &out),
            0)
      << out;
  j = Json::parse(out);
  EXPECT_EQ(j["n_params"], 27);
  EXPECT_EQ(j["rank"], 26);  // against three known planes the scale is seen, the offset not
  ASSERT_EQ(j["dependencies"].size(), 1u);
  std::set<std::string> pair;
  for (const auto& t : j["dependencies"][0]) pair.insert(t["name"].get<std::string>());
  EXPECT_EQ(pair, (std::set<std::string>{"d6", "ranger_offset"}));
}

// Design on a pool spanning three planes chooses (configuration, plane) rows: the chosen file
// keeps each row's plane, and the counts per plane add up to k.
TEST_F(CliTest, DesignChoosesConfigurationPlanePairs) {
  const std::string planes = " --plane 0,0,1,0.3 --plane 1,0,0,0.9 --plane 0,1,0,0.9";
  std::string out;
  ASSERT_EQ(Run("sample --count 30 --seed 4 --out " + Path("pool.csv") + planes, &out), 0) << out;
  ASSERT_EQ(Run("design --pool " + Path("pool.csv") + planes +
                    " --select 40 --method backward --baseline 10 --format json --out " +
                    Path("chosen.csv"),
                &out),
            0)
      << out;
  const Json j = Json::parse(out);
  const std::vector<int> per_plane = j["selected_per_plane"];
  ASSERT_EQ(per_plane.size(), 3u);
  EXPECT_EQ(per_plane[0] + per_plane[1] + per_plane[2], 40);
  // Row i of the chosen file is pool row selected[i], plane column included.
  const auto lines = [&](const std::string& file) {
    std::vector<std::string> rows;
    std::istringstream in(testing::ReadFile(Path(file)));
    for (std::string line; std::getline(in, line);) rows.push_back(line);
    return rows;
  };
  const std::vector<std::string> pool_rows = lines("pool.csv"), chosen_rows = lines("chosen.csv");
  ASSERT_EQ(chosen_rows.size(), 41u);
  EXPECT_EQ(chosen_rows[0], "q1,q2,q3,q4,q5,q6,plane");
  std::vector<int> counted(3, 0);
  for (int i = 0; i < 40; ++i) {
    const int row = j["selected"][i].get<int>() + 1;
    EXPECT_EQ(chosen_rows[i + 1], pool_rows[row]) << i;
    ++counted[std::stoi(chosen_rows[i + 1].substr(chosen_rows[i + 1].rfind(',') + 1)) - 1];
  }
  EXPECT_EQ(counted, per_plane);
}

// design --criterion I: the predicted RMS position error at the user's poses, as JSON reports
// it, against tr(W (GᵀG)⁻¹) computed here from the pool's and the poses' Jacobians; the I design
// predicts better at those poses than the E design on the same pool.
TEST_F(CliTest, DesignTaskCriterionMinimisesThePredictedErrorAtThePoses) {
  std::string out;
  ASSERT_EQ(Run("sample --count 101 --seed 3 --out " + Path("pool.csv"), &out), 0) << out;
  ASSERT_EQ(Run("sample --validation --count 50 --seed 8 --out " + Path("poses.csv"), &out), 0)
      << out;
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const TargetedConfigurations pool = ReadConfigurations(Path("pool.csv"), 6);
  const TargetedConfigurations poses = ReadConfigurations(Path("poses.csv"), 6);
  const Eigen::MatrixXd G = IdentificationJacobian(model, pool);
  const std::vector<double> zero(25, 0.0);
  const Eigen::MatrixXd J6 = PoseJacobian(model, zero.data(), poses);
  const auto predicted_rms = [&](const Json& selected) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(25, 25);
    for (const auto& i : selected) A += G.row(i.get<int>()).transpose() * G.row(i.get<int>());
    const Eigen::MatrixXd C = A.inverse();
    double sum = 0;
    for (int j = 0; j < poses.size(); ++j)
      sum += (J6.middleRows(6 * j, 3) * C * J6.middleRows(6 * j, 3).transpose()).trace();
    return std::sqrt(sum / poses.size());
  };
  const std::string design = "design --pool " + Path("pool.csv") + " --select 30 --baseline 10 " +
                             "--format json --criterion ";
  ASSERT_EQ(Run(design + "I --poses " + Path("poses.csv"), &out), 0) << out;
  const Json task = Json::parse(out);
  EXPECT_EQ(task["criterion"], "I");
  EXPECT_EQ(task["task"]["poses"], 50);
  const double rms_i = predicted_rms(task["selected"]);
  EXPECT_NEAR(task["task"]["rms_position_per_unit_sigma"].get<double>(), rms_i, 1e-9 * rms_i);
  ASSERT_EQ(Run(design + "E", &out), 0) << out;
  const double rms_e = predicted_rms(Json::parse(out)["selected"]);
  EXPECT_LT(rms_i, rms_e);
  // Without --poses, poses over the joint ranges are used and said so.
  ASSERT_EQ(
      Run("design --pool " + Path("pool.csv") + " --select 30 --baseline 10 --criterion I", &out),
      0)
      << out;
  EXPECT_THAT(
      out, ::testing::HasSubstr("criterion I (predicted RMS position error at 200 workspace poses"))
      << out;
}

// A robot file may list planes; sample → simulate → identify on them comes back to the truth
// within 5 predicted standard deviations, and the planes' names work in a CSV's plane column.
TEST_F(CliTest, RobotFileWithPlanesRoundTrip) {
  std::string robot = testing::ReadFile(testing::SourcePath("studies/robots/paper.yaml"));
  const std::size_t at = robot.find("plane: {");
  ASSERT_NE(at, std::string::npos);
  robot.replace(at, robot.find('\n', at) - at,
                "planes:\n  - {normal: [0, 1, 4.6], offset: -0.69, name: table}\n"
                "  - {normal: [1, 0, 0], offset: 0.9, name: wall}");
  Write("rig.yaml", robot);
  std::string out;
  ASSERT_EQ(
      Run("sample --robot " + Path("rig.yaml") + " --count 40 --seed 2 --out " + Path("c.csv"),
          &out),
      0)
      << out;
  ASSERT_EQ(Run("simulate --robot " + Path("rig.yaml") + " --configs " + Path("c.csv") +
                    " --sigma-mm 0.05 --repetitions 3 --seed 4 --out " + Path("m.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("identify --robot " + Path("rig.yaml") + " --data " + Path("m.csv") +
                    " --sigma-mm 0.05 --format json",
                &out),
            0)
      << out;
  const Json j = Json::parse(out);
  EXPECT_EQ(j["rank"], 25);
  const RobotModel& paper = testing::PaperRobot();
  for (const auto& p : j["parameters"]) {
    const double truth = testing::PaperTrueErrors()[paper.FindValue(p["name"])];
    EXPECT_LT(std::fabs(p["delta"].get<double>() - truth), 5 * p["std_given_sigma"].get<double>())
        << p["name"];
  }
  // A configuration file naming the planes.
  Write("named.csv", "q1,q2,q3,q4,q5,q6,plane\n0,-0.7,0,0,0,0,table\n0,-0.7,0,0,0,0,wall\n");
  EXPECT_EQ(Run("kinematics --robot " + Path("rig.yaml") + " --configs " + Path("named.csv") +
                    " --format json",
                &out),
            0)
      << out;
  Write("bad.csv", "q1,q2,q3,q4,q5,q6,plane\n0,-0.7,0,0,0,0,ceiling\n");
  EXPECT_EQ(Run("kinematics --robot " + Path("rig.yaml") + " --configs " + Path("bad.csv"), &out),
            2);
  EXPECT_THAT(out,
              ::testing::HasSubstr(
                  "'ceiling' is not one of the 2 plane(s) given: expected 1 (table), 2 (wall)"))
      << out;
}

// identify --holdout K: with the true sigma the held-out readings are predicted as the fit
// says; with half of it they are not (and the fit check exits 4); K out of range exits 2.
TEST_F(CliTest, IdentifyHoldoutChecksPredictionsOfHeldOutReadings) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 3 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") +
                    " --sigma-mm 0.2 --repetitions 3 --seed 9 --out " + Path("m.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(
      Run("identify --data " + Path("m.csv") + " --sigma-mm 0.2 --holdout 5 --format json", &out),
      0)
      << out;
  Json j = Json::parse(out)["holdout"];
  EXPECT_EQ(j["folds"], 5);
  ASSERT_EQ(j["predictions"].size(), 60u);
  EXPECT_EQ(j["predictions"][0]["configuration"], 1);
  EXPECT_EQ(j["predictions"][7]["fold"], 2);
  EXPECT_TRUE(j["consistent"].get<bool>()) << j.dump(2);
  EXPECT_NEAR(j["ratio"].get<double>(), 1.0, 0.3);
  EXPECT_TRUE(j["failed_folds"].empty());
  EXPECT_EQ(Run("identify --data " + Path("m.csv") + " --sigma-mm 0.1 --holdout 5", &out), 4);
  EXPECT_THAT(out, ::testing::HasSubstr("held-out readings are predicted WORSE than the fit says"))
      << out;
  EXPECT_EQ(Run("identify --data " + Path("m.csv") + " --holdout 61", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("--holdout: expected 2 to 60 folds")) << out;
}

TEST_F(CliTest, IdentifyRefusesRankDeficientSetAndSuggestsTheFix) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 4 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv"), &out), 0);
  EXPECT_EQ(Run("identify --data " + Path("m.csv") + " --estimate-plane normal", &out), 3);
  EXPECT_THAT(out, ::testing::HasSubstr("--fix")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("theta1")) << out;
  EXPECT_EQ(
      Run("identify --data " + Path("m.csv") + " --estimate-plane normal --auto-fix --format json",
          &out),
      0)
      << out;
  EXPECT_EQ(Json::parse(out)["fixed_for_rank"].size(), 1u);
}

// identify --prior-sigma on a horizontal plane, which cannot see theta1, a1 and d3: the maximum
// a-posteriori estimate converges (exit 0) where least squares is refused, and says which terms
// the priors set, in text and JSON.
TEST_F(CliTest, IdentifyWithPriorsSetsWhatTheReadingsCannotSee) {
  std::string out;
  const std::string plane = " --plane 0,0,1,0.3";
  ASSERT_EQ(Run("sample --count 60 --out " + Path("c.csv") + plane, &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv") + plane +
                    " --sigma-mm 0.2 --seed 3",
                &out),
            0)
      << out;
  const std::string identify = "identify --data " + Path("m.csv") + plane + " --sigma-mm 0.2";
  EXPECT_EQ(Run(identify, &out), 3) << out;
  const std::string priors = " --prior-sigma theta=5mrad,alpha=5mrad,beta=5mrad,a=5mm,d=5mm";
  ASSERT_EQ(Run(identify + priors, &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("least squares with priors"));
  EXPECT_THAT(out, ::testing::HasSubstr("set by the prior (posterior/prior std above 0.9): "
                                        "theta1 a1 d3"));
  ASSERT_EQ(Run(identify + priors + " --format json", &out), 0) << out;
  const Json j = Json::parse(out);
  EXPECT_EQ(j["set_by_prior"], Json({"theta1", "a1", "d3"}));
  EXPECT_EQ(j["fit"]["num_priors"], 25);
  // The same question before any reading: identifiability at the configurations.
  ASSERT_EQ(Run("identifiability --configs " + Path("c.csv") + plane + priors +
                    " --sigma-mm 0.2 --format json",
                &out),
            0)
      << out;
  const Json before = Json::parse(out)["priors"];
  EXPECT_EQ(before["set_by_prior"], Json({"theta1", "a1", "d3"}));
  EXPECT_TRUE(before["defined"].get<bool>());
  EXPECT_EQ(before["terms"].size(), 25u);
  // The same priors as a robot file's tolerances: --prior gives the same estimate, bit for bit.
  std::string robot = testing::ReadFile(testing::SourcePath("studies/robots/paper.yaml"));
  robot +=
      "tolerances:\n  angle_unit: mrad\n  length_unit: mm\n"
      "  every_link: {theta: 5, alpha: 5, beta: 5, a: 5, d: 5}\n";
  const std::string file = Write("tolerant.yaml", robot);
  ASSERT_EQ(Run(identify + " --robot " + file + " --prior --format json", &out), 0) << out;
  EXPECT_EQ(Json::parse(out)["parameters"], j["parameters"]);
  EXPECT_EQ(Run(identify + " --prior", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("--prior: the robot file"));
  EXPECT_THAT(out, ::testing::HasSubstr("has no tolerances:"));
  for (const Json& p : j["parameters"]) {
    EXPECT_DOUBLE_EQ(p["prior_sigma"].get<double>(), 5e-3) << p["name"];
    EXPECT_GT(p["posterior_to_prior"].get<double>(), 0) << p["name"];
  }
}

// identify with --sigma-mm: a consistent fit passes; a stated σ of a fifth of the real one is
// exit 4 with the verdict in words; too few configurations are exit 2 naming the file.
TEST_F(CliTest, IdentifyChecksTheFitAgainstTheStatedNoise) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 4 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv"), &out), 0);
  ASSERT_EQ(Run("identify --data " + Path("m.csv") + " --sigma-mm 0.2 --format json", &out), 0)
      << out;
  const Json fit = Json::parse(out)["fit"];
  EXPECT_EQ(fit["dof"], 35);
  EXPECT_TRUE(fit["consistent"].get<bool>());
  EXPECT_GT(fit["p_value"].get<double>(), 1e-3);
  EXPECT_EQ(fit["standardized_residuals"].size(), 60u);
  EXPECT_EQ(Run("identify --data " + Path("m.csv") + " --sigma-mm 0.04", &out), 4);
  EXPECT_THAT(out, ::testing::HasSubstr("INCONSISTENT with the stated noise")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("wrong units")) << out;
  EXPECT_EQ(Run("identify --data " + Path("m.csv") + " --sigma-mm 0.04 --format json", &out), 4);
  EXPECT_FALSE(Json::parse(out.substr(0, out.rfind('}') + 1))["fit"]["consistent"].get<bool>());
  // Without σ: no test, σ̂ and the standardised residuals.
  ASSERT_EQ(Run("identify --data " + Path("m.csv") + " --format json", &out), 0) << out;
  EXPECT_TRUE(Json::parse(out)["fit"]["chi2"].is_null());
  // Ten configurations for 25 parameters.
  std::string ten;
  {
    std::ifstream in(Path("m.csv"));
    std::string line;
    std::getline(in, line);
    ten = line + "\n";  // the header as simulate writes it
    std::set<std::string> seen;
    while (std::getline(in, line) && seen.size() < 10) {
      std::size_t end = 0;
      for (int c = 0; c < 6; ++c) end = line.find(',', end) + 1;
      seen.insert(line.substr(0, end));  // the joint values q1..q6
      ten += line + "\n";
    }
  }
  Write("few.csv", ten);
  EXPECT_EQ(Run("identify --data " + Path("few.csv"), &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("few.csv")) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("25 parameters need at least as many configurations"))
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("10 given")) << out;
  EXPECT_THAT(out, ::testing::Not(::testing::HasSubstr("dependence"))) << out;
}

// Issue 31: with a `configuration` column the suspects are named by their labels too.
TEST_F(CliTest, IdentifyNamesSuspectsByTheirConfigurationLabels) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 4 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv"), &out), 0);
  std::ifstream in(Path("m.csv"));
  std::string line, labelled;
  std::getline(in, line);
  labelled = line + ",configuration\n";
  std::map<std::string, int> station;  // joint values → 1-based configuration
  while (std::getline(in, line)) {
    std::vector<std::string> cells = SplitList(line);
    std::string q;
    for (int c = 0; c < 6; ++c) q += cells[static_cast<std::size_t>(c)] + ",";
    const int k = station.emplace(q, static_cast<int>(station.size()) + 1).first->second;
    if (k == 18) cells[6] = FormatExact(std::stod(cells[6]) + 0.5e-3);  // 0.5 mm off: 8 sigma
    for (const std::string& cell : cells) labelled += cell + ",";
    labelled += "station_" + std::to_string(k) + "\n";
  }
  Write("labelled.csv", labelled);
  ASSERT_EQ(Run("identify --data " + Path("labelled.csv") + " --sigma-mm 0.2 --format json", &out),
            4)
      << out;
  const Json fit = Json::parse(out.substr(0, out.rfind('}') + 1))["fit"];
  EXPECT_EQ(fit["suspects"], Json::array({18}));
  EXPECT_EQ(fit["suspect_labels"], Json::array({"station_18"}));
  EXPECT_EQ(Run("identify --data " + Path("labelled.csv") + " --sigma-mm 0.2", &out), 4);
  EXPECT_THAT(out, ::testing::HasSubstr("18 'station_18' (")) << out;
  // Without labels, no suspect_labels.
  ASSERT_EQ(Run("identify --data " + Path("m.csv") + " --sigma-mm 0.2 --format json", &out), 0);
  EXPECT_FALSE(Json::parse(out)["fit"].contains("suspect_labels"));
}

// identify --write-robot: the calibrated model as a robot file whose nominal values are the
// estimates to the last bit, with the record; every command takes it, and identifying again from
// it on the same readings finds nothing left to correct.
TEST_F(CliTest, IdentifyWritesTheCalibratedRobot) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 6 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv"), &out), 0);
  ASSERT_EQ(Run("identify --data " + Path("m.csv") +
                    " --sigma-mm 0.2 --estimate-plane offset --auto-fix " +
                    "--format json --write-robot " + Path("cal.yaml"),
                &out),
            0)
      << out;
  const Json j = Json::parse(out.substr(0, out.rfind('}') + 1));
  const RobotFile cal = LoadRobotFile(Path("cal.yaml"));
  for (const Json& p : j["parameters"]) {
    const std::string name = p["name"];
    if (name == "plane_f") {
      EXPECT_EQ((*cal.planes)[0].offset, p["estimate"].get<double>());
      continue;
    }
    const int k = cal.robot.FindValue(name);
    ASSERT_GE(k, 0) << name;
    EXPECT_EQ(cal.robot.nominal_values()[k], p["estimate"].get<double>()) << name;
    EXPECT_EQ(cal.truth.LinkErrors(cal.robot)[k], 0.0);
  }
  const std::string text = testing::ReadFile(Path("cal.yaml"));
  EXPECT_THAT(text, ::testing::HasSubstr("data_fnv1a"));
  EXPECT_THAT(text, ::testing::HasSubstr("sigma: 0.00020000000000000001  # m, one reading\n"
                                         "  sigma_source: \"given (--sigma-mm)\""))
      << text;
  EXPECT_THAT(text, ::testing::HasSubstr("held: [d1, plane_u1, plane_u2, ranger_offset, "
                                         "ranger_scale]"));
  ASSERT_TRUE(cal.calibration.has_value());
  EXPECT_EQ(cal.calibration->sigma_source, "given (--sigma-mm)");
  EXPECT_EQ(cal.calibration->estimate_shift.rows(), 25);
  EXPECT_EQ(cal.calibration->estimate_shift.cols(), 5);
  ASSERT_EQ(Run("kinematics --robot " + Path("cal.yaml") + " --configs " + Path("c.csv"), &out), 0)
      << out;
  ASSERT_EQ(Run("identify --robot " + Path("cal.yaml") + " --data " + Path("m.csv") +
                    " --estimate-plane offset --auto-fix --format json",
                &out),
            0)
      << out;
  const Json again = Json::parse(out);  // kept alive: a range-for over a temporary's member
  for (const Json& p : again["parameters"])
    EXPECT_NEAR(p["delta"].get<double>(), 0.0, 1e-9) << p["name"];
}

// identify --predict-at and lrcal accuracy on the written robot file give the same predicted
// accuracy at the same poses; a robot file without a record is exit 2 saying how to get one.
TEST_F(CliTest, AccuracyAtPosesFromTheFitAndFromTheCalibratedFile) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 8 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("sample --count 4 --seed 9 --out " + Path("poses.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv"), &out), 0);
  ASSERT_EQ(Run("identify --data " + Path("m.csv") + " --sigma-mm 0.2 --predict-at " +
                    Path("poses.csv") + " --write-robot " + Path("cal.yaml") + " --format json",
                &out),
            0)
      << out;
  const Json fit = Json::parse(out.substr(0, out.rfind('}') + 1))["accuracy"];
  ASSERT_EQ(fit["poses"].size(), 4u);
  ASSERT_EQ(Run("accuracy --robot " + Path("cal.yaml") + " --configs " + Path("poses.csv") +
                    " --format json",
                &out),
            0)
      << out;
  const Json file = Json::parse(out);
  for (int j = 0; j < 4; ++j)
    for (const char* key :
         {"position_std", "orientation_std", "position_std_total", "orientation_std_total"})
      for (int a = 0; a < 3; ++a) {
        const double x = fit["poses"][j][key][a], y = file["poses"][j][key][a];
        EXPECT_NEAR(x, y, 1e-6 * x) << key << " pose " << j;
      }
  for (const char* key : {"rms_position", "rms_position_total"})
    EXPECT_NEAR(fit[key].get<double>(), file[key].get<double>(), 1e-6 * file[key].get<double>());
  // The paper's plane is given, not estimated, and no tolerance is known: the total holds the
  // plane and ranger terms at lrcal's defaults and names them.
  EXPECT_EQ(file["defaulted"],
            Json({"plane_u1", "plane_u2", "plane_f", "ranger_offset", "ranger_scale"}));
  // The base and tool transforms have no tolerance and were not estimated: exact, and said so.
  EXPECT_EQ(file["taken_as_exact"].size(), 12u);
  EXPECT_EQ(fit["taken_as_exact"], file["taken_as_exact"]);
  ASSERT_EQ(fit["sources"].size(), file["sources"].size());
  for (std::size_t k = 0; k < file["sources"].size(); ++k) {
    EXPECT_EQ(fit["sources"][k]["name"], file["sources"][k]["name"]);
    EXPECT_EQ(fit["sources"][k]["absorbed_by"], file["sources"][k]["absorbed_by"]);
  }
  EXPECT_GT(file["rms_position_total"].get<double>(), 10 * file["rms_position"].get<double>());
  EXPECT_EQ(file["sigma_used"]["source"], "given");
  EXPECT_GT(file["poses"][0]["position_radius_95"].get<double>(), 0);
  ASSERT_EQ(Run("accuracy --robot " + Path("cal.yaml") + " --configs " + Path("poses.csv"), &out),
            0);
  EXPECT_THAT(out, ::testing::HasSubstr("Predicted accuracy of the calibrated arm")) << out;
  EXPECT_EQ(Run("accuracy --robot paper --configs " + Path("poses.csv"), &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("--write-robot")) << out;
}

// The issue's rig: a 7-joint arm, its ranger off the flange along the flange's z, two surveyed
// planes and a true ranger offset of 0.3 mm that no reading can tell from d7. The fit is
// consistent and the data-only statement holds the true error at no pose; the total names the
// ranger offset (absorbed by d7, default tolerance, warned about) and holds it at every pose.
TEST_F(CliTest, TotalAccuracyCoversTheRangerOffsetTheReadingsCannotSee) {
  std::string out;
  const std::string rig =
      " --robot " + testing::SourcePath("examples/rigs/seven_joint_ranger.yaml");
  ASSERT_EQ(Run("sample" + rig + " --count 60 --seed 3 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate" + rig + " --configs " + Path("c.csv") +
                    " --sigma-mm 0.05 --seed 2 --out " + Path("m.csv"),
                &out),
            0)
      << out;
  ASSERT_EQ(Run("sample" + rig + " --validation --count 100 --seed 1 --out " + Path("v.csv"), &out),
            0)
      << out;
  ASSERT_EQ(Run("identify" + rig + " --data " + Path("m.csv") + " --sigma-mm 0.05 --write-robot " +
                    Path("cal.yaml"),
                &out),
            0)
      << out;
  ASSERT_EQ(
      Run("accuracy --robot " + Path("cal.yaml") + " --configs " + Path("v.csv") + " --format json",
          &out),
      0)
      << out;
  const Json acc = Json::parse(out);
  ASSERT_EQ(
      Run("kinematics" + rig + " --model true --configs " + Path("v.csv") + " --format json", &out),
      0);
  const Json truth = Json::parse(out);
  ASSERT_EQ(Run("kinematics --robot " + Path("cal.yaml") + " --configs " + Path("v.csv") +
                    " --format json",
                &out),
            0);
  const Json calibrated = Json::parse(out);
  ASSERT_EQ(truth.size(), acc["poses"].size());
  int inside_total = 0, inside_data = 0;
  double sum2 = 0;
  for (std::size_t j = 0; j < truth.size(); ++j) {
    double e2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double d =
          truth[j]["position"][a].get<double>() - calibrated[j]["position"][a].get<double>();
      e2 += d * d;
    }
    sum2 += e2;
    inside_total += std::sqrt(e2) <= acc["poses"][j]["position_radius_95_total"].get<double>();
    inside_data += std::sqrt(e2) <= acc["poses"][j]["position_radius_95"].get<double>();
  }
  const int m = static_cast<int>(truth.size());
  EXPECT_NEAR(std::sqrt(sum2 / m), 0.3e-3, 0.03e-3);  // the offset, moved into d7
  EXPECT_EQ(inside_total, m);
  EXPECT_EQ(inside_data, 0);
  const Json& top = acc["sources"][0];
  EXPECT_EQ(top["name"], "ranger_offset");
  EXPECT_EQ(top["absorbed_by"], "d7");
  EXPECT_TRUE(top["defaulted"].get<bool>());
  EXPECT_EQ(acc["defaulted"], Json({"ranger_offset", "ranger_scale"}));
  // The surveyed planes' tolerances come from the robot file.
  for (const Json& s : acc["sources"])
    if (s["name"] == "plane1_f") {
      EXPECT_DOUBLE_EQ(s["prior_sigma"].get<double>(), 0.05e-3);
    }
}

// Issue 31: a file-size limit (ulimit -f) killed lrcal with SIGXFSZ; the write now fails like
// a full disk: exit 5 naming the file, nothing half-written in its place.
TEST_F(CliTest, AFileSizeLimitIsAStorageErrorNotASignal) {
  std::string out;
  ASSERT_EQ(Run("sample --count 300 --out " + Path("c.csv"), &out), 0) << out;
  const int code =
      testing::RunCommand("ulimit -f 20 && " + testing::LrcalBinary() + " simulate --configs " +
                              Path("c.csv") + " --out " + Path("m.csv"),
                          &out);
  EXPECT_EQ(code, 5) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("could not write results: cannot write " + Path("m.csv")))
      << out;
  EXPECT_THAT(out, ::testing::HasSubstr("File too large")) << out;
  EXPECT_FALSE(std::ifstream(Path("m.csv")).good());
}

// identify --encoder-sigma-mrad: readings whose recorded joint values are off by 0.1 mrad fail
// the χ² check as plain least squares and pass it with errors in variables; without the
// readings' noise the option is refused, named.
TEST_F(CliTest, IdentifyWithErrorsInVariables) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 4 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv") +
                    " --sigma-mm 0.05 --repetitions 1 --encoder-sigma-mrad 0.1 --seed 5",
                &out),
            0)
      << out;
  const std::string identify = "identify --data " + Path("m.csv") + " --sigma-mm 0.05";
  EXPECT_EQ(Run(identify, &out), 4) << out;
  ASSERT_EQ(Run(identify + " --encoder-sigma-mrad 0.1", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("errors in variables (joint sigma 0.1000 mrad)"));
  EXPECT_THAT(out, ::testing::HasSubstr("consistent with the stated noise"));
  EXPECT_EQ(Run("identify --data " + Path("m.csv") + " --encoder-sigma-mrad 0.1", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("--encoder-sigma-mrad")) << out;
}

// --average median: gross errors in one reading of five no longer reject the fit, and the
// weights carry the median's variance factor.
TEST_F(CliTest, IdentifyWithAMedianOfTheReadings) {
  std::string out;
  ASSERT_EQ(Run("sample --count 60 --seed 4 --out " + Path("c.csv"), &out), 0) << out;
  ASSERT_EQ(Run("simulate --configs " + Path("c.csv") + " --out " + Path("m.csv") +
                    " --sigma-mm 0.05 --repetitions 5 --outlier-fraction 0.05 --seed 5",
                &out),
            0)
      << out;
  const std::string identify = "identify --data " + Path("m.csv") + " --sigma-mm 0.05";
  EXPECT_EQ(Run(identify, &out), 4) << out;  // the means carry the gross errors
  ASSERT_EQ(Run(identify + " --average median", &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("readings: the median of each configuration's readings, "
                                        "weighted R/c (c = 1.4"));
  EXPECT_THAT(out, ::testing::HasSubstr("consistent with the stated noise"));
  ASSERT_EQ(Run(identify + " --average median --format json", &out), 0) << out;
  EXPECT_EQ(Json::parse(out)["average"], "median");
  for (const char* bad : {"mode", "trimmed:0.7"}) {
    EXPECT_EQ(Run(identify + " --average " + bad, &out), 2) << bad;
    EXPECT_THAT(out, ::testing::HasSubstr("--average")) << out;
    EXPECT_THAT(out, ::testing::HasSubstr("expected")) << out;
  }
}

TEST_F(CliTest, DesignChoosesKAndBeatsTheRandomBaseline) {
  std::string out;
  ASSERT_EQ(Run("design --generate 60 --seed 2 --select 30 --method exchange --criterion E "
                "--baseline 200 "
                "--format json --out " +
                    Path("chosen.csv"),
                &out),
            0)
      << out;
  Json j = Json::parse(out);
  EXPECT_EQ(j["selected"].size(), 30u);
  EXPECT_EQ(j["pool"]["size"], 60);
  EXPECT_GT(j["pool"]["tried"].get<int>(), 60);  // some candidates were rejected
  EXPECT_GE(j["score"].get<double>(), j["indices"]["E"]["random_p95"].get<double>());
  EXPECT_NEAR(j["indices"]["E"]["chosen"].get<double>(), j["score"].get<double>(), 1e-12);
  // The chosen configurations were written, and the same call chooses the same set.
  std::string again;
  ASSERT_EQ(Run("design --generate 60 --seed 2 --select 30 --method exchange --baseline 200 "
                "--format json",
                &again),
            0);
  EXPECT_EQ(Json::parse(again)["selected"], j["selected"]);
  ASSERT_EQ(Run("identifiability --configs " + Path("chosen.csv") + " --format json", &out), 0)
      << out;
  EXPECT_EQ(Json::parse(out)["rank"], 25);
}

TEST_F(CliTest, PaperIsDeterministicForASeed) {
  std::string a, b, c;
  ASSERT_EQ(Run("paper --seed 5 --format json", &a), 0) << a;
  ASSERT_EQ(Run("paper --seed 5 --format json", &b), 0);
  ASSERT_EQ(Run("paper --seed 6 --format json", &c), 0);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  Json j = Json::parse(a);
  ASSERT_EQ(j["cases"].size(), 2u);
  EXPECT_EQ(j["cases"][1]["selected"].size(), 100u);
  EXPECT_EQ(j["cases"][0]["termination"], "converged");
}

struct BadInput {
  std::string name;
  std::string file;      // written to bad.csv
  std::string args;      // {} replaced by the file's path
  std::string expected;  // substring of the message
};
// Short, stable test names in ctest (not the struct's bytes).
void PrintTo(const BadInput& b, std::ostream* os) { *os << b.name; }

class CliErrorTest : public CliTest, public ::testing::WithParamInterface<BadInput> {};

TEST_P(CliErrorTest, ExitsTwoWithAMessageNamingWhere) {
  const BadInput& p = GetParam();
  std::string path = Write("bad.csv", p.file);
  std::string args = p.args;
  for (std::size_t at; (at = args.find("{}")) != std::string::npos;) args.replace(at, 2, path);
  std::string out;
  EXPECT_EQ(Run(args, &out), 2) << out;
  EXPECT_THAT(out, ::testing::HasSubstr(p.expected)) << "message was: " << out;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CliErrorTest,
    ::testing::Values(
        BadInput{"MissingJointColumn", "q1,q2,q3,q4,q5\n0,0,0,0,0\n", "kinematics --configs {}",
                 "bad.csv:1 column 'q6': missing"},
        BadInput{"NonNumericCell", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n0,0,x,0,0,0\n",
                 "kinematics --configs {}", "bad.csv:3 column 'q3': expected a finite number"},
        BadInput{"WrongJointCount", "q1,q2,q3,q4,q5,q6,q7\n0,0,0,0,0,0,0\n",
                 "kinematics --configs {}", "column 'q7': the robot has only 6 joints"},
        BadInput{"RaggedRow", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0\n", "kinematics --configs {}",
                 "bad.csv:2: expected 6 cells"},
        BadInput{"MissingH", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n", "identify --data {}",
                 "column 'h': missing"},
        BadInput{"NegativeH", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,-1\n", "identify --data {}",
                 "bad.csv:2 column 'h'"},
        BadInput{"UnknownParameter", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "identifiability --configs {} --fix theta9", "--fix: unknown parameter 'theta9'"},
        BadInput{"FixedValueNotAParameter", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "identifiability --configs {} --fix d2", "'d2' is fixed on this robot already"},
        BadInput{"ZeroPlaneNormal", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "kinematics --configs {} --plane 0,0,0,1",
                 "--plane: plane normal (nx, ny, nz) is zero"},
        BadInput{"PlaneNotFourNumbers", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "kinematics --configs {} --plane 0,0,1", "expected four numbers"},
        BadInput{"UnknownPlaneTerm", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "identifiability --configs {} --estimate-plane tilt", "unknown plane term 'tilt'"},
        BadInput{"MissingFile", "", "kinematics --configs /nonexistent/c.csv", "cannot open file"},
        BadInput{"UnknownRobot", "", "kinematics --robot nosuchrobot --configs {}",
                 "neither a robot file nor a shipped robot name"},
        BadInput{"UnknownOption", "", "kinematics --colour red", "unrecognised option"},
        BadInput{"UnknownCommand", "", "calibrate", "unknown command 'calibrate'"},
        BadInput{"DesignMoreThanThePool", "", "design --generate 30 --select 40",
                 "cannot select 40 of 30 candidates"},
        BadInput{"DesignFewerThanParameters", "", "design --generate 30 --select 10",
                 "need at least as many configurations as parameters"},
        BadInput{"DesignEmptyPool", "q1,q2,q3,q4,q5,q6\n", "design --pool {} --select 30",
                 "no configurations (only a header)"},
        BadInput{"DesignUnknownCriterion", "", "design --generate 30 --select 26 --criterion F",
                 "unknown criterion 'F'"},
        BadInput{"DesignPoolAndGenerate", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "design --pool {} --generate 5 --select 26", "give exactly one"},
        // Options validated against their range (one Validate() per options struct).
        BadInput{"RankToleranceOne", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "identifiability --configs {} --rank-tolerance 1",
                 "--rank-tolerance: expected a value in [0, 1), got 1"},
        BadInput{"RankToleranceNegative", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "identifiability --configs {} --rank-tolerance -1",
                 "--rank-tolerance: expected a value in [0, 1), got -1"},
        BadInput{"RankToleranceNan", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "identifiability --configs {} --rank-tolerance nan",
                 "--rank-tolerance: expected a value in [0, 1), got nan"},
        BadInput{"SimulateInfiniteSigma", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n",
                 "simulate --configs {} --sigma-mm inf --out /tmp/lrcal_never.csv",
                 "--sigma-mm: expected a finite value >= 0 (mm), got inf"},
        BadInput{"SampleNanSingularValue", "", "sample --min-singular-value nan --out /tmp/x.csv",
                 "--min-singular-value: expected a finite value >= 0, got nan"},
        BadInput{"RunNegativeMaxTrials", "", "run quick --max-trials -5 --out /tmp/lrcal_never",
                 "--max-trials: expected 0 (no limit) or more new trials to compute, got -5"},
        BadInput{"IdentifyUnknownLoss", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,1\n",
                 "identify --data {} --loss tukey",
                 "--loss: unknown loss 'tukey'; expected none, "
                 "huber or cauchy"},
        // Several planes: a plane column is resolved against the planes given, never ignored.
        BadInput{"PlaneColumnNamesAnAbsentPlane",
                 "q1,q2,q3,q4,q5,q6,plane\n0,0,0,0,0,0,1\n0,0,0,0,0,0,3\n",
                 "kinematics --configs {} --plane 0,0,1,0.3 --plane 1,0,0,0.9",
                 "bad.csv:3 column 'plane': '3' is not one of the 2 plane(s) given: expected 1, 2"},
        BadInput{"PlaneColumnAgainstOnePlane", "q1,q2,q3,q4,q5,q6,plane\n0,0,0,0,0,0,2\n",
                 "identifiability --configs {}",
                 "bad.csv:2 column 'plane': '2' is not one of the 1 plane(s) given"},
        BadInput{"NoPlaneColumnWithTwoPlanes", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,1\n",
                 "identify --data {} --plane 0,0,1,0.3 --plane 1,0,0,0.9",
                 "bad.csv:1 column 'plane': missing: 2 planes are given"},
        BadInput{"UnknownPlaneTermName", "q1,q2,q3,q4,q5,q6,plane\n0,0,0,0,0,0,1\n",
                 "identifiability --configs {} --plane 0,0,1,0.3 --plane 1,0,0,0.9 "
                 "--estimate-plane offset --fix plane_f",
                 "--fix: unknown plane term 'plane_f': with 2 plane(s) the names are plane1_u1"},
        BadInput{"IdentifyUnknownSolver", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,1\n",
                 "identify --data {} --solver gn",
                 "--solver: unknown solver 'gn'; expected lm or "
                 "ceres"}),
    [](const ::testing::TestParamInfo<BadInput>& info) { return info.param.name; });

}  // namespace
}  // namespace lrcal
