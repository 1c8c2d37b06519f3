// What a study's identification is told beyond the readings (study.h: identification.prior_sigma
// and identification.errors_in_variables): the trials then solve as `lrcal identify --prior-sigma`
// and `--encoder-sigma-mrad` do, and the cell's prediction is the covariance those state. Checked
// by Monte Carlo: the spread of the trials' parameter errors is what the prediction says.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <string>

#include "lrcal/core/error.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial_store.h"
#include "run_summaries.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// Each cell's parameter statistics, in study order, after running `body` for `trials` trials.
std::vector<CellSummary> RunCells(const std::string& dir, const std::string& body, int trials,
                                  int count = 40) {
  std::ofstream(dir + "/s.yaml") << "name: modelled\nseed: 5\ntrials: " << trials
                                 << "\npool: {size: 80}\nselection: {count: " << count
                                 << "}\nvalidation: {size: 10}\n"
                                 << body;
  EXPECT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  return testing::SummarizeRun(dir + "/run");
}

// The mean over parameters of the empirical std's ratio to the predicted std, and its standard
// error (the parameters' ratios are correlated: the mean of their SEs bounds it).
std::pair<double, double> MeanRatio(const CellSummary& s) {
  double ratio = 0, se = 0;
  for (const ParameterStats& p : s.parameters) {
    ratio += p.ratio / static_cast<double>(s.parameters.size());
    se += p.ratio_se / static_cast<double>(s.parameters.size());
  }
  return {ratio, se};
}

// Encoder noise of 0.2 mrad on every reading (one reading per configuration) against readings of
// 0.05 mm: least squares' prediction (readings only) misses most of the spread; with errors in
// variables the prediction is the spread, parameter by parameter.
TEST(ModelledUncertainty, ErrorsInVariablesPredictTheSpreadUnderEncoderNoise) {
  const std::string dir = testing::TempDir("modelled_eiv");
  const std::vector<CellSummary> cells =
      RunCells(dir,
               "noise: {sigma_mm: 0.05, repetitions: 1, encoder_sigma_mrad: 0.2}\n"
               "sweep:\n  axes:\n"
               "    - {key: identification.errors_in_variables, values: [false, true]}\n",
               300);
  ASSERT_EQ(cells.size(), 2u);
  ASSERT_EQ(cells[1].ok, 300);
  const auto [plain, plain_se] = MeanRatio(cells[0]);
  const auto [eiv, eiv_se] = MeanRatio(cells[1]);
  EXPECT_GT(plain - 4 * plain_se, 1.5) << "least squares: empirical/predicted std " << plain;
  EXPECT_NEAR(eiv, 1.0, 4 * eiv_se + 0.03) << "errors in variables: empirical/predicted " << eiv;
  // Each parameter within 4 standard errors of its prediction, and a linearisation margin.
  for (const ParameterStats& p : cells[1].parameters)
    EXPECT_NEAR(p.ratio, 1.0, 4 * p.ratio_se + 0.03) << p.name;
  // σ̂ of the weighted residuals estimates one reading's σ (0.05 mm) with errors in variables;
  // least squares' residuals carry the encoder noise too.
  EXPECT_NEAR(cells[1].sigma_hat.mean / 0.05e-3, 1.0, 0.05);
  EXPECT_GT(cells[0].sigma_hat.mean / 0.05e-3, 2.0);
  std::cout << "sigma_hat/sigma: least squares " << cells[0].sigma_hat.mean / 0.05e-3
            << ", errors in variables " << cells[1].sigma_hat.mean / 0.05e-3 << "\n";
  std::cout << "empirical/predicted std: least squares " << plain << " ± " << plain_se
            << ", errors in variables " << eiv << " ± " << eiv_se << "\n";
}

// A truth drawn per trial from N(0, 1 mrad²) and N(0, 1 mm²) and the priors of that truth
// (identification.prior_sigma: truth): the maximum a-posteriori estimate's error is distributed
// as its posterior covariance says (Bayes, linear to first order), on a design of as many
// configurations as parameters, where least squares is at its weakest.
TEST(ModelledUncertainty, PriorsFromTheTruthPredictTheSpreadOfARandomTruth) {
  const std::string dir = testing::TempDir("modelled_priors");
  const std::vector<CellSummary> cells =
      RunCells(dir,
               "truth: {mode: random, angle_sigma_mrad: 1, length_sigma_mm: 1}\n"
               "noise: {sigma_mm: 0.1}\n"
               "sweep:\n  axes:\n"
               "    - {key: identification.prior_sigma, values: [none, truth]}\n",
               300, 25);
  ASSERT_EQ(cells.size(), 2u);
  ASSERT_EQ(cells[1].ok, 300);
  const auto [map, map_se] = MeanRatio(cells[1]);
  EXPECT_NEAR(map, 1.0, 4 * map_se + 0.03) << "posterior std against the MAP errors' spread";
  std::cout << "empirical/posterior std " << map << " ± " << map_se << "; least squares "
            << MeanRatio(cells[0]).first << "\n";
  for (const ParameterStats& p : cells[1].parameters)
    EXPECT_NEAR(p.ratio, 1.0, 4 * p.ratio_se + 0.03) << p.name;
  // The priors never widen a parameter's spread: each is at most least squares' (a margin of 4
  // standard errors of the two empirical stds).
  ASSERT_EQ(cells[0].parameters.size(), cells[1].parameters.size());
  for (std::size_t k = 0; k < cells[1].parameters.size(); ++k) {
    const ParameterStats &ls = cells[0].parameters[k], &map_k = cells[1].parameters[k];
    EXPECT_LT(map_k.predicted_std, ls.predicted_std) << map_k.name;
    EXPECT_LT(map_k.std, ls.std + 4 * std::hypot(ls.std_se, map_k.std_se)) << map_k.name;
  }
}

// A plane whose offset and tilt are estimated with the robot's every parameter: least squares
// cannot tell the plane's offset from the base's, and a cell that says on_rank_deficient: fail
// fails every trial; priors on the plane's terms set that direction and the trials identify.
TEST(ModelledUncertainty, PriorsLetARankDeficientCellIdentify) {
  const std::string dir = testing::TempDir("modelled_rank");
  const std::vector<CellSummary> cells =
      RunCells(dir,
               "noise: {sigma_mm: 0.05}\n"
               "identification: {estimate_plane: 'normal,offset'}\n"
               "sweep:\n  axes:\n"
               "    - {key: identification.prior_sigma, values: [none, "
               "'truth,plane_f=1mm,plane_u=1mrad']}\n",
               20);
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_EQ(cells[0].ok, 0);
  EXPECT_EQ(cells[1].ok, 20);
  EXPECT_TRUE(cells[1].cell.fixed_for_rank.empty());
}

// The settings are checked where they are written.
TEST(ModelledUncertainty, BadSettingsAreRefusedAtTheirLine) {
  const std::string dir = testing::TempDir("modelled_refused");
  const auto refused = [&](const std::string& body) {
    std::ofstream(dir + "/s.yaml") << "name: s\nseed: 1\ntrials: 2\n" << body;
    try {
      LoadStudy(dir + "/s.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(refused("noise: {sigma_mm: 0}\nidentification: {errors_in_variables: true}\n"),
              AllOf(HasSubstr("s.yaml:5 key 'identification.errors_in_variables'"),
                    HasSubstr("needs noise.sigma_mm > 0")));
  EXPECT_THAT(refused("noise: {sigma_mm: 0}\nidentification: {prior_sigma: truth}\n"),
              AllOf(HasSubstr("s.yaml:5 key 'identification.prior_sigma'"),
                    HasSubstr("needs noise.sigma_mm > 0")));
  EXPECT_THAT(refused("identification: {prior_sigma: 'theta=1mm'}\n"),
              AllOf(HasSubstr("s.yaml:4 key 'identification.prior_sigma'"),
                    HasSubstr("'theta' is an angle")));
  EXPECT_THAT(refused("identification: {prior_sigma: 'truth,wheel=1mm'}\n"),
              HasSubstr("'wheel' is neither a term nor a class"));
  EXPECT_THAT(refused("truth: {angle_sigma_mrad: 0}\nidentification: {prior_sigma: truth}\n"),
              HasSubstr("priors from the truth need truth.angle_sigma_mrad"));
  EXPECT_THAT(refused("identification: {errors_in_variables: 1}\n"),
              HasSubstr("identification.errors_in_variables"));
}

// A study without the keys, or with their neutral values, keeps its cells' names; the keys set
// the identification options the trials use.
TEST(ModelledUncertainty, NeutralValuesKeepTheCellsAndTheKeysReachTheOptions) {
  const std::string dir = testing::TempDir("modelled_ids");
  const auto load = [&](const std::string& identification) {
    std::ofstream(dir + "/s.yaml") << "name: s\nseed: 1\ntrials: 2\n"
                                      "noise: {sigma_mm: 0.1, repetitions: 4, "
                                      "encoder_sigma_mrad: 0.2}\nidentification: "
                                   << identification << "\n";
    return LoadStudy(dir + "/s.yaml");
  };
  const Study plain = load("{}");
  EXPECT_EQ(load("{prior_sigma: none, errors_in_variables: false}").cells[0].id, plain.cells[0].id);
  EXPECT_EQ(plain.cells[0].typed.identification.encoder_sigma, 0.0);
  EXPECT_TRUE(plain.cells[0].typed.identification.priors.empty());

  const Study eiv = load("{errors_in_variables: true}");
  EXPECT_NE(eiv.cells[0].id, plain.cells[0].id);
  // 0.2 mrad on each of 4 readings: the averaged configuration's joint error is 0.1 mrad.
  EXPECT_DOUBLE_EQ(eiv.cells[0].typed.identification.encoder_sigma, 0.2e-3 / 2);
  EXPECT_DOUBLE_EQ(eiv.cells[0].typed.identification.sigma, 0.1e-3);

  const Study priors = load("{prior_sigma: 'truth,d=0.2mm,theta2=3mrad'}");
  const PriorSigmas& p = priors.cells[0].typed.identification.priors;
  EXPECT_DOUBLE_EQ(p.SigmaOf("theta1"), 1e-3);  // truth.angle_sigma_mrad's default
  EXPECT_DOUBLE_EQ(p.SigmaOf("theta2"), 3e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("a3"), 1e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("d4"), 0.2e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("plane_f"), 0.0);
}

}  // namespace
}  // namespace lrcal
