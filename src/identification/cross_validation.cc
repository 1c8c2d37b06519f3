#include "lrcal/identification/cross_validation.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/settings.h"
#include "lrcal/measurement/measurement_kind.h"

namespace lrcal {

std::string CrossValidation::ToString() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(4);
  std::size_t configurations = 0;  // predictions are sorted by configuration
  for (std::size_t i = 0; i < predictions.size(); ++i)
    if (i == 0 || predictions[i].configuration != predictions[i - 1].configuration)
      ++configurations;
  out << "cross-validation: " << folds << " folds (configuration i in fold i mod " << folds << "), "
      << configurations << " held-out configurations predicted";
  if (configurations != predictions.size()) out << " (" << predictions.size() << " values)";
  if (!failed_folds.empty()) out << ", " << failed_folds.size() << " fold(s) not fitted";
  out << "\n";
  for (const auto& [fold, why] : failed_folds) out << "  fold " << fold << ": " << why << "\n";
  if (predictions.empty()) return out.str();
  const auto mean_z2_text = [&] {
    out << "mean z^2 " << mean_z2 << " (about 1 +- " << mean_z2_tolerance << " expected)\n";
  };
  if (rms_predicted_angle > 0) {  // lengths and angles apart, then z over every value
    if (rms_predicted > 0)
      out << "  held-out error RMS " << rms_error * 1e3 << " mm, predicted " << rms_predicted * 1e3
          << " mm (ratio " << std::setprecision(3) << rms_error / rms_predicted << ")\n"
          << std::setprecision(4);
    out << "  held-out angle error RMS " << rms_error_angle * 1e3 << " mrad, predicted "
        << rms_predicted_angle * 1e3 << " mrad (ratio " << std::setprecision(3)
        << rms_error_angle / rms_predicted_angle << ")\n  ";
    mean_z2_text();
  } else {
    out << "  held-out error RMS " << rms_error * 1e3 << " mm, predicted " << rms_predicted * 1e3
        << " mm (ratio " << std::setprecision(3) << rms_error / rms_predicted << "); ";
    mean_z2_text();
  }
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

// A fold's fit options: its fit verdict is not used.
IdentificationOptions FoldOptions(const IdentificationOptions& options) {
  IdentificationOptions fold = options;
  fold.robust_fit_check = false;
  return fold;
}

// The fold fit's covariance and σ (the given ones when options.sigma > 0, else residual-based);
// "" or why the fold cannot predict.
std::string FoldStatistics(const IdentificationSummary& s, const IdentificationOptions& options,
                           const Eigen::MatrixXd** C, double* sigma) {
  if (!s.IsSolutionUsable()) return s.message.empty() ? "the fit did not converge" : s.message;
  const bool given = options.sigma > 0;
  *C = given ? &s.covariance_given : &s.covariance_residual;
  *sigma = given ? options.sigma : s.sigma_hat;
  if (!(*C)->allFinite() || !std::isfinite(*sigma))
    return "no residual degrees of freedom without this fold, and no sigma given";
  return "";
}

// Predicts the held-out configurations of `fold` from the fit of the others; returns "" or why
// the fold could not be fitted.
std::string PredictFold(const MeasurementModel& model, const MeasurementSet& data, int folds,
                        int fold, const IdentificationOptions& options,
                        std::vector<HeldOutReading>* out) {
  const IdentificationSummary s =
      Identify(model, FoldData(data, folds, fold, false), FoldOptions(options));
  const Eigen::MatrixXd* C = nullptr;
  double sigma = 0;
  const std::string why = FoldStatistics(s, options, &C, &sigma);
  if (!why.empty()) return why;
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
    r.predicted_std = std::sqrt(sigma * sigma / data.Weight(i) + g.dot(*C * g));
    r.z = r.error / r.predicted_std;
    out->push_back(r);
  }
  return "";
}

// The values of `data` in (held_out) or out of `fold`, with their weights.
MeasuredValues FoldValues(const MeasuredValues& data, int k, int folds, int fold, bool held_out) {
  MeasuredValues out{TargetedConfigurations(data.configs.num_joints()), {}, {}};
  const std::vector<double> weights = data.RowWeights(k);
  for (int i = 0; i < data.size(); ++i) {
    if ((i % folds == fold) != held_out) continue;
    out.configs.AddFrom(data.configs, i);
    const auto first = static_cast<std::size_t>(i) * static_cast<std::size_t>(k);
    out.y.insert(out.y.end(), data.y.begin() + static_cast<long>(first),
                 data.y.begin() + static_cast<long>(first + static_cast<std::size_t>(k)));
    out.repetitions.push_back(data.repetitions[static_cast<std::size_t>(i)]);
    if (!data.weights.empty())
      out.weights.insert(out.weights.end(), weights.begin() + static_cast<long>(first),
                         weights.begin() + static_cast<long>(first + static_cast<std::size_t>(k)));
  }
  return out;
}

// The kind's PredictFold: every value of the held-out configurations of `fold`.
std::string PredictKindFold(const MeasurementKind& kind, const MeasuredValues& data, int folds,
                            int fold, const IdentificationOptions& options,
                            std::vector<HeldOutReading>* out) {
  const int k = kind.rows_per_configuration();
  const IdentificationSummary s =
      Identify(kind, FoldValues(data, k, folds, fold, false), FoldOptions(options));
  const Eigen::MatrixXd* C = nullptr;
  double sigma = 0;
  const std::string why = FoldStatistics(s, options, &C, &sigma);
  if (!why.empty()) return why;
  const std::unique_ptr<MeasurementKind> solved = kind.Without(s.fixed);
  const MeasuredValues held = FoldValues(data, k, folds, fold, true);
  const std::vector<double> weights = held.RowWeights(k);
  const auto rows = static_cast<Eigen::Index>(held.y.size());
  std::vector<double> y(static_cast<std::size_t>(rows));
  Eigen::MatrixXd J(rows, solved->num_parameters());
  if (!solved->Bind(held.configs)->Predict(s.delta.data(), y.data(), J.data()))
    return "a held-out value is undefined at the fold's estimate";
  for (Eigen::Index r = 0; r < rows; ++r) {
    const auto c = static_cast<int>(r / k);
    HeldOutReading h;
    h.configuration = fold + c * folds;
    h.fold = fold;
    h.component = static_cast<int>(r % k);
    h.angle = kind.RowIsAngle(h.component);
    h.error = held.y[static_cast<std::size_t>(r)] - y[static_cast<std::size_t>(r)];
    const Eigen::VectorXd j = J.row(r).transpose();
    h.predicted_std =
        std::sqrt(sigma * sigma / weights[static_cast<std::size_t>(r)] + j.dot(*C * j));
    h.z = h.error / h.predicted_std;
    out->push_back(h);
  }
  return "";
}

void CheckFolds(int folds, int configurations) {
  if (folds < 2 || folds > configurations)
    throw SettingError(
        SettingSpec::Named("identification", "holdout", "holdout", "cross-validation folds"),
        "expected 2 to " + std::to_string(configurations) +
            " folds (the number of configurations), got " + std::to_string(folds));
}

// The summary of the folds' predictions (sorted by configuration, then value).
void Summarise(CrossValidation* cv) {
  std::stable_sort(cv->predictions.begin(), cv->predictions.end(),
                   [](const HeldOutReading& a, const HeldOutReading& b) {
                     return a.configuration < b.configuration;
                   });
  const double n = static_cast<double>(cv->predictions.size());
  if (n == 0) return;
  double e2[2] = {0, 0}, v[2] = {0, 0}, count[2] = {0, 0}, z2 = 0;
  for (const auto& r : cv->predictions) {
    const int a = r.angle ? 1 : 0;
    e2[a] += r.error * r.error;
    v[a] += r.predicted_std * r.predicted_std;
    ++count[a];
    z2 += r.z * r.z;
    if (std::fabs(r.z) > 4 && (cv->beyond_4.empty() || cv->beyond_4.back() != r.configuration))
      cv->beyond_4.push_back(r.configuration);
  }
  if (count[0] > 0) {
    cv->rms_error = std::sqrt(e2[0] / count[0]);
    cv->rms_predicted = std::sqrt(v[0] / count[0]);
  }
  if (count[1] > 0) {
    cv->rms_error_angle = std::sqrt(e2[1] / count[1]);
    cv->rms_predicted_angle = std::sqrt(v[1] / count[1]);
  }
  cv->mean_z2 = z2 / n;
  cv->mean_z2_tolerance = 3 * std::sqrt(2 / n);
}

// Every fold predicted by `predict_fold(fold, &predictions)` ("" or why it could not be), then
// summarised.
CrossValidation RunFolds(
    int folds, int configurations,
    const std::function<std::string(int, std::vector<HeldOutReading>*)>& predict_fold) {
  CheckFolds(folds, configurations);
  CrossValidation cv;
  cv.folds = folds;
  for (int f = 0; f < folds; ++f) {
    const std::string why = predict_fold(f, &cv.predictions);
    if (!why.empty()) cv.failed_folds.emplace_back(f, why);
  }
  Summarise(&cv);
  return cv;
}

}  // namespace

CrossValidation CrossValidate(const MeasurementModel& model, const MeasurementSet& data, int folds,
                              const IdentificationOptions& options) {
  return RunFolds(folds, data.size(), [&](int f, std::vector<HeldOutReading>* out) {
    return PredictFold(model, data, folds, f, options, out);
  });
}

CrossValidation CrossValidate(const MeasurementKind& kind, const MeasuredValues& data, int folds,
                              const IdentificationOptions& options) {
  return RunFolds(folds, data.size(), [&](int f, std::vector<HeldOutReading>* out) {
    return PredictKindFold(kind, data, folds, f, options, out);
  });
}

}  // namespace lrcal
