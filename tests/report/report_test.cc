// lrcal report end to end: the analysis scripts on the output of studies/quick.yaml, the page in
// headless Chromium (no console errors, every figure decoded, a screenshot written), a partial
// run said so, and clear errors for missing or malformed run directories.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "test_util.h"

namespace lrcal {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::LrcalBinary;
using testing::RunCommand;

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Debian's chromium, started as the probe of this machine does (no sandbox as root, no GPU, no
// background networking on a closed network).
std::string Chromium(const std::string& profile) {
  return "chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --no-first-run "
         "--disable-background-networking --disable-component-update --disable-sync "
         "--user-data-dir=" +
         profile + " ";
}

TEST(Report, QuickStudyReportRendersInHeadlessChromium) {
  const std::string dir = testing::TempDir("report_quick");
  const std::string run = dir + "/run";
  std::string out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " run " + testing::SourcePath("studies/quick.yaml") +
                           " --out " + run + " --quiet",
                       &out),
            0)
      << out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " report " + run, &out), 0) << out;
  const fs::path report = fs::path(run) / "report";
  ASSERT_TRUE(fs::exists(report / "report.html")) << out;
  const Json figures = Json::parse(Read(report / "figures.json"));
  const std::vector<std::string> names = figures["figures"];
  // One-realisation (2), distributions, sensitivity, and per cell histograms, parameters and
  // correlation (2 × 3).
  EXPECT_EQ(names.size(), 10u) << figures.dump();
  // The snapshot of the store is gone once the figures are drawn.
  EXPECT_FALSE(fs::exists(report / "trials.snapshot.sqlite"));
  const std::string captions = figures["captions"].dump();
  EXPECT_THAT(captions, ::testing::HasSubstr("Red diamonds"));  // paper cells: paper values
  EXPECT_THAT(captions,
              ::testing::HasSubstr("the swept settings (case 1, case 2), drawn as categories"))
      << captions;
  EXPECT_THAT(captions,
              ::testing::Not(::testing::HasSubstr("Only the first")));  // every cell is drawn
  for (const auto& png : names) {
    EXPECT_GT(fs::file_size(report / "figures" / png), 10000u) << png;
    EXPECT_TRUE(fs::exists(report / "figures" / (png.substr(0, png.size() - 4) + ".svg"))) << png;
  }
  const std::string html = Read(report / "report.html");
  EXPECT_THAT(html, ::testing::Not(::testing::HasSubstr("Partial run")));
  EXPECT_THAT(html, ::testing::HasSubstr("The paper"));  // the placement table is in

  if (RunCommand("command -v chromium", &out) != 0) GTEST_SKIP() << "chromium is not installed";
  const std::string profile = dir + "/chromium-profile";
  // Load the page; the page's own script puts "k/n figures" decoded into the title.
  ASSERT_EQ(RunCommand(Chromium(profile) +
                           "--enable-logging=stderr --v=0 --virtual-time-budget=10000 "
                           "--dump-dom file://" +
                           (report / "report.html").string() + " 2>" + dir + "/console.log",
                       &out),
            0);
  const std::string title = "lrcal report: " + std::to_string(names.size()) + "/" +
                            std::to_string(names.size()) + " figures";
  EXPECT_THAT(out, ::testing::HasSubstr("<title>" + title + "</title>"))
      << "expected the title '" << title << "'";
  const std::string console = Read(dir + "/console.log");
  EXPECT_THAT(console, ::testing::Not(::testing::HasSubstr("CONSOLE"))) << "console messages:\n"
                                                                        << console;
  // A screenshot into the run directory.
  const fs::path shot = report / "screenshot.png";
  ASSERT_EQ(RunCommand(Chromium(profile) + "--window-size=1280,2400 --screenshot=" + shot.string() +
                           " file://" + (report / "report.html").string() + " 2>/dev/null",
                       &out),
            0);
  EXPECT_GT(fs::file_size(shot), 20000u);
}

TEST(Report, FiguresSayWhatTheyLeaveOutAndMarkPaperValuesOnlyWhereThereAreAny) {
  const std::string dir = testing::TempDir("report_sweep");
  const std::string study = dir + "/sweep.yaml";
  std::ofstream(study) << "name: sweep\nseed: 3\ntrials: 30\nrobot: "
                       << testing::SourcePath("studies/robots/paper.yaml")
                       << "\npool: {size: 60}\nvalidation: {size: 10}\n"
                          "sweep:\n  axes:\n    - key: noise.repetitions\n"
                          "      values: [1, 2, 3, 4, 5]\n";
  std::string out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " run " + study + " --out " + dir + "/run --quiet", &out), 0)
      << out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " report " + dir + "/run", &out), 0) << out;
  const Json figures = Json::parse(Read(fs::path(dir) / "run/report/figures.json"));
  const std::string captions = figures["captions"].dump();
  EXPECT_THAT(captions, ::testing::Not(::testing::HasSubstr("Red diamonds"))) << captions;
  EXPECT_THAT(captions, ::testing::HasSubstr("Only the first 4 of the 5 cells")) << captions;
  EXPECT_THAT(captions, ::testing::HasSubstr("Validation accuracy against noise.repetitions."))
      << captions;
}

// A study with a sensitivity section: the report draws its indices with their intervals, and
// for a single trial's figure (quantity: trial) the noise's share beside them.
TEST(Report, SensitivityStudyDrawsItsIndices) {
  for (const std::string quantity : {"cell_mean", "trial"}) {
    const std::string dir = testing::TempDir("report_sensitivity_" + quantity);
    const std::string study = dir + "/sens.yaml";
    std::ofstream(study) << "name: sens\nseed: 3\ntrials: 10\npool: {size: 60}\nselection: "
                            "{count: 40}\nvalidation: {size: 10}\nsensitivity:\n  samples: 4\n"
                            "  bootstrap: 100\n  quantity: "
                         << quantity
                         << "\n  inputs:\n    - {key: noise.sigma_mm, min: 0.1, "
                            "max: 0.4}\n    - {key: noise.form_sigma_mm, min: 0, max: 0.1}\n";
    std::string out;
    ASSERT_EQ(RunCommand(LrcalBinary() + " run " + study + " --out " + dir + "/run --quiet", &out),
              0)
        << out;
    ASSERT_EQ(RunCommand(LrcalBinary() + " report " + dir + "/run", &out), 0) << out;
    const Json figures = Json::parse(Read(fs::path(dir) / "run/report/figures.json"));
    const std::vector<std::string> names = figures["figures"];
    EXPECT_NE(std::find(names.begin(), names.end(), "global_sensitivity.png"), names.end())
        << figures.dump();
    EXPECT_THAT(
        figures["captions"].dump(),
        ::testing::HasSubstr(quantity == "trial" ? "Sobol indices of a single calibration's rms_pos"
                                                 : "Sobol indices of the cell mean of rms_pos"))
        << quantity;
    EXPECT_GT(fs::file_size(fs::path(dir) / "run/report/figures/global_sensitivity.png"), 10000u);
  }
}

TEST(Report, PartialRunIsReportedAsPartial) {
  const std::string dir = testing::TempDir("report_partial");
  const std::string run = dir + "/run";
  std::string out;
  RunCommand(LrcalBinary() + " run " + testing::SourcePath("studies/quick.yaml") + " --out " + run +
                 " --quiet --max-trials 60",
             &out);
  ASSERT_EQ(RunCommand(LrcalBinary() + " report " + run, &out), 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("PARTIAL")) << out;
  const Json status = Json::parse(Read(fs::path(run) / "report" / "status.json"));
  EXPECT_FALSE(status["complete"].get<bool>());
  EXPECT_EQ(status["done"], 60);
  EXPECT_THAT(Read(fs::path(run) / "report" / "report.html"), ::testing::HasSubstr("Partial run"));
}

TEST(Report, MissingOrMalformedRunDirectoriesAreClearErrors) {
  const std::string dir = testing::TempDir("report_bad");
  std::string out;
  EXPECT_EQ(RunCommand(LrcalBinary() + " report " + dir + "/nothing", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("no such run directory")) << out;
  fs::create_directories(dir + "/empty");
  EXPECT_EQ(RunCommand(LrcalBinary() + " report " + dir + "/empty", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("manifest.json is missing")) << out;
  fs::create_directories(dir + "/broken");
  std::ofstream(dir + "/broken/manifest.json") << "{ not json";
  EXPECT_EQ(RunCommand(LrcalBinary() + " report " + dir + "/broken", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("broken/manifest.json: not valid JSON")) << out;
  // The page module alone, on a directory lrcal report has not prepared, and with bad usage.
  std::ofstream(dir + "/empty/manifest.json") << "{}";
  const std::string module =
      "PYTHONPATH=" + std::string(LRCAL_BINARY_DIR) + "/python /usr/bin/python3 -m lrcal.report ";
  EXPECT_EQ(RunCommand(module + dir + "/empty", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("summary.json: missing")) << out;
  EXPECT_EQ(RunCommand(module + "--calibration " + dir + "/empty", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("empty/calibration.json: expected the JSON")) << out;
  EXPECT_EQ(RunCommand(module + dir + "/empty " + dir + "/nothing", &out), 2);
  EXPECT_THAT(out, ::testing::HasSubstr("expected one folder")) << out;
  // An interpreter that cannot be started: exit 2 naming it, and the snapshot removed.
  ASSERT_EQ(RunCommand(LrcalBinary() + " run quick --out " + dir + "/run --quiet", &out), 0) << out;
  EXPECT_EQ(
      RunCommand("LRCAL_PYTHON=/nonexistent/python3 " + LrcalBinary() + " report " + dir + "/run",
                 &out),
      2);
  EXPECT_THAT(out, ::testing::HasSubstr("LRCAL_PYTHON: cannot run the Python interpreter "
                                        "'/nonexistent/python3': No such file or directory"))
      << out;
  EXPECT_FALSE(fs::exists(dir + "/run/report/trials.snapshot.sqlite"));
}

// identify --report DIR (issue 13 item 9): from a measured CSV to a page with the fit check,
// parameters, identifiability, cross-validation and the accuracy map, its five figures decoded
// in headless Chromium, the calibrated robot file beside it usable by `lrcal accuracy`, and the
// same numbers in calibration.json as identify's own JSON.
TEST(Report, CalibrationReportRendersInHeadlessChromium) {
  const std::string dir = testing::TempDir("report_calibration");
  std::string out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " sample --count 60 --seed 3 --out " + dir + "/c.csv", &out),
            0)
      << out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " simulate --configs " + dir +
                           "/c.csv --sigma-mm 0.2 --repetitions 3 --seed 9 --out " + dir + "/m.csv",
                       &out),
            0)
      << out;
  const std::string identify =
      LrcalBinary() + " identify --data " + dir + "/m.csv --sigma-mm 0.2 --holdout 4";
  ASSERT_EQ(RunCommand(identify + " --report " + dir + "/cal", &out), 0) << out;
  const fs::path cal = fs::path(dir) / "cal";
  for (const char* f :
       {"report.html", "calibration.json", "calibrated.yaml", "calibrated.urdf", "figures.json"})
    EXPECT_TRUE(fs::exists(cal / f)) << f;
  const Json figures = Json::parse(Read(cal / "figures.json"));
  const std::vector<std::string> names = figures["figures"];
  EXPECT_EQ(names, (std::vector<std::string>{"residuals.png", "parameters.png", "correlation.png",
                                             "holdout.png", "accuracy.png"}));
  const Json j = Json::parse(Read(cal / "calibration.json"));
  EXPECT_EQ(j["holdout"]["folds"], 4);
  EXPECT_EQ(j["workspace_accuracy"]["poses"].size(), 500u);
  EXPECT_EQ(j["identifiability"]["rank"], 25);
  ASSERT_EQ(RunCommand(identify + " --format json", &out), 0) << out;
  const Json plain = Json::parse(out);
  EXPECT_EQ(plain["parameters"], j["parameters"]);
  EXPECT_EQ(plain["holdout"], j["holdout"]);
  const std::string html = Read(cal / "report.html");
  for (const char* section :
       {"Fit check", "Before and after", "nominal (before)", "calibrated (after)", "Parameters",
        "Identifiability", "Cross-validation", "Accuracy over the workspace", "Calibrated files",
        "consistent with the stated noise", "calibrated.urdf"})
    EXPECT_THAT(html, ::testing::HasSubstr(section)) << section;
  // Issue 31: nominal D-H angles in degrees, not "3141.5927 mrad".
  EXPECT_THAT(html, ::testing::HasSubstr("<td>theta5</td><td>180.000000°</td>"));
  EXPECT_THAT(html, ::testing::Not(::testing::HasSubstr("3141.5927")));
  EXPECT_EQ(RunCommand(LrcalBinary() + " accuracy --robot " + (cal / "calibrated.yaml").string() +
                           " --workspace 0",
                       &out),
            2);
  EXPECT_THAT(out, ::testing::HasSubstr("--workspace: expected 1 to 100,000 poses, got 0")) << out;
  // The map's poses, predicted again from the written file: the same accuracy.
  {
    std::ofstream poses(dir + "/poses.csv");
    poses.precision(17);
    poses << "q1,q2,q3,q4,q5,q6\n";
    for (const auto& pose : j["workspace_accuracy"]["poses"]) {
      for (int k = 0; k < 6; ++k) poses << (k ? "," : "") << pose["q"][k].get<double>();
      poses << "\n";
    }
  }
  ASSERT_EQ(RunCommand(LrcalBinary() + " accuracy --robot " + (cal / "calibrated.yaml").string() +
                           " --configs " + dir + "/poses.csv --format json",
                       &out),
            0)
      << out;
  EXPECT_NEAR(Json::parse(out)["rms_position"].get<double>(),
              j["workspace_accuracy"]["rms_position"].get<double>(),
              1e-9 * j["workspace_accuracy"]["rms_position"].get<double>());
  // Issue 31: `lrcal accuracy --workspace 500` on the written file is the report's map, bit for
  // bit (it drew its poses over the nominal arm and disagreed in the 4th digit).
  ASSERT_EQ(RunCommand(LrcalBinary() + " accuracy --robot " + (cal / "calibrated.yaml").string() +
                           " --workspace 500 --format json",
                       &out),
            0)
      << out;
  const Json workspace = Json::parse(out);
  for (const char* key : {"rms_position", "rms_position_total", "p95_position_radius_95_total",
                          "worst", "sources", "poses"})
    EXPECT_EQ(workspace[key], j["workspace_accuracy"][key]) << key;

  if (RunCommand("command -v chromium", &out) != 0) GTEST_SKIP() << "chromium is not installed";
  ASSERT_EQ(RunCommand(Chromium(dir + "/chromium-profile") +
                           "--enable-logging=stderr --v=0 --virtual-time-budget=10000 "
                           "--dump-dom file://" +
                           (cal / "report.html").string() + " 2>" + dir + "/console.log",
                       &out),
            0);
  EXPECT_THAT(out, ::testing::HasSubstr("<title>lrcal report: 5/5 figures</title>"));
  const std::string console = Read(dir + "/console.log");
  EXPECT_THAT(console, ::testing::Not(::testing::HasSubstr("CONSOLE"))) << "console messages:\n"
                                                                        << console;
}

// A report folder that cannot be created is a clear error (exit 2), after nothing was lost.
TEST(Report, CalibrationReportIntoAFileIsAClearError) {
  const std::string dir = testing::TempDir("report_calibration_bad");
  std::string out;
  ASSERT_EQ(RunCommand(LrcalBinary() + " sample --count 40 --seed 3 --out " + dir + "/c.csv", &out),
            0);
  ASSERT_EQ(RunCommand(LrcalBinary() + " simulate --configs " + dir +
                           "/c.csv --sigma-mm 0.2 --seed 9 --out " + dir + "/m.csv",
                       &out),
            0);
  std::ofstream(dir + "/afile") << "x";
  EXPECT_EQ(RunCommand(
                LrcalBinary() + " identify --data " + dir + "/m.csv --report " + dir + "/afile/cal",
                &out),
            2);
  EXPECT_THAT(out, ::testing::HasSubstr("--report: cannot create the folder")) << out;
}

}  // namespace
}  // namespace lrcal
