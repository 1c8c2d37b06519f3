// Every instruction-set variant of the hot kernels that this CPU can run returns the same bits:
// the reproducibility promise of cpu_dispatch.h.
#include "core/cpu_dispatch.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "core/dense_kernel_variants.h"
#include "lrcal/core/dense_kernels.h"
#include "lrcal/core/machine.h"
#include "lrcal/identification/identification.h"
#include "measurement/batch_evaluation.h"
#include "test_util.h"

namespace lrcal {
namespace {

bool SameBits(const double* a, const double* b, std::size_t n) {
  return std::memcmp(a, b, n * sizeof(double)) == 0;
}

TEST(CpuDispatch, ListsTheDefaultVariantAndUsesASupportedOne) {
  const auto isas = SupportedIsas();
  ASSERT_FALSE(isas.empty());
  EXPECT_EQ(isas.front(), Isa::kDefault);
  EXPECT_NE(std::find(isas.begin(), isas.end(), ActiveIsa()), isas.end());
  std::cout << "supported:";
  for (Isa i : isas) std::cout << " " << IsaName(i);
  std::cout << "; active: " << IsaName(ActiveIsa()) << "\n";
}

TEST(CpuDispatch, TheAvx512VariantsLanesRunWhereverAvx2DoesButOnlyWhenForced) {
  const auto isas = SupportedIsas();
  const auto has = [&](Isa i) { return std::find(isas.begin(), isas.end(), i) != isas.end(); };
  // The eight-lane code compiled for AVX2 is what lets an AVX2-only machine (CI's) test the
  // AVX-512 variant's code: every test that loops over SupportedIsas() runs it.
  EXPECT_EQ(has(Isa::kAvx512OnAvx2), has(Isa::kAvx2));
  EXPECT_STREQ(IsaName(Isa::kAvx512OnAvx2), "avx512-on-avx2");
  if (std::getenv("LRCAL_ISA") == nullptr) {
    // Unforced, the best real variant runs, never the test variant.
    const Isa best = has(Isa::kAvx512) ? Isa::kAvx512
                     : has(Isa::kAvx2) ? Isa::kAvx2
                                       : Isa::kDefault;
    EXPECT_EQ(ActiveIsa(), best);
    EXPECT_STREQ(KernelVariant(), IsaName(best));
  }
}

TEST(CpuDispatch, NormalMatrixHasTheSameBitsInEveryVariant) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  // Sizes that reach every path of the AVX-512 variant: rows fewer than 8 (tail only), a
  // multiple of 8 (no tail), blocks of eight columns with and without a partner row, and the
  // columns left over.
  for (const auto& [m, n] : std::vector<std::pair<int, int>>{
           {25, 27}, {100, 27}, {103, 27}, {5, 9}, {96, 8}, {100, 25}, {17, 1}, {600, 30}}) {
    Eigen::MatrixXd J(m, n);
    for (int k = 0; k < J.size(); ++k) J.data()[k] = u(rng);
    Eigen::MatrixXd reference;
    NormalMatrix(J, &reference, Isa::kDefault);
    EXPECT_LT((reference - J.transpose() * J).norm(), 1e-12 * reference.norm());
    // The order of the sums is the documented one (entry by entry, in every variant).
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        double lanes[8] = {0, 0, 0, 0, 0, 0, 0, 0}, tail = 0;
        const int full = m - m % 8;
        for (int i = 0; i < full; ++i) lanes[i % 8] += J(i, a) * J(i, b);
        for (int i = full; i < m; ++i) tail += J(i, a) * J(i, b);
        const double expected = ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) +
                                ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7])) + tail;
        ASSERT_TRUE(SameBits(&reference(a, b), &expected, 1)) << a << "," << b << " m=" << m;
      }
    }
    for (Isa isa : SupportedIsas()) {
      Eigen::MatrixXd A;
      NormalMatrix(J, &A, isa);
      EXPECT_TRUE(SameBits(A.data(), reference.data(), A.size()))
          << IsaName(isa) << " m=" << m << " n=" << n;
    }
  }
}

// The Cholesky solve against the left-looking formula written out here (the order in which
// every entry loses its products): L and x bit for bit (the solver's steps, hence every study
// table, depend on them); a pivot below the threshold is refused.
TEST(CpuDispatch, CholeskySolveHasTheBitsOfTheLeftLookingFormula) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int n : {1, 2, 5, 8, 9, 25, 30, 33}) {
    Eigen::MatrixXd G(n + 3, n);
    for (int k = 0; k < G.size(); ++k) G.data()[k] = u(rng);
    const Eigen::MatrixXd A = G.transpose() * G + 0.1 * Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) b[i] = u(rng);
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n, n);
    for (int j = 0; j < n; ++j) {
      double d = A(j, j);
      for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
      L(j, j) = std::sqrt(d);
      const double inv = 1.0 / L(j, j);
      for (int i = j + 1; i < n; ++i) {
        double s = A(i, j);
        for (int k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
        L(i, j) = s * inv;
      }
    }
    Eigen::VectorXd x(n);
    for (int i = 0; i < n; ++i) {
      double s = b[i];
      for (int k = 0; k < i; ++k) s -= L(i, k) * x[k];
      x[i] = s / L(i, i);
    }
    for (int i = n - 1; i >= 0; --i) {
      double s = x[i];
      for (int k = i + 1; k < n; ++k) s -= L(k, i) * x[k];
      x[i] = s / L(i, i);
    }
    EXPECT_LT((A * x - b).norm(), 1e-10 * b.norm());
    RowMajorMatrixXd factor;
    Eigen::VectorXd solution;
    ASSERT_TRUE(CholeskySolve(A, b, &factor, &solution)) << " n=" << n;
    for (int j = 0; j < n; ++j)
      for (int i = j; i < n; ++i)
        ASSERT_TRUE(SameBits(&factor(i, j), &L(i, j), 1))
            << " n=" << n << " L(" << i << "," << j << ")";
    EXPECT_TRUE(SameBits(solution.data(), x.data(), n)) << " n=" << n;
    // The cached factor's substitution gives the same solution.
    Eigen::VectorXd again;
    CholeskySubstitute(factor, b, &again);
    EXPECT_TRUE(SameBits(again.data(), x.data(), n)) << " n=" << n;
  }
  // A singular matrix, and a pivot under the caller's threshold, are refused.
  Eigen::MatrixXd singular = Eigen::MatrixXd::Identity(4, 4);
  singular(3, 3) = 0;
  Eigen::MatrixXd tiny = Eigen::MatrixXd::Identity(4, 4);
  tiny(2, 2) = 1e-15;
  RowMajorMatrixXd factor;
  Eigen::VectorXd solution;
  EXPECT_FALSE(CholeskySolve(singular, Eigen::VectorXd::Ones(4), &factor, &solution, 0));
  EXPECT_TRUE(CholeskySolve(tiny, Eigen::VectorXd::Ones(4), &factor, &solution, 0));
  EXPECT_FALSE(CholeskySolve(tiny, Eigen::VectorXd::Ones(4), &factor, &solution, 1e-13));
}

// The solver's row weighting and Marquardt scaling: Eigen's expressions' bits in every variant.
TEST(CpuDispatch, ScalingsHaveTheBitsOfEigensExpressionsInEveryVariant) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-3, 3);
  for (const auto& [m, n] : std::vector<std::pair<int, int>>{{100, 25}, {7, 3}, {301, 27}}) {
    Eigen::MatrixXd J(m, n), A(n, n);
    Eigen::VectorXd w(m), s(n);
    for (int k = 0; k < J.size(); ++k) J.data()[k] = u(rng);
    for (int k = 0; k < A.size(); ++k) A.data()[k] = u(rng);
    for (int i = 0; i < m; ++i) w[i] = std::exp(u(rng));
    for (int i = 0; i < n; ++i) s[i] = std::exp(u(rng));
    Eigen::MatrixXd rows = J;
    rows.array().colwise() *= w.array();
    Eigen::MatrixXd scaled;
    scaled.noalias() = s.asDiagonal() * A * s.asDiagonal();
    scaled.diagonal().array() += 0.37;
    for (Isa isa : SupportedIsas()) {
      Eigen::MatrixXd got = J, got_scaled;
      ScaleRows(w, &got, isa);
      EXPECT_TRUE(SameBits(got.data(), rows.data(), got.size())) << IsaName(isa) << " m=" << m;
      ScaleSymmetric(s, A, 0.37, &got_scaled, isa);
      EXPECT_TRUE(SameBits(got_scaled.data(), scaled.data(), scaled.size()))
          << IsaName(isa) << " n=" << n;
    }
  }
}

TEST(CpuDispatch, BatchKernelHasTheSameBitsInEveryVariant) {
  const RobotModel& robot = testing::PaperRobot();
  MeasurementModel model(robot, testing::PaperPlane(),
                         MakeParameterSet(robot, PlaneTerms{true, true}));
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(101);
  std::vector<double> e(model.num_parameters(), 1e-3);
  ModelPoint point;
  model.Prepare(e.data(), &point);
  BatchEvaluator batch;
  batch.SetConfigurations(configs);
  const std::size_t m = configs.size(), n = model.num_parameters();
  std::vector<double> h0(m), J0(m * n);
  batch.Evaluate(model, point, h0.data(), J0.data(), Isa::kDefault);
  for (Isa isa : SupportedIsas()) {
    std::vector<double> h(m), J(m * n);
    batch.Evaluate(model, point, h.data(), J.data(), isa);
    EXPECT_TRUE(SameBits(h.data(), h0.data(), m)) << IsaName(isa);
    EXPECT_TRUE(SameBits(J.data(), J0.data(), m * n)) << IsaName(isa);
    batch.Evaluate(model, point, h.data(), nullptr, isa);
    EXPECT_TRUE(SameBits(h.data(), h0.data(), m)) << IsaName(isa);
  }
}

}  // namespace
}  // namespace lrcal
