// Identification of the geometric parameters (and plane terms) from laser-plane readings.
//
// Least squares on the distance residuals r_i = √R_i·(h̄_i − h(e, q_i)), h̄_i the mean of R_i
// readings at configuration i (equal-weight readings: the same estimate as using every reading),
// starting from the nominal model e = 0. Two solvers, tested to agree to 1e-9:
//  - kLevenbergMarquardt: lrcal's own Levenberg–Marquardt on the analytic Jacobian, normal
//    equations accumulated in one pass, no allocation per iteration once the workspace is warm.
//    The Monte-Carlo hot path.
//  - kCeres: Ceres' Levenberg–Marquardt on the same analytic cost (one residual block for all
//    configurations). The reference path.
// With a robust loss (Huber, Cauchy: Ceres' definitions, on each configuration's weighted
// residual) both solve least squares first and then refine from that estimate to the minimum of
// ½·Σρ(r_i²); they agree to 1e-8.
// A rank-deficient parameter set is detected before solving (identifiability.h) and reported as
// Termination::kRankDeficient with the dependencies, unless the options say to fix the suggested
// parameters and go on.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "lrcal/core/enum_names.h"
#include "lrcal/core/settings.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/linearisation_check.h"
#include "lrcal/identification/prior.h"
#include "lrcal/measurement/measurement_model.h"
#include "lrcal/measurement/measurement_set.h"

namespace lrcal {

enum class RobustLoss { kNone, kHuber, kCauchy };
inline constexpr EnumName<RobustLoss> kRobustLossNames[] = {
    {RobustLoss::kNone, "none"}, {RobustLoss::kHuber, "huber"}, {RobustLoss::kCauchy, "cauchy"}};

struct IdentificationOptions {
  enum class Solver { kLevenbergMarquardt, kCeres };  ///< names: kSolverNames
  /// lrcal's own LM is the fast default; kCeres is the reference. Both take the robust losses.
  Solver solver = Solver::kLevenbergMarquardt;
  RobustLoss loss = RobustLoss::kNone;
  /// Scale of the robust loss (m), applied to each configuration's weighted residual
  /// √R·(h̄ − h): residuals beyond it are down-weighted. Unused when loss_scale_sigma > 0.
  double loss_scale = 1e-3;
  /// The same scale in multiples of one reading's σ (`sigma`, which it needs): 1.345 for Huber,
  /// 2.385 for Cauchy give 95 % efficiency under Gaussian noise. 0: the scale is loss_scale.
  double loss_scale_sigma = 0;
  int max_iterations = 100;
  /// Iterations of the robust refinement (after least squares). Its own budget: at loss scales
  /// far below the noise nearly every residual is in the loss' tail and the refinement
  /// converges only linearly (Ceres' too), e.g. ~200 iterations at 0.005 σ.
  int max_robust_iterations = 1000;
  /// Stop when the step is below parameter_tolerance·(‖e‖ + parameter_tolerance). Ceres'
  /// defaults stop measurably short of the minimum on this problem (DESIGN.md); 1e-12 reaches
  /// it to rounding.
  double parameter_tolerance = 1e-12;
  /// Stop when the cost decreases by less than this fraction.
  double function_tolerance = 1e-16;
  /// Per-reading standard deviation (m) if known, for the "given σ" covariance; 0 = unknown.
  double sigma = 0;
  /// What to do with a rank-deficient parameter set: stop (kRankDeficient) or fix the
  /// identifiability analysis' suggested parameters at nominal and identify the rest.
  bool fix_dependent_parameters = false;
  IdentifiabilityOptions identifiability;
  /// Errors in variables: the standard deviation of each recorded joint value (rad; m for a
  /// prismatic joint), one error per configuration. Each measured value's variance becomes
  /// σ²/R + σ_q²·Σ_j (∂y/∂q_j)² (the joint gradient at the nominal model, by central
  /// differences), so the weights, the covariance, the χ² check and every accuracy statement
  /// account for it. Needs `sigma`. 0: exact joint values, bit for bit as without this field.
  double encoder_sigma = 0;
  /// Prior standard deviations of the estimated terms (prior.h): when given, the maximum
  /// a-posteriori estimate around the nominal values, which needs `sigma` (the priors are weighed
  /// against the readings' noise). Empty: least squares, bit for bit as without this field.
  PriorSigmas priors;
  /// With a robust loss and `sigma`, judge the fit by the robust scale of its residuals
  /// (FitCheck::robust_*: 1999 Monte-Carlo draws of the statistic, a few ms for a hundred
  /// configurations). Off where nothing reads the verdict (a study's trials); then the fit check
  /// is χ²'s as without a robust loss.
  bool robust_fit_check = true;
  /// Check the covariance against the model's curvature (linearisation_check.h) and report it in
  /// IdentificationSummary::linearisation: 2n + 4·n(n−1)/2 extra predictions, so off where
  /// nothing reads it (a study's trials); lrcal identify turns it on.
  bool check_linearisation = false;
  /// The numeric settings (settings.h): max_iterations (1 to 10,000), max_robust_iterations (1
  /// to 1,000,000), parameter_tolerance and function_tolerance (≥ 0), sigma_mm (σ, ≥ 0 mm; the
  /// command line's --sigma-mm), loss_scale_mm (> 0 mm; --loss-scale-mm) and loss_scale_sigma
  /// (≥ 0 multiples of σ; --loss-scale-sigma). Every front end spells the loss scale these two
  /// ways, its unit in its name; a study gives σ as noise.sigma_mm.
  static const std::vector<SettingField<IdentificationOptions>>& Settings();
  /// Throws SettingError naming the library field (identification.sigma, ...) and the range;
  /// with priors, naming identification.priors unless sigma > 0; with loss_scale_sigma > 0,
  /// naming it unless sigma > 0.
  void Validate() const;
  /// The robust loss scale in metres: loss_scale_sigma · sigma if loss_scale_sigma > 0, else
  /// loss_scale.
  double LossScale() const { return loss_scale_sigma > 0 ? loss_scale_sigma * sigma : loss_scale; }
};

/// Solver names in study files and options.
inline constexpr EnumName<IdentificationOptions::Solver> kSolverNames[] = {
    {IdentificationOptions::Solver::kLevenbergMarquardt, "lm"},
    {IdentificationOptions::Solver::kCeres, "ceres"}};

enum class Termination {
  kConverged,         ///< a tolerance was met: the estimate is the least-squares minimum
  kMaxIterations,     ///< stopped at max_iterations without meeting a tolerance
  kRankDeficient,     ///< the parameter set is not identifiable from these configurations
  kBeamMissed,        ///< at some iterate the model's beam ran parallel to the plane
  kNumericalFailure,  ///< non-finite cost or a failed factorisation
  kInvalidInput,      ///< too few readings, bad options
};
inline constexpr EnumName<Termination> kTerminationNames[] = {
    {Termination::kConverged, "converged"},
    {Termination::kMaxIterations, "max_iterations"},
    {Termination::kRankDeficient, "rank_deficient"},
    {Termination::kBeamMissed, "beam_missed"},
    {Termination::kNumericalFailure, "numerical_failure"},
    {Termination::kInvalidInput, "invalid_input"}};
inline const char* TerminationName(Termination t) { return NameOf(kTerminationNames, t); }

/// How well the estimate fits the readings: the χ² test against a stated noise, and the
/// configurations whose residuals stand out.
struct FitCheck {
  /// The reading noise σ was given (IdentificationOptions::sigma): chi2, p_value, consistent
  /// test against it. Otherwise residuals are standardised by σ̂ and there is no test.
  bool sigma_given = false;
  /// χ² = Σ R_i·(h̄_i − h_i)²/σ² (the mean of R readings has variance σ²/R); NaN without σ.
  double chi2 = std::numeric_limits<double>::quiet_NaN();
  int dof = 0;  ///< configurations − parameters
  /// P(χ²_dof ≥ chi2): below 0.001 the fit is inconsistent with σ. NaN without σ or dof.
  double p_value = std::numeric_limits<double>::quiet_NaN();
  bool consistent = true;  ///< p_value ≥ 0.001 (true when there is no test)
  /// √R_i·(ȳ_i − y_i)/s per measured value, s = σ if given, else σ̂ (empty when neither is).
  /// For the ranger a measured value is a configuration's mean reading h̄_i.
  std::vector<double> standardized;
  /// Measured values (0-based, data order) with |standardized| > 4: readings to check. For the
  /// ranger these are configurations; a kind with k values per configuration has value c of
  /// configuration i at i·k + c.
  std::vector<int> suspects;
  /// Measured values per configuration (measurement_kind.h): 1 for the ranger.
  int rows_per_configuration = 1;
  /// The configurations' labels (MeasurementSet::labels) when the data has them: suspects are
  /// then named by label as well as by number. Empty otherwise.
  std::vector<std::string> configuration_labels{};
  /// Configuration i's label, or "" without labels.
  std::string LabelOf(int configuration) const;
  /// The label of each suspect's configuration, in the order of `suspects`; empty without labels.
  std::vector<std::string> SuspectLabels() const;
  /// With priors (prior.h): how many terms have one, and their part of chi2, Σ e_k²/σ_k² (the
  /// rest is the readings'). A large part says the priors are tighter than the terms' true
  /// deviations. NaN without σ.
  int num_priors = 0;
  double chi2_priors = std::numeric_limits<double>::quiet_NaN();
  /// A robust fit (IdentificationOptions::loss other than none) with σ given is judged by the
  /// robust scale of its standardised residuals instead of χ² (which the outliers a robust loss
  /// is meant for would fail): robust_scale = 1.4826·median|z_i| (1 for Gaussian residuals of
  /// known σ), and robust_p_value = P(scale ≥ robust_scale) under the linearised null (Gaussian
  /// readings of the stated σ, the fit's own projection of them), by kRobustCheckDraws
  /// Monte-Carlo draws: (1 + #{draws ≥ observed})/(1 + draws), so the test has level 0.001 at
  /// the threshold. `consistent` then means robust_p_value > 0.001. NaN otherwise.
  bool robust = false;
  double robust_scale = std::numeric_limits<double>::quiet_NaN();
  double robust_p_value = std::numeric_limits<double>::quiet_NaN();
  static constexpr int kRobustCheckDraws = 1999;
  /// Which test decided `consistent`: "chi2", "robust_scale", or "none" without σ.
  const char* TestName() const;
  /// The verdict in words, with the likely causes when the fit is inconsistent.
  std::string Explain() const;
};

struct IdentificationSummary {
  std::vector<std::string> names;  ///< estimated quantities (parameter_set.h)
  Eigen::VectorXd nominal;   ///< their nominal values (link values; 0 for u; f0 for plane_f), SI
  Eigen::VectorXd estimate;  ///< nominal + delta
  Eigen::VectorXd delta;     ///< the identified errors e, SI
  Eigen::VectorXd std_residual;         ///< √diag of covariance_residual
  Eigen::VectorXd std_given;            ///< √diag of covariance_given (empty unless sigma > 0)
  Eigen::MatrixXd covariance_residual;  ///< σ̂²·(GᵀWG)⁻¹, σ̂² = Σ r²/(m − n)
  Eigen::MatrixXd covariance_given;     ///< σ²·(GᵀWG)⁻¹ with the given per-reading σ
  Eigen::MatrixXd correlation;          ///< from covariance_residual
  /// m, residual-based per-reading σ estimate; NaN when there are no more configurations than
  /// parameters (no residual degrees of freedom: the residual-based covariance is undefined)
  double sigma_hat = 0;
  FitCheck fit;
  double initial_cost = 0;  ///< ½Σr² at the nominal model (m²)
  double final_cost = 0;    ///< ½Σr² at the estimate (m²)
  double residual_rms = 0;  ///< m, RMS of h̄_i − h(e, q_i) over configurations
  int iterations = 0;
  int num_configurations = 0;
  Termination termination = Termination::kInvalidInput;
  std::string message;                    ///< why it stopped, in words
  std::vector<std::string> fixed;         ///< parameters fixed because of rank deficiency
  IdentifiabilityReport identifiability;  ///< of the parameter set at the nominal model
  std::string solver;                     ///< "lrcal-lm" or "ceres"
  /// The cost minimised, in words: "least squares", or "huber loss, scale 0.269 mm" (the
  /// scale on each configuration's weighted residual √R·(h̄ − h)).
  std::string loss = "least squares";
  /// Whether the stated covariance (covariance_given with σ, else covariance_residual) holds
  /// at second order; computed with IdentificationOptions::check_linearisation.
  LinearisationCheck linearisation;
  /// With priors (IdentificationOptions::priors): each estimated term's prior σ (SI, 0 where it
  /// has none) and the ratio of its posterior standard deviation (given σ) to it (NaN where it
  /// has none): near 1 the prior alone sets the term. Empty without priors.
  Eigen::VectorXd prior_sigma;
  Eigen::VectorXd posterior_to_prior;
  /// Above this ratio a term is "set by the prior" (prior.h): the readings barely inform it.
  static constexpr double kSetByPrior = kSetByPriorRatio;
  /// The terms set by the prior (posterior_to_prior > kSetByPrior), in parameter order.
  std::vector<std::string> SetByPrior() const;

  bool IsSolutionUsable() const { return termination == Termination::kConverged; }
  /// One line: solver, loss, termination, iterations, sizes, cost, residual RMS.
  std::string BriefReport() const;
  /// `lrcal identify`'s text: the brief report, then σ̂, the fit check, the parameter table and
  /// the parameters fixed for rank deficiency; or, unusable, the solver's message (and, when the
  /// set is rank-deficient, the identifiability report).
  std::string FullReport() const;
  /// The identified parameters as a text table (delta and std in mm / mrad); "" unless usable.
  std::string ParameterTable() const;
};

/// The covariance σ²·A⁻¹ of a least-squares estimate from its normal matrix A = GᵀWG (by LDLᵀ);
/// σ is the per-reading standard deviation (m). The one place both the identification summary
/// and the Monte-Carlo prediction compute it.
Eigen::MatrixXd ParameterCovariance(const Eigen::MatrixXd& normal_matrix, double sigma);

/// Identifies the model's parameter set from `data` (its configuration labels, if any, go to the
/// fit check).
IdentificationSummary Identify(const MeasurementModel& model, const MeasurementSet& data,
                               const IdentificationOptions& options = {});

/// Identifies any measurement kind's terms (measurement_kind.h) from `data`: the same solvers,
/// identifiability check, covariance and fit check as the ranger's overload above, on every
/// measured value (rows_per_configuration per configuration, each weighted by its
/// configuration's repetitions). With priors (options.priors) the maximum a-posteriori estimate
/// (prior.h): the identifiability check, the covariance and the fit check (χ² over the readings
/// and the prior rows, dof = values + priors − terms) are those of the augmented system, and the
/// ranger's overload above comes here. A robust loss is refused for kinds with more than one value
/// per configuration (message). For a RangerMeasurement it agrees with the overload above to
/// rounding (its statistics come from the batch kernel instead of the per-configuration path).
IdentificationSummary Identify(const MeasurementKind& kind, const MeasuredValues& data,
                               const IdentificationOptions& options = {});

/// Errors in variables: each measured value's weight σ²/var (in units of single readings) for
/// recorded joint values with standard deviation `joint_sigma` (rad, or m for a prismatic
/// joint), one error per configuration: var = σ²/R + joint_sigma²·Σ_j (∂y/∂q_j)², R the value's
/// own weight (data.RowWeights: its repetitions, or R/c for a median), the joint gradient at the
/// nominal model by central differences (step 1e-6).
std::vector<double> ErrorsInVariablesWeights(const MeasurementKind& kind,
                                             const MeasuredValues& data, double sigma,
                                             double joint_sigma);

/// The model Identify solved: `model`'s parameter set without the parameters it fixed for rank
/// deficiency (s.delta is laid out for it).
MeasurementModel SolvedModel(const MeasurementModel& model, const IdentificationSummary& s);

/// The estimate's covariance: with the given σ when options.sigma > 0, else residual-based.
const Eigen::MatrixXd& FitCovariance(const IdentificationSummary& s,
                                     const IdentificationOptions& options);

}  // namespace lrcal
