#include "lrcal/study/prepared_cell.h"

#include "study/trial_pipeline.h"

namespace lrcal {

PreparedCell::PreparedCell(std::unique_ptr<CellContext> context) : context_(std::move(context)) {}
PreparedCell::PreparedCell(PreparedCell&&) noexcept = default;
PreparedCell& PreparedCell::operator=(PreparedCell&&) noexcept = default;
PreparedCell::~PreparedCell() = default;

PreparedCell PreparedCell::Prepare(const Study& study, const Cell& cell) {
  return PreparedCell(PrepareCell(study, cell));
}

const TargetedConfigurations& PreparedCell::pool() const { return context_->pool; }
const ConfigurationSet& PreparedCell::validation() const { return context_->validation; }
int PreparedCell::num_parameters() const {
  return static_cast<int>(context_->parameter_names.size());
}
const std::vector<std::string>& PreparedCell::parameter_names() const {
  return context_->parameter_names;
}
int PreparedCell::num_planes() const { return context_->planes.size(); }

Eigen::MatrixXd PreparedCell::LinearisedValidationDraws(int draws) const {
  return lrcal::LinearisedValidationDraws(*context_, draws);
}

FirstOrderDraws PreparedCell::LinearisedValidationDraws(int draws, int repetitions) const {
  return lrcal::LinearisedValidationDraws(*context_, draws, repetitions);
}

std::optional<AccuracyPrediction> PreparedCell::StatedValidationAccuracy(int repetitions) const {
  return lrcal::StatedValidationAccuracy(*context_, repetitions);
}

TrialRecord PreparedCell::Run(long long trial, TrialDetails* details) const {
  TrialWorkspace workspace;
  return RunTrial(*context_, trial, &workspace, details);
}

}  // namespace lrcal
