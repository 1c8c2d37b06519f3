#include "lrcal/measurement/measurement_set.h"

#include <map>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"

namespace lrcal {

MeasurementSet GroupReadings(const ConfigurationSet& q, const std::vector<double>& h,
                             const RangerSpec* ranger,
                             const std::function<std::string(int)>& where) {
  if (static_cast<std::size_t>(q.size()) != h.size())
    throw InputError(where(-1), std::to_string(q.size()) + " joint rows but " +
                                    std::to_string(h.size()) + " readings; expected one each");
  const int n = q.num_joints();
  std::map<std::vector<double>, int> index;
  std::vector<int> first;  // the reading that opened each configuration
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
    auto [it, inserted] =
        index.emplace(std::vector<double>(q.q(r), q.q(r) + n), static_cast<int>(first.size()));
    if (inserted) {
      first.push_back(r);
      sums.push_back(0);
      counts.push_back(0);
    }
    sums[it->second] += h[r];
    counts[it->second] += 1;
  }
  MeasurementSet data;
  data.configs = ConfigurationSet(n);
  data.configs.Reserve(static_cast<int>(first.size()));
  for (std::size_t i = 0; i < first.size(); ++i) {
    data.configs.AddFrom(q, first[i]);
    data.mean_h.push_back(sums[i] / counts[i]);
    data.repetitions.push_back(counts[i]);
  }
  return data;
}

}  // namespace lrcal
