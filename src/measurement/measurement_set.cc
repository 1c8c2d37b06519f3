#include "lrcal/measurement/measurement_set.h"

#include <cmath>
#include <map>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"

namespace lrcal {

namespace {

// The label and joint values of each labelled configuration: its first reading's joint values
// if all its readings agree, else their mean (summed in reading order).
void LabelledJointValues(const TargetedConfigurations& q, const std::vector<int>& group,
                         const std::vector<int>& first, const std::vector<std::string>& labels,
                         MeasurementSet* data) {
  for (int r : first) data->labels.push_back(labels[static_cast<std::size_t>(r)]);
  const int n = q.num_joints(), m = static_cast<int>(first.size());
  std::vector<double> sum(static_cast<std::size_t>(m) * n, 0.0);
  std::vector<int> count(m, 0);
  std::vector<bool> differ(m, false);
  for (int r = 0; r < q.size(); ++r) {
    const int g = group[r];
    ++count[g];
    for (int j = 0; j < n; ++j) {
      sum[static_cast<std::size_t>(g) * n + j] += q.q(r)[j];
      differ[g] = differ[g] || q.q(r)[j] != q.q(first[g])[j];
    }
  }
  data->configs = TargetedConfigurations(n);
  data->configs.Reserve(m);
  std::vector<double> mean(n);
  for (int g = 0; g < m; ++g) {
    if (!differ[g]) {
      data->configs.AddFrom(q, first[g]);
      continue;
    }
    for (int j = 0; j < n; ++j) mean[j] = sum[static_cast<std::size_t>(g) * n + j] / count[g];
    data->configs.Add(mean.data(), q.target(first[g]));
    data->configs.SetEnvironment(g, q.environment(first[g]));
  }
}

// A median or trimmed mean of each configuration's readings (group[r]: reading r's configuration,
// first[i]: configuration i's first reading) in place of their mean, with its variance factor.
void CombineRobustly(const std::vector<double>& h, const std::vector<int>& group,
                     const std::vector<int>& first, const Averaging& average,
                     const std::function<std::string(int)>& where, MeasurementSet* data) {
  std::vector<std::vector<double>> readings(first.size());
  for (std::size_t r = 0; r < group.size(); ++r)
    readings[static_cast<std::size_t>(group[r])].push_back(h[r]);
  for (std::size_t i = 0; i < first.size(); ++i) {
    const int n = static_cast<int>(readings[i].size());
    data->mean_h[i] = average.Combine(readings[i].data(), n);
    try {
      data->variance_factor.push_back(average.VarianceFactor(n));
    } catch (const SettingError& e) {
      throw InputError(where(first[i]), e.Problem());
    }
  }
}

}  // namespace

namespace {

// What makes reading r's configuration: its joint values, its plane (one pose read on two planes
// is two configurations) and, when given, its environment (one pose read warm and cold is two).
std::vector<double> ReadingKey(const TargetedConfigurations& q, int r, bool environments) {
  std::vector<double> key(q.q(r), q.q(r) + q.num_joints());
  key.push_back(q.target(r));
  if (environments) {
    const Environment& e = q.environment(r);
    // A field not given (NaN) keys as −∞, which no read value is: NaN has no order.
    const auto ordered = [](double x) { return x == x ? x : -HUGE_VAL; };
    key.insert(key.end(), {ordered(e.gravity[0]), ordered(e.gravity[1]), ordered(e.gravity[2]),
                           ordered(e.temperature_c)});
  }
  return key;
}

// Reading r joins the configuration opened by reading `first`, grouped by label: the same plane
// and the same environment.
void CheckSameConfiguration(const TargetedConfigurations& q, int r, int first,
                            const std::function<std::string(int)>& where) {
  if (!(q.environment(r) == q.environment(first)))
    throw InputError(where(r), "this reading's environment (" + q.environment(r).ToString() +
                                   ") is not that of earlier readings of its configuration (" +
                                   q.environment(first).ToString() +
                                   "); one configuration is read in one environment");
  if (q.target(r) != q.target(first))
    throw InputError(where(r), "this reading is on plane " + std::to_string(q.target(r) + 1) +
                                   " but earlier readings of its configuration are on plane " +
                                   std::to_string(q.target(first) + 1) +
                                   "; one configuration's readings are on one plane");
}

}  // namespace

MeasurementSet GroupReadings(const TargetedConfigurations& q, const std::vector<double>& h,
                             const RangerSpec* ranger, const std::function<std::string(int)>& where,
                             const std::vector<std::string>* labels, const Averaging& average) {
  if (static_cast<std::size_t>(q.size()) != h.size())
    throw InputError(where(-1), std::to_string(q.size()) + " joint rows but " +
                                    std::to_string(h.size()) + " readings; expected one each");
  const int n = q.num_joints();
  if (labels && labels->size() != h.size())
    throw InputError(where(-1), "expected one configuration label per reading");
  const bool environments = q.HasEnvironments();
  std::map<std::vector<double>, int> index;
  std::map<std::string, int> label_index;
  std::vector<int> first;  // the reading that opened each configuration
  std::vector<int> group;  // each reading's configuration
  std::vector<double> sums;
  std::vector<int> counts;
  for (int r = 0; r < q.size(); ++r) {
    if (!(h[r] > 0))
      throw InputError(where(r),
                       "a reading must be a positive distance in m, got " + FormatExact(h[r]));
    if (ranger && (h[r] < ranger->min_range || h[r] > ranger->max_range))
      throw InputError(where(r), FormatExact(h[r]) + " m is outside the ranger's range [" +
                                     FormatExact(ranger->min_range) + ", " +
                                     FormatExact(ranger->max_range) +
                                     "] m (the robot file's ranger:); readings are in metres: "
                                     "were they written in mm?");
    const int next = static_cast<int>(first.size());
    int id;
    if (labels) {
      id = label_index.emplace((*labels)[r], next).first->second;
    } else {
      id = index.emplace(ReadingKey(q, r, environments), next).first->second;
    }
    if (id != next) CheckSameConfiguration(q, r, first[id], where);
    if (id == next) {
      first.push_back(r);
      sums.push_back(0);
      counts.push_back(0);
    }
    group.push_back(id);
    sums[id] += h[r];
    counts[id] += 1;
  }
  MeasurementSet data;
  if (labels) {
    LabelledJointValues(q, group, first, *labels, &data);
  } else {
    data.configs = TargetedConfigurations(n);
    data.configs.Reserve(static_cast<int>(first.size()));
    for (std::size_t i = 0; i < first.size(); ++i) data.configs.AddFrom(q, first[i]);
  }
  for (std::size_t i = 0; i < first.size(); ++i) {
    data.mean_h.push_back(sums[i] / counts[i]);
    data.repetitions.push_back(counts[i]);
  }
  if (!average.IsMean()) CombineRobustly(h, group, first, average, where, &data);
  return data;
}

}  // namespace lrcal
