// Experimental design: choosing k measurement configurations out of N candidates.
//
// The criteria are functions of the singular values σ_i of the identification Jacobian G (m×n)
// of the chosen configurations, computed from the eigenvalues λ_i = σ_i² of GᵀG; every score
// is "larger is better":
//   E  = O3 = σ_min                (the paper's E-optimality, slide 'Optimal Experimental Design')
//   O1 = (Π σ_i)^(1/n) / √m        O2 = σ_min/σ_max        O4 = σ_min²/σ_max
//   O5 = 1 / Σ 1/σ_i               D  = log det GᵀG        A  = −trace (GᵀG)⁻¹
// G's columns are in SI (m/rad, m/m) unless a scaling is applied first (column weights): the
// E-optimal set depends on units, and the paper's criterion is σ_min of G as it stands (SI).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/random.h"

namespace lrcal {

enum class DesignCriterion { kE, kD, kA, kO1, kO2, kO4, kO5 };
DesignCriterion ParseDesignCriterion(const std::string& text, const std::string& source);
const char* DesignCriterionName(DesignCriterion c);

enum class SelectionMethod {
  kExhaustive,  ///< every subset (k = N−1 is the paper's case 2: N evaluations)
  kGreedy,      ///< backward elimination: drop the candidate whose removal hurts least
  kSampled,     ///< the paper's case 1: best of `samples` random subsets
  kRandom,      ///< one random subset: the baseline
};
SelectionMethod ParseSelectionMethod(const std::string& text, const std::string& source);
const char* SelectionMethodName(SelectionMethod m);

struct SelectionOptions {
  DesignCriterion criterion = DesignCriterion::kE;
  SelectionMethod method = SelectionMethod::kGreedy;
  int samples = 1000;                   ///< subsets tried by kSampled
  double exhaustive_limit = 5e6;        ///< most subsets kExhaustive will enumerate
};

struct SelectionResult {
  std::vector<int> indices;  ///< chosen candidates, ascending
  double score = 0;          ///< criterion value of the chosen set
  long long evaluations = 0; ///< criterion evaluations spent
};

/// Score of the normal matrix A = GᵀG of m configurations. When A is singular the σ-based
/// indices (E, O1, O2, O4, O5) are 0 and D, A are −∞.
double CriterionScore(const Eigen::MatrixXd& A, int m, DesignCriterion criterion);

/// Chooses k rows of G (N×n). Throws InputError for k > N, k < n, or an exhaustive search too
/// large for exhaustive_limit.
SelectionResult SelectConfigurations(const Eigen::MatrixXd& G, int k,
                                     const SelectionOptions& options, const RandomStream& stream);

}  // namespace lrcal
