// Checks of a prepared cell's trials that several study tests make.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>

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

}  // namespace lrcal::testing
