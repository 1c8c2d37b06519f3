#include "lrcal/study/trial_replay.h"

#include <cstring>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/validation_metric.h"
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
  if (a.errors.size() != b.errors.size() ||
      (!a.errors.empty() &&
       std::memcmp(a.errors.data(), b.errors.data(), a.errors.size() * sizeof(double)) != 0))
    out.emplace_back("errors");
  // A failed trial has no validation of an identified model: the store keeps none (NULL), so
  // there is nothing to compare unless both succeeded.
  const bool both_ok = a.status == TrialStatus::kOk && b.status == TrialStatus::kOk;
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
  if (!found) throw InputError("--cell", "no cell '" + cell + "' in the run; cells: " + known);
  if (trial < 0 || trial >= study.trials)
    throw InputError("--trial", "expected 0 to " + std::to_string(study.trials - 1) + ", got " +
                                    std::to_string(trial));
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

}  // namespace lrcal
