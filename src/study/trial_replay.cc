#include "lrcal/study/trial_replay.h"

#include <cmath>
#include <cstring>
#include <ostream>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/settings.h"
#include "lrcal/core/text_table.h"
#include "lrcal/kinematics/validation_metric.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/study/run_directory.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial_store.h"
#include "study/trial_pipeline.h"

namespace lrcal {

namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The fields of two records that differ (the wall time aside).
std::vector<std::string> Differences(const TrialRecord& a, const TrialRecord& b) {
  std::vector<std::string> out;
  if (a.status != b.status) out.emplace_back("status");
  if (a.iterations != b.iterations) out.emplace_back("iterations");
  if (!SameBits(a.residual_rms, b.residual_rms)) out.emplace_back("residual_rms");
  if (!SameBits(a.sigma_hat, b.sigma_hat)) out.emplace_back("sigma_hat");
  if (!SameBits(a.sigma_min, b.sigma_min)) out.emplace_back("sigma_min");
  if (a.missed_configurations != b.missed_configurations) out.emplace_back("missed_configurations");
  if (a.errors.size() != b.errors.size() ||
      (!a.errors.empty() &&
       std::memcmp(a.errors.data(), b.errors.data(), a.errors.size() * sizeof(double)) != 0))
    out.emplace_back("errors");
  // A failed trial has no validation of an identified model: the store keeps none (NULL), so
  // there is nothing to compare unless both succeeded.
  const bool both_ok = a.status == TrialStatus::kOk && b.status == TrialStatus::kOk;
  // Coverage: NULL in the store where there is none (NaN either way).
  const auto same_share = [](double x, double y) {
    return (std::isnan(x) && std::isnan(y)) || SameBits(x, y);
  };
  if (both_ok && !same_share(a.coverage, b.coverage)) out.emplace_back("coverage");
  if (both_ok && !same_share(a.coverage_total, b.coverage_total))
    out.emplace_back("coverage_total");
  for (int k = 0; k < kNumValidationColumns; ++k) {
    if (both_ok && !SameBits(a.validation[k], b.validation[k]))
      out.push_back(std::string("val_") + ValidationColumnName(k));
    if (!SameBits(a.nominal[k], b.nominal[k]))
      out.push_back(std::string("nom_") + ValidationColumnName(k));
  }
  return out;
}

// The stored record of (cell, trial) in any store of the run, if there is one.
std::optional<TrialRecord> StoredRecord(const RunDirectory& dir, const std::string& cell_id,
                                        long long trial) {
  for (const std::string& path : dir.StorePaths()) {
    TrialStore store(path);
    if (auto r = store.GetTrial(cell_id, trial)) return r;
  }
  return std::nullopt;
}

// The run's study, re-read from the file it recorded, checked against the manifest.
Study RunStudyFile(const RunDirectory& dir) {
  const Json manifest = dir.ReadManifest();
  const std::string file = manifest.value("study_file", std::string());
  if (file.empty())
    throw InputError(dir.ManifestPath(), "records no study_file; cannot replay its trials");
  const Study study = LoadStudy(file);
  if (StudyFingerprint(study.ToJson()) != StudyFingerprint(manifest["study"]))
    throw InputError(file, "has changed since the run in " + dir.path() +
                               " (seed, trials or base settings differ): a replay would not be "
                               "the recorded trial");
  return study;
}

}  // namespace

TrialReplay ReplayTrial(const std::string& run_dir, const std::string& cell, long long trial) {
  const RunDirectory dir(run_dir);
  const Study study = RunStudyFile(dir);
  const Cell* found = nullptr;
  std::string known;
  for (const Cell& c : study.cells) {
    if (c.id == cell || c.label == cell) found = &c;
    known += (known.empty() ? "" : ", ") + c.label + " (" + c.id + ")";
  }
  if (!found)
    throw SettingError(SettingSpec::Named("replay", "cell", "cell", "cell id or label"),
                       "no cell '" + cell + "' in the run; cells: " + known);
  if (trial < 0 || trial >= study.trials)
    throw SettingError(
        SettingSpec::Named("replay", "trial", "trial", "trial index"),
        "expected 0 to " + std::to_string(study.trials - 1) + ", got " + std::to_string(trial));
  const auto context = PrepareCell(study, *found);
  TrialWorkspace workspace;
  TrialReplay out;
  out.run_dir = run_dir;
  out.cell_id = found->id;
  out.cell_label = found->label;
  out.trial = trial;
  out.recomputed = RunTrial(*context, trial, &workspace, &out.details);
  out.parameter_names = context->parameter_names;
  out.configurations = workspace.data.configs;
  out.mean_h = workspace.data.mean_h;
  out.repetitions = workspace.data.repetitions;
  out.estimate_delta = workspace.e;
  out.stored = StoredRecord(dir, found->id, trial);
  if (out.stored) out.differences = Differences(out.recomputed, *out.stored);
  return out;
}

namespace {

ResultJson RecordJson(const TrialRecord& r) {
  ResultJson j;
  j["status"] = TrialStatusName(r.status);
  j["iterations"] = r.iterations;
  j["residual_rms"] = r.residual_rms;
  j["sigma_hat"] = r.sigma_hat;
  j["sigma_min"] = r.sigma_min;
  j["missed_configurations"] = r.missed_configurations;
  j["coverage"] = std::isnan(r.coverage) ? ResultJson() : ResultJson(r.coverage);
  j["coverage_total"] = std::isnan(r.coverage_total) ? ResultJson() : ResultJson(r.coverage_total);
  j["errors"] = r.errors;
  // A failed trial identified no model: its validation is null (as the store has it).
  const bool ok = r.status == TrialStatus::kOk;
  ResultJson val = ResultJson::object(), nom = ResultJson::object();
  for (int k = 0; k < kNumValidationColumns; ++k) {
    val[ValidationColumnName(k)] =
        !ok || std::isnan(r.validation[k]) ? ResultJson() : ResultJson(r.validation[k]);
    nom[ValidationColumnName(k)] = r.nominal[k];
  }
  j["validation"] = val;
  j["nominal_validation"] = nom;
  return j;
}

// The identified model's parameter errors and validation errors (a successful trial).
void PrintIdentifiedModel(const TrialReplay& t, std::ostream& out) {
  Table e({"parameter", "unit", "estimate - truth"}, "Parameter errors (mm, mrad, ppm)");
  for (std::size_t k = 0; k < t.recomputed.errors.size() && k < t.parameter_names.size(); ++k)
    e.AddRow({t.parameter_names[k], DisplayUnitOf(t.parameter_names[k]).unit,
              Fixed(t.recomputed.errors[k] * DisplayUnitOf(t.parameter_names[k]).factor, 6)});
  out << e.ToText();
  Table v({"metric", "x", "y", "z"}, "Validation errors of the identified model (mm, mrad)");
  for (int m = 0; m < kNumValidationMetrics; ++m)
    v.AddRow({NameOf(kValidationMetricNames, static_cast<ValidationMetric>(m)),
              Fixed(t.recomputed.validation[3 * m] * 1e3, 6),
              Fixed(t.recomputed.validation[3 * m + 1] * 1e3, 6),
              Fixed(t.recomputed.validation[3 * m + 2] * 1e3, 6)});
  out << v.ToText() << t.configurations.size()
      << " configurations read (--format json lists them with their readings and "
         "residuals)";
  if (t.recomputed.missed_configurations > 0)
    out << "; " << t.recomputed.missed_configurations
        << " more of the design had no reading (the true beam missed its plane) and were left out";
  out << "\n";
}

}  // namespace

ResultJson TrialReplay::ToJson() const {
  const TrialReplay& t = *this;
  ResultJson j;
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
  j["failure"] = status == TrialStatus::kOk ? ResultJson() : ResultJson(TrialStatusReason(status));
  // The readings the trial had (none when a beam missed before any was taken); the residuals
  // only when it identified a model.
  const auto residual = [](const std::vector<double>& v, std::size_t i) {
    return i < v.size() ? ResultJson(v[i]) : ResultJson();
  };
  ResultJson configs = ResultJson::array();
  for (int i = 0; i < t.configurations.size(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    configs.push_back(
        {{"q", std::vector<double>(t.configurations.q(i),
                                   t.configurations.q(i) + t.configurations.num_joints())},
         {"mean_h", k < t.mean_h.size() ? ResultJson(t.mean_h[k]) : ResultJson()},
         {"repetitions", k < t.repetitions.size() ? ResultJson(t.repetitions[k]) : ResultJson()},
         {"residual_nominal", residual(t.details.distance_error_nominal, k)},
         {"residual_identified", residual(t.details.distance_error_identified, k)}});
  }
  j["configurations"] = configs;
  j["estimate_delta"] = lrcal::ToJson(t.estimate_delta);
  return j;
}

std::string TrialReplay::ToText() const {
  const TrialReplay& t = *this;
  std::ostringstream out;
  out << "trial " << t.trial << " of cell " << t.cell_label << " (" << t.cell_id << ") in "
      << t.run_dir << ": " << TrialStatusName(t.recomputed.status) << ", "
      << t.recomputed.iterations << " iterations, "
      << (t.recomputed.iterations > 0
              ? "residual RMS " + Fixed(t.recomputed.residual_rms * 1e3, 6) + " mm, "
              : std::string("no identification, "))
      << "design sigma_min " << Fixed(t.recomputed.sigma_min, 6) << "\n";
  if (t.recomputed.status != TrialStatus::kOk) {
    // A failed trial identified no model: no parameter errors, no validation to show.
    out << "the trial failed (" << TrialStatusName(t.recomputed.status)
        << "): " << TrialStatusReason(t.recomputed.status) << "\n"
        << t.configurations.size() << " configurations with readings, "
        << t.recomputed.missed_configurations << " without (the true beam missed its plane)\n";
  } else {
    PrintIdentifiedModel(t, out);
  }
  if (!t.stored) {
    out << "not recorded in the run: nothing to compare with\n";
  } else if (t.identical()) {
    out << "identical to the stored record, bit for bit\n";
  } else {
    out << "DIFFERS from the stored record in:";
    for (const auto& d : t.differences) out << " " << d;
    out << "\n";
  }
  return out.str();
}

}  // namespace lrcal
