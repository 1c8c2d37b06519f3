#include "lrcal/design/design_choice.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/random.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/block_selection.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/design/random_baseline.h"
#include "lrcal/measurement/ranger_measurement.h"

namespace lrcal {

std::string DesignRequest::CriterionName() const {
  return task.count > 0 ? "I" : DesignCriterionName(selection.criterion);
}

const std::vector<SettingField<DesignRequest>>& DesignRequest::Settings() {
  using R = DesignRequest;
  static const std::vector<SettingField<R>> fields = {
      {{"design", "expected_angle", "expected_angle_mrad", "mrad", 1e-3, "rad", 0, kInf, true,
        false, "", "", "expected angle error (scaling: expected)"},
       &R::expected_angle},
      {{"design", "expected_length", "expected_length_mm", "mm", 1e-3, "m", 0, kInf, true, false,
        "", "", "expected length error (scaling: expected)"},
       &R::expected_length},
      {RandomBaselineSetting(), nullptr, &R::baseline},
      {WorkspacePosesSetting(), nullptr, &R::workspace},
  };
  return fields;
}

void DesignRequest::Validate() const {
  CheckSettings(*this, Settings());
  selection.Validate();
}

DesignChoice ChooseDesign(const MeasurementKind& kind, const TargetedConfigurations& pool,
                          const DesignRequest& request) {
  request.Validate();
  const int rows = kind.rows_per_configuration();
  SelectionOptions options = request.selection;
  const bool task = request.task.count > 0;
  if (task) options.criterion = DesignCriterion::kA;  // I is A on the task-weighted G
  const Eigen::MatrixXd G = task ? TaskDesignJacobian(kind, pool, request.task)
                                 : DesignJacobian(kind, pool, request.scaling,
                                                  request.expected_angle, request.expected_length);
  DesignChoice out;
  const auto t0 = std::chrono::steady_clock::now();
  out.chosen = SelectBlocks(G, rows, request.count, options,
                            RandomStream(request.seed, 1, 0, RandomPurpose::kSelection));
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.baseline =
      CompareWithRandomDesigns(G, out.chosen.indices, request.baseline, request.seed, rows);
  if (rows == 1) {
    out.certificate = CertifyDesign(G, out.chosen.indices, options.criterion);
    out.certificate_statement =
        out.certificate.ToString(options.criterion, request.count, static_cast<int>(pool.size()));
  } else {  // the relaxation weighs single rows, not a configuration's block of them
    out.certificate_statement = "no certificate for configurations of " + std::to_string(rows) +
                                " values (the relaxation bound weighs single rows)";
  }
  out.per_plane.assign(static_cast<std::size_t>(std::max(pool.num_targets_referenced(), 1)), 0);
  for (int i : out.chosen.indices) ++out.per_plane[static_cast<std::size_t>(pool.target(i))];
  if (task)
    out.task_rms_per_sigma =
        TaskRmsPositionPerUnitSigma(kind, pool.Subset(out.chosen.indices), request.task);
  return out;
}

DesignChoice ChooseDesign(const MeasurementModel& model, const TargetedConfigurations& pool,
                          const DesignRequest& request) {
  DesignChoice out = ChooseDesign(RangerMeasurement(model), pool, request);
  // Bind refused any target beyond the model's planes: this only adds the planes none chose.
  out.per_plane.resize(static_cast<std::size_t>(model.nominal_planes().size()), 0);
  return out;
}

std::string CriterionText(const DesignRequest& request, const DesignChoice& choice) {
  std::ostringstream out;
  if (!choice.task_rms_per_sigma) {
    out << DesignCriterionName(request.selection.criterion) << " = " << choice.chosen.score;
    return out.str();
  }
  out << "I (predicted RMS position error at " << request.task.count << " " << request.task.source
      << " poses: " << *choice.task_rms_per_sigma << " mm per mm of reading noise)";
  return out.str();
}

namespace {

Table BaselineTable(const DesignRequest& request, const DesignChoice& choice, int pool_size) {
  Table t({"index", "chosen", "random mean", "random p5", "random p95", "percentile of chosen"},
          "Observability of the chosen " + std::to_string(request.count) + " of " +
              std::to_string(pool_size) + " against " + std::to_string(request.baseline) +
              " random designs (G scaled: " + DesignScalingName(request.scaling) +
              "; E = sigma_min, D = log det, A = -trace inv)");
  for (const BaselineIndex& b : choice.baseline)
    t.AddRow({DesignCriterionName(b.criterion), Fixed(b.chosen, 6), Fixed(b.random.mean, 6),
              Fixed(b.random.p5, 6), Fixed(b.random.p95, 6), Fixed(b.percentile, 1)});
  return t;
}

// "chosen per plane: plane 1: 19, wall: 6\n" with several planes, else "".
std::string PerPlaneText(const PlaneSet& planes, const std::vector<int>& per_plane) {
  if (planes.size() < 2) return "";
  std::string out = "chosen per plane:";
  for (int p = 0; p < planes.size(); ++p)
    out += (p ? ", " : " ") + planes.Label(p) + ": " + std::to_string(per_plane[p]);
  return out + "\n";
}

}  // namespace

std::string DesignChoiceText(const DesignRequest& request, const DesignChoice& choice,
                             const PlaneSet& planes, int pool_size) {
  std::ostringstream out;
  out << "chose " << request.count << " of " << pool_size << " by "
      << SelectionMethodName(request.selection.method) << ", criterion "
      << CriterionText(request, choice) << " (" << choice.chosen.evaluations << " evaluations, "
      << Fixed(choice.seconds * 1e3, 1) << " ms)\n"
      << "chosen (0-based pool indices):";
  for (int i : choice.chosen.indices) out << " " << i;
  out << "\n"
      << PerPlaneText(planes, choice.per_plane) << "certificate: " << choice.certificate_statement
      << "\n\n"
      << BaselineTable(request, choice, pool_size).ToText();
  return out.str();
}

}  // namespace lrcal
