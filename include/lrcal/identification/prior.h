// What the user knows of the estimated terms before any reading: a standard deviation per term
// around its nominal value (a drawing's tolerance, a datasheet's accuracy, a previous
// calibration's uncertainty).
//
// With priors the identification solves for the maximum a-posteriori estimate: the prior enters
// as one extra residual per term, e_k with weight (σ/σ_k)² beside the readings' R_i·(ȳ_i − y_i)²,
// so it minimises  Σ R_i·(ȳ_i − y_i(e))²/σ² + Σ_k e_k²/σ_k²  (σ the noise of one reading), and
// the covariance is that of the augmented system, σ²·(GᵀWG + diag(σ²/σ_k²))⁻¹. A direction the
// readings cannot see is then set by the priors instead of stopping the identification; the
// ratio of a term's posterior to its prior standard deviation says how much the data informed it
// (near 1: the prior alone sets it).
//
// Priors are given by term name ("d6") or by class — the name without its digits: "theta" for
// every θ_i, "plane_u" for every plane's u1 and u2, "target_x" for every target's x — a name's
// own entry winning over its class's. Values carry their unit: rad, mrad, urad or deg for
// angles; m, mm or um for lengths; ppm for the ranger's scale; urad/Nm or rad/Nm for a joint's
// compliance (c3, class c) and ppm/K for a thermal coefficient (environment_measurement.h).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/measurement/measurement_kind.h"

namespace lrcal {

/// Above this ratio of a term's posterior to its prior standard deviation the term is "set by the
/// prior": the readings barely inform it.
inline constexpr double kSetByPriorRatio = 0.9;

/// The class of a term: its name without digits ("theta3" → "theta", "plane2_u1" → "plane_u",
/// "target2_x" → "target_x").
std::string TermClass(const std::string& name);

struct PriorSigmas {
  struct Entry {
    std::string key;  ///< a term's name, or a class (TermClass)
    double sigma;     ///< SI (rad, m, or dimensionless for the ranger's scale), > 0
  };
  std::vector<Entry> entries;

  bool empty() const { return entries.empty(); }
  /// Parses "theta=1mrad,a=0.5mm,d6=0.2mm,ranger_scale=200ppm". Throws InputError (where =
  /// `source`) naming the item for an unknown term or class, a missing or wrong unit (an angle in
  /// mm), a value that is not a finite number > 0, or a key given twice.
  static PriorSigmas Parse(const std::string& text, const std::string& source = "--prior-sigma");
  /// The prior σ (SI) of term `name`: its own entry, else its class's, else 0 (no prior).
  double SigmaOf(const std::string& name) const;
  /// The priors of `names` (SI), 0 where a term has none.
  Eigen::VectorXd SigmasOf(const std::vector<std::string>& names) const;
  /// These priors with `over`'s entries in place of any of the same key (a robot file's
  /// tolerances with the command line's --prior-sigma over them). A term's own entry still wins
  /// over its class's, whichever of the two gave it.
  PriorSigmas OverriddenBy(const PriorSigmas& over) const;
  /// "theta=1 mrad, d6=0.2 mm": the entries in their display units (DisplayUnitOf).
  std::string ToString() const;
};

/// How much readings inform each term against its prior, before any reading is taken: with the
/// readings' Jacobian G (rows: measured values), their weights w (repetitions), the noise σ of
/// one reading and the priors σ_k, the posterior covariance is (GᵀWG/σ² + diag(1/σ_k²))⁻¹.
struct PriorInformation {
  std::vector<std::string> names;
  double sigma = 0;                 ///< m, the noise of one reading assumed
  Eigen::VectorXd prior_sigma;      ///< SI, 0 where a term has no prior
  Eigen::VectorXd posterior_sigma;  ///< SI; infinite where neither readings nor priors see
  /// (GᵀWG/σ² + diag(1/σ_k²))⁻¹ (SI) when `defined`; empty otherwise.
  Eigen::MatrixXd posterior_covariance;
  Eigen::VectorXd posterior_to_prior;  ///< NaN where a term has no prior, or !defined
  /// Every direction is seen by the readings or set by a prior (the posterior is proper).
  bool defined = false;
  /// The terms whose posterior/prior ratio is above kSetByPriorRatio: the priors alone set them.
  std::vector<std::string> SetByPrior() const;
  /// A table: term, unit, prior, posterior, posterior/prior; then the terms set by the prior.
  std::string ToString() const;
};

/// PriorInformation of the terms `names` (G's columns). Throws InputError unless sigma > 0.
PriorInformation InformationFromPriors(const Eigen::MatrixXd& G, const std::vector<double>& weights,
                                       double sigma, const PriorSigmas& priors,
                                       const std::vector<std::string>& names);

/// The same for a kind's terms at `configs` (at the nominal model), each configuration the mean
/// of noise.repetitions readings of noise σ. Throws SettingError naming noise.sigma unless it is
/// > 0 (priors are weighed against it).
PriorInformation InformationFromPriors(const MeasurementKind& kind,
                                       const TargetedConfigurations& configs,
                                       const NoiseModel& noise, const PriorSigmas& priors);

/// A kind's evaluator with one more row per term that has a prior: row m + p predicts the term's
/// deviation e_k (its measured value is 0, the nominal) with Jacobian row e_kᵀ. With weights
/// (σ/σ_k)² on those rows the least-squares solution of the augmented rows is the maximum
/// a-posteriori estimate (file comment). The data evaluator must outlive this one.
class PriorRowsEvaluator : public MeasurementEvaluator {
 public:
  /// `terms`: the columns with a prior, ascending.
  PriorRowsEvaluator(MeasurementEvaluator& data, std::vector<int> terms);
  int num_rows() const override;
  int num_parameters() const override { return data_.num_parameters(); }
  bool Predict(const double* e, double* y, double* J) override;

 private:
  MeasurementEvaluator& data_;
  std::vector<int> terms_;
  std::vector<double> scratch_;
};

}  // namespace lrcal
