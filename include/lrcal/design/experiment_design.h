// Experimental design: choosing k measurement configurations out of N candidates.
//
// The criteria are functions of the singular values σ_i of the identification Jacobian G (m×n)
// of the chosen configurations, computed from the eigenvalues λ_i = σ_i² of A = GᵀG; every score
// is "larger is better":
//   E  = O3 = σ_min                (the paper's E-optimality, slide 'Optimal Experimental Design')
//   O1 = (Π σ_i)^(1/n) / √m        O2 = σ_min/σ_max        O4 = σ_min²/σ_max
//   O5 = 1 / Σ 1/σ_i               D  = log det GᵀG        A  = −trace (GᵀG)⁻¹
// When A is singular the σ-based indices are 0 and D, A are −∞.
//
// Column scaling is a stated choice, because E-optimality depends on units (m/rad against m/m):
//  - kSI: G as it stands. **This is the paper's method** (σ_min of the identification Jacobian,
//    no scaling mentioned); for the paper's arm, link lengths of ~1 m make rad and m columns of
//    similar size.
//  - kUnitColumns: every column of the candidate pool's G scaled to unit norm.
//  - kExpectedErrors: column j multiplied by the expected magnitude of parameter j's error
//    (prior σ in rad or m), so the criterion weighs the readings' sensitivity to plausible errors.
//
// Candidate evaluations use rank-one spectral updates: with A = QΛQᵀ and z = Qᵀg, the spectrum of
// A ± ggᵀ follows from the secular equation 1 ± Σ z_i²/(λ_i − μ) = 0 (each root bracketed between
// consecutive λ), log det from the determinant lemma and trace A⁻¹ from Sherman–Morrison: O(n²)
// per candidate instead of an O(n³) eigendecomposition.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/core/enum_names.h"
#include "lrcal/core/random.h"
#include "lrcal/core/settings.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/measurement_model.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

enum class DesignCriterion { kE, kD, kA, kO1, kO2, kO4, kO5 };
/// Names in study files and options; O3 is another name of E.
inline constexpr EnumName<DesignCriterion> kDesignCriterionNames[] = {
    {DesignCriterion::kE, "E"},   {DesignCriterion::kD, "D"},   {DesignCriterion::kA, "A"},
    {DesignCriterion::kO1, "O1"}, {DesignCriterion::kO2, "O2"}, {DesignCriterion::kE, "O3"},
    {DesignCriterion::kO4, "O4"}, {DesignCriterion::kO5, "O5"}};
inline DesignCriterion ParseDesignCriterion(const std::string& text, const std::string& source) {
  return ParseName(kDesignCriterionNames, text, source, "criterion");
}
inline const char* DesignCriterionName(DesignCriterion c) {
  return NameOf(kDesignCriterionNames, c);
}

enum class SelectionMethod {
  kExhaustive,  ///< every subset (k = N−1 is the paper's case 2: N evaluations)
  kGreedy,      ///< greedy forward: add the candidate that helps most (D-optimal until rank n)
  kBackward,    ///< greedy backward elimination: drop the candidate whose removal hurts least
  kExchange,    ///< Fedorov / DETMAX exchange: best single swaps until none improves, restarts
  kSampled,     ///< the paper's case 1: best of `samples` random subsets
  kRandom,      ///< one random subset: the baseline
};
/// Names in study files and options; "forward" is another name of greedy.
inline constexpr EnumName<SelectionMethod> kSelectionMethodNames[] = {
    {SelectionMethod::kExhaustive, "exhaustive"}, {SelectionMethod::kGreedy, "greedy"},
    {SelectionMethod::kBackward, "backward"},     {SelectionMethod::kExchange, "exchange"},
    {SelectionMethod::kSampled, "sampled"},       {SelectionMethod::kRandom, "random"},
    {SelectionMethod::kGreedy, "forward"}};
inline SelectionMethod ParseSelectionMethod(const std::string& text, const std::string& source) {
  return ParseName(kSelectionMethodNames, text, source, "selection method");
}
inline const char* SelectionMethodName(SelectionMethod m) {
  return NameOf(kSelectionMethodNames, m);
}

enum class DesignScaling { kSI, kUnitColumns, kExpectedErrors };
inline constexpr EnumName<DesignScaling> kDesignScalingNames[] = {
    {DesignScaling::kSI, "si"},
    {DesignScaling::kUnitColumns, "unit"},
    {DesignScaling::kExpectedErrors, "expected"},
    {DesignScaling::kSI, "SI"}};
inline DesignScaling ParseDesignScaling(const std::string& text, const std::string& source) {
  return ParseName(kDesignScalingNames, text, source, "scaling");
}
inline const char* DesignScalingName(DesignScaling s) { return NameOf(kDesignScalingNames, s); }

struct SelectionOptions {
  DesignCriterion criterion = DesignCriterion::kE;
  SelectionMethod method = SelectionMethod::kBackward;
  int samples = 1000;  ///< subsets tried by kSampled
  /// kExchange: starts = the backward- and forward-greedy designs and the relaxation's rounded
  /// solution (design_certificate.h), then (restarts−1) kicks of the best end so far (⌈k/10⌉,
  /// at least 2, of its members swapped for random candidates, iterated local search): the best
  /// end wins.
  int restarts = 4;
  double exhaustive_limit = 5e6;  ///< most subsets kExhaustive will enumerate
  /// The numeric settings (settings.h): samples (1 to 1,000,000 random subsets; a study's
  /// selection.samples, --samples, samples=), restarts (1 to 1000 starts; selection.restarts,
  /// --restarts, restarts=) and exhaustive_limit (at least 1 subset; the library's only).
  static const std::vector<SettingField<SelectionOptions>>& Settings();
  /// Throws SettingError naming the library field (selection.samples, ...) and the range.
  void Validate() const;
};

struct SelectionResult {
  std::vector<int> indices;   ///< chosen candidates, ascending
  double score = 0;           ///< criterion value of the chosen set (exact eigendecomposition)
  long long evaluations = 0;  ///< candidate evaluations spent
  double start_score = 0;     ///< kExchange: score of the best start before exchanging
};

/// Score of the normal matrix A = GᵀG of m configurations.
double CriterionScore(const Eigen::MatrixXd& A, int m, DesignCriterion criterion);

/// The scores of A under several criteria from one eigendecomposition: element c equals
/// CriterionScore(A, m, criteria[c]) bit for bit.
std::vector<double> CriterionScores(const Eigen::MatrixXd& A, int m,
                                    const std::vector<DesignCriterion>& criteria);

/// Scales the columns of G (N×n) as `scaling` says; `expected` holds each parameter's expected
/// error magnitude (rad or m) for kExpectedErrors. Column norms are those of G itself.
Eigen::MatrixXd ScaleColumns(const Eigen::MatrixXd& G, DesignScaling scaling,
                             const Eigen::VectorXd& expected = Eigen::VectorXd());

/// Expected error magnitudes of a parameter set's entries: `angle` (rad) for angular ones,
/// `length` (m) for the others; the column weights of DesignScaling::kExpectedErrors.
Eigen::VectorXd ExpectedErrors(const ParameterSet& parameters, double angle, double length);
/// The same for terms named `names` (IsAngularName, parameter_set.h): any kind's terms.
Eigen::VectorXd ExpectedErrors(const std::vector<std::string>& names, double angle, double length);

/// The task criterion's selection matrix (criterion I): G (N×n, SI) times L⁻ᵀ, where
/// W = LLᵀ = PᵀP + ridge and P (3M×n) stacks the position rows of ∂(pose)/∂e at M poses, so that
/// A on it is −tr(W·(GᵀG)⁻¹), the summed predicted mean-square position error at the poses per
/// unit reading variance. W is singular for terms that move no pose (plane, ranger): a ridge of
/// 1e-9·tr W/n keeps it invertible (those columns then weigh nothing).
Eigen::MatrixXd TaskWeightedJacobian(const Eigen::MatrixXd& G,
                                     const Eigen::MatrixXd& position_rows);

/// The Jacobian ∂y/∂e of `kind`'s measurements at `pool` at its nominal terms
/// (MeasurementJacobian, rows_per_configuration rows per candidate), columns scaled as
/// `scaling` says (expected errors `angle` rad and `length` m for kExpectedErrors): what design
/// selects from, for any measurement kind. SelectConfigurations chooses rows, so a kind of one
/// row per configuration (the ranger) is selected by configuration; blocks of rows (a tracker's
/// three) are chosen by SelectBlocks (block_selection.h).
Eigen::MatrixXd DesignJacobian(const MeasurementKind& kind, const TargetedConfigurations& pool,
                               DesignScaling scaling, double angle, double length);
/// The ranger's: the same for RangerMeasurement(model) (the bits of the identification's
/// Jacobian, IdentificationJacobian).
Eigen::MatrixXd DesignJacobian(const MeasurementModel& model, const TargetedConfigurations& pool,
                               DesignScaling scaling, double angle, double length);

/// Chooses k rows of G (N×n). Throws InputError for an empty pool, k > N, k < n, or an
/// exhaustive search beyond exhaustive_limit.
SelectionResult SelectConfigurations(const Eigen::MatrixXd& G, int k,
                                     const SelectionOptions& options, const RandomStream& stream);

/// Eigenvalues (ascending) of diag(lambda) + rho·z·zᵀ, rho = ±1, by the secular equation
/// (exposed for tests).
Eigen::VectorXd RankOneUpdatedEigenvalues(const Eigen::VectorXd& lambda, const Eigen::VectorXd& z,
                                          double rho);

}  // namespace lrcal
