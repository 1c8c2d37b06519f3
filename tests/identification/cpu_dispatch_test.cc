// Every instruction-set variant of the hot kernels that this CPU can run returns the same bits:
// the reproducibility promise of cpu_dispatch.h.
#include "core/cpu_dispatch.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "core/dense_kernel_variants.h"
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
