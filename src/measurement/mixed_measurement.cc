#include "lrcal/measurement/mixed_measurement.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/parameter_set.h"

namespace lrcal {

namespace {

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// Predicts every part at its share of the mixed estimate and lays the rows out as the entries.
// It owns the parts' configurations, which their evaluators may point to.
class MixedEvaluator : public MeasurementEvaluator {
 public:
  MixedEvaluator(const std::vector<MixedPart>& kinds, const std::vector<std::vector<int>>& columns,
                 std::vector<TargetedConfigurations> configs, std::vector<std::vector<int>> entries,
                 int num_rows, int num_parameters)
      : configs_(std::move(configs)), rows_(num_rows), parameters_(num_parameters) {
    for (std::size_t p = 0; p < kinds.size(); ++p) {
      Part part;
      part.evaluator = kinds[p].kind->Bind(configs_[p]);
      part.columns = &columns[p];
      part.entries = std::move(entries[p]);
      const int r = part.evaluator->num_rows(), n = part.evaluator->num_parameters();
      part.e.assign(static_cast<std::size_t>(n), 0.0);
      part.y.assign(static_cast<std::size_t>(r), 0.0);
      part.J.assign(static_cast<std::size_t>(r) * n, 0.0);
      parts_.push_back(std::move(part));
    }
  }
  int num_rows() const override { return rows_; }
  int num_parameters() const override { return parameters_; }
  bool Predict(const double* e, double* y, double* J) override {
    bool ok = true;
    if (J) std::fill(J, J + static_cast<std::ptrdiff_t>(rows_) * parameters_, 0.0);
    for (Part& p : parts_) {
      const int rows = p.evaluator->num_rows(), n = p.evaluator->num_parameters();
      if (rows == 0) continue;
      for (int t = 0; t < n; ++t) p.e[t] = e[(*p.columns)[t]];
      ok = p.evaluator->Predict(p.e.data(), p.y.data(), J ? p.J.data() : nullptr) && ok;
      for (int r = 0; r < rows; ++r) y[p.entries[r]] = p.y[r];
      if (!J) continue;
      for (int t = 0; t < n; ++t) {
        double* column = J + static_cast<std::ptrdiff_t>((*p.columns)[t]) * rows_;
        const double* part_column = p.J.data() + static_cast<std::ptrdiff_t>(t) * rows;
        for (int r = 0; r < rows; ++r) column[p.entries[r]] = part_column[r];
      }
    }
    return ok;
  }

 private:
  struct Part {
    std::unique_ptr<MeasurementEvaluator> evaluator;
    const std::vector<int>* columns = nullptr;  // the part's terms' columns in the mixed estimate
    std::vector<int> entries;                   // per row of the part's evaluator, its entry
    std::vector<double> e, y, J;
  };
  std::vector<TargetedConfigurations> configs_;
  std::vector<Part> parts_;
  int rows_, parameters_;
};

}  // namespace

std::vector<MixedPart> PartsLabelledByKind(
    const std::vector<std::shared_ptr<const MeasurementKind>>& kinds) {
  std::map<std::string, int> seen, total;
  for (const auto& kind : kinds) ++total[kind->name()];
  std::vector<MixedPart> parts;
  for (const auto& kind : kinds) {
    const std::string name = kind->name();
    const int n = ++seen[name];
    parts.push_back({kind, total[name] > 1 ? name + std::to_string(n) : name});
  }
  return parts;
}

bool MixedMeasurement::IsSharedTerm(const std::string& full_name) {
  constexpr int kAnyLinks = 1000;  // link value names are theta<k>, a<k>, …: any chain length
  // A tree's chain labels its own links and tool ("left_tool.theta4", chain_measurement.h): the
  // chains that have that link or tool share it by that name.
  const std::string name = UnlabelledName(full_name);
  return LinkValueIndex(name, kAnyLinks) >= 0 || StartsWith(name, "tool_") ||
         (name == full_name && (StartsWith(name, "base_") || StartsWith(name, "plane")));
}

MixedMeasurement::MixedMeasurement(std::vector<MixedPart> parts)
    : MixedMeasurement(std::move(parts), {}) {}

namespace {

// Labels filled in and checked; how many parts have each own (unshared) term.
std::map<std::string, int> CountOwnTerms(std::vector<MixedPart>* parts) {
  if (parts->empty()) throw InputError("sensor", "a mixed measurement needs at least one kind");
  std::set<std::string> labels;
  std::map<std::string, int> own_count;
  for (MixedPart& p : *parts) {
    if (!p.kind) throw InputError("sensor", "a mixed measurement's part has no kind");
    if (p.label.empty()) p.label = p.kind->name();
    if (!labels.insert(p.label).second)
      throw InputError("sensor", "two parts of a mixed measurement are labelled '" + p.label +
                                     "': give each its own label");
    if (p.names_are_shared) continue;
    for (const std::string& name : p.kind->parameter_names())
      if (!MixedMeasurement::IsSharedTerm(name)) ++own_count[name];
  }
  return own_count;
}

}  // namespace

MixedMeasurement::MixedMeasurement(std::vector<MixedPart> parts, std::set<std::string> prefixed)
    : parts_(std::move(parts)), prefixed_(std::move(prefixed)) {
  const std::map<std::string, int> own_count = CountOwnTerms(&parts_);
  std::map<std::string, int> column_of;
  std::vector<double> nominal;
  std::vector<std::string> first_part;  // per mixed term, the label of the first part with it
  for (const MixedPart& p : parts_) {
    max_rows_ = std::max(max_rows_, p.kind->rows_per_configuration());
    const Eigen::VectorXd values = p.kind->NominalValues();
    std::vector<int> columns;
    std::vector<std::string> own;
    for (int t = 0; t < p.kind->num_parameters(); ++t) {
      const std::string& term = p.kind->parameter_names()[static_cast<std::size_t>(t)];
      const std::string label_term = p.label + "." + term;
      const auto count = own_count.find(term);
      if ((count != own_count.end() && count->second > 1) || prefixed_.count(label_term))
        prefixed_.insert(label_term);
      const std::string name = prefixed_.count(label_term) ? label_term : term;
      own.push_back(name);
      const auto [it, inserted] = column_of.emplace(name, static_cast<int>(names_.size()));
      const auto column = static_cast<std::size_t>(it->second);
      if (inserted) {
        names_.push_back(name);
        nominal.push_back(values[t]);
        first_part.push_back(p.label);
      } else if (std::abs(nominal[column] - values[t]) >
                 1e-12 * std::max(1.0, std::abs(nominal[column]))) {
        throw InputError("sensor", "the " + first_part[column] + " and " + p.label +
                                       " measurements disagree on " + name +
                                       "'s nominal value; build them on the same robot and planes");
      }
      columns.push_back(it->second);
    }
    columns_.push_back(std::move(columns));
    own_names_.push_back(std::move(own));
  }
  nominal_ =
      Eigen::Map<const Eigen::VectorXd>(nominal.data(), static_cast<Eigen::Index>(nominal.size()));
}

int MixedMeasurement::Tag(int part, int target, int component) const {
  return (target * num_parts() + part) * max_rows_ + component;
}

MixedMeasurement::Entry MixedMeasurement::Decode(int tag) const {
  Entry e;
  e.component = tag % max_rows_;
  e.part = (tag / max_rows_) % num_parts();
  e.target = tag / max_rows_ / num_parts();
  return e;
}

MeasuredValues MixedMeasurement::Combine(const std::vector<MeasuredValues>& values) const {
  if (static_cast<int>(values.size()) != num_parts())
    throw InputError("sensor", "expected measured values for each of the " +
                                   std::to_string(num_parts()) + " kinds, got " +
                                   std::to_string(values.size()));
  int num_joints = -1;
  for (const MeasuredValues& v : values)
    if (v.size() > 0) {
      if (num_joints >= 0 && v.configs.num_joints() != num_joints)
        throw InputError("sensor", "the kinds' data have different numbers of joints (" +
                                       std::to_string(num_joints) + " and " +
                                       std::to_string(v.configs.num_joints()) + ")");
      num_joints = v.configs.num_joints();
    }
  MeasuredValues out{TargetedConfigurations(std::max(num_joints, 0)), {}, {}};
  for (int p = 0; p < num_parts(); ++p) {
    const MeasuredValues& v = values[static_cast<std::size_t>(p)];
    const int k = part(p).kind->rows_per_configuration();
    const std::vector<double> weights = v.RowWeights(k);
    if (v.y.size() != static_cast<std::size_t>(k) * v.size() ||
        v.repetitions.size() != static_cast<std::size_t>(v.size()) || weights.size() != v.y.size())
      throw InputError(part(p).label,
                       "measured values are inconsistent (configurations, values, "
                       "repetitions, weights)");
    for (int i = 0; i < v.size(); ++i)
      for (int c = 0; c < k; ++c) {
        const auto row = static_cast<std::size_t>(i) * k + c;
        out.configs.AddFrom(v.configs, i, Tag(p, v.configs.target(i), c));
        out.y.push_back(v.y[row]);
        out.repetitions.push_back(v.repetitions[static_cast<std::size_t>(i)]);
        out.weights.push_back(weights[row]);
      }
  }
  return out;
}

MixedMeasurement::Grouped MixedMeasurement::Group(const TargetedConfigurations& configs) const {
  Grouped g;
  g.configs.assign(static_cast<std::size_t>(num_parts()),
                   TargetedConfigurations(configs.num_joints()));
  g.entries.resize(static_cast<std::size_t>(num_parts()));
  const int nj = configs.num_joints();
  for (int i = 0; i < configs.size();) {
    const Entry first = Decode(configs.target(i));
    const std::string where = "mixed measurement entry " + std::to_string(i + 1);
    if (first.component != 0)
      throw InputError(where,
                       "expected the first value of a configuration (component 0), got "
                       "component " +
                           std::to_string(first.component));
    const int k = part(first.part).kind->rows_per_configuration();
    for (int c = 1; c < k; ++c) {
      const int j = i + c;
      if (j >= configs.size())
        throw InputError(where, "the " + part(first.part).label + " configuration has " +
                                    std::to_string(c) + " of its " + std::to_string(k) + " values");
      const Entry e = Decode(configs.target(j));
      if (e.part != first.part || e.target != first.target || e.component != c ||
          !std::equal(configs.q(i), configs.q(i) + nj, configs.q(j)))
        throw InputError("mixed measurement entry " + std::to_string(j + 1),
                         "expected value " + std::to_string(c + 1) + " of the " +
                             part(first.part).label + " configuration at entry " +
                             std::to_string(i + 1));
    }
    const auto p = static_cast<std::size_t>(first.part);
    g.configs[p].AddFrom(configs, i, first.target);
    for (int c = 0; c < k; ++c) g.entries[p].push_back(i + c);
    i += k;
  }
  return g;
}

std::vector<int> MixedMeasurement::ConfigurationsPerPart(
    const TargetedConfigurations& configs) const {
  const Grouped g = Group(configs);
  std::vector<int> counts;
  for (const TargetedConfigurations& c : g.configs) counts.push_back(c.size());
  return counts;
}

std::unique_ptr<MeasurementEvaluator> MixedMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  Grouped g = Group(configs);
  return std::make_unique<MixedEvaluator>(parts_, columns_, std::move(g.configs),
                                          std::move(g.entries), configs.size(), num_parameters());
}

std::vector<std::string> MixedMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                       const double* e) const {
  const Grouped g = Group(configs);
  std::vector<std::string> out(static_cast<std::size_t>(configs.size()));
  for (int p = 0; p < num_parts(); ++p) {
    const auto u = static_cast<std::size_t>(p);
    std::vector<double> part_e(columns_[u].size(), 0.0);
    if (e)
      for (std::size_t t = 0; t < part_e.size(); ++t) part_e[t] = e[columns_[u][t]];
    const std::vector<std::string> reasons = part(p).kind->MissReasons(g.configs[u], part_e.data());
    const int k = part(p).kind->rows_per_configuration();
    for (std::size_t r = 0; r < g.entries[u].size(); ++r)
      out[static_cast<std::size_t>(g.entries[u][r])] = reasons[r / static_cast<std::size_t>(k)];
  }
  return out;
}

TargetedConfigurations MixedMeasurement::LinearisationConfigurations(
    const TargetedConfigurations& configs) const {
  const Grouped g = Group(configs);
  std::vector<TargetedConfigurations> moved;
  std::vector<int> source_part(static_cast<std::size_t>(configs.size())),
      source_index(static_cast<std::size_t>(configs.size()));
  for (int p = 0; p < num_parts(); ++p) {
    const auto u = static_cast<std::size_t>(p);
    moved.push_back(part(p).kind->LinearisationConfigurations(g.configs[u]));
    const int k = part(p).kind->rows_per_configuration();
    for (std::size_t r = 0; r < g.entries[u].size(); ++r) {
      source_part[static_cast<std::size_t>(g.entries[u][r])] = p;
      source_index[static_cast<std::size_t>(g.entries[u][r])] = static_cast<int>(r) / k;
    }
  }
  TargetedConfigurations out(configs.num_joints());
  out.Reserve(configs.size());
  for (int i = 0; i < configs.size(); ++i)
    out.AddFrom(moved[static_cast<std::size_t>(source_part[static_cast<std::size_t>(i)])],
                source_index[static_cast<std::size_t>(i)], configs.target(i));
  return out;
}

std::unique_ptr<MeasurementKind> MixedMeasurement::Without(
    const std::vector<std::string>& names) const {
  std::set<std::string> wanted(names.begin(), names.end()), found;
  std::vector<MixedPart> parts;
  for (int p = 0; p < num_parts(); ++p) {
    const auto u = static_cast<std::size_t>(p);
    std::vector<std::string> held;
    for (std::size_t t = 0; t < own_names_[u].size(); ++t)
      if (wanted.count(own_names_[u][t])) {
        held.push_back(part(p).kind->parameter_names()[t]);
        found.insert(own_names_[u][t]);
      }
    parts.push_back({held.empty()
                         ? part(p).kind
                         : std::shared_ptr<const MeasurementKind>(part(p).kind->Without(held)),
                     part(p).label, part(p).names_are_shared});
  }
  for (const std::string& name : names)
    if (!found.count(name))
      throw InputError("fix", "'" + name + "' is not a term of this mixed measurement");
  // The names stay as they were: a term prefixed for a clash keeps its prefix when the term it
  // clashed with is held.
  return std::unique_ptr<MeasurementKind>(new MixedMeasurement(std::move(parts), prefixed_));
}

}  // namespace lrcal
