#include "lrcal/measurement/constraint_kinds.h"

#include <algorithm>

#include "lrcal/core/error.h"

namespace lrcal {

TargetedConfigurations SeatEach(const TargetedConfigurations& configs,
                                const std::function<bool(double* q, int target)>& seat) {
  const int nj = configs.num_joints();
  TargetedConfigurations seated(nj);
  seated.Reserve(configs.size());
  std::vector<double> q(static_cast<std::size_t>(nj));
  for (int i = 0; i < configs.size(); ++i) {
    std::copy(configs.q(i), configs.q(i) + nj, q.begin());
    if (seat(q.data(), configs.target(i)))
      seated.Add(q.data(), configs.target(i));
    else
      seated.AddFrom(configs, i);
  }
  return seated;
}

std::vector<std::string> HeldTerms(const std::vector<std::string>& fixed,
                                   const std::vector<std::string>& names,
                                   const std::vector<std::string>& all, const std::string& kind) {
  std::vector<std::string> held = fixed;
  for (const std::string& name : names) {
    if (std::find(all.begin(), all.end(), name) == all.end())
      throw InputError("fix", "'" + name + "' is not a term of the " + kind + " measurement");
    if (std::find(held.begin(), held.end(), name) == held.end()) held.push_back(name);
  }
  return held;
}

}  // namespace lrcal
