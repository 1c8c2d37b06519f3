#include "lrcal/measurement/chain_measurement.h"

#include <algorithm>
#include <map>
#include <set>
#include <utility>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

namespace {

// The chain's own configurations bound to the kind: the evaluator owns them (the kind's
// evaluator may point into them).
class ChainEvaluator : public MeasurementEvaluator {
 public:
  ChainEvaluator(const MeasurementKind& kind, TargetedConfigurations configs)
      : configs_(std::move(configs)), evaluator_(kind.Bind(configs_)) {}
  int num_rows() const override { return evaluator_->num_rows(); }
  int num_parameters() const override { return evaluator_->num_parameters(); }
  bool Predict(const double* e, double* y, double* J) override {
    return evaluator_->Predict(e, y, J);
  }

 private:
  TargetedConfigurations configs_;
  std::unique_ptr<MeasurementEvaluator> evaluator_;
};

// Terms of what the chain's tool carries — its frame, a tracker's target, a probe's tip, a
// scanner, a ranger — are the chain's own; the rest (an instrument's frame, sockets, planes) are
// fixed in the world, shared by the chains that see them.
bool IsOnTheTool(const std::string& term) {
  for (const char* prefix : {"tool_", "target", "scanner_", "ranger_"})
    if (term.rfind(prefix, 0) == 0) return true;
  return false;
}

}  // namespace

ChainMeasurement::ChainMeasurement(std::shared_ptr<const MeasurementKind> kind, ChainOfTree chain)
    : kind_(std::move(kind)), chain_(std::move(chain)) {
  if (!kind_) throw InputError("tool-link", "a chain's measurement has no kind");
  if (chain_.label.empty()) throw InputError("tool-link", "a chain needs a label (its tool link)");
  std::set<int> seen;
  for (int j : chain_.joints)
    if (j < 0 || j >= chain_.robot_joints || !seen.insert(j).second)
      throw InputError("tool-link", "chain '" + chain_.label + "': joint index " +
                                        std::to_string(j) + " is repeated or not one of the " +
                                        std::to_string(chain_.robot_joints) + " robot joints");
  const int links = static_cast<int>(chain_.joints.size());
  if (static_cast<int>(chain_.link_labels.size()) != links)
    throw InputError("tool-link", "chain '" + chain_.label + "' has " + std::to_string(links) +
                                      " links and " + std::to_string(chain_.link_labels.size()) +
                                      " link labels");
  for (const std::string& term : kind_->parameter_names()) {
    const int k = LinkValueIndex(term, links);
    const std::string label = k >= 0
                                  ? chain_.link_labels[static_cast<std::size_t>(k / kValuesPerLink)]
                                  : (IsOnTheTool(term) ? chain_.label : "");
    names_.push_back(label.empty() ? term : label + "." + term);
  }
}

void ChainMeasurement::CheckJoints(const TargetedConfigurations& configs) const {
  if (configs.size() > 0 && configs.num_joints() != chain_.robot_joints)
    throw InputError("tool-link", "chain '" + chain_.label + "': configurations of " +
                                      std::to_string(configs.num_joints()) +
                                      " joints, expected the robot's " +
                                      std::to_string(chain_.robot_joints));
}

TargetedConfigurations ChainMeasurement::ChainConfigurations(
    const TargetedConfigurations& configs) const {
  CheckJoints(configs);
  TargetedConfigurations out(static_cast<int>(chain_.joints.size()));
  out.Reserve(configs.size());
  std::vector<double> q(chain_.joints.size());
  for (int i = 0; i < configs.size(); ++i) {
    for (std::size_t k = 0; k < q.size(); ++k) q[k] = configs.q(i)[chain_.joints[k]];
    out.Add(q, configs.target(i));
  }
  return out;
}

TargetedConfigurations ChainMeasurement::RobotConfigurations(
    const TargetedConfigurations& configs, const std::vector<double>& rest) const {
  if (static_cast<int>(rest.size()) != chain_.robot_joints)
    throw InputError("tool-link", "chain '" + chain_.label + "': the robot's rest vector has " +
                                      std::to_string(rest.size()) + " joints, expected " +
                                      std::to_string(chain_.robot_joints));
  if (configs.size() > 0 && configs.num_joints() != static_cast<int>(chain_.joints.size()))
    throw InputError("tool-link", "chain '" + chain_.label + "': configurations of " +
                                      std::to_string(configs.num_joints()) + " joints, expected " +
                                      std::to_string(chain_.joints.size()));
  TargetedConfigurations out(chain_.robot_joints);
  out.Reserve(configs.size());
  std::vector<double> q = rest;
  for (int i = 0; i < configs.size(); ++i) {
    for (std::size_t k = 0; k < chain_.joints.size(); ++k)
      q[static_cast<std::size_t>(chain_.joints[k])] = configs.q(i)[k];
    out.Add(q, configs.target(i));
  }
  return out;
}

std::unique_ptr<MeasurementEvaluator> ChainMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  return std::make_unique<ChainEvaluator>(*kind_, ChainConfigurations(configs));
}

std::vector<std::string> ChainMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                       const double* e) const {
  return kind_->MissReasons(ChainConfigurations(configs), e);
}

TargetedConfigurations ChainMeasurement::LinearisationConfigurations(
    const TargetedConfigurations& configs) const {
  const TargetedConfigurations moved =
      kind_->LinearisationConfigurations(ChainConfigurations(configs));
  TargetedConfigurations out(chain_.robot_joints);
  out.Reserve(configs.size());
  for (int i = 0; i < configs.size(); ++i) {
    std::vector<double> q(configs.q(i), configs.q(i) + chain_.robot_joints);
    for (std::size_t k = 0; k < chain_.joints.size(); ++k)
      q[static_cast<std::size_t>(chain_.joints[k])] = moved.q(i)[k];
    out.Add(q, moved.target(i));
  }
  return out;
}

std::unique_ptr<MeasurementKind> ChainMeasurement::Without(
    const std::vector<std::string>& names) const {
  std::vector<std::string> inner;
  for (const std::string& name : names) {
    const auto it = std::find(names_.begin(), names_.end(), name);
    if (it == names_.end())
      throw InputError("fix", "'" + name + "' is not a term of chain '" + chain_.label + "'");
    inner.push_back(kind_->parameter_names()[static_cast<std::size_t>(it - names_.begin())]);
  }
  return std::make_unique<ChainMeasurement>(
      std::shared_ptr<const MeasurementKind>(kind_->Without(inner)), chain_);
}

}  // namespace lrcal
