#include "lrcal/core/dense_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <vector>

#include "core/dense_kernel_variants.h"
#include "core/lanes.h"

namespace lrcal {

namespace {

// s[r] −= Σ_{k < count} L(row0 + r, k)·x[k] for the four rows r = 0 … 3 of a row-major matrix
// of leading dimension n (`rows` points at row row0): each row's subtractions in the order of k,
// the four rows' chains independent of each other (the factorisation and the substitution are
// latency-bound, one chain at a time).
[[gnu::always_inline]] inline void SubtractFourRowProducts(const double* rows, int n,
                                                           const double* x, int count,
                                                           double s[4]) {
  const double *l0 = rows, *l1 = l0 + n, *l2 = l1 + n, *l3 = l2 + n;
  double s0 = s[0], s1 = s[1], s2 = s[2], s3 = s[3];
  for (int k = 0; k < count; ++k) {
    const double xk = x[k];
    s0 -= l0[k] * xk;
    s1 -= l1[k] * xk;
    s2 -= l2[k] * xk;
    s3 -= l3[k] * xk;
  }
  s[0] = s0;
  s[1] = s1;
  s[2] = s2;
  s[3] = s3;
}

}  // namespace

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
    // Entries (i … i + 3, j) side by side, each in the order of the one-entry loop below.
    int i = j + 1;
    for (; i + 3 < n; i += 4) {
      double s[4] = {A(i, j), A(i + 1, j), A(i + 2, j), A(i + 3, j)};
      SubtractFourRowProducts(L + i * n, n, lj, j, s);
      for (int r = 0; r < 4; ++r) L[(i + r) * n + j] = s[r] * inv;
    }
    for (; i < n; ++i) {
      const double* li = L + i * n;
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= li[k] * lj[k];
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
  // L·y = b. Rows i … i + 3 side by side over the y already known, then in turn: each row's
  // subtractions in the order of the one-row loop below.
  int i = 0;
  for (; i + 3 < n; i += 4) {
    double s[4] = {b[i], b[i + 1], b[i + 2], b[i + 3]};
    SubtractFourRowProducts(L + i * n, n, y, i, s);
    // Then each row's last terms, y[i] … y[i + r − 1], in order.
    const double *l0 = L + i * n, *l1 = l0 + n, *l2 = l1 + n, *l3 = l2 + n;
    y[i] = s[0] / l0[i];
    s[1] -= l1[i] * y[i];
    y[i + 1] = s[1] / l1[i + 1];
    s[2] -= l2[i] * y[i];
    s[2] -= l2[i + 1] * y[i + 1];
    y[i + 2] = s[2] / l2[i + 2];
    s[3] -= l3[i] * y[i];
    s[3] -= l3[i + 1] * y[i + 1];
    s[3] -= l3[i + 2] * y[i + 2];
    y[i + 3] = s[3] / l3[i + 3];
  }
  for (; i < n; ++i) {
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

// Eight doubles as one value (core/lanes.h): one AVX-512 register; four: one AVX2 register.
using Lanes8 = lanes::VectorOf<8>::type;
using Lanes4 = lanes::VectorOf<4>::type;

// Entry (a, b) alone: eight partial sums (row index mod 8) over the first `full` rows, the tail
// (the last m mod 8 rows) in order, added in the fixed order below; plain loops that the compiler
// vectorises at each variant's width.
[[gnu::always_inline]] inline void NormalMatrixEntry(const double* __restrict J, int m, int n,
                                                     int a, int b, int full, double* __restrict A) {
  constexpr int kLanes = 8;
  const double* __restrict ca = J + static_cast<std::size_t>(a) * m;
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

// Entries (a + r, b … b + 7) for r < kRows at once, their partial sums reduced side by side:
// the eight accumulators of a row are transposed pairwise, so each level of NormalMatrixEntry's
// tree is one vector addition (lane k of the result is entry b + k, its sums added in that order),
// and the tails come from `tail_rows` (the last m mod 8 rows of J, row-major: tail_rows[i·n + c] =
// J(full + i, c)).
template <int kRows>
[[gnu::always_inline]] inline void NormalMatrixEntries8(const double* __restrict J, int m, int n,
                                                        int a, int b, int full,
                                                        const double* __restrict tail_rows,
                                                        double* __restrict A) {
  Lanes8 acc[kRows][8];
  for (auto& row : acc)
    for (auto& v : row) v = Lanes8{0, 0, 0, 0, 0, 0, 0, 0};
  for (int i = 0; i < full; i += 8) {
    Lanes8 x[kRows];
    for (int r = 0; r < kRows; ++r)
      x[r] = lanes::Load<Lanes8>(J + static_cast<std::size_t>(a + r) * m + i);
    for (int w = 0; w < 8; ++w) {
      const Lanes8 y = lanes::Load<Lanes8>(J + static_cast<std::size_t>(b + w) * m + i);
      for (int r = 0; r < kRows; ++r) acc[r][w] += x[r] * y;
    }
  }
  for (int r = 0; r < kRows; ++r) {
    // Level 1: lanes (2j, 2j+1) of entries w and w+1 → (acc[2j] + acc[2j+1]) of each.
    Lanes8 p[4];
    for (int k = 0; k < 4; ++k) {
      const Lanes8 lo =
          __builtin_shufflevector(acc[r][2 * k], acc[r][2 * k + 1], 0, 8, 2, 10, 4, 12, 6, 14);
      const Lanes8 hi =
          __builtin_shufflevector(acc[r][2 * k], acc[r][2 * k + 1], 1, 9, 3, 11, 5, 13, 7, 15);
      p[k] = lo + hi;  // [e0 s01, e1 s01, e0 s23, e1 s23, e0 s45, e1 s45, e0 s67, e1 s67]
    }
    // Level 2: (s01 + s23) and (s45 + s67) of four entries.
    Lanes8 q[2];
    for (int k = 0; k < 2; ++k) {
      const Lanes8 lo = __builtin_shufflevector(p[2 * k], p[2 * k + 1], 0, 1, 8, 9, 4, 5, 12, 13);
      const Lanes8 hi = __builtin_shufflevector(p[2 * k], p[2 * k + 1], 2, 3, 10, 11, 6, 7, 14, 15);
      q[k] = lo + hi;  // [e0..e3 (s01 + s23), e0..e3 (s45 + s67)]
    }
    // Level 3: the two halves of each entry's sum.
    const Lanes8 lo = __builtin_shufflevector(q[0], q[1], 0, 1, 2, 3, 8, 9, 10, 11);
    const Lanes8 hi = __builtin_shufflevector(q[0], q[1], 4, 5, 6, 7, 12, 13, 14, 15);
    Lanes8 tail = Lanes8{0, 0, 0, 0, 0, 0, 0, 0};
    for (int i = 0; i < m - full; ++i)
      tail += tail_rows[static_cast<std::size_t>(i) * n + a + r] *
              lanes::Load<Lanes8>(tail_rows + static_cast<std::size_t>(i) * n + b);
    const Lanes8 sum = (lo + hi) + tail;
    lanes::Store(A + static_cast<std::size_t>(a + r) * n + b, sum);
    for (int w = 0; w < 8; ++w) A[a + r + static_cast<std::size_t>(b + w) * n] = sum[w];
  }
}

// Entries (a, b … b + 3) at once with four-double vectors (AVX2's registers): each entry's
// eight partial sums are two vectors (row index mod 8 = 0…3 and 4…7), and the four entries'
// sums are reduced side by side in NormalMatrixEntry's tree (lane w of the result is entry
// b + w). The tails come from `tail_rows` as in NormalMatrixEntries8.
[[gnu::always_inline]] inline void NormalMatrixEntries4(const double* __restrict J, int m, int n,
                                                        int a, int b, int full,
                                                        const double* __restrict tail_rows,
                                                        double* __restrict A) {
  Lanes4 lo[4] = {}, hi[4] = {};  // entry b + w: partial sums 0…3, 4…7, from zero
  const double* __restrict ca = J + static_cast<std::size_t>(a) * m;
  for (int i = 0; i < full; i += 8) {
    const Lanes4 xl = lanes::Load<Lanes4>(ca + i), xh = lanes::Load<Lanes4>(ca + i + 4);
    for (int w = 0; w < 4; ++w) {
      const double* cb = J + static_cast<std::size_t>(b + w) * m + i;
      lo[w] += xl * lanes::Load<Lanes4>(cb);
      hi[w] += xh * lanes::Load<Lanes4>(cb + 4);
    }
  }
  // Level 1: [e0 s01, e1 s01, e0 s23, e1 s23] of entries (0, 1) and (2, 3), likewise s45, s67.
  Lanes4 pl[2], ph[2];
  for (int k = 0; k < 2; ++k) {
    pl[k] = __builtin_shufflevector(lo[2 * k], lo[2 * k + 1], 0, 4, 2, 6) +
            __builtin_shufflevector(lo[2 * k], lo[2 * k + 1], 1, 5, 3, 7);
    ph[k] = __builtin_shufflevector(hi[2 * k], hi[2 * k + 1], 0, 4, 2, 6) +
            __builtin_shufflevector(hi[2 * k], hi[2 * k + 1], 1, 5, 3, 7);
  }
  // Level 2: s01 + s23 and s45 + s67 of the four entries.
  const Lanes4 ql = __builtin_shufflevector(pl[0], pl[1], 0, 1, 4, 5) +
                    __builtin_shufflevector(pl[0], pl[1], 2, 3, 6, 7);
  const Lanes4 qh = __builtin_shufflevector(ph[0], ph[1], 0, 1, 4, 5) +
                    __builtin_shufflevector(ph[0], ph[1], 2, 3, 6, 7);
  Lanes4 tail = Lanes4{0, 0, 0, 0};
  for (int i = 0; i < m - full; ++i)
    tail += tail_rows[static_cast<std::size_t>(i) * n + a] *
            lanes::Load<Lanes4>(tail_rows + static_cast<std::size_t>(i) * n + b);
  const Lanes4 sum = (ql + qh) + tail;
  lanes::Store(A + static_cast<std::size_t>(a) * n + b, sum);
  for (int w = 0; w < 4; ++w) A[a + static_cast<std::size_t>(b + w) * n] = sum[w];
}

// J's last m − full rows, row-major (tail_rows[i·n + c] = J(full + i, c)), for the blocked
// entries' tails.
[[gnu::always_inline]] inline const double* TailRows(const double* __restrict J, int m, int n,
                                                     int full) {
  thread_local std::vector<double> tail_rows;
  tail_rows.resize(static_cast<std::size_t>(m - full) * n);
  for (int r = 0; r < m - full; ++r)
    for (int c = 0; c < n; ++c)
      tail_rows[static_cast<std::size_t>(r) * n + c] =
          J[static_cast<std::size_t>(c) * m + full + r];
  return tail_rows.data();
}

// Entry (a, b) = Σ_i J(i,a)·J(i,b) as NormalMatrixEntry sums it, in every variant. The blocks
// also reach past the diagonal (entry (a, b) and entry (b, a) have the same bits: each product
// commutes); the entries no block covers are taken one by one. kBlock 8 (AVX-512, whose 32
// registers hold sixteen entries' sums) takes two rows by eight columns of entries at a time;
// kBlock 4 (AVX2: sixteen registers) one row by four columns; kBlock 1 (SSE2) every entry alone
// (there GCC's own vectorisation of NormalMatrixEntry is faster than any lowering of wider
// vectors to its two-double registers).
template <int kBlock>
[[gnu::always_inline]] inline void NormalMatrixBody(const double* __restrict J, int m, int n,
                                                    double* __restrict A) {
  constexpr int kLanes = 8;
  const int full = m - m % kLanes;
  const auto rest_of_row = [&](int a, int b) {  // entries (a, b …  a)
    for (; b <= a; ++b) NormalMatrixEntry(J, m, n, a, b, full, A);
  };
  if constexpr (kBlock == 1) {
    for (int a = 0; a < n; ++a) rest_of_row(a, 0);
  } else if constexpr (kBlock == 4) {
    const double* tail_rows = TailRows(J, m, n, full);
    for (int a = 0; a < n; ++a) {
      int b = 0;
      for (; b <= a && b + 4 <= n; b += 4) NormalMatrixEntries4(J, m, n, a, b, full, tail_rows, A);
      rest_of_row(a, b);
    }
  } else {
    const double* tail_rows = TailRows(J, m, n, full);
    int a = 0;
    for (; a + 1 < n; a += 2) {  // rows a and a + 1 share the loads of their blocks
      int b = 0;
      for (; b <= a + 1 && b + 8 <= n; b += 8)
        NormalMatrixEntries8<2>(J, m, n, a, b, full, tail_rows, A);
      rest_of_row(a, b);
      rest_of_row(a + 1, b);
    }
    for (; a < n; ++a) {
      int b = 0;
      for (; b <= a && b + 8 <= n; b += 8)
        NormalMatrixEntries8<1>(J, m, n, a, b, full, tail_rows, A);
      rest_of_row(a, b);
    }
  }
}

void NormalMatrixDefault(const double* J, int m, int n, double* A) {
  NormalMatrixBody<1>(J, m, n, A);
}
#if defined(__x86_64__)
__attribute__((target("avx2"))) void NormalMatrixAvx2(const double* J, int m, int n, double* A) {
  NormalMatrixBody<4>(J, m, n, A);
}
__attribute__((target("avx512f"))) void NormalMatrixAvx512(const double* J, int m, int n,
                                                           double* A) {
  NormalMatrixBody<8>(J, m, n, A);
}
// The AVX-512 variant's code on an AVX2 machine (cpu_dispatch.h, Isa::kAvx512OnAvx2).
__attribute__((target("avx2"))) void NormalMatrixAvx512OnAvx2(const double* J, int m, int n,
                                                              double* A) {
  NormalMatrixBody<8>(J, m, n, A);
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
    case Isa::kAvx512OnAvx2:
      NormalMatrixAvx512OnAvx2(J.data(), m, n, A->data());
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

namespace {

// J(i, k) *= s[i] for a column-major m×n J: one multiplication per entry, any width.
[[gnu::always_inline]] inline void ScaleRowsBody(const double* __restrict s, int m, int n,
                                                 double* __restrict J) {
  for (int k = 0; k < n; ++k) {
    double* __restrict col = J + static_cast<std::size_t>(k) * m;
    for (int i = 0; i < m; ++i) col[i] *= s[i];
  }
}

// As(i, j) = (s[i]·A(i, j))·s[j], then λ added on the diagonal: Eigen's
// s.asDiagonal() * A * s.asDiagonal() and diagonal() += λ, entry by entry.
[[gnu::always_inline]] inline void ScaleSymmetricBody(const double* __restrict s,
                                                      const double* __restrict A, int n,
                                                      double lambda, double* __restrict As) {
  for (int j = 0; j < n; ++j) {
    const double* __restrict a = A + static_cast<std::size_t>(j) * n;
    double* __restrict out = As + static_cast<std::size_t>(j) * n;
    const double sj = s[j];
    for (int i = 0; i < n; ++i) out[i] = (s[i] * a[i]) * sj;
    out[j] += lambda;
  }
}

void ScaleRowsDefault(const double* s, int m, int n, double* J) { ScaleRowsBody(s, m, n, J); }
void ScaleSymmetricDefault(const double* s, const double* A, int n, double lambda, double* As) {
  ScaleSymmetricBody(s, A, n, lambda, As);
}
#if defined(__x86_64__)
__attribute__((target("avx2"))) void ScaleRowsAvx2(const double* s, int m, int n, double* J) {
  ScaleRowsBody(s, m, n, J);
}
__attribute__((target("avx512f"))) void ScaleRowsAvx512(const double* s, int m, int n, double* J) {
  ScaleRowsBody(s, m, n, J);
}
__attribute__((target("avx2"))) void ScaleSymmetricAvx2(const double* s, const double* A, int n,
                                                        double lambda, double* As) {
  ScaleSymmetricBody(s, A, n, lambda, As);
}
__attribute__((target("avx512f"))) void ScaleSymmetricAvx512(const double* s, const double* A,
                                                             int n, double lambda, double* As) {
  ScaleSymmetricBody(s, A, n, lambda, As);
}
#endif

}  // namespace

void ScaleRows(const double* s, int m, int n, double* J, Isa isa) {
  switch (isa) {
#if defined(__x86_64__)
    case Isa::kAvx512:
      return ScaleRowsAvx512(s, m, n, J);
    case Isa::kAvx2:
    case Isa::kAvx512OnAvx2:  // no lanes of its own: the AVX-512 variant is this loop
      return ScaleRowsAvx2(s, m, n, J);
#endif
    default:
      return ScaleRowsDefault(s, m, n, J);
  }
}

void ScaleRows(const Eigen::VectorXd& s, Eigen::MatrixXd* J, Isa isa) {
  ScaleRows(s.data(), static_cast<int>(J->rows()), static_cast<int>(J->cols()), J->data(), isa);
}

void ScaleRows(const Eigen::VectorXd& s, Eigen::MatrixXd* J) { ScaleRows(s, J, ActiveIsa()); }

void ScaleSymmetric(const Eigen::VectorXd& s, const Eigen::MatrixXd& A, double lambda,
                    Eigen::MatrixXd* As, Isa isa) {
  const int n = static_cast<int>(A.rows());
  As->resize(n, n);
  switch (isa) {
#if defined(__x86_64__)
    case Isa::kAvx512:
      return ScaleSymmetricAvx512(s.data(), A.data(), n, lambda, As->data());
    case Isa::kAvx2:
    case Isa::kAvx512OnAvx2:  // no lanes of its own: the AVX-512 variant is this loop
      return ScaleSymmetricAvx2(s.data(), A.data(), n, lambda, As->data());
#endif
    default:
      return ScaleSymmetricDefault(s.data(), A.data(), n, lambda, As->data());
  }
}

void ScaleSymmetric(const Eigen::VectorXd& s, const Eigen::MatrixXd& A, double lambda,
                    Eigen::MatrixXd* As) {
  ScaleSymmetric(s, A, lambda, As, ActiveIsa());
}

}  // namespace lrcal
