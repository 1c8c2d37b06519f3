// The dense kernels (lrcal/core/dense_kernels.h) with a chosen instruction-set variant, for the
// tests that check every variant gives the same bits, for the benchmarks and for the batch
// evaluator (which is handed its variant).
#pragma once

#include <Eigen/Core>

#include "core/cpu_dispatch.h"

namespace lrcal {

/// NormalMatrix(J, A) run by the given variant (one this CPU supports: SupportedIsas()).
void NormalMatrix(const Eigen::MatrixXd& J, Eigen::MatrixXd* A, Isa isa);
/// ScaleRows and ScaleSymmetric run by the given variant.
void ScaleRows(const Eigen::VectorXd& s, Eigen::MatrixXd* J, Isa isa);
/// The same on raw storage: J(i, k) ← J(i, k)·s[i] for a column-major m×n J (leading
/// dimension m), for callers that hold J as a pointer (the batch evaluator's weighted rows).
void ScaleRows(const double* s, int m, int n, double* J, Isa isa);
void ScaleSymmetric(const Eigen::VectorXd& s, const Eigen::MatrixXd& A, double lambda,
                    Eigen::MatrixXd* As, Isa isa);

}  // namespace lrcal
