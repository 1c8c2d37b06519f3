// Small dense kernels shared by the least-squares solver, the design criteria and the
// Monte-Carlo statistics: the normal matrix JᵀJ in fixed partial-sum lanes (the same bits on every
// instruction set) and a plain Cholesky factorisation, faster than Eigen's LLT at the sizes of a
// calibration (n ≈ 25).
#pragma once

#include <Eigen/Core>

namespace lrcal {

/// A Cholesky factor stored row-major, so that the factorisation's inner products run over
/// contiguous memory.
using RowMajorMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// A = JᵀJ (n×n, both triangles) for a column-major m×n J. Each entry is summed in 8 fixed
/// partial sums (index mod 8) added in a fixed order, so the result has the same bits whatever
/// vector width runs it (SSE2, AVX2, AVX-512; chosen at run time, cpu_dispatch.h), and it
/// vectorises without -ffast-math.
void NormalMatrix(const Eigen::MatrixXd& J, Eigen::MatrixXd* A);

/// J(i, k) ← J(i, k)·s[i] for every entry (the solver's row weights √w on its Jacobian), run by
/// the widest variant the CPU has; the same bits as Eigen's `J.array().colwise() *= s.array()`.
void ScaleRows(const Eigen::VectorXd& s, Eigen::MatrixXd* J);

/// As = diag(s)·A·diag(s) + λ·I for a square A, each entry (s[i]·A(i, j))·s[j] (+ λ on the
/// diagonal): the Marquardt-scaled, damped normal matrix, with the bits of Eigen's
/// `s.asDiagonal() * A * s.asDiagonal()` and `diagonal().array() += λ`, in every variant.
void ScaleSymmetric(const Eigen::VectorXd& s, const Eigen::MatrixXd& A, double lambda,
                    Eigen::MatrixXd* As);

/// Solves the symmetric positive definite system A·x = b by a plain Cholesky factorisation,
/// leaving the factor in L. Returns false if a pivot is not positive, or below `min_pivot` × the
/// largest diagonal entry of A (the caller's test of numerical rank).
bool CholeskySolve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, RowMajorMatrixXd* L,
                   Eigen::VectorXd* x, double min_pivot = 0);

/// Solves L·Lᵀ·x = b for a row-major Cholesky factor L (from CholeskySolve).
void CholeskySubstitute(const RowMajorMatrixXd& L, const Eigen::VectorXd& b, Eigen::VectorXd* x);

}  // namespace lrcal
