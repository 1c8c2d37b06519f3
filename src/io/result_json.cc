#include "lrcal/io/result_json.h"

#include <cmath>

namespace lrcal {

namespace {

ResultJson Vec3(const Eigen::Vector3d& v) { return ResultJson::array({v.x(), v.y(), v.z()}); }

}  // namespace

ResultJson ToJson(const Eigen::VectorXd& v) {
  ResultJson j = ResultJson::array();
  for (int i = 0; i < v.size(); ++i) j.push_back(v[i]);
  return j;
}

ResultJson ToJson(const Eigen::MatrixXd& m) {
  ResultJson j = ResultJson::array();
  for (int r = 0; r < m.rows(); ++r) {
    ResultJson row = ResultJson::array();
    for (int c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    j.push_back(row);
  }
  return j;
}

ResultJson IdentifiabilityJson(const IdentifiabilityReport& r) {
  ResultJson j;
  j["n_params"] = r.num_params();
  j["n_configurations"] = r.num_configurations;
  j["rank"] = r.rank;
  j["parameters"] = r.names;
  j["singular_values"] = ToJson(r.singular_values);
  j["condition_number"] =
      std::isfinite(r.condition_number) ? ResultJson(r.condition_number) : ResultJson();
  j["unidentifiable"] = r.unidentifiable;
  ResultJson deps = ResultJson::array();
  for (const auto& d : r.dependencies) {
    ResultJson terms = ResultJson::array();
    for (const auto& [name, c] : d.terms) terms.push_back({{"name", name}, {"coefficient", c}});
    deps.push_back(terms);
  }
  j["dependencies"] = deps;
  j["suggested_fixed"] = r.suggested_fixed;
  if (!r.explanations.empty()) j["lost_in_words"] = r.explanations;
  return j;
}

ResultJson RemediesJson(const RemedyReport& r) {
  ResultJson j;
  j["lost"] = r.lost;
  ResultJson list = ResultJson::array();
  for (const auto& m : r.remedies) {
    ResultJson e{{"kind", RemedyKindName(m.kind)}, {"action", m.action}, {"recovers", m.recovers}};
    if (!m.parameter.empty()) e["parameter"] = m.parameter;
    if (m.kind == Remedy::Kind::kAddPlane || m.kind == Remedy::Kind::kAddKnownDistance)
      e["plane"] = {{"normal", {m.plane.normal[0], m.plane.normal[1], m.plane.normal[2]}},
                    {"offset", m.plane.offset}};
    list.push_back(e);
  }
  j["remedies"] = list;
  ResultJson cheapest = ResultJson::array();
  for (int c : r.cheapest)
    cheapest.push_back(c >= 0 ? ResultJson(r.remedies[c].action) : ResultJson());
  j["cheapest_fix"] = cheapest;
  j["unreachable"] = r.unreachable;
  return j;
}

namespace {

ResultJson OrNull(double x) { return std::isnan(x) ? ResultJson() : ResultJson(x); }

// The parameters of a usable identification, with their priors when it had any.
ResultJson ParametersJson(const IdentificationSummary& s) {
  ResultJson params = ResultJson::array();
  for (std::size_t k = 0; k < s.names.size() && s.IsSolutionUsable(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    params.push_back(
        {{"name", s.names[k]},
         {"nominal", s.nominal[i]},
         {"estimate", s.estimate[i]},
         {"delta", s.delta[i]},
         {"std", s.std_residual[i]},
         {"std_given_sigma", s.std_given.size() ? ResultJson(s.std_given[i]) : ResultJson()}});
    if (s.prior_sigma.size() == 0) continue;  // without priors the JSON is as before them
    const bool has = s.prior_sigma[i] > 0;
    params.back()["prior_sigma"] = has ? ResultJson(s.prior_sigma[i]) : ResultJson();
    params.back()["posterior_to_prior"] = has ? ResultJson(s.posterior_to_prior[i]) : ResultJson();
  }
  return params;
}

ResultJson FitJson(const FitCheck& f) {
  ResultJson fit = {{"dof", f.dof}, {"standardized_residuals", f.standardized}};
  fit["test"] = f.TestName();
  if (f.robust) {
    fit["robust_scale"] = OrNull(f.robust_scale);
    fit["robust_p_value"] = OrNull(f.robust_p_value);
  }
  ResultJson suspects = ResultJson::array();
  for (int i : f.suspects) suspects.push_back(i + 1);
  fit["suspects"] = suspects;           // 1-based configurations
  if (!f.configuration_labels.empty())  // and by the labels of the measurement file
    fit["suspect_labels"] = f.SuspectLabels();
  if (f.num_priors > 0) {  // without priors the JSON is as before them
    fit["num_priors"] = f.num_priors;
    fit["chi2_priors"] = OrNull(f.chi2_priors);
  }
  if (f.sigma_given) {
    fit["chi2"] = f.chi2;
    fit["p_value"] = OrNull(f.p_value);
    fit["consistent"] = f.consistent;
  } else {
    fit["chi2"] = fit["p_value"] = fit["consistent"] = nullptr;  // no σ given: no test
  }
  return fit;
}

}  // namespace

ResultJson MeasuredAccuracyJson(const MeasuredAccuracy& r) {
  ResultJson j;
  j["points"] = r.num_points;
  j["rms"] = r.rms;
  j["worst"] = r.worst;
  j["worst_point"] = r.worst_index + 1;
  j["registered"] = r.registered;
  j["instrument"] = {{"xyz", ToJson(Eigen::VectorXd(r.instrument.translation))},
                     {"rpy", ToJson(Eigen::VectorXd(r.instrument.Rpy()))}};
  ResultJson errors = ResultJson::array(), targets = ResultJson::array();
  for (const Eigen::Vector3d& e : r.errors) errors.push_back({e.x(), e.y(), e.z()});
  for (const Eigen::Vector3d& t : r.targets) targets.push_back({t.x(), t.y(), t.z()});
  j["errors"] = errors;
  j["targets"] = targets;
  return j;
}

ResultJson IdentificationJson(const IdentificationSummary& s) {
  ResultJson j;
  j["parameters"] = ParametersJson(s);
  if (s.prior_sigma.size()) j["set_by_prior"] = s.SetByPrior();
  j["covariance"] = s.IsSolutionUsable() ? ToJson(s.covariance_residual) : ResultJson();
  j["covariance_given_sigma"] =
      s.covariance_given.size() ? ToJson(s.covariance_given) : ResultJson();
  j["correlation"] = s.IsSolutionUsable() ? ToJson(s.correlation) : ResultJson();
  j["rank"] = s.identifiability.rank;
  j["n_params"] = s.identifiability.num_params();
  j["fixed_for_rank"] = s.fixed;
  j["iterations"] = s.iterations;
  j["termination"] = TerminationName(s.termination);
  j["usable"] = s.IsSolutionUsable();
  j["message"] = s.message;
  j["residual_rms"] = s.residual_rms;
  j["initial_cost"] = s.initial_cost;  // ½Σ w·r² (m²) at the nominal model: before
  j["final_cost"] = s.final_cost;      // and at the estimate: after
  j["sigma_hat"] = OrNull(s.sigma_hat);
  if (s.IsSolutionUsable()) j["fit"] = FitJson(s.fit);
  if (s.linearisation.num_parameters > 0) {
    const LinearisationCheck& c = s.linearisation;
    j["linearisation"] = {{"computed", c.computed},
                          {"excess", OrNull(c.excess)},
                          {"relative_excess", OrNull(c.RelativeExcess())},
                          {"holds", c.Holds()},
                          {"pairs", c.pairs},
                          {"message", c.message}};
    if (c.computed && c.worst_direction.size() == static_cast<Eigen::Index>(s.names.size())) {
      ResultJson direction = ResultJson::object();
      for (std::size_t k = 0; k < s.names.size(); ++k)
        direction[s.names[k]] = c.worst_direction[static_cast<Eigen::Index>(k)];
      j["linearisation"]["worst_direction"] = direction;
      j["linearisation"]["worst_direction_sigma"] = c.worst_direction_sigma;
    }
  }
  j["n_configurations"] = s.num_configurations;
  j["solver"] = s.solver;
  j["loss"] = s.loss;
  if (!s.identifiability.full_rank()) j["identifiability"] = IdentifiabilityJson(s.identifiability);
  return j;
}

ResultJson PriorInformationJson(const PriorInformation& info) {
  const auto finite = [](double x) { return std::isfinite(x) ? ResultJson(x) : ResultJson(); };
  ResultJson terms = ResultJson::array();
  for (std::size_t k = 0; k < info.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    terms.push_back(
        {{"name", info.names[k]},
         {"prior_sigma", info.prior_sigma[i] > 0 ? ResultJson(info.prior_sigma[i]) : ResultJson()},
         {"posterior_sigma", finite(info.posterior_sigma[i])},
         {"posterior_to_prior", finite(info.posterior_to_prior[i])}});
  }
  ResultJson j;
  j["sigma"] = info.sigma;
  j["terms"] = terms;
  j["set_by_prior"] = info.SetByPrior();
  j["defined"] = info.defined;
  return j;
}

ResultJson CrossValidationJson(const CrossValidation& cv) {
  ResultJson predictions = ResultJson::array();
  bool several = false, angles = false;  // a kind of several values per configuration
  for (const auto& p : cv.predictions) {
    several = several || p.component > 0;
    angles = angles || p.angle;
  }
  for (const auto& p : cv.predictions) {
    ResultJson one = {{"configuration", p.configuration + 1},
                      {"fold", p.fold},
                      {"error", p.error},
                      {"predicted_std", p.predicted_std},
                      {"z", p.z}};
    if (several) one["component"] = p.component;
    if (angles) one["unit"] = p.angle ? "rad" : "m";
    predictions.push_back(one);
  }
  ResultJson failed = ResultJson::array();
  for (const auto& [fold, why] : cv.failed_folds)
    failed.push_back({{"fold", fold}, {"reason", why}});
  ResultJson beyond = ResultJson::array();
  for (int i : cv.beyond_4) beyond.push_back(i + 1);
  const bool any = !cv.predictions.empty();
  ResultJson j = {{"folds", cv.folds},
                  {"assignment", "configuration i (0-based) in fold i mod K"},
                  {"predictions", predictions},
                  {"failed_folds", failed},
                  {"rms_error", any ? ResultJson(cv.rms_error) : ResultJson()},
                  {"rms_predicted", any ? ResultJson(cv.rms_predicted) : ResultJson()},
                  {"ratio", any ? ResultJson(cv.rms_error / cv.rms_predicted) : ResultJson()},
                  {"mean_z2", any ? ResultJson(cv.mean_z2) : ResultJson()},
                  {"mean_z2_tolerance", any ? ResultJson(cv.mean_z2_tolerance) : ResultJson()},
                  {"consistent", any ? ResultJson(cv.consistent()) : ResultJson()},
                  {"beyond_4", beyond}};
  if (angles) {  // rms_error and rms_predicted are then the lengths' (m)
    j["rms_error_angle"] = cv.rms_error_angle;
    j["rms_predicted_angle"] = cv.rms_predicted_angle;
    j["ratio_angle"] = cv.rms_error_angle / cv.rms_predicted_angle;
  }
  return j;
}

ResultJson AccuracySourcesJson(const std::vector<AccuracySource>& sources) {
  ResultJson out = ResultJson::array();
  for (const AccuracySource& s : sources)
    out.push_back(
        {{"name", s.name},
         {"prior_sigma", s.prior_sigma > 0 ? ResultJson(s.prior_sigma) : ResultJson()},
         {"defaulted", s.defaulted},
         {"absorbed_by", s.absorbed_by.empty() ? ResultJson() : ResultJson(s.absorbed_by)},
         {"position_rms", s.position_rms},
         {"orientation_rms", s.orientation_rms},
         {"share", s.share}});
  return out;
}

ResultJson PoseAccuracyJson(const AccuracyPrediction& prediction, const ConfigurationSet& configs) {
  const std::vector<PoseAccuracy>& poses = prediction.poses;
  ResultJson list = ResultJson::array();
  for (std::size_t j = 0; j < poses.size(); ++j) {
    const PoseAccuracy& p = poses[j];
    const double* q = configs.q(static_cast<int>(j));
    list.push_back({{"q", std::vector<double>(q, q + configs.num_joints())},
                    {"position_std", Vec3(p.position_std)},
                    {"orientation_std", Vec3(p.orientation_std)},
                    {"position_radius_95", p.position_radius_95},
                    {"position_std_total", Vec3(p.position_std_total)},
                    {"orientation_std_total", Vec3(p.orientation_std_total)},
                    {"position_radius_95_total", p.position_radius_95_total}});
  }
  const ResultJson sources = AccuracySourcesJson(prediction.sources);
  const PoseAccuracySummary s = SummarizePoseAccuracy(poses);
  return {{"poses", list},
          {"rms_position", s.rms_position},
          {"p95_position_radius_95", s.p95_radius_95},
          {"rms_position_total", prediction.rms_position_total},
          {"p95_position_radius_95_total", prediction.p95_radius_95_total},
          {"worst", s.worst + 1},
          {"sources", sources},
          {"defaulted", prediction.defaulted},
          {"taken_as_exact", prediction.exact},
          {"defaults", prediction.defaults.ToString()},
          {"sigma_used",
           {{"sigma", prediction.sigma_used.sigma},
            {"source", prediction.sigma_used.source},
            {"reason", prediction.sigma_used.reason}}}};
}

ResultJson CertificateJson(const DesignCertificate& certificate, const std::string& statement) {
  ResultJson j = {{"available", certificate.available},
                  {"statement", statement},
                  {"iterations", certificate.iterations}};
  if (certificate.available) {
    j["bound"] = certificate.bound;
    j["achieved"] = certificate.achieved;
    j["efficiency"] = certificate.efficiency;
  }
  return j;
}

ResultJson DesignChoiceJson(const DesignRequest& request, const DesignChoice& choice) {
  ResultJson j;
  j["method"] = SelectionMethodName(request.selection.method);
  j["criterion"] = request.CriterionName();
  if (choice.task_rms_per_sigma)
    j["task"] = {{"poses", request.task.count},
                 {"source", request.task.source},
                 {"rms_position_per_unit_sigma", *choice.task_rms_per_sigma}};
  j["scaling"] = DesignScalingName(request.scaling);
  j["selected"] = choice.chosen.indices;
  j["selected_per_plane"] = choice.per_plane;
  j["score"] = choice.chosen.score;
  j["evaluations"] = choice.chosen.evaluations;
  j["seconds"] = choice.seconds;
  ResultJson indices = ResultJson::object();
  for (const BaselineIndex& b : choice.baseline)
    indices[DesignCriterionName(b.criterion)] = {{"chosen", b.chosen},
                                                 {"random_mean", b.random.mean},
                                                 {"random_p5", b.random.p5},
                                                 {"random_p95", b.random.p95},
                                                 {"percentile", b.percentile}};
  j["indices"] = indices;
  j["certificate"] = CertificateJson(choice.certificate, choice.certificate_statement);
  return j;
}

}  // namespace lrcal
