// Results as JSON, the form `--format json` prints, the calibration report's calibration.json
// holds and the Python module returns: one builder per result type, shared by every front end so
// that a field has one name and one unit (SI unless its name says otherwise).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lrcal/design/design_choice.h"
#include "lrcal/design/identifiability_remedies.h"
#include "lrcal/identification/cross_validation.h"
#include "lrcal/identification/identification.h"
#include "lrcal/identification/measured_accuracy.h"
#include "lrcal/identification/total_accuracy.h"

namespace lrcal {

/// JSON of a result: keys in the order written (the order a reader meets them), unlike the
/// sorted-key Json of manifests and hashes (core/json.h).
using ResultJson = nlohmann::ordered_json;

/// A vector as a JSON array.
ResultJson ToJson(const Eigen::VectorXd& v);
/// A matrix as a JSON array of rows.
ResultJson ToJson(const Eigen::MatrixXd& m);

/// Rank, singular values, dependencies and suggested fixes.
ResultJson IdentifiabilityJson(const IdentifiabilityReport& r);
/// What each remedy recovers; `cheapest_fix` has one entry per lost direction (null: none found).
ResultJson RemediesJson(const RemedyReport& r);
/// An identification: parameters with their standard deviations, covariance, correlation, fit
/// check (suspects 1-based) and termination.
ResultJson IdentificationJson(const IdentificationSummary& s);
/// `lrcal accuracy --measured`'s numbers (SI): points, rms, worst, worst_point (1-based),
/// registered, instrument {xyz, rpy}, errors and targets.
ResultJson MeasuredAccuracyJson(const MeasuredAccuracy& r);
/// What readings tell against priors (`lrcal identifiability --prior-sigma`): sigma (m), per term
/// prior_sigma, posterior_sigma (null where unbounded), posterior_to_prior (null without a
/// prior), then set_by_prior and defined.
ResultJson PriorInformationJson(const PriorInformation& info);
/// K-fold cross-validation (configurations 1-based, like the fit's suspects).
ResultJson CrossValidationJson(const CrossValidation& cv);
/// Predicted accuracy at poses (`configs` gives each pose's joint values; SI): per pose the data
/// part (position_std, orientation_std, position_radius_95) and the total (the same names with
/// _total); the summary (rms_position, p95_position_radius_95 and their _total; `worst`
/// 1-based); `sources` (name, prior_sigma, defaulted, absorbed_by, position_rms,
/// orientation_rms, share), `defaulted` (held terms with the default σ), `defaults` (the
/// stated defaults in words) and `sigma_used`
/// (sigma, source "given" or "residual", reason).
/// The sources of a statement: name, prior_sigma (SI, null for the data part), defaulted,
/// absorbed_by (null when none), position_rms (m), orientation_rms (rad), share.
ResultJson AccuracySourcesJson(const std::vector<AccuracySource>& sources);
ResultJson PoseAccuracyJson(const AccuracyPrediction& prediction, const ConfigurationSet& configs);
/// A design certificate with its statement.
ResultJson CertificateJson(const DesignCertificate& certificate, const std::string& statement);
/// A design choice: the selected pool indices (0-based), scores, the random baseline, the
/// certificate and, for criterion I, the task's prediction.
ResultJson DesignChoiceJson(const DesignRequest& request, const DesignChoice& choice);

}  // namespace lrcal
