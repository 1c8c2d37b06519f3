// Studies of a ranger on an arm that bends under gravity and grows with temperature (issue 28):
// environment: and identification.estimate through the runner, against what the model implies —
// compliance and thermal terms recover what a geometric calibration on the ground cannot carry to
// orbit, a calibration that cannot see a term holds it and says so, and studies without the new
// settings keep their cells.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <string>

#include "lrcal/core/error.h"
#include "lrcal/study/study.h"
#include "run_summaries.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;

std::string Header(int trials) {
  return "name: g2o\nseed: 5\ntrials: " + std::to_string(trials) +
         "\nrobot: " + testing::SourcePath("studies/robots/paper_space.yaml") +
         "\nnoise: {sigma_mm: 0.02}\npool: {size: 80}\nselection: {count: 45}\n"
         "validation: {size: 24}\n";
}

// Mean over x, y, z of the RMS position error on orbit (m).
double OrbitRms(const CellSummary& c) { return c.axis_mean[0].mean; }

TEST(EnvironmentStudy, ComplianceAndThermalTermsCarryAGroundCalibrationToOrbit) {
  const std::string dir = testing::TempDir("environment_study");
  std::ofstream(dir + "/s.yaml")
      << Header(20)
      << "identification: {on_rank_deficient: fix}\n"
         "environment:\n  validation: {gravity: [0, 0, 0], temperature_c: [-40, 80]}\n"
         "sweep:\n  combine: product\n  axes:\n"
         "    - key: environment.calibration\n"
         "      values: [{gravity: [0, 0, -9.81], temperature_c: 20},\n"
         "               {gravity: [0, 0, -9.81], temperature_c: [0, 40]}]\n"
         "      labels: [ground, chamber]\n"
         "    - key: identification.estimate\n"
         "      values: [geometric, [geometric, compliance], [geometric, compliance, thermal]]\n"
         "      labels: [geometric, compliance, both]\n";
  ASSERT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  const std::vector<CellSummary> cells = testing::SummarizeRun(dir + "/run");
  ASSERT_EQ(cells.size(), 6u);
  for (const CellSummary& c : cells) EXPECT_EQ(c.ok, 20) << c.cell.label;
  // Product order: ground × (geometric, compliance, both), then the chamber's.
  const double geometric = OrbitRms(cells[0]), compliance = OrbitRms(cells[1]),
               both = OrbitRms(cells[2]), chamber_both = OrbitRms(cells[5]);
  // The arm sags by millimetres on the ground: a geometric model carries it to orbit.
  EXPECT_GT(geometric, 1e-3);
  // Compliance removes the sag; the growth over ±60 K (23 ppm/K: ~1 mm at the reach) stays.
  EXPECT_LT(compliance, 0.5 * geometric);
  EXPECT_GT(compliance, 2e-4);
  // The thermal coefficient (nominal 23.1 ppm/K, truth 23.6) brings it to tens of µm, and
  // estimating it at two temperatures to the noise's level.
  EXPECT_LT(both, 0.1 * compliance);
  EXPECT_LT(chamber_both, both);
  EXPECT_LT(chamber_both, 2e-5);
  // Where the model is incomplete the residuals say so: σ̂ far above the stated σ.
  EXPECT_GT(cells[0].sigma_hat.mean, 100 * 0.02e-3);
  EXPECT_NEAR(cells[5].sigma_hat.mean, 0.02e-3, 0.002e-3);
}

// Where the model is complete (calibrated in a chamber at two temperatures, compliance and the
// thermal coefficient estimated; c1 carries no torque on the ground nor anything on orbit), the
// first-order prediction of the validation error on orbit follows the trials, by Monte Carlo:
// judged at 20 °C (no growth) and at −40 and +80 °C, the trials' mean is the same multiple of
// the prediction, so the thermal coefficient's uncertainty is in it (without it the prediction at
// the extremes falls 8 % further short). The multiple itself (~1.09 here) is the prediction's
// linearisation at the nominal model, as for every cell (prediction_test.cc).
TEST(EnvironmentStudy, TheFirstOrderPredictionFollowsTheTrialsAcrossTemperatures) {
  const std::string dir = testing::TempDir("environment_study_prediction");
  std::ofstream(dir + "/s.yaml")
      << Header(3000)
      << "identification: {on_rank_deficient: fix, estimate: [geometric, compliance, thermal]}\n"
         "environment:\n  calibration: {gravity: [0, 0, -9.81], temperature_c: [0, 40]}\n"
         "sweep:\n  axes:\n    - key: environment.validation\n"
         "      values: [{gravity: [0, 0, 0], temperature_c: 20},\n"
         "               {gravity: [0, 0, 0], temperature_c: [-40, 80]}]\n";
  ASSERT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  const std::vector<CellSummary> cells = testing::SummarizeRun(dir + "/run");
  ASSERT_EQ(cells.size(), 2u);
  std::array<double, 2> ratio{}, ratio_se{};
  for (std::size_t k = 0; k < 2; ++k) {
    const std::vector<double>& p = cells[k].cell.predicted_validation;
    ASSERT_EQ(p.size(), 12u);
    const double predicted = (p[0] + p[1] + p[2]) / 3;
    ratio[k] = OrbitRms(cells[k]) / predicted;
    ratio_se[k] = cells[k].axis_mean[0].mean_se / predicted;
    EXPECT_NEAR(ratio[k], 1.0, 0.15) << cells[k].cell.label;
  }
  EXPECT_NEAR(ratio[1], ratio[0], 0.03 + 3 * std::hypot(ratio_se[0], ratio_se[1]));
}

TEST(EnvironmentStudy, ExactReadingsRecoverComplianceAndTheThermalCoefficient) {
  const std::string dir = testing::TempDir("environment_study_exact");
  std::ofstream(dir + "/s.yaml")
      << "name: exact\nseed: 2\ntrials: 2\nrobot: "
      << testing::SourcePath("studies/robots/paper_space.yaml")
      << "\nnoise: {sigma_mm: 0}\npool: {size: 80}\nselection: {count: 60}\nvalidation: {size: "
         "12}\n"
         "identification: {on_rank_deficient: fix, estimate: [geometric, compliance, thermal]}\n"
         "environment:\n  calibration: {gravity: [0, 0, -9.81], temperature_c: [0, 40]}\n"
         "  validation: {gravity: [0, 0, 0], temperature_c: [-40, 80]}\n";
  ASSERT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  const std::vector<CellSummary> cells = testing::SummarizeRun(dir + "/run");
  ASSERT_EQ(cells.size(), 1u);
  ASSERT_EQ(cells[0].ok, 2);
  // c1 (no torque about a vertical axis) is held; every estimated term's error is rounding.
  bool saw_c2 = false, saw_thermal = false;
  for (const ParameterStats& p : cells[0].parameters) {
    EXPECT_NEAR(p.bias, 0.0, testing::tolerance::kRoundTrip) << p.name;
    saw_c2 |= p.name == "c2";
    saw_thermal |= p.name == "thermal_links";
    EXPECT_NE(p.name, "c1");
  }
  EXPECT_TRUE(saw_c2 && saw_thermal);
  EXPECT_LT(OrbitRms(cells[0]), 1e-9);
}

TEST(EnvironmentStudy, BadSettingsNameTheirKey) {
  const std::string dir = testing::TempDir("environment_study_bad");
  std::ofstream(dir + "/s.yaml") << "name: b\nseed: 1\ntrials: 2\n"
                                    "identification: {estimate: [geometric, elastic]}\n";
  try {
    LoadStudy(dir + "/s.yaml");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("'elastic': expected geometric"));
  }
  std::ofstream(dir + "/s.yaml") << "name: b\nseed: 1\ntrials: 2\nenvironment:\n"
                                    "  calibration: {gravity: [0, 9.81]}\n";
  EXPECT_THROW(LoadStudy(dir + "/s.yaml"), InputError);
  std::ofstream(dir + "/s.yaml") << "name: b\nseed: 1\ntrials: 2\nenvironment:\n"
                                    "  orbit: {gravity: [0, 0, 0]}\n";
  try {
    LoadStudy(dir + "/s.yaml");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("s.yaml:5 key 'environment.orbit'"));
  }
  std::ofstream(dir + "/s.yaml")
      << "name: b\nseed: 1\ntrials: 2\nsensor: {kind: point, instrument: [2, 0, 0.5, 0, 0, 0]}\n"
         "identification: {estimate: [geometric, compliance]}\n";
  try {
    LoadStudy(dir + "/s.yaml");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("sensor.kind: ranger"));
  }
}

}  // namespace
}  // namespace lrcal
