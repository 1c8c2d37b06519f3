#include "lrcal/measurement/tree_measurement.h"

#include <utility>

#include "lrcal/core/error.h"

namespace lrcal {

namespace {

MixedMeasurement ChainsAsMixed(const std::vector<std::shared_ptr<const ChainMeasurement>>& chains) {
  if (chains.empty()) throw InputError("sensor", "a tree's measurement needs at least one chain");
  std::vector<MixedPart> parts;
  for (const auto& chain : chains) {
    if (!chain) throw InputError("sensor", "a tree's chain has no measurement");
    const std::string kind = chain->name();
    if (kind == "socket" || kind == "contact")
      throw InputError("sensor", "chain '" + chain->chain().label + "': " + kind +
                                     " data seat each chain at configurations of its own, which "
                                     "one joint vector of the tree cannot hold; identify them "
                                     "chain by chain (lrcal identify --tool-link a,b)");
    if (chain->chain().robot_joints != chains.front()->chain().robot_joints)
      throw InputError("sensor", "the chains are of robots of different joint counts");
    parts.push_back({chain, chain->chain().label, true});
  }
  return MixedMeasurement(std::move(parts));
}

}  // namespace

TreeMeasurement::TreeMeasurement(const std::vector<std::shared_ptr<const ChainMeasurement>>& chains)
    : TreeMeasurement(ChainsAsMixed(chains)) {}

TreeMeasurement::TreeMeasurement(MixedMeasurement mixed) : mixed_(std::move(mixed)) {
  name_ = mixed_.part(0).kind->name();
  for (int p = 0; p < mixed_.num_parts(); ++p) {
    rows_ += mixed_.part(p).kind->rows_per_configuration();
    if (name_ != mixed_.part(p).kind->name()) name_ = "mixed";
  }
}

const char* TreeMeasurement::name() const { return name_.c_str(); }

bool TreeMeasurement::RowIsAngle(int component) const {
  for (int p = 0; p < mixed_.num_parts(); ++p) {
    const int k = mixed_.part(p).kind->rows_per_configuration();
    if (component < k) return mixed_.part(p).kind->RowIsAngle(component);
    component -= k;
  }
  return false;
}

TargetedConfigurations TreeMeasurement::Expand(const TargetedConfigurations& configs) const {
  TargetedConfigurations out(configs.num_joints());
  out.Reserve(configs.size() * rows_);
  for (int i = 0; i < configs.size(); ++i)
    for (int p = 0; p < mixed_.num_parts(); ++p)
      for (int c = 0; c < mixed_.part(p).kind->rows_per_configuration(); ++c)
        out.AddFrom(configs, i, mixed_.Tag(p, configs.target(i), c));
  return out;
}

namespace {

// The mixed evaluator over the expanded configurations, which it needs to outlive it.
class TreeEvaluator : public MeasurementEvaluator {
 public:
  TreeEvaluator(const MixedMeasurement& mixed, TargetedConfigurations expanded)
      : expanded_(std::move(expanded)), evaluator_(mixed.Bind(expanded_)) {}
  int num_rows() const override { return evaluator_->num_rows(); }
  int num_parameters() const override { return evaluator_->num_parameters(); }
  bool Predict(const double* e, double* y, double* J) override {
    return evaluator_->Predict(e, y, J);
  }

 private:
  TargetedConfigurations expanded_;
  std::unique_ptr<MeasurementEvaluator> evaluator_;
};

}  // namespace

std::unique_ptr<MeasurementEvaluator> TreeMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  return std::make_unique<TreeEvaluator>(mixed_, Expand(configs));
}

std::vector<std::string> TreeMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                      const double* e) const {
  const std::vector<std::string> per_value = mixed_.MissReasons(Expand(configs), e);
  std::vector<std::string> out(static_cast<std::size_t>(configs.size()), "ok");
  for (std::size_t i = 0; i < out.size(); ++i)
    for (std::size_t r = 0; r < static_cast<std::size_t>(rows_); ++r) {
      const std::string& reason = per_value[i * static_cast<std::size_t>(rows_) + r];
      if (reason != "ok") {
        out[i] = reason;
        break;
      }
    }
  return out;
}

std::unique_ptr<MeasurementKind> TreeMeasurement::Without(
    const std::vector<std::string>& names) const {
  std::unique_ptr<MeasurementKind> held = mixed_.Without(names);
  return std::unique_ptr<MeasurementKind>(
      new TreeMeasurement(std::move(dynamic_cast<MixedMeasurement&>(*held))));
}

}  // namespace lrcal
