// Choosing configurations of a measurement kind with several values per configuration (a
// tracker's point: 3, a pose: 6, a scanner's fan: one per beam): the experiment design of
// experiment_design.h, on blocks of rows instead of rows.
//
// G stacks the kind's design Jacobian (DesignJacobian: rows_per_configuration rows per
// candidate, configuration-major). A design of configurations S has the information
// A(S) = Σ_{i∈S} B_iᵀB_i, B_i configuration i's block of rows, and is scored by the criterion of
// experiment_design.h on A(S) (CriterionScore). One row per configuration is
// SelectConfigurations itself (the ranger's selection, bit for bit).
#pragma once

#include <Eigen/Core>

#include "lrcal/core/random.h"
#include "lrcal/design/experiment_design.h"

namespace lrcal {

/// Chooses k of the G.rows()/rows_per_configuration candidates. Methods:
///  - random: one random subset; sampled: the best of `samples` random subsets;
///  - greedy (forward): from nothing, add the candidate that most increases log det(A + εI)
///    (ε = 1e-9·tr(A_all)/n) while A is singular, then the criterion;
///  - backward: from the whole pool, drop the candidate whose removal lowers the criterion least;
///  - exchange: the backward design, then the best single swap of a chosen and an unchosen
///    candidate while one raises the criterion by more than 1e-12 (relative), at most 100 passes.
/// Every score is exact (an eigendecomposition of A per evaluation); ties go to the lower index.
/// Throws InputError ("selection") for an empty pool, k beyond it or below the parameters, G's
/// rows not a multiple of rows_per_configuration (< 1), and exhaustive search for more than one
/// row per configuration.
SelectionResult SelectBlocks(const Eigen::MatrixXd& G, int rows_per_configuration, int k,
                             const SelectionOptions& options, const RandomStream& stream);

}  // namespace lrcal
