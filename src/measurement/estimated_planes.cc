#include "lrcal/measurement/estimated_planes.h"

#include <algorithm>

#include "lrcal/core/error.h"

namespace lrcal {

namespace {
constexpr const char* kPlaneTerms[3] = {"u1", "u2", "f"};
}  // namespace

EstimatedPlanes::EstimatedPlanes(PlaneSet planes, std::vector<PlaneTerms> terms,
                                 const std::vector<std::string>& fixed,
                                 std::vector<std::string>* names)
    : planes_(std::move(planes)), terms_(std::move(terms)) {
  const std::vector<std::string> estimable = TermNames();
  const int np = planes_.size();
  for (int p = 0; p < np; ++p) {
    charts_.emplace_back(planes_[p].normal);
    std::array<int, 3> columns = {-1, -1, -1};
    for (int t = 0; t < 3; ++t) {
      const std::string name = PlaneTermName(p, np, kPlaneTerms[t]);
      if (std::find(estimable.begin(), estimable.end(), name) == estimable.end() ||
          std::find(fixed.begin(), fixed.end(), name) != fixed.end())
        continue;
      columns[static_cast<std::size_t>(t)] = static_cast<int>(names->size());
      names->push_back(name);
    }
    columns_.push_back(columns);
  }
}

std::vector<std::string> EstimatedPlanes::TermNames() const {
  std::vector<std::string> names;
  const int np = planes_.size();
  for (int p = 0; p < np && !terms_.empty(); ++p) {
    const PlaneTerms& t = terms_[static_cast<std::size_t>(p)];
    if (t.normal) {
      names.push_back(PlaneTermName(p, np, "u1"));
      names.push_back(PlaneTermName(p, np, "u2"));
    }
    if (t.offset) names.push_back(PlaneTermName(p, np, "f"));
  }
  return names;
}

EstimatedPlanes::State EstimatedPlanes::At(const double* e, int k) const {
  State s;
  const std::array<int, 3>& columns = columns_[static_cast<std::size_t>(k)];
  for (int t = 0; t < 3; ++t) s.column[t] = columns[static_cast<std::size_t>(t)];
  for (int a = 0; a < 2; ++a) s.u[a] = s.column[a] >= 0 ? e[s.column[a]] : 0.0;
  charts_[static_cast<std::size_t>(k)].NormalAndJacobian(s.u[0], s.u[1], &s.normal, &s.dn_du);
  s.offset = planes_[k].offset + (s.column[2] >= 0 ? e[s.column[2]] : 0.0);
  return s;
}

void EstimatedPlanes::SetNominal(Eigen::VectorXd* nominal) const {
  for (int p = 0; p < planes_.size(); ++p) {
    const int f = columns_[static_cast<std::size_t>(p)][2];
    if (f >= 0) (*nominal)[f] = planes_[p].offset;
  }
}

void EstimatedPlanes::CheckConfigurations(const TargetedConfigurations& configs, int num_joints,
                                          const std::string& verb) const {
  if (configs.num_targets_referenced() > planes_.size())
    throw InputError("configurations", "a configuration " + verb + " plane " +
                                           std::to_string(configs.num_targets_referenced()) +
                                           " but the set-up has " + std::to_string(planes_.size()) +
                                           " plane(s)");
  if (configs.num_joints() != num_joints)
    throw InputError("configurations", "the robot has " + std::to_string(num_joints) +
                                           " joints, the configurations " +
                                           std::to_string(configs.num_joints()));
}

}  // namespace lrcal
