// The linearisation check (linearisation_check.h) on models whose second-order error is known in
// closed form: none for a linear model, and for one term entering quadratically the excess
// E[d₂²]/Σ = 3·(Σ w·a·b)²·s²/(Σ w·a²)² (d₂ = −(Σ w·a·b/Σ w·a²)·d₁², E[d₁⁴] = 3·s⁴). Its Monte-Carlo
// test on a real measurement kind is in socket_measurement_test.cc.
#include "lrcal/identification/linearisation_check.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace lrcal {
namespace {

constexpr double kRounding = 1e-12;  // relative, for closed forms evaluated in double

// y_i = A_i·e + ½·Σ_k e_k·(B_k)_i·e: a model with constant second derivatives B_k per row.
class QuadraticEvaluator : public MeasurementEvaluator {
 public:
  QuadraticEvaluator(Eigen::MatrixXd A, std::vector<Eigen::MatrixXd> B)
      : A_(std::move(A)), B_(std::move(B)) {}
  int num_rows() const override { return static_cast<int>(A_.rows()); }
  int num_parameters() const override { return static_cast<int>(A_.cols()); }
  bool Predict(const double* e_data, double* y, double* J) override {
    const Eigen::Map<const Eigen::VectorXd> e(e_data, num_parameters());
    Eigen::Map<Eigen::MatrixXd> jacobian(J ? J : scratch(), num_rows(), num_parameters());
    for (int i = 0; i < num_rows(); ++i) {
      const auto u = static_cast<std::size_t>(i);
      y[i] = A_.row(i).dot(e) + 0.5 * e.dot(B_[u] * e);
      jacobian.row(i) = A_.row(i) + (B_[u] * e).transpose();
    }
    return true;
  }

 private:
  double* scratch() {
    scratch_.resize(A_.rows(), A_.cols());
    return scratch_.data();
  }
  Eigen::MatrixXd A_;
  std::vector<Eigen::MatrixXd> B_;
  Eigen::MatrixXd scratch_;
};

Eigen::MatrixXd Covariance(const Eigen::MatrixXd& A, const std::vector<double>& w, double sigma) {
  const Eigen::VectorXd weights = Eigen::Map<const Eigen::VectorXd>(w.data(), A.rows());
  return sigma * sigma * (A.transpose() * weights.asDiagonal() * A).inverse();
}

TEST(LinearisationCheck, ALinearModelHasNoExcess) {
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(30, 4);
  QuadraticEvaluator linear(A, std::vector<Eigen::MatrixXd>(30, Eigen::MatrixXd::Zero(4, 4)));
  const std::vector<double> w(30, 3.0);
  const LinearisationCheck c =
      CheckLinearisation(linear, w, Eigen::VectorXd::Zero(4), Covariance(A, w, 0.1), 0.1);
  ASSERT_TRUE(c.computed) << c.message;
  EXPECT_NEAR(c.excess, 0.0, kRounding);
  EXPECT_TRUE(c.Holds());
  EXPECT_EQ(c.pairs, 4 + 6);
  EXPECT_THAT(c.Explain(), ::testing::HasSubstr("the linearised covariance holds"));
}

TEST(LinearisationCheck, OneQuadraticTermHasItsClosedFormExcess) {
  constexpr int kRows = 12;
  Eigen::MatrixXd A(kRows, 1);
  std::vector<Eigen::MatrixXd> B;
  std::vector<double> w;
  double wab = 0, waa = 0;
  for (int i = 0; i < kRows; ++i) {
    const double a = 0.5 + 0.1 * i, b = std::sin(1.0 + i);  // y_i = a·e + b·e²
    A(i, 0) = a;
    B.push_back(Eigen::MatrixXd::Constant(1, 1, 2 * b));
    w.push_back(1 + i % 3);
    wab += w.back() * a * b;
    waa += w.back() * a * a;
  }
  QuadraticEvaluator model(A, B);
  for (double sigma : {0.01, 0.3}) {
    const double s2 = sigma * sigma / waa;
    const LinearisationCheck c =
        CheckLinearisation(model, w, Eigen::VectorXd::Zero(1), Covariance(A, w, sigma), sigma);
    ASSERT_TRUE(c.computed) << c.message;
    const double expected = 3 * wab * wab * s2 / (waa * waa);
    EXPECT_NEAR(c.excess, expected, kRounding * expected) << sigma;
  }
  // Large enough to be flagged: the excess grows as σ².
  const LinearisationCheck flagged =
      CheckLinearisation(model, w, Eigen::VectorXd::Zero(1), Covariance(A, w, 15.0), 15.0);
  EXPECT_GT(flagged.RelativeExcess(), LinearisationCheck::kMaxRelativeExcess);
  EXPECT_FALSE(flagged.Holds());
  EXPECT_THAT(flagged.Explain(), ::testing::HasSubstr("the covariance is optimistic"));
}

TEST(LinearisationCheck, WithoutACovarianceItSaysSo) {
  QuadraticEvaluator model(Eigen::MatrixXd::Identity(2, 2),
                           std::vector<Eigen::MatrixXd>(2, Eigen::MatrixXd::Zero(2, 2)));
  const LinearisationCheck c = CheckLinearisation(model, {1.0, 1.0}, Eigen::VectorXd::Zero(2),
                                                  Eigen::MatrixXd::Identity(2, 2), std::nan(""));
  EXPECT_FALSE(c.computed);
  EXPECT_FALSE(c.Holds());
  EXPECT_THAT(c.Explain(), ::testing::HasSubstr("not computed (no covariance to check)"));
}

}  // namespace
}  // namespace lrcal
