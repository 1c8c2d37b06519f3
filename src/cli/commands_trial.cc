// lrcal trial: replay one recorded trial of a run with everything in it, and check it against the
// stored record bit for bit.
#include "cli_common.h"
#include "lrcal/core/text_table.h"
#include "lrcal/kinematics/validation_metric.h"
#include "lrcal/study/trial_replay.h"
#include "lrcal/study/trial_store.h"

namespace lrcal::cli {

namespace {

Json RecordJson(const TrialRecord& r) {
  Json j;
  j["status"] = TrialStatusName(r.status);
  j["iterations"] = r.iterations;
  j["residual_rms"] = r.residual_rms;
  j["sigma_hat"] = r.sigma_hat;
  j["sigma_min"] = r.sigma_min;
  j["errors"] = r.errors;
  // A failed trial identified no model: its validation is null (as the store has it).
  const bool ok = r.status == TrialStatus::kOk;
  Json val = Json::object(), nom = Json::object();
  for (int k = 0; k < kNumValidationColumns; ++k) {
    val[ValidationColumnName(k)] =
        !ok || std::isnan(r.validation[k]) ? Json() : Json(r.validation[k]);
    nom[ValidationColumnName(k)] = r.nominal[k];
  }
  j["validation"] = val;
  j["nominal_validation"] = nom;
  return j;
}

Json ReplayJson(const TrialReplay& t) {
  Json j;
  j["run"] = t.run_dir;
  j["cell_id"] = t.cell_id;
  j["cell_label"] = t.cell_label;
  j["trial"] = t.trial;
  j["stored"] = t.stored.has_value();
  j["identical"] = t.identical();
  j["differences"] = t.differences;
  j["parameters"] = t.parameter_names;
  j["record"] = RecordJson(t.recomputed);
  const TrialStatus status = t.recomputed.status;
  j["failure"] = status == TrialStatus::kOk ? Json() : Json(TrialStatusReason(status));
  // The readings the trial had (none when a beam missed before any was taken); the residuals
  // only when it identified a model.
  const auto residual = [](const std::vector<double>& v, std::size_t i) {
    return i < v.size() ? Json(v[i]) : Json();
  };
  Json configs = Json::array();
  for (int i = 0; i < t.configurations.size(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    configs.push_back(
        {{"q", std::vector<double>(t.configurations.q(i),
                                   t.configurations.q(i) + t.configurations.num_joints())},
         {"mean_h", k < t.mean_h.size() ? Json(t.mean_h[k]) : Json()},
         {"repetitions", k < t.repetitions.size() ? Json(t.repetitions[k]) : Json()},
         {"residual_nominal", residual(t.details.distance_error_nominal, k)},
         {"residual_identified", residual(t.details.distance_error_identified, k)}});
  }
  j["configurations"] = configs;
  j["estimate_delta"] = ToJson(t.estimate_delta);
  return j;
}

// The identified model's parameter errors and validation errors (a successful trial).
void PrintIdentifiedModel(const TrialReplay& t) {
  Table e({"parameter", "unit", "estimate - truth"}, "Parameter errors (mm, mrad, ppm)");
  for (std::size_t k = 0; k < t.recomputed.errors.size() && k < t.parameter_names.size(); ++k)
    e.AddRow({t.parameter_names[k], DisplayUnitOf(t.parameter_names[k]).unit,
              Fixed(t.recomputed.errors[k] * DisplayUnitOf(t.parameter_names[k]).factor, 6)});
  std::cout << e.ToText();
  Table v({"metric", "x", "y", "z"}, "Validation errors of the identified model (mm, mrad)");
  for (int m = 0; m < kNumValidationMetrics; ++m)
    v.AddRow({NameOf(kValidationMetricNames, static_cast<ValidationMetric>(m)),
              Fixed(t.recomputed.validation[3 * m] * 1e3, 6),
              Fixed(t.recomputed.validation[3 * m + 1] * 1e3, 6),
              Fixed(t.recomputed.validation[3 * m + 2] * 1e3, 6)});
  std::cout << v.ToText() << t.configurations.size()
            << " configurations read (--format json lists them with their readings and "
               "residuals)\n";
}

void PrintReplay(const TrialReplay& t) {
  std::cout << "trial " << t.trial << " of cell " << t.cell_label << " (" << t.cell_id << ") in "
            << t.run_dir << ": " << TrialStatusName(t.recomputed.status) << ", "
            << t.recomputed.iterations << " iterations, "
            << (t.recomputed.iterations > 0
                    ? "residual RMS " + Fixed(t.recomputed.residual_rms * 1e3, 6) + " mm, "
                    : std::string("no identification, "))
            << "design sigma_min " << Fixed(t.recomputed.sigma_min, 6) << "\n";
  if (t.recomputed.status != TrialStatus::kOk) {
    // A failed trial identified no model: no parameter errors, no validation to show.
    std::cout << "the trial failed (" << TrialStatusName(t.recomputed.status)
              << "): " << TrialStatusReason(t.recomputed.status) << "\n"
              << t.configurations.size() << " configurations with readings\n";
  } else {
    PrintIdentifiedModel(t);
  }
  if (!t.stored) {
    std::cout << "not recorded in the run: nothing to compare with\n";
  } else if (t.identical()) {
    std::cout << "identical to the stored record, bit for bit\n";
  } else {
    std::cout << "DIFFERS from the stored record in:";
    for (const auto& d : t.differences) std::cout << " " << d;
    std::cout << "\n";
  }
}

}  // namespace

int TrialCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal trial options");
  o.add_options()("dir", po::value<std::string>()->required(), "run directory")(
      "cell", po::value<std::string>()->required(), "cell id or label")(
      "trial", po::value<long long>()->required(), "trial index (0-based)")(
      "format", po::value<std::string>()->default_value("text"), "text or json");
  po::positional_options_description pos;
  pos.add("dir", 1);
  po::variables_map vm;
  if (!Parse("trial", "RUN_DIR --cell ID --trial N [--format json]", o, args, &vm, &pos)) return 0;
  const Format format = ResolveFormat(vm);
  const TrialReplay t = ReplayTrial(vm["dir"].as<std::string>(), vm["cell"].as<std::string>(),
                                    vm["trial"].as<long long>());
  if (format == Format::kJson) {
    std::cout << ReplayJson(t).dump(2) << "\n";
  } else {
    PrintReplay(t);
  }
  // A recorded trial that cannot be reproduced is a failure a script must see.
  return t.stored && !t.identical() ? 1 : 0;
}

}  // namespace lrcal::cli
