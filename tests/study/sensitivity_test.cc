// Sobol indices on the Ishigami function against its closed-form indices, and Morris' elementary
// effects on functions whose effects are known exactly.
#include "lrcal/study/sensitivity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <tuple>

namespace lrcal {
namespace {

// Ishigami (1990): f = sin x1 + a sin² x2 + b x3⁴ sin x1 on [−π, π]³, a = 7, b = 0.1.
constexpr double kA = 7, kB = 0.1;
double Ishigami(const Eigen::RowVectorXd& u) {
  const Eigen::RowVectorXd x = (-M_PI + 2 * M_PI * u.array()).matrix();
  return std::sin(x[0]) + kA * std::pow(std::sin(x[1]), 2) +
         kB * std::pow(x[2], 4) * std::sin(x[0]);
}

// Closed form (Sobol' & Levitan 1999): V = a²/8 + bπ⁴/5 + b²π⁸/18 + 1/2, V1 = (1 + bπ⁴/5)²/2,
// V2 = a²/8, V3 = 0, V13 = b²π⁸(1/18 − 1/50).
struct IshigamiIndices {
  double first[3], total[3];
};
IshigamiIndices IshigamiTruth() {
  const double pi4 = std::pow(M_PI, 4), pi8 = std::pow(M_PI, 8);
  const double v1 = 0.5 * std::pow(1 + kB * pi4 / 5, 2), v2 = kA * kA / 8;
  const double v13 = kB * kB * pi8 * (1.0 / 18 - 1.0 / 50);
  const double v = v1 + v2 + v13;
  return {{v1 / v, v2 / v, 0.0}, {(v1 + v13) / v, v2 / v, v13 / v}};
}

TEST(Sobol, IshigamiIndicesMatchTheClosedFormWithinTheirIntervals) {
  const SaltelliPlan plan = MakeSaltelliPlan(20000, 3, 7);
  ASSERT_EQ(plan.points.rows(), 20000 * 5);
  Eigen::VectorXd values(plan.points.rows());
  for (Eigen::Index r = 0; r < plan.points.rows(); ++r) values[r] = Ishigami(plan.points.row(r));
  const SobolIndices s = EstimateSobolIndices(plan, values, 300, 0.95, 11);
  const IshigamiIndices truth = IshigamiTruth();
  // The truth: S = (0.3139, 0.4424, 0), T = (0.5576, 0.4424, 0.2437).
  EXPECT_NEAR(truth.first[0], 0.3139, 1e-4);
  EXPECT_NEAR(truth.total[2], 0.2437, 1e-4);
  for (int i = 0; i < 3; ++i) {
    for (const auto& [estimate, exact, what] : {std::tuple{s.first[i], truth.first[i], "S"},
                                                std::tuple{s.total[i], truth.total[i], "T"}}) {
      const double half_width = 0.5 * (estimate.high - estimate.low);
      EXPECT_GT(half_width, 0) << what << i + 1;
      EXPECT_LE(estimate.low, estimate.estimate);
      EXPECT_GE(estimate.high, estimate.estimate);
      // Within 4 bootstrap standard errors (half-width / 1.96) and within 0.03.
      EXPECT_LT(std::fabs(estimate.estimate - exact), 4 * half_width / 1.96)
          << what << i + 1 << " = " << estimate.estimate << " [" << estimate.low << ", "
          << estimate.high << "], exact " << exact;
      EXPECT_LT(std::fabs(estimate.estimate - exact), 0.03) << what << i + 1;
    }
  }
}

TEST(Sobol, IntervalsShrinkLikeOneOverRootN) {
  const auto half_width = [](int n) {
    const SaltelliPlan plan = MakeSaltelliPlan(n, 3, 5);
    Eigen::VectorXd values(plan.points.rows());
    for (Eigen::Index r = 0; r < plan.points.rows(); ++r) values[r] = Ishigami(plan.points.row(r));
    const SobolIndices s = EstimateSobolIndices(plan, values, 300, 0.95, 3);
    return 0.5 * (s.total[0].high - s.total[0].low);
  };
  const double ratio = half_width(1000) / half_width(16000);  // √16 = 4
  EXPECT_GT(ratio, 3.0);
  EXPECT_LT(ratio, 5.3);
}

TEST(Sobol, PlansAreReproducibleAndChecked) {
  const SaltelliPlan a = MakeSaltelliPlan(50, 4, 9), b = MakeSaltelliPlan(50, 4, 9);
  EXPECT_EQ(a.points, b.points);
  EXPECT_NE(a.points, MakeSaltelliPlan(50, 4, 10).points);
  EXPECT_GT(a.points.minCoeff(), 0.0);
  EXPECT_LE(a.points.maxCoeff(), 1.0);
  // AB_2 is A with column 2 from B.
  EXPECT_EQ(a.points.block(150, 0, 50, 1), a.points.block(0, 0, 50, 1));   // A's column 1
  EXPECT_EQ(a.points.block(150, 1, 50, 1), a.points.block(50, 1, 50, 1));  // B's column 2
  EXPECT_EQ(a.points.block(150, 2, 50, 2), a.points.block(0, 2, 50, 2));   // A's columns 3, 4
  EXPECT_THROW(MakeSaltelliPlan(1, 3, 1), std::invalid_argument);
  EXPECT_THROW(EstimateSobolIndices(a, Eigen::VectorXd::Zero(10), 0, 0.95, 1),
               std::invalid_argument);
}

TEST(Morris, LinearFunctionHasItsSlopesAndNoSpread) {
  const MorrisPlan plan = MakeMorrisPlan(20, 3, 4, 2);
  EXPECT_DOUBLE_EQ(plan.delta, 4.0 / 6.0);
  Eigen::VectorXd values(plan.points.rows());
  for (Eigen::Index r = 0; r < plan.points.rows(); ++r)
    values[r] = 2 * plan.points(r, 0) - 3 * plan.points(r, 1);
  const MorrisEffects e = EstimateMorrisEffects(plan, values);
  const double mu[3] = {2, -3, 0};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(e.mu[i], mu[i], 1e-12);
    EXPECT_NEAR(e.mu_star[i], std::fabs(mu[i]), 1e-12);
    EXPECT_NEAR(e.sigma[i], 0, 1e-12);
  }
}

TEST(Morris, InteractionsAndCurvatureShowAsSpread) {
  const MorrisPlan plan = MakeMorrisPlan(40, 4, 6, 3);
  Eigen::VectorXd values(plan.points.rows());
  for (Eigen::Index r = 0; r < plan.points.rows(); ++r) {
    const auto x = plan.points.row(r);
    values[r] = x[0] * x[1] + x[2] * x[2];  // x4 has no effect
  }
  const MorrisEffects e = EstimateMorrisEffects(plan, values);
  EXPECT_GT(e.sigma[0], 0.1);
  EXPECT_GT(e.sigma[1], 0.1);
  EXPECT_GT(e.sigma[2], 0.1);
  EXPECT_EQ(e.mu_star[3], 0.0);
  // Every step moves one input by ±Δ and stays on the grid in [0, 1].
  for (int t = 0; t < plan.trajectories; ++t)
    for (int s = 0; s < plan.inputs; ++s) {
      const Eigen::Index at = static_cast<Eigen::Index>(t) * (plan.inputs + 1) + s;
      const Eigen::RowVectorXd step = plan.points.row(at + 1) - plan.points.row(at);
      const int c = plan.moved[static_cast<std::size_t>(t) * plan.inputs + s];
      EXPECT_NEAR(step[c], plan.sign[static_cast<std::size_t>(t) * plan.inputs + s] * plan.delta,
                  1e-15);
      EXPECT_NEAR(step.cwiseAbs().sum(), plan.delta, 1e-15);
    }
  EXPECT_GE(plan.points.minCoeff(), 0.0);
  EXPECT_LE(plan.points.maxCoeff(), 1.0 + 1e-15);
  EXPECT_THROW(MakeMorrisPlan(10, 3, 5, 1), std::invalid_argument);  // odd levels
}

}  // namespace
}  // namespace lrcal
