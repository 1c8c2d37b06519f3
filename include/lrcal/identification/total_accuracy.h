// What a calibration cannot see: the total predicted error of a calibrated arm — the part the
// reading noise leaves in the estimated terms, plus everything the calibration did not estimate
// (fixed parameters, combinations lost to rank deficiency, plane and ranger terms taken as
// known), each propagated from its prior standard deviation.
//
// Model (first order, around the estimate). The readings depend on the estimated terms e and on
// the terms u the calibration holds at their nominal values: ȳ = y(e, u) + noise. With the
// readings' Jacobians G (∂y/∂e) and G_u (∂y/∂u), the weights W = diag(R_i)/σ² and the priors
// Λ = diag(1/σ_k²) of estimated terms that have one (none: Λ = 0), a deviation u of the held
// terms moves the estimate by
//     ê − e = S·u,   S = (GᵀWG + Λ)⁻¹ GᵀW G_u          (the "estimate shift", n × k)
// — the estimated terms absorb what they can of u. At a pose with Jacobians P (∂pose/∂e) and P_u
// (∂pose/∂u; zero for plane and ranger terms, which do not move the arm) the calibrated model's
// pose error is P·(ê − e) − P_u·u, so with u ~ N(0, diag σ_u²) independent of the noise
//     Σ_total = P·C·Pᵀ + (P·S − P_u)·diag(σ_u²)·(P·S − P_u)ᵀ
// (C the estimate's covariance from the noise). Each held term k is one *source*: its column
// (P·S − P_u)_k·σ_k, whose mean square over the poses is its share of the total mean square; the
// estimated parameters' share is the data part. A robust loss is linearised with unit weights.
//
// Where no tolerance is known for a held term the stated defaults below apply, and the terms
// they applied to are listed so every statement can warn about them. The base and tool
// transforms are the exception: without a tolerance (the robot file's tolerances.base and
// tolerances.tool, or --prior-sigma base_x=...) they are exact by definition, because lrcal
// cannot tell whether the base frame B is the robot's own (then its base transform has no error)
// or a frame outside it (the planes', the cell's), nor whether the tool frame is the ranger's
// by definition; the statements name them as taken as exact.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/identification/identification.h"
#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/identification/prior.h"
#include "lrcal/measurement/measurement_model.h"
#include "lrcal/measurement/measurement_set.h"

namespace lrcal {

/// Prior standard deviations of held terms nobody gave a tolerance for (SI).
struct DefaultTolerances {
  double angle = 1e-3;          ///< rad: θ, α, β, a plane's normal chart coordinates
  double length = 1e-3;         ///< m: a, d, a plane's offset f
  double ranger_offset = 5e-4;  ///< m
  double ranger_scale = 2e-4;   ///< dimensionless (200 ppm)
  /// The default of term `name` (by its unit class: IsAngularName, ranger_offset, ranger_scale).
  double Of(const std::string& name) const;
  /// "1 mm, 1 mrad, 0.5 mm (ranger offset), 200 ppm (ranger scale)".
  std::string ToString() const;
};

/// The terms a calibration held at nominal and how each moves its estimate (file comment).
struct UnestimatedTerms {
  std::vector<std::string> names;      ///< held terms, in the complete set's order
  Eigen::VectorXd sigma;               ///< their prior σ (SI)
  std::vector<std::string> defaulted;  ///< the held terms whose σ is DefaultTolerances'
  Eigen::MatrixXd estimate_shift;      ///< S: estimated terms × held terms, ∂ê/∂u
  /// Base and tool terms neither estimated nor given a tolerance: taken as exact (not sources).
  std::vector<std::string> exact;
  bool empty() const { return names.empty(); }
};

/// Every term a ranger set-up could estimate on `robot` with `num_planes` planes: each robot
/// parameter, each plane's u1, u2 and f, the ranger's offset and scale, the base's and the tool's
/// six terms (MakeParameterSet's order).
ParameterSet CompleteParameterSet(const RobotModel& robot, int num_planes);
/// "the base transform, tool_x tool_y": the frames whose six terms are all in `exact`, then the
/// other frame terms in `exact` by name.
std::string ExactFramesText(const std::vector<std::string>& exact);

/// The held terms of the identification `s` of `data` on `model` (SolvedModel's parameter set:
/// the requested set without the terms fixed for rank deficiency): their σ from `known` (the
/// robot file's tolerances and --prior-sigma), else the defaults; S at the estimate. The noise σ
/// and the priors of the estimated terms are `options`' (σ cancels without priors).
UnestimatedTerms FindUnestimatedTerms(const MeasurementModel& solved,
                                      const IdentificationSummary& s, const MeasurementSet& data,
                                      const IdentificationOptions& options,
                                      const PriorSigmas& known,
                                      const DefaultTolerances& defaults = {});

/// One source of error at the predicted poses.
struct AccuracySource {
  std::string name;        ///< "estimated parameters (reading noise)" or a held term's name
  double prior_sigma = 0;  ///< SI; 0 for the estimated parameters
  bool defaulted = false;  ///< prior_sigma is the stated default
  /// The estimated term that absorbs most of this term's deviation (|S_ik|·σ_k/std_i largest,
  /// above 0.1); "" when the readings do not see the term (it moves the pose unabsorbed).
  std::string absorbed_by;
  double position_rms = 0;     ///< m, RMS over the poses of this source's position error
  double orientation_rms = 0;  ///< rad
  double share = 0;            ///< its part of the total mean-square position error, 0..1
};

/// Which σ of one reading a statement's data part uses, and why.
struct SigmaUsed {
  double sigma = 0;    ///< m
  std::string source;  ///< "given" or "residual"
  std::string reason;  ///< why, in words (e.g. the χ² check rejected the given σ)
};

/// The σ an identification's statements use: the given σ unless the fit check rejects it (then
/// σ̂ from the residuals, and the reason says so), σ̂ when none was given. The covariance goes
/// with it (FitCovariance, or the residual-based one when the given σ is rejected).
SigmaUsed ChooseSigma(const IdentificationSummary& s, const IdentificationOptions& options);
const Eigen::MatrixXd& CovarianceFor(const IdentificationSummary& s, const SigmaUsed& used);

/// The accuracy statement at a set of poses: per pose the data part and the total, and the
/// sources of the total over the poses (largest first, the data part among them).
struct AccuracyPrediction {
  std::vector<PoseAccuracy> poses;
  std::vector<AccuracySource> sources;
  std::vector<std::string> defaulted;  ///< held terms with the default σ
  std::vector<std::string> exact;      ///< base and tool terms taken as exact (UnestimatedTerms)
  DefaultTolerances defaults;
  SigmaUsed sigma_used;
  /// RMS over the poses of the total position error (m), and the 95th percentile of the total
  /// 95 % radius (m).
  double rms_position_total = 0;
  double p95_radius_95_total = 0;
};

/// The total prediction at `configs` for the estimate e (of `solved`'s parameter set) with
/// covariance C and the held terms `held` (their estimate shift laid out for e). With no held
/// terms the total equals the data part.
AccuracyPrediction PredictTotalAccuracy(const MeasurementModel& solved, const double* e,
                                        const Eigen::MatrixXd& covariance,
                                        const UnestimatedTerms& held,
                                        const ConfigurationSet& configs);

/// The pose error of one prior σ of each held term at `configs` for the estimate e of `solved`'s
/// parameter set: (P·S − P_u)·diag(σ), six rows per configuration (position, then orientation, as
/// PoseJacobian lays them out), one column per held term. A draw w ~ N(0, I) gives the held
/// terms' part of the calibrated model's pose error, M·w.
Eigen::MatrixXd HeldTermPoseColumns(const MeasurementModel& solved, const double* e,
                                    const UnestimatedTerms& held, const ConfigurationSet& configs);

/// The statement at `poses` after the identification `s` on `model`, what `identify --predict-at`
/// and the calibration report give: the σ ChooseSigma picks with its covariance, the estimate
/// and the held terms `held` (FindUnestimatedTerms). Empty when that covariance is undefined (as
/// many configurations as parameters and no σ given); each front end says so in its words.
std::optional<AccuracyPrediction> PredictAccuracyAfterFit(const MeasurementModel& model,
                                                          const IdentificationSummary& s,
                                                          const IdentificationOptions& options,
                                                          const UnestimatedTerms& held,
                                                          const ConfigurationSet& poses);

/// The sources of a statement as a table: name, prior σ (and whether it is the default), the
/// estimated term that absorbs it, its position and orientation RMS over the poses (mm, mrad) and
/// its share of the total mean square; the twelve largest, the rest summed in one row.
std::string AccuracySourceTable(const AccuracyPrediction& prediction);

/// The statement as text: the summary, the σ used, the source table, a warning naming the terms
/// that took a default tolerance (if any), then the per-pose table (data part and total, mm and
/// mrad).
std::string AccuracyPredictionText(const AccuracyPrediction& prediction);

}  // namespace lrcal
