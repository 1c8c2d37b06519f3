#include "lrcal/identification/total_accuracy.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/measurement/ranger_measurement.h"

namespace lrcal {

double DefaultTolerances::Of(const std::string& name) const {
  if (name == "ranger_offset") return ranger_offset;
  if (name == "ranger_scale") return ranger_scale;
  return IsAngularName(name) ? angle : length;
}

std::string DefaultTolerances::ToString() const {
  return Fixed(length * 1e3, 3) + " mm, " + Fixed(angle * 1e3, 3) + " mrad, " +
         Fixed(ranger_offset * 1e3, 3) + " mm (ranger offset), " + Fixed(ranger_scale * 1e6, 1) +
         " ppm (ranger scale)";
}

ParameterSet CompleteParameterSet(const RobotModel& robot, int num_planes) {
  FrameTerms all;
  all.estimated.fill(true);
  return MakeParameterSet(robot, std::vector<PlaneTerms>(num_planes, PlaneTerms{true, true}), {},
                          "complete parameter set", RangerTerms{true, true}, all, all);
}

namespace {

// Where each of `names` is in `all`; throws InternalError for a name `all` lacks.
std::vector<int> IndicesIn(const ParameterSet& all, const std::vector<std::string>& names) {
  std::vector<int> at;
  at.reserve(names.size());
  for (const std::string& name : names) {
    const int k = all.Find(name);
    if (k < 0) throw std::logic_error("total accuracy: '" + name + "' is not a term of the set-up");
    at.push_back(k);
  }
  return at;
}

// The complete set's terms that `estimated` does not hold, in the complete set's order.
std::vector<int> HeldIndices(const ParameterSet& all, const std::vector<std::string>& estimated) {
  std::vector<int> held;
  for (int k = 0; k < all.size(); ++k)
    if (std::find(estimated.begin(), estimated.end(), all.names[k]) == estimated.end())
      held.push_back(k);
  return held;
}

Eigen::MatrixXd Columns(const Eigen::MatrixXd& m, const std::vector<int>& at) {
  Eigen::MatrixXd out(m.rows(), static_cast<Eigen::Index>(at.size()));
  for (std::size_t c = 0; c < at.size(); ++c) out.col(static_cast<Eigen::Index>(c)) = m.col(at[c]);
  return out;
}

}  // namespace

UnestimatedTerms FindUnestimatedTerms(const MeasurementModel& solved,
                                      const IdentificationSummary& s, const MeasurementSet& data,
                                      const IdentificationOptions& options,
                                      const PriorSigmas& known, const DefaultTolerances& defaults) {
  const ParameterSet all = CompleteParameterSet(solved.robot(), solved.num_planes());
  const std::vector<std::string>& names = solved.parameters().names;
  const std::vector<int> est = IndicesIn(all, names);
  std::vector<int> held;
  UnestimatedTerms out;
  // A frame term with no tolerance is exact by definition (the header's comment).
  for (int c : HeldIndices(all, names)) {
    if (IsFrameTermName(all.names[c]) && !(known.SigmaOf(all.names[c]) > 0)) {
      out.exact.push_back(all.names[c]);
      continue;
    }
    held.push_back(c);
  }
  const int k = static_cast<int>(held.size()), n = static_cast<int>(est.size());
  out.sigma.resize(k);
  for (int c = 0; c < k; ++c) {
    const std::string& name = all.names[held[c]];
    out.names.push_back(name);
    out.sigma[c] = known.SigmaOf(name);
    if (!(out.sigma[c] > 0)) {
      out.sigma[c] = defaults.Of(name);
      out.defaulted.push_back(name);
    }
  }
  out.estimate_shift = Eigen::MatrixXd::Zero(n, k);
  if (k == 0) return out;
  Eigen::VectorXd e_all = Eigen::VectorXd::Zero(all.size());
  for (int i = 0; i < n; ++i) e_all[est[i]] = s.delta[i];
  const RangerMeasurement kind(MeasurementModel(solved.robot(), solved.nominal_planes(), all));
  const Eigen::MatrixXd G_all = MeasurementJacobian(kind, data.configs, e_all.data());
  const Eigen::MatrixXd G = Columns(G_all, est), Gu = Columns(G_all, held);
  // Weights R_i/σ² (σ cancels without priors) and the priors of the estimated terms.
  const double sigma = options.sigma > 0 ? options.sigma : 1.0;
  // The readings' weights as the identification used them (errors in variables included).
  const std::vector<double> rows =
      options.encoder_sigma > 0 && options.sigma > 0
          ? ErrorsInVariablesWeights(RangerMeasurement(solved), ToMeasuredValues(data),
                                     options.sigma, options.encoder_sigma)
          : data.Weights();
  Eigen::VectorXd w(data.size());
  for (int i = 0; i < data.size(); ++i) w[i] = rows[i] / (sigma * sigma);
  Eigen::MatrixXd A = G.transpose() * w.asDiagonal() * G;
  for (int i = 0; i < n; ++i) {
    const double p = options.priors.SigmaOf(names[i]);
    if (p > 0) A(i, i) += 1 / (p * p);  // SigmaOf: 0 without a prior
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
  if (ldlt.info() != Eigen::Success)
    throw std::logic_error("total accuracy: the estimated terms' normal matrix is singular");
  out.estimate_shift = ldlt.solve(G.transpose() * w.asDiagonal() * Gu);
  return out;
}

std::string ExactFramesText(const std::vector<std::string>& exact) {
  std::string t;
  for (int f = 0; f < 2; ++f) {
    std::vector<std::string> names;
    for (int k = 0; k < 6; ++k)
      if (std::find(exact.begin(), exact.end(), FrameTermName(f, k)) != exact.end())
        names.push_back(FrameTermName(f, k));
    if (names.empty()) continue;
    if (!t.empty()) t += ", ";
    if (names.size() == 6) {
      t += std::string("the ") + kFrameNames[f] + " transform";
      continue;
    }
    for (std::size_t i = 0; i < names.size(); ++i) t += (i ? " " : "") + names[i];
  }
  return t;
}

SigmaUsed ChooseSigma(const IdentificationSummary& s, const IdentificationOptions& options) {
  SigmaUsed used;
  if (options.sigma > 0 &&
      !(s.fit.sigma_given && !s.fit.consistent && std::isfinite(s.sigma_hat))) {
    used.sigma = options.sigma;
    used.source = "given";
    used.reason = "the given sigma, consistent with the residuals (chi-squared check)";
    return used;
  }
  used.sigma = s.sigma_hat;
  used.source = "residual";
  used.reason = options.sigma > 0
                    ? "the chi-squared check rejects the given sigma " +
                          Fixed(options.sigma * 1e3) + " mm (p = " + Fixed(s.fit.p_value, 6) +
                          "): the residuals' sigma " + Fixed(s.sigma_hat * 1e3) + " mm is used"
                    : "no sigma given: the residuals' sigma is used";
  return used;
}

const Eigen::MatrixXd& CovarianceFor(const IdentificationSummary& s, const SigmaUsed& used) {
  return used.source == "given" ? s.covariance_given : s.covariance_residual;
}

namespace {

// The estimated term that absorbs most of held term c (module comment of AccuracySource).
std::string AbsorbedBy(const UnestimatedTerms& held, int c, const Eigen::MatrixXd& covariance,
                       const std::vector<std::string>& names) {
  double best = 0.1;
  std::string who;
  for (Eigen::Index i = 0; i < held.estimate_shift.rows(); ++i) {
    const double sd = std::sqrt(std::max(covariance(i, i), 0.0));
    const double moved = std::abs(held.estimate_shift(i, c)) * held.sigma[c];
    const double ratio = sd > 0 ? moved / sd : (moved > 0 ? INFINITY : 0);
    if (ratio > best) {
      best = ratio;
      who = names[static_cast<std::size_t>(i)];
    }
  }
  return who;
}

double Percentile95(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(0.95 * v.size())) - 1)];
}

}  // namespace

std::optional<AccuracyPrediction> PredictAccuracyAfterFit(const MeasurementModel& model,
                                                          const IdentificationSummary& s,
                                                          const IdentificationOptions& options,
                                                          const UnestimatedTerms& held,
                                                          const ConfigurationSet& poses) {
  const SigmaUsed used = ChooseSigma(s, options);
  const Eigen::MatrixXd& C = CovarianceFor(s, used);
  if (!C.allFinite()) return std::nullopt;
  AccuracyPrediction p =
      PredictTotalAccuracy(SolvedModel(model, s), s.delta.data(), C, held, poses);
  p.sigma_used = used;
  return p;
}

namespace {

// The estimated terms' pose Jacobian P and the held terms' pose columns (P·S − P_u)·diag(σ) at
// `configs` for the estimate e.
struct HeldPose {
  Eigen::MatrixXd P, M;
};

HeldPose HeldPoseAt(const MeasurementModel& solved, const double* e, const UnestimatedTerms& held,
                    const ConfigurationSet& configs) {
  const int n = solved.num_parameters(), k = static_cast<int>(held.names.size());
  if (held.estimate_shift.rows() != n || held.estimate_shift.cols() != k || held.sigma.size() != k)
    throw InputError("held terms", "expected an estimate shift of " + std::to_string(n) + " x " +
                                       std::to_string(k) + " and one sigma per held term");
  const ParameterSet all = CompleteParameterSet(solved.robot(), solved.num_planes());
  const std::vector<int> est = IndicesIn(all, solved.parameters().names);
  const std::vector<int> at_held = IndicesIn(all, held.names);
  Eigen::VectorXd e_all = Eigen::VectorXd::Zero(all.size());
  for (int i = 0; i < n; ++i) e_all[est[i]] = e[i];
  const MeasurementModel complete(solved.robot(), solved.nominal_planes(), all);
  const Eigen::MatrixXd J = PoseJacobian(complete, e_all.data(), configs);
  HeldPose out;
  out.P = Columns(J, est);
  // Per held term, the pose error of one prior σ: (P·S − P_u)·diag(σ).
  out.M = (out.P * held.estimate_shift - Columns(J, at_held)) * held.sigma.asDiagonal();
  return out;
}

}  // namespace

Eigen::MatrixXd HeldTermPoseColumns(const MeasurementModel& solved, const double* e,
                                    const UnestimatedTerms& held, const ConfigurationSet& configs) {
  return HeldPoseAt(solved, e, held, configs).M;
}

AccuracyPrediction PredictTotalAccuracy(const MeasurementModel& solved, const double* e,
                                        const Eigen::MatrixXd& covariance,
                                        const UnestimatedTerms& held,
                                        const ConfigurationSet& configs) {
  const int n = solved.num_parameters(), k = static_cast<int>(held.names.size());
  if (covariance.rows() != n || covariance.cols() != n)
    throw InputError("covariance", "expected " + std::to_string(n) + " x " + std::to_string(n) +
                                       " (one row and column per estimated parameter)");
  const HeldPose pose = HeldPoseAt(solved, e, held, configs);
  const Eigen::MatrixXd& P = pose.P;
  const Eigen::MatrixXd& M = pose.M;

  AccuracyPrediction out;
  out.defaulted = held.defaulted;
  out.exact = held.exact;
  const int m = configs.size();
  Eigen::VectorXd pos_ms = Eigen::VectorXd::Zero(k), ori_ms = Eigen::VectorXd::Zero(k);
  double data_pos = 0, data_ori = 0, total_pos = 0;
  std::vector<double> radii;
  for (int j = 0; j < m; ++j) {
    const Eigen::Matrix<double, 6, Eigen::Dynamic> Pj = P.middleRows(6 * j, 6);
    const Eigen::Matrix<double, 6, Eigen::Dynamic> Mj = M.middleRows(6 * j, 6);
    const Eigen::Matrix<double, 6, 6> D = Pj * covariance * Pj.transpose();
    const Eigen::Matrix<double, 6, 6> T = D + Mj * Mj.transpose();
    out.poses.push_back(PoseAccuracyFromCovariance(D, T));  // T == D when nothing is held
    pos_ms += Mj.topRows<3>().colwise().squaredNorm().transpose();
    ori_ms += Mj.bottomRows<3>().colwise().squaredNorm().transpose();
    data_pos += D.topLeftCorner<3, 3>().trace();
    data_ori += D.bottomRightCorner<3, 3>().trace();
    total_pos += T.topLeftCorner<3, 3>().trace();
    radii.push_back(out.poses.back().position_radius_95_total);
  }
  if (m == 0) return out;
  out.rms_position_total = std::sqrt(total_pos / m);
  out.p95_radius_95_total = Percentile95(radii);
  AccuracySource data_part;
  data_part.name = "estimated parameters (reading noise)";
  data_part.position_rms = std::sqrt(data_pos / m);
  data_part.orientation_rms = std::sqrt(data_ori / m);
  data_part.share = total_pos > 0 ? data_pos / total_pos : 1;
  out.sources.push_back(data_part);
  for (int c = 0; c < k; ++c) {
    AccuracySource src;
    src.name = held.names[c];
    src.prior_sigma = held.sigma[c];
    src.defaulted =
        std::find(held.defaulted.begin(), held.defaulted.end(), src.name) != held.defaulted.end();
    src.absorbed_by = AbsorbedBy(held, c, covariance, solved.parameters().names);
    src.position_rms = std::sqrt(pos_ms[c] / m);
    src.orientation_rms = std::sqrt(ori_ms[c] / m);
    src.share = total_pos > 0 ? pos_ms[c] / total_pos : 0;
    out.sources.push_back(src);
  }
  std::stable_sort(out.sources.begin(), out.sources.end(),
                   [](const AccuracySource& a, const AccuracySource& b) {
                     return a.position_rms > b.position_rms;
                   });
  return out;
}

namespace {

std::string PoseTable(const AccuracyPrediction& p) {
  Table t({"pose", "position std x", "y", "z", "orientation std x", "y", "z", "95 % radius",
           "total position std x", "y", "z", "total 95 % radius"},
          "Predicted accuracy of the calibrated arm (position in mm, orientation in mrad; "
          "the data part, then the total with the terms held at nominal)");
  for (std::size_t j = 0; j < p.poses.size(); ++j) {
    const PoseAccuracy& a = p.poses[j];
    t.AddRow({std::to_string(j + 1), Fixed(a.position_std.x() * 1e3),
              Fixed(a.position_std.y() * 1e3), Fixed(a.position_std.z() * 1e3),
              Fixed(a.orientation_std.x() * 1e3), Fixed(a.orientation_std.y() * 1e3),
              Fixed(a.orientation_std.z() * 1e3), Fixed(a.position_radius_95 * 1e3),
              Fixed(a.position_std_total.x() * 1e3), Fixed(a.position_std_total.y() * 1e3),
              Fixed(a.position_std_total.z() * 1e3), Fixed(a.position_radius_95_total * 1e3)});
  }
  return t.ToText();
}

}  // namespace

std::string AccuracySourceTable(const AccuracyPrediction& p) {
  constexpr std::size_t kShown = 12;
  Table t({"source", "prior", "absorbed by", "position RMS mm", "orientation RMS mrad",
           "share of the total"},
          "Where the total comes from (each source's RMS over these poses; shares of the mean "
          "square add to 100 %)");
  double rest_pos = 0, rest_ori = 0, rest_share = 0;
  int rest = 0;
  for (std::size_t i = 0; i < p.sources.size(); ++i) {
    const AccuracySource& s = p.sources[i];
    if (i >= kShown) {
      rest_pos += s.position_rms * s.position_rms;
      rest_ori += s.orientation_rms * s.orientation_rms;
      rest_share += s.share;
      ++rest;
      continue;
    }
    const DisplayUnit u = DisplayUnitOf(s.name);
    const std::string prior = s.prior_sigma > 0 ? Fixed(s.prior_sigma * u.factor, 3) + " " +
                                                      u.unit + (s.defaulted ? " (default)" : "")
                                                : "-";
    t.AddRow({s.name, prior,
              s.prior_sigma > 0 ? (s.absorbed_by.empty() ? "(not seen)" : s.absorbed_by) : "-",
              Fixed(s.position_rms * 1e3), Fixed(s.orientation_rms * 1e3),
              Fixed(s.share * 100, 1) + " %"});
  }
  if (rest > 0)
    t.AddRow({std::to_string(rest) + " other terms", "-", "-", Fixed(std::sqrt(rest_pos) * 1e3),
              Fixed(std::sqrt(rest_ori) * 1e3), Fixed(rest_share * 100, 1) + " %"});
  return t.ToText();
}

std::string AccuracyPredictionText(const AccuracyPrediction& p) {
  std::vector<double> radii;
  double data_ms = 0;
  for (const PoseAccuracy& a : p.poses) {
    radii.push_back(a.position_radius_95);
    data_ms += a.position_std.squaredNorm();
  }
  const std::size_t m = p.poses.size();
  // The answer first (a workspace of 500 poses would push it below 500 rows), the poses last.
  std::string t;
  t += "over these " + std::to_string(m) + " poses: RMS position error " +
       Fixed(m ? std::sqrt(data_ms / m) * 1e3 : 0) + " mm from the reading noise alone, " +
       Fixed(p.rms_position_total * 1e3) +
       " mm in total; 95th percentile of the total 95 % radius " +
       Fixed(p.p95_radius_95_total * 1e3) + " mm (data part " + Fixed(Percentile95(radii) * 1e3) +
       " mm)\n";
  if (!p.sigma_used.source.empty())
    t += "sigma used: " + Fixed(p.sigma_used.sigma * 1e3) + " mm per reading (" +
         p.sigma_used.reason + ")\n";
  t += AccuracySourceTable(p);
  if (!p.defaulted.empty()) {
    t += "warning: no tolerance known for " + std::to_string(p.defaulted.size()) +
         " held terms; the stated defaults (" + p.defaults.ToString() + ") were used for:";
    for (const std::string& name : p.defaulted) t += " " + name;
    t += "\n         give them when calibrating: the robot file's tolerances:, or identify "
         "--prior-sigma\n";
  }
  if (!p.exact.empty())
    t += "note: taken as exact (no tolerance given, not estimated): " + ExactFramesText(p.exact) +
         "; give tolerances.base/tool in the robot file (or --prior-sigma base_x=...) if the "
         "base frame is not the robot's own\n";
  return t + PoseTable(p);
}

}  // namespace lrcal
