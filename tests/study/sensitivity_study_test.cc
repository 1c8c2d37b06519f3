// A study's sensitivity section: its plan becomes ordinary cells, repeated plan points share a
// cell, the tables give the indices, and the numbers do not depend on the thread count.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/study/sensitivity.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial_store.h"
#include "test_util.h"

namespace lrcal {
namespace {

// outlier_sigma_mm has no effect without outliers: lrcal leaves it out of a cell's identity at
// outlier_fraction 0, so every plan point that differs only in it is the same cell.
const char kStudy[] =
    "name: sens\nseed: 5\ntrials: 20\npool: {size: 60}\nselection: {count: 40}\n"
    "validation: {size: 10}\nsensitivity:\n  method: METHOD\n  samples: 6\n  bootstrap: 200\n"
    "  inputs:\n    - {key: noise.sigma_mm, min: 0.1, max: 0.4}\n"
    "    - {key: noise.outlier_sigma_mm, min: 1, max: 10}\n";

std::string WriteSensitivityStudy(const std::string& dir, const std::string& method) {
  std::string text = kStudy;
  text.replace(text.find("METHOD"), 6, method);
  std::ofstream(dir + "/s.yaml") << text;
  return dir + "/s.yaml";
}

TEST(SensitivityStudy, PlanPointsAreCellsAndAnInputWithoutEffectHasZeroIndices) {
  const std::string dir = testing::TempDir("sensitivity_sobol");
  const Study study = LoadStudy(WriteSensitivityStudy(dir, "sobol"));
  // Saltelli: N(d+2) = 6·4 = 24 points; AB_2 differs from A only in outlier_sigma_mm (the same
  // cells as A), and AB_1 only from B: 12 distinct cells.
  ASSERT_EQ(study.sensitivity["plan_cells"].size(), 24u);
  EXPECT_EQ(study.cells.size(), 12u);
  EXPECT_EQ(study.sensitivity["plan_cells"][12], study.sensitivity["plan_cells"][6]);  // AB_1 = B
  EXPECT_EQ(study.sensitivity["plan_cells"][18], study.sensitivity["plan_cells"][0]);  // AB_2 = A
  ASSERT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  const auto j = nlohmann::json::parse(testing::ReadFile(dir + "/run/tables/summary.json"));
  const auto& s = j["sensitivity"];
  ASSERT_EQ(s["method"], "sobol");
  ASSERT_TRUE(s["available"].get<bool>());
  ASSERT_EQ(s["inputs"].size(), 2u);
  EXPECT_EQ(s["inputs"][1]["first"][0].get<double>(), 0.0);
  EXPECT_EQ(s["inputs"][1]["total"][0].get<double>(), 0.0);
  EXPECT_GT(s["inputs"][0]["total"][0].get<double>(), 0.5);  // σ is the only input that acts
  const std::string csv = testing::ReadFile(dir + "/run/tables/sensitivity.csv");
  EXPECT_EQ(csv.rfind("input,min,max,method,first,first_low,first_high,total", 0), 0u) << csv;
  EXPECT_THAT(testing::ReadFile(dir + "/run/tables/summary.md"),
              ::testing::HasSubstr("## Sensitivity (Sobol"));
  // The same tables with one thread: the plan and its cells are independent of scheduling.
  ASSERT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run1", 1).complete);
  EXPECT_EQ(testing::ReadFile(dir + "/run1/tables/sensitivity.csv"), csv);
}

TEST(SensitivityStudy, MorrisScreensTheInputs) {
  const std::string dir = testing::TempDir("sensitivity_morris");
  const Study study = LoadStudy(WriteSensitivityStudy(dir, "morris"));
  EXPECT_EQ(study.sensitivity["plan_cells"].size(), 6u * 3);  // r(d+1)
  ASSERT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  const auto j = nlohmann::json::parse(testing::ReadFile(dir + "/run/tables/summary.json"));
  const auto& in = j["sensitivity"]["inputs"];
  EXPECT_GT(in[0]["mu_star"].get<double>(), 0.01);  // mm across σ's range
  EXPECT_EQ(in[1]["mu_star"].get<double>(), 0.0);
  EXPECT_EQ(in[1]["sigma"].get<double>(), 0.0);
  // sensitivity_plan.csv: one row per plan point, its inputs as the cell's settings and the
  // quantity of interest as the cell's validation means (summary.json, m) averaged over x, y, z.
  std::map<std::string, double> cell_mean;
  for (const auto& c : j["cells"]) {
    double sum = 0;
    for (const char* a : {"x", "y", "z"})
      sum += c["validation"][std::string("rms_pos_") + a]["mean"].get<double>();
    cell_mean[c["id"]] = sum / 3 * 1e3;
  }
  std::istringstream plan(testing::ReadFile(dir + "/run/tables/sensitivity_plan.csv"));
  std::string line;
  std::getline(plan, line);
  EXPECT_EQ(line,
            "point,cell_id,noise.sigma_mm,noise.outlier_sigma_mm,rms_pos_mean_mm,rms_pos_se_mm,ok");
  int points = 0;
  for (; std::getline(plan, line); ++points) {
    std::vector<std::string> f;
    std::stringstream in_line(line);
    for (std::string c; std::getline(in_line, c, ',');) f.push_back(c);
    ASSERT_EQ(f.size(), 7U) << line;
    EXPECT_EQ(f[0], std::to_string(points));
    EXPECT_EQ(f[1], study.sensitivity["plan_cells"][points].get<std::string>());
    const double sigma = std::stod(f[2]);
    EXPECT_GE(sigma, 0.1);
    EXPECT_LE(sigma, 0.4);
    EXPECT_NEAR(std::stod(f[4]), cell_mean.at(f[1]), 5e-7) << line;  // 6 decimals in the CSV
    EXPECT_EQ(f[6], "20");
  }
  EXPECT_EQ(points, 18);
}

TEST(SensitivityStudy, NormalInputsFollowTheirLaw) {
  const std::string dir = testing::TempDir("sensitivity_normal");
  std::ofstream(dir + "/n.yaml")
      << "name: n\nseed: 2\ntrials: 5\nsensitivity:\n  samples: 400\n"
         "  inputs: [{key: truth.ranger_scale_ppm, mean: 100, std: 20}]\n";
  const Study study = LoadStudy(dir + "/n.yaml");
  // A and B: 800 independent draws (AB_1 repeats B's cells).
  ASSERT_EQ(study.cells.size(), 800u);
  double sum = 0, sum2 = 0;
  for (const Cell& c : study.cells) {
    const double v = c.settings["truth"]["ranger_scale_ppm"].get<double>();
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / 800, std = std::sqrt(sum2 / 800 - mean * mean);
  EXPECT_NEAR(mean, 100, 4 * 20 / std::sqrt(800.0));
  EXPECT_NEAR(std, 20, 4 * 20 / std::sqrt(1600.0));
}

// The plane's tilt is an uncertain input when the study gives its plane by tilt and azimuth:
// each plan point's cell has its own plane (the other plane keys kept), and the tilt acts.
TEST(SensitivityStudy, ThePlaneTiltIsAnInput) {
  const std::string dir = testing::TempDir("sensitivity_tilt");
  std::ofstream(dir + "/t.yaml")
      << "name: t\nseed: 3\ntrials: 20\npool: {size: 60}\nselection: {count: 40}\n"
         "validation: {size: 10}\n"
         "plane: {tilt_deg: 12, azimuth_deg: 90, through: [0, 0, 0.15]}\n"
         "sensitivity:\n  samples: 6\n  bootstrap: 100\n"
         "  inputs: [{key: plane.tilt_deg, min: 5, max: 40}, {key: noise.sigma_mm, min: 0.1, "
         "max: 0.11}]\n";
  const Study study = LoadStudy(dir + "/t.yaml");
  ASSERT_EQ(study.cells.size(), 24u);  // N(d+2), all distinct
  double lo = 180, hi = 0;
  for (const Cell& c : study.cells) {
    const auto& plane = c.settings["plane"];
    EXPECT_EQ(plane["azimuth_deg"], 90);
    EXPECT_EQ(plane["through"], nlohmann::json::parse("[0, 0, 0.15]"));
    lo = std::min(lo, plane["tilt_deg"].get<double>());
    hi = std::max(hi, plane["tilt_deg"].get<double>());
  }
  EXPECT_GE(lo, 5);
  EXPECT_LE(hi, 40);
  EXPECT_GT(hi - lo, 15);  // 12 draws spread over the range
  ASSERT_TRUE(testing::RunStudyFile(dir + "/t.yaml", dir + "/run", 2).complete);
  const auto j = nlohmann::json::parse(testing::ReadFile(dir + "/run/tables/summary.json"));
  const auto& in = j["sensitivity"]["inputs"];
  ASSERT_EQ(in[0]["key"], "plane.tilt_deg");
  // The tilt changes the design's conditioning several-fold across 5–40°; σ barely moves.
  EXPECT_GT(in[0]["total"][0].get<double>(), in[1]["total"][0].get<double>());
}

// quantity: trial. The variance of a single calibration's figure, Var Y = Var f + E[Var(Y|x)],
// must be that of every plan point's trials pooled (law of total variance, read back from the
// store), the noise's total index E[Var(Y|x)] / Var Y, and the inputs' indices those of the cell
// means times Var(cell means) / Var Y.
TEST(SensitivityStudy, ASingleTrialsFigureHasTheNoiseAsAnInput) {
  const std::string dir = testing::TempDir("sensitivity_trial");
  const std::string body =
      "seed: 4\ntrials: 60\npool: {size: 60}\nselection: {count: 40}\nvalidation: {size: 10}\n"
      "sensitivity:\n  samples: 16\n  bootstrap: 200\n  metric: max_pos\n"
      "  inputs: [{key: noise.sigma_mm, min: 0.1, max: 0.4}, {key: noise.encoder_sigma_mrad, "
      "min: 0, max: 0.05}]\n";
  std::ofstream(dir + "/t.yaml") << "name: t\n" << body << "  quantity: trial\n";
  std::ofstream(dir + "/m.yaml") << "name: m\n" << body;
  ASSERT_TRUE(testing::RunStudyFile(dir + "/t.yaml", dir + "/t", 2).complete);
  ASSERT_TRUE(testing::RunStudyFile(dir + "/m.yaml", dir + "/m", 2).complete);
  const auto t = nlohmann::json::parse(testing::ReadFile(dir + "/t/tables/summary.json"));
  const auto m = nlohmann::json::parse(testing::ReadFile(dir + "/m/tables/summary.json"));
  const auto& st = t["sensitivity"];
  ASSERT_TRUE(st["available"].get<bool>());
  EXPECT_EQ(st["quantity"], "trial");
  EXPECT_FALSE(m["sensitivity"].contains("quantity"));
  const double var_y = st["trial_variance"], variance = st["variance"];
  EXPECT_EQ(variance, m["sensitivity"]["variance"].get<double>());  // the same cells
  // Every plan point's trials, pooled (each point weighs its own cell's trials).
  const Study study = LoadStudy(dir + "/t.yaml");
  TrialStore store(dir + "/t/trials.sqlite");
  std::vector<double> pooled;
  double within = 0, noise = 0;
  const auto& plan = study.sensitivity["plan_cells"];
  for (const auto& id : plan) {
    std::vector<double> y;
    store.ForEachTrial(id.get<std::string>(), [&](const TrialRecord& r) {
      if (r.status == TrialStatus::kOk)
        y.push_back((r.validation[6] + r.validation[7] + r.validation[8]) / 3 * 1e3);  // max_pos
    });
    const Distribution d = Describe(y);
    within += d.std * d.std / static_cast<double>(plan.size());
    noise += d.std * d.std / static_cast<double>(d.n) / static_cast<double>(plan.size());
    pooled.insert(pooled.end(), y.begin(), y.end());
  }
  const double pooled_var = std::pow(Describe(pooled).std, 2);
  EXPECT_NEAR(var_y, pooled_var, 0.03 * pooled_var);  // equal up to the cells' finite trials
  EXPECT_NEAR(st["noise_total"].get<double>(), within / var_y, 1e-9);
  // The cell means' Monte-Carlo noise: the variance of each plan point's mean over its trials of
  // the axis-averaged metric (the axes of a trial are correlated: their SEs do not add).
  EXPECT_NEAR(m["sensitivity"]["noise_variance"].get<double>(), noise, 1e-9 * noise);
  EXPECT_GT(st["noise_total"].get<double>(), 0.3);  // a single max error is mostly noise
  for (int i = 0; i < 2; ++i)
    for (const char* kind : {"first", "total"})
      for (int e = 0; e < 3; ++e)
        EXPECT_NEAR(st["inputs"][i][kind][e].get<double>(),
                    m["sensitivity"]["inputs"][i][kind][e].get<double>() * variance / var_y, 1e-12)
            << i << " " << kind << " " << e;
  const std::string csv = testing::ReadFile(dir + "/t/tables/sensitivity.csv");
  EXPECT_THAT(csv, ::testing::HasSubstr("\nnoise (one trial),,,sobol,,,,")) << csv;
}

// A normal input has no min and max: its table row states its law and the CSV leaves them empty
// (writing the tables used to fail on such a study).
TEST(SensitivityStudy, NormalInputsReachTheTables) {
  const std::string dir = testing::TempDir("sensitivity_normal_tables");
  std::ofstream(dir + "/n.yaml")
      << "name: n\nseed: 3\ntrials: 5\npool: {size: 60}\nselection: {count: 40}\n"
         "validation: {size: 10}\nsensitivity:\n  samples: 4\n  bootstrap: 50\n"
         "  inputs: [{key: noise.sigma_mm, mean: 0.2, std: 0.05}, {key: "
         "noise.encoder_sigma_mrad, min: 0, max: 0.1}]\n";
  ASSERT_TRUE(testing::RunStudyFile(dir + "/n.yaml", dir + "/run", 2).complete);
  const std::string csv = testing::ReadFile(dir + "/run/tables/sensitivity.csv");
  EXPECT_THAT(csv, ::testing::HasSubstr("\nnoise.sigma_mm,,,sobol,")) << csv;
  EXPECT_THAT(csv, ::testing::HasSubstr("\nnoise.encoder_sigma_mrad,0.000000,0.100000,sobol,"))
      << csv;
  EXPECT_THAT(testing::ReadFile(dir + "/run/tables/summary.md"),
              ::testing::HasSubstr("| noise.sigma_mm | normal, mean 0.2000, std 0.0500 |"));
}

TEST(SensitivityStudy, BadSectionsNameTheKey) {
  const std::string dir = testing::TempDir("sensitivity_bad");
  const auto expect_error = [&](const std::string& body, const std::string& expected) {
    std::ofstream(dir + "/b.yaml") << "name: b\nseed: 1\ntrials: 5\n" << body;
    try {
      LoadStudy(dir + "/b.yaml");
      ADD_FAILURE() << "no error for " << body;
    } catch (const InputError& e) {
      EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr(expected)) << e.what();
    }
  };
  const std::string input = "  inputs: [{key: noise.sigma_mm, min: 0.1, max: 0.3}]\n";
  expect_error("sensitivity:\n  method: fast\n" + input, "key 'sensitivity.method'");
  expect_error("sensitivity:\n  method: morris\n  levels: 5\n" + input,
               "key 'sensitivity.levels': expected an even number");
  expect_error("sensitivity:\n  inputs: [{key: selection.method, min: 0, max: 1}]\n",
               "'selection.method' is not a numeric study setting");
  expect_error("sensitivity:\n  inputs: [{key: noise.sigma_mm, min: 0.3, max: 0.1}]\n",
               "expected min < max");
  expect_error("sensitivity:\n  metric: bias\n" + input, "key 'sensitivity.metric'");
  expect_error("sweep: {axes: [{key: noise.sigma_mm, values: [0.1]}]}\nsensitivity:\n" + input,
               "either a sweep or a sensitivity analysis");
  expect_error("sensitivity:\n  samples: 100000\n" + input, "at most 100000 cells");
  expect_error(
      "sensitivity:\n  method: morris\n  inputs: [{key: noise.sigma_mm, mean: 0.2, std: "
      "0.01}]\n",
      "a normal input needs method sobol");
  expect_error("sensitivity:\n  inputs: [{key: noise.sigma_mm, mean: 0.2, std: 0}]\n",
               "expected std > 0");
  expect_error("sensitivity:\n  inputs: [{key: noise.sigma_mm, min: 0.1, mean: 0.2, std: 1}]\n",
               "not both");
  expect_error("sensitivity:\n  quantity: single\n" + input, "key 'sensitivity.quantity'");
  expect_error("sensitivity:\n  method: morris\n  quantity: trial\n" + input,
               "quantity trial needs method sobol");
  expect_error("sensitivity:\n  inputs: [{key: plane.tilt_deg, min: 1, max: 20}]\n",
               "'plane.tilt_deg' needs the study's plane given as one mapping {tilt_deg, "
               "azimuth_deg, through}");
  expect_error(
      "plane: {normal: [0, 0, 1], offset: 0.2}\n"
      "sensitivity:\n  inputs: [{key: plane.tilt_deg, min: 1, max: 20}]\n",
      "'plane.tilt_deg' needs the study's plane given as one mapping");
  expect_error("sensitivity:\n  inputs: [{key: plane.through, min: 1, max: 20}]\n",
               "'plane.through' is not a numeric plane setting");
  expect_error(
      "plane: {tilt_deg: 10, azimuth_deg: 90, through: [0, 0, 0.15]}\n"
      "sensitivity:\n  inputs: [{key: plane.tilt_deg, mean: 1, std: 20}]\n",
      "expected an angle in [0, 180] degrees");
}

}  // namespace
}  // namespace lrcal
