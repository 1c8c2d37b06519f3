#include "lrcal/measurement/chain_measurement.h"

#include <algorithm>
#include <set>
#include <utility>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

namespace {

// Terms of what the chain's tool carries — its frame, a tracker's target, a probe's tip, a
// scanner, a ranger — are the chain's own; the rest (an instrument's frame, sockets, planes) are
// fixed in the world, shared by the chains that see them.
bool IsOnTheTool(const std::string& term) {
  for (const char* prefix : {"tool_", "target", "scanner_", "ranger_"})
    if (term.rfind(prefix, 0) == 0) return true;
  return false;
}

}  // namespace

void ChainMeasurement::CheckChain() const {
  if (!kind_) throw InputError("tool-link", "a chain's measurement has no kind");
  if (chain_.label.empty()) throw InputError("tool-link", "a chain needs a label (its tool link)");
  const int links = static_cast<int>(chain_.joints.size());
  const std::string chain = "chain '" + chain_.label + "': ";
  std::vector<bool> coupled(static_cast<std::size_t>(links), false);
  for (const JointCoupling& c : chain_.couplings) {
    if (c.link < 0 || c.link >= links || coupled[static_cast<std::size_t>(c.link)] ||
        chain_.joints[static_cast<std::size_t>(c.link)] != c.joint)
      throw InputError("tool-link", chain + "a coupling of link " + std::to_string(c.link + 1) +
                                        " that is not one of its links, is given twice, or "
                                        "does not name the joint the link lists");
    coupled[static_cast<std::size_t>(c.link)] = true;
  }
  std::set<int> seen;
  for (int k = 0; k < links; ++k) {
    const int j = chain_.joints[static_cast<std::size_t>(k)];
    if (j < 0 || j >= chain_.robot_joints ||
        (!coupled[static_cast<std::size_t>(k)] && !seen.insert(j).second))
      throw InputError("tool-link", chain + "joint index " + std::to_string(j) +
                                        " is repeated or not one of the " +
                                        std::to_string(chain_.robot_joints) + " robot joints");
  }
  if (static_cast<int>(chain_.link_labels.size()) != links)
    throw InputError("tool-link", chain + std::to_string(links) + " links and " +
                                      std::to_string(chain_.link_labels.size()) + " link labels");
}

ChainMeasurement::ChainMeasurement(std::shared_ptr<const MeasurementKind> kind, ChainOfTree chain,
                                   const std::vector<int>& held_gains,
                                   const std::vector<int>& hidden)
    : kind_(std::move(kind)), chain_(std::move(chain)), hidden_(hidden) {
  CheckChain();
  const int links = static_cast<int>(chain_.joints.size());
  const std::vector<std::string>& inner = kind_->parameter_names();
  for (int t = 0; t < static_cast<int>(inner.size()); ++t) {
    if (std::find(hidden_.begin(), hidden_.end(), t) != hidden_.end()) continue;
    const std::string& term = inner[static_cast<std::size_t>(t)];
    const int k = LinkValueIndex(term, links);
    const std::string label = k >= 0
                                  ? chain_.link_labels[static_cast<std::size_t>(k / kValuesPerLink)]
                                  : (IsOnTheTool(term) ? chain_.label : "");
    names_.push_back(label.empty() ? term : label + "." + term);
    layout_.inner_column.push_back(t);
  }
  // A gain is estimated with its link's joint offset (θ0, or d0 for a prismatic link).
  for (int c = 0; c < static_cast<int>(chain_.couplings.size()); ++c) {
    const JointCoupling& coupling = chain_.couplings[static_cast<std::size_t>(c)];
    const std::string offset =
        LinkValueFullName(coupling.link * kValuesPerLink + (coupling.prismatic ? kD : kTheta));
    const auto it = std::find(inner.begin(), inner.end(), offset);
    const bool held = std::find(held_gains.begin(), held_gains.end(), c) != held_gains.end();
    if (it == inner.end() || held) {
      gain_names_.emplace_back();
      continue;
    }
    const std::string& label = chain_.link_labels[static_cast<std::size_t>(coupling.link)];
    const std::string name = "coupling" + std::to_string(coupling.link + 1) + "_gain";
    gain_names_.push_back(label.empty() ? name : label + "." + name);
    names_.push_back(gain_names_.back());
    layout_.gain_coupling.push_back(c);
    layout_.gain_column.push_back(static_cast<int>(it - inner.begin()));
  }
}

Eigen::VectorXd ChainMeasurement::NominalValues() const {
  const Eigen::VectorXd inner = kind_->NominalValues();
  Eigen::VectorXd out = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(names_.size()));
  for (std::size_t t = 0; t < layout_.inner_column.size(); ++t)
    out[static_cast<Eigen::Index>(t)] = inner[layout_.inner_column[t]];
  return out;
}

std::vector<double> ChainMeasurement::Gains(const double* e) const {
  std::vector<double> gains(chain_.couplings.size(), 0.0);
  if (!e) return gains;
  const std::size_t shown = layout_.inner_column.size();
  for (std::size_t g = 0; g < layout_.gain_coupling.size(); ++g)
    gains[static_cast<std::size_t>(layout_.gain_coupling[g])] = e[shown + g];
  return gains;
}

std::vector<bool> ChainMeasurement::CoupledLinks() const {
  std::vector<bool> coupled(chain_.joints.size(), false);
  for (const JointCoupling& c : chain_.couplings) coupled[static_cast<std::size_t>(c.link)] = true;
  return coupled;
}

void ChainMeasurement::CheckJoints(const TargetedConfigurations& configs) const {
  if (configs.size() > 0 && configs.num_joints() != chain_.robot_joints)
    throw InputError("tool-link", "chain '" + chain_.label + "': configurations of " +
                                      std::to_string(configs.num_joints()) +
                                      " joints, expected the robot's " +
                                      std::to_string(chain_.robot_joints));
}

TargetedConfigurations ChainMeasurement::ChainConfigurations(
    const TargetedConfigurations& configs, const std::vector<double>& gains) const {
  CheckJoints(configs);
  TargetedConfigurations out(static_cast<int>(chain_.joints.size()));
  out.Reserve(configs.size());
  std::vector<double> q(chain_.joints.size());
  for (int i = 0; i < configs.size(); ++i) {
    for (std::size_t k = 0; k < q.size(); ++k) q[k] = configs.q(i)[chain_.joints[k]];
    for (std::size_t c = 0; c < chain_.couplings.size(); ++c) {
      const JointCoupling& coupling = chain_.couplings[c];
      const double m = coupling.multiplier + (gains.empty() ? 0.0 : gains[c]);
      q[static_cast<std::size_t>(coupling.link)] =
          m * configs.q(i)[coupling.joint] + coupling.offset;
    }
    out.Add(q, configs.target(i));
  }
  return out;
}

TargetedConfigurations ChainMeasurement::RobotConfigurations(
    const TargetedConfigurations& configs, const std::vector<double>& rest) const {
  if (!rest.empty() && static_cast<int>(rest.size()) != chain_.robot_joints)
    throw InputError("tool-link", "chain '" + chain_.label + "': the robot's rest vector has " +
                                      std::to_string(rest.size()) + " joints, expected " +
                                      std::to_string(chain_.robot_joints));
  if (configs.size() > 0 && configs.num_joints() != static_cast<int>(chain_.joints.size()))
    throw InputError("tool-link", "chain '" + chain_.label + "': configurations of " +
                                      std::to_string(configs.num_joints()) + " joints, expected " +
                                      std::to_string(chain_.joints.size()));
  const std::vector<bool> coupled = CoupledLinks();
  TargetedConfigurations out(chain_.robot_joints);
  out.Reserve(configs.size());
  std::vector<double> q =
      rest.empty() ? std::vector<double>(static_cast<std::size_t>(chain_.robot_joints), 0.0) : rest;
  for (int i = 0; i < configs.size(); ++i) {
    for (std::size_t k = 0; k < chain_.joints.size(); ++k)
      if (!coupled[k]) q[static_cast<std::size_t>(chain_.joints[k])] = configs.q(i)[k];
    out.Add(q, configs.target(i));
  }
  return out;
}

namespace {

// The kind bound to the chain's configurations at the current gains, rebound when they change.
// The kind's estimate holds the shown terms (a hidden one at 0); each gain's column is its
// link's joint-offset column times the joint it follows.
class ChainEvaluator : public MeasurementEvaluator {
 public:
  ChainEvaluator(const ChainMeasurement& chain, const TargetedConfigurations& configs)
      : chain_(chain),
        layout_(chain.layout()),
        robot_configs_(configs),
        nominal_configs_(chain.ChainConfigurations(configs)),
        gains_(chain.chain().couplings.size(), 0.0),
        inner_e_(static_cast<std::size_t>(chain.kind().num_parameters()), 0.0) {
    Rebind();
  }
  int num_rows() const override { return evaluator_->num_rows(); }
  int num_parameters() const override {
    return static_cast<int>(layout_.inner_column.size() + layout_.gain_coupling.size());
  }
  bool Predict(const double* e, double* y, double* J) override {
    const std::size_t shown = layout_.inner_column.size();
    for (std::size_t t = 0; t < shown; ++t)
      inner_e_[static_cast<std::size_t>(layout_.inner_column[t])] = e[t];
    bool changed = false;
    for (std::size_t g = 0; g < layout_.gain_coupling.size(); ++g) {
      double& gain = gains_[static_cast<std::size_t>(layout_.gain_coupling[g])];
      changed = changed || gain != e[shown + g];
      gain = e[shown + g];
    }
    if (changed) Rebind();
    const int rows = num_rows();
    inner_J_.resize(J ? static_cast<std::size_t>(rows) * inner_e_.size() : 0);
    const bool ok = evaluator_->Predict(inner_e_.data(), y, J ? inner_J_.data() : nullptr);
    if (!J) return ok;
    const auto column = [&](int inner) {
      return inner_J_.data() + static_cast<std::ptrdiff_t>(inner) * rows;
    };
    for (std::size_t t = 0; t < shown; ++t)
      std::copy(column(layout_.inner_column[t]), column(layout_.inner_column[t]) + rows,
                J + static_cast<std::ptrdiff_t>(t) * rows);
    const int per_config = chain_.rows_per_configuration();
    for (std::size_t g = 0; g < layout_.gain_coupling.size(); ++g) {
      const JointCoupling& c =
          chain_.chain().couplings[static_cast<std::size_t>(layout_.gain_coupling[g])];
      const double* offset = column(layout_.gain_column[g]);
      double* out = J + static_cast<std::ptrdiff_t>(shown + g) * rows;
      for (int r = 0; r < rows; ++r) out[r] = offset[r] * robot_configs_.q(r / per_config)[c.joint];
    }
    return ok;
  }

 private:
  // The values stay in the charts of the configurations at the nominal multipliers (a pose's
  // orientation rows are measured from them): only the coupled joints move with the gains.
  void Rebind() {
    configs_ = chain_.ChainConfigurations(robot_configs_, gains_);
    evaluator_ = chain_.kind().BindInChartsOf(configs_, nominal_configs_);
  }

  const ChainMeasurement& chain_;
  const ChainMeasurement::Layout& layout_;
  TargetedConfigurations robot_configs_, nominal_configs_, configs_;
  std::vector<double> gains_, inner_e_, inner_J_;
  std::unique_ptr<MeasurementEvaluator> evaluator_;
};

}  // namespace

std::unique_ptr<MeasurementEvaluator> ChainMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  CheckJoints(configs);
  return std::make_unique<ChainEvaluator>(*this, configs);
}

std::vector<std::string> ChainMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                       const double* e) const {
  if (!e) return kind_->MissReasons(ChainConfigurations(configs), nullptr);
  std::vector<double> inner(static_cast<std::size_t>(kind_->num_parameters()), 0.0);
  for (std::size_t t = 0; t < layout_.inner_column.size(); ++t)
    inner[static_cast<std::size_t>(layout_.inner_column[t])] = e[t];
  return kind_->MissReasons(ChainConfigurations(configs, Gains(e)), inner.data());
}

TargetedConfigurations ChainMeasurement::LinearisationConfigurations(
    const TargetedConfigurations& configs) const {
  const TargetedConfigurations moved =
      kind_->LinearisationConfigurations(ChainConfigurations(configs));
  const std::vector<bool> coupled = CoupledLinks();
  TargetedConfigurations out(chain_.robot_joints);
  out.Reserve(configs.size());
  for (int i = 0; i < configs.size(); ++i) {
    std::vector<double> q(configs.q(i), configs.q(i) + chain_.robot_joints);
    for (std::size_t k = 0; k < chain_.joints.size(); ++k)
      if (!coupled[k]) q[static_cast<std::size_t>(chain_.joints[k])] = moved.q(i)[k];
    out.Add(q, moved.target(i));
  }
  return out;
}

std::unique_ptr<MeasurementKind> ChainMeasurement::Without(
    const std::vector<std::string>& names) const {
  std::vector<int> held_gains, hidden = hidden_, inner_held;
  for (std::size_t c = 0; c < gain_names_.size(); ++c)
    if (gain_names_[c].empty()) held_gains.push_back(static_cast<int>(c));
  for (const std::string& name : names) {
    const auto it = std::find(names_.begin(), names_.end(), name);
    if (it == names_.end())
      throw InputError("fix", "'" + name + "' is not a term of chain '" + chain_.label + "'");
    const auto t = static_cast<std::size_t>(it - names_.begin());
    if (t >= layout_.inner_column.size()) {  // a gain
      held_gains.push_back(layout_.gain_coupling[t - layout_.inner_column.size()]);
      continue;
    }
    const int inner = layout_.inner_column[t];
    const bool feeds_a_gain = std::find(layout_.gain_column.begin(), layout_.gain_column.end(),
                                        inner) != layout_.gain_column.end();
    (feeds_a_gain ? hidden : inner_held).push_back(inner);
  }
  // The kind without the held terms; the hidden ones' columns renumbered with it.
  std::vector<std::string> held_names;
  for (int t : inner_held)
    held_names.push_back(kind_->parameter_names()[static_cast<std::size_t>(t)]);
  std::shared_ptr<const MeasurementKind> kept(kind_->Without(held_names));
  std::vector<int> renumbered;
  for (int t : hidden) {
    const std::string& term = kind_->parameter_names()[static_cast<std::size_t>(t)];
    const auto at = std::find(kept->parameter_names().begin(), kept->parameter_names().end(), term);
    renumbered.push_back(static_cast<int>(at - kept->parameter_names().begin()));
  }
  return std::unique_ptr<MeasurementKind>(
      new ChainMeasurement(std::move(kept), chain_, held_gains, renumbered));
}

}  // namespace lrcal
