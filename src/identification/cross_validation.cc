#include "lrcal/identification/cross_validation.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/settings.h"

namespace lrcal {

std::string CrossValidation::ToString() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(4);
  out << "cross-validation: " << folds << " folds (configuration i in fold i mod " << folds << "), "
      << predictions.size() << " held-out configurations predicted";
  if (!failed_folds.empty()) out << ", " << failed_folds.size() << " fold(s) not fitted";
  out << "\n";
  for (const auto& [fold, why] : failed_folds) out << "  fold " << fold << ": " << why << "\n";
  if (predictions.empty()) return out.str();
  out << "  held-out error RMS " << rms_error * 1e3 << " mm, predicted " << rms_predicted * 1e3
      << " mm (ratio " << std::setprecision(3) << rms_error / rms_predicted << "); mean z^2 "
      << mean_z2 << " (about 1 +- " << mean_z2_tolerance << " expected)\n";
  if (consistent()) {
    out << "  held-out readings are predicted as well as the fit says they are\n";
  } else {
    out << "  held-out readings are predicted WORSE than the fit says: the model misses "
           "something (a second plane, a ranger offset or scale, joint errors), the stated "
           "noise is too small, or some readings are outliers\n";
  }
  if (!beyond_4.empty()) {
    out << "  held-out beyond 4 predicted std (configuration, 1-based):";
    for (int i : beyond_4) out << " " << i + 1;
    out << "\n";
  }
  return out.str();
}

namespace {

MeasurementSet FoldData(const MeasurementSet& data, int folds, int fold, bool held_out) {
  MeasurementSet out;
  out.configs = TargetedConfigurations(data.configs.num_joints());
  for (int i = 0; i < data.size(); ++i) {
    if ((i % folds == fold) != held_out) continue;
    out.configs.AddFrom(data.configs, i);
    out.mean_h.push_back(data.mean_h[i]);
    out.repetitions.push_back(data.repetitions[i]);
    if (!data.variance_factor.empty()) out.variance_factor.push_back(data.variance_factor[i]);
  }
  return out;
}

// Predicts the held-out configurations of `fold` from the fit of the others; returns "" or why
// the fold could not be fitted.
std::string PredictFold(const MeasurementModel& model, const MeasurementSet& data, int folds,
                        int fold, const IdentificationOptions& options,
                        std::vector<HeldOutReading>* out) {
  IdentificationOptions fold_options = options;
  fold_options.robust_fit_check = false;  // a fold's fit verdict is not used
  const IdentificationSummary s = Identify(model, FoldData(data, folds, fold, false), fold_options);
  if (!s.IsSolutionUsable()) return s.message.empty() ? "the fit did not converge" : s.message;
  const bool given = options.sigma > 0;
  const Eigen::MatrixXd& C = given ? s.covariance_given : s.covariance_residual;
  const double sigma = given ? options.sigma : s.sigma_hat;
  if (!C.allFinite() || !std::isfinite(sigma))
    return "no residual degrees of freedom without this fold, and no sigma given";
  const MeasurementModel solved(model.robot(), model.nominal_planes(),
                                WithoutParameters(model.robot(), model.parameters(), s.fixed));
  ModelPoint point;
  solved.Prepare(s.delta.data(), &point);
  Eigen::VectorXd g(solved.num_parameters());
  for (int i = fold; i < data.size(); i += folds) {
    double h = 0;
    solved.Evaluate(point, data.configs, i, &h, g.data());
    HeldOutReading r;
    r.configuration = i;
    r.fold = fold;
    r.error = data.mean_h[i] - h;
    r.predicted_std = std::sqrt(sigma * sigma / data.Weight(i) + g.dot(C * g));
    r.z = r.error / r.predicted_std;
    out->push_back(r);
  }
  return "";
}

}  // namespace

CrossValidation CrossValidate(const MeasurementModel& model, const MeasurementSet& data, int folds,
                              const IdentificationOptions& options) {
  if (folds < 2 || folds > data.size())
    throw SettingError(
        SettingSpec::Named("identification", "holdout", "holdout", "cross-validation folds"),
        "expected 2 to " + std::to_string(data.size()) +
            " folds (the number of configurations), got " + std::to_string(folds));
  CrossValidation cv;
  cv.folds = folds;
  for (int f = 0; f < folds; ++f) {
    const std::string why = PredictFold(model, data, folds, f, options, &cv.predictions);
    if (!why.empty()) cv.failed_folds.emplace_back(f, why);
  }
  std::sort(cv.predictions.begin(), cv.predictions.end(),
            [](const HeldOutReading& a, const HeldOutReading& b) {
              return a.configuration < b.configuration;
            });
  const double n = static_cast<double>(cv.predictions.size());
  if (n == 0) return cv;
  double e2 = 0, v = 0, z2 = 0;
  for (const auto& r : cv.predictions) {
    e2 += r.error * r.error;
    v += r.predicted_std * r.predicted_std;
    z2 += r.z * r.z;
    if (std::fabs(r.z) > 4) cv.beyond_4.push_back(r.configuration);
  }
  cv.rms_error = std::sqrt(e2 / n);
  cv.rms_predicted = std::sqrt(v / n);
  cv.mean_z2 = z2 / n;
  cv.mean_z2_tolerance = 3 * std::sqrt(2 / n);
  return cv;
}

}  // namespace lrcal
