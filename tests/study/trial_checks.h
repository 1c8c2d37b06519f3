// Checks of a prepared cell's trials that several study tests make.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <string>

#include "lrcal/study/study.h"
#include "study/trial_pipeline.h"

namespace lrcal::testing {

/// The mean over trials 0 … trials − 1 of the Mahalanobis distance δᵀΣ⁻¹δ of each trial's
/// parameter errors under the cell's predicted covariance Σ: n on average when Σ holds (χ²(n)).
/// A failed trial fails the calling test (and counts 0).
inline double MeanMahalanobis(const CellContext& c, int trials) {
  const Eigen::LDLT<Eigen::MatrixXd> inverse(c.predicted_covariance);
  double sum = 0;
  TrialWorkspace ws;
  for (int t = 0; t < trials; ++t) {
    const TrialRecord r = RunTrial(c, t, &ws);
    EXPECT_EQ(r.status, TrialStatus::kOk) << "trial " << t;
    if (r.status != TrialStatus::kOk) continue;
    const Eigen::Map<const Eigen::VectorXd> d(r.errors.data(),
                                              static_cast<Eigen::Index>(r.errors.size()));
    sum += d.dot(inverse.solve(d));
  }
  return sum / trials;
}

/// Trials 0 … trials − 1 converge, each parameter error within `errors` (none checked when < 0)
/// and each validation metric within `validation` of 0.
inline void ExpectTrialsRecoverTheTruth(const CellContext& c, int trials, double errors,
                                        double validation) {
  TrialWorkspace ws;
  for (int t = 0; t < trials; ++t) {
    const TrialRecord r = RunTrial(c, t, &ws);
    ASSERT_EQ(r.status, TrialStatus::kOk) << "trial " << t;
    ASSERT_EQ(r.errors.size(), c.parameter_names.size());
    if (errors >= 0) {
      for (std::size_t k = 0; k < r.errors.size(); ++k)
        EXPECT_NEAR(r.errors[k], 0, errors) << c.parameter_names[k] << ", trial " << t;
    }
    for (int a = 0; a < 12; ++a) EXPECT_NEAR(r.validation[a], 0, validation) << a;
    EXPECT_GT(r.nominal[0], 1e-4);  // the nominal arm is off by millimetres
  }
}

/// A cell prepared for its trials alone (CellPreparation::kForTrials, as a resume prepares a cell
/// whose row is stored) runs trials 0 … trials − 1 to the bits of the cell prepared in full, with
/// the stored row's parts left out (NaN) and ToStoredCell refusing it.
inline void ExpectForTrialsPreparesTheSameTrials(const Study& study, const Cell& cell, int trials) {
  const auto full = PrepareCell(study, cell);
  const auto lean = PrepareCell(study, cell, CellPreparation::kForTrials);
  EXPECT_FALSE(full->for_trials_only);
  EXPECT_TRUE(lean->for_trials_only);
  EXPECT_TRUE(std::isnan(lean->design_efficiency));
  for (double v : lean->predicted_validation) EXPECT_TRUE(std::isnan(v));
  EXPECT_FALSE(std::isnan(full->predicted_validation[0]));  // what the lean cell leaves out
  EXPECT_THROW(ToStoredCell(*lean), std::logic_error);
  EXPECT_EQ(ToStoredCell(*full).id, cell.id);
  TrialWorkspace ws_full, ws_lean;
  for (int t = 0; t < trials; ++t) {
    const TrialRecord a = RunTrial(*full, t, &ws_full), b = RunTrial(*lean, t, &ws_lean);
    EXPECT_EQ(a.status, b.status) << "trial " << t;
    EXPECT_EQ(a.iterations, b.iterations) << "trial " << t;
    EXPECT_EQ(a.residual_rms, b.residual_rms) << "trial " << t;
    EXPECT_EQ(a.sigma_hat, b.sigma_hat) << "trial " << t;
    EXPECT_EQ(a.sigma_min, b.sigma_min) << "trial " << t;
    EXPECT_EQ(a.errors, b.errors) << "trial " << t;
    EXPECT_EQ(a.validation, b.validation) << "trial " << t;
    EXPECT_EQ(a.nominal, b.nominal) << "trial " << t;
    EXPECT_EQ(a.missed_configurations, b.missed_configurations) << "trial " << t;
    // NaN unless the cell asks for coverage: compare the bits' meaning, NaN equal to NaN.
    EXPECT_TRUE(a.coverage == b.coverage || (std::isnan(a.coverage) && std::isnan(b.coverage)));
    EXPECT_TRUE(a.coverage_total == b.coverage_total ||
                (std::isnan(a.coverage_total) && std::isnan(b.coverage_total)));
  }
}

}  // namespace lrcal::testing
