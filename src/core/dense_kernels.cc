#include "lrcal/core/dense_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/dense_kernel_variants.h"

namespace lrcal {

bool CholeskySolve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, RowMajorMatrixXd* L_out,
                   Eigen::VectorXd* x, double min_pivot) {
  const int n = static_cast<int>(A.rows());
  L_out->resize(n, n);
  double* L = L_out->data();  // row-major: L[i*n + k]
  double max_diag = 0;
  for (int i = 0; i < n; ++i) max_diag = std::max(max_diag, A(i, i));
  const double threshold = min_pivot * max_diag;
  for (int j = 0; j < n; ++j) {
    const double* lj = L + j * n;
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= lj[k] * lj[k];
    if (!(d > threshold) || !(d > 0)) return false;
    const double ljj = std::sqrt(d);
    L[j * n + j] = ljj;
    const double inv = 1.0 / ljj;
    for (int i = j + 1; i < n; ++i) {
      const double* li = L + i * n;
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= li[k] * lj[k];  // contiguous in both rows
      L[i * n + j] = s * inv;
    }
  }
  CholeskySubstitute(*L_out, b, x);
  return true;
}

void CholeskySubstitute(const RowMajorMatrixXd& L_in, const Eigen::VectorXd& b,
                        Eigen::VectorXd* x) {
  const int n = static_cast<int>(L_in.rows());
  const double* L = L_in.data();
  x->resize(n);
  double* y = x->data();
  for (int i = 0; i < n; ++i) {  // L·y = b
    const double* li = L + i * n;
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= li[k] * y[k];
    y[i] = s / li[i];
  }
  for (int i = n - 1; i >= 0; --i) {  // Lᵀ·x = y
    double s = y[i];
    for (int k = i + 1; k < n; ++k) s -= L[k * n + i] * y[k];
    y[i] = s / L[i * n + i];
  }
}

namespace {

[[gnu::always_inline]] inline void NormalMatrixBody(const double* __restrict J, int m, int n,
                                                    double* __restrict A) {
  constexpr int kLanes = 8;
  const int full = m - m % kLanes;
  for (int a = 0; a < n; ++a) {
    const double* __restrict ca = J + static_cast<std::size_t>(a) * m;
    for (int b = 0; b <= a; ++b) {
      const double* __restrict cb = J + static_cast<std::size_t>(b) * m;
      double acc[kLanes] = {0, 0, 0, 0, 0, 0, 0, 0};
      for (int i = 0; i < full; i += kLanes)
        for (int l = 0; l < kLanes; ++l) acc[l] += ca[i + l] * cb[i + l];
      double tail = 0;
      for (int i = full; i < m; ++i) tail += ca[i] * cb[i];
      const double sum =
          ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])) + tail;
      A[a + static_cast<std::size_t>(b) * n] = sum;
      A[b + static_cast<std::size_t>(a) * n] = sum;
    }
  }
}

void NormalMatrixDefault(const double* J, int m, int n, double* A) { NormalMatrixBody(J, m, n, A); }
#if defined(__x86_64__)
__attribute__((target("avx2"))) void NormalMatrixAvx2(const double* J, int m, int n, double* A) {
  NormalMatrixBody(J, m, n, A);
}
__attribute__((target("avx512f"))) void NormalMatrixAvx512(const double* J, int m, int n,
                                                           double* A) {
  NormalMatrixBody(J, m, n, A);
}
#endif

}  // namespace

void NormalMatrix(const Eigen::MatrixXd& J, Eigen::MatrixXd* A, Isa isa) {
  const int m = static_cast<int>(J.rows()), n = static_cast<int>(J.cols());
  A->resize(n, n);
  switch (isa) {
#if defined(__x86_64__)
    case Isa::kAvx512:
      NormalMatrixAvx512(J.data(), m, n, A->data());
      return;
    case Isa::kAvx2:
      NormalMatrixAvx2(J.data(), m, n, A->data());
      return;
#endif
    default:
      NormalMatrixDefault(J.data(), m, n, A->data());
      return;
  }
}

void NormalMatrix(const Eigen::MatrixXd& J, Eigen::MatrixXd* A) { NormalMatrix(J, A, ActiveIsa()); }

}  // namespace lrcal
