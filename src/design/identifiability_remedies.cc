#include "lrcal/design/identifiability_remedies.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/design/configuration_sampling.h"

namespace lrcal {

const char* RemedyKindName(Remedy::Kind kind) {
  switch (kind) {
    case Remedy::Kind::kFixParameter:
      return "fix_parameter";
    case Remedy::Kind::kKnowPlaneOffset:
      return "know_plane_offset";
    case Remedy::Kind::kAddPlane:
      return "add_plane";
    case Remedy::Kind::kAddKnownDistance:
      return "add_known_distance";
  }
  return "?";
}

std::string RemedyReport::ToString() const {
  std::ostringstream out;
  for (std::size_t d = 0; d < lost.size(); ++d) {
    out << "lost: " << lost[d] << "\n  cheapest fix: "
        << (cheapest[d] >= 0 ? remedies[cheapest[d]].action : "none of those tried") << "\n";
    std::string also;
    for (std::size_t r = 0; r < remedies.size(); ++r) {
      const auto& rec = remedies[r].recovers;
      if (static_cast<int>(r) != cheapest[d] &&
          std::find(rec.begin(), rec.end(), static_cast<int>(d)) != rec.end())
        also += (also.empty() ? "" : "; ") + remedies[r].action;
    }
    if (!also.empty()) out << "  also recovered by: " << also << "\n";
  }
  std::string useless;
  for (const auto& r : remedies)
    if (r.recovers.empty()) useless += (useless.empty() ? "" : "; ") + r.action;
  if (!useless.empty()) out << "tried, recovers nothing: " << useless << "\n";
  for (const auto& u : unreachable) out << "not tried (no reachable plane found): " << u << "\n";
  return out.str();
}

namespace {

// True if v (old coordinates, scaled by `weights`) lies in the span of N's columns.
bool StillLost(const Eigen::VectorXd& v, const Eigen::MatrixXd& N, const Eigen::VectorXd& weights) {
  if (N.cols() == 0) return false;
  const Eigen::VectorXd vw = v.cwiseProduct(weights);
  const Eigen::MatrixXd Nw = weights.asDiagonal() * N;
  const Eigen::VectorXd c = Nw.colPivHouseholderQr().solve(vw);
  return (Nw * c - vw).norm() <= 1e-6 * vw.norm();
}

struct Context {
  const MeasurementModel* model;
  const TargetedConfigurations* configs;
  const RemedyOptions* options;
  Eigen::MatrixXd G;        // the identification Jacobian of the set as it is
  Eigen::VectorXd weights;  // column norms (1 for zero columns): a unit-free comparison
  std::vector<Eigen::VectorXd> lost;
};

std::vector<int> Recovered(const Context& c, const Eigen::MatrixXd& null_old) {
  std::vector<int> out;
  for (std::size_t d = 0; d < c.lost.size(); ++d)
    if (!StillLost(c.lost[d], null_old, c.weights)) out.push_back(static_cast<int>(d));
  return out;
}

// Fixing parameter k: the null space of G without column k, with zero at k.
std::vector<int> RecoveredByFixing(const Context& c, int k) {
  const int n = static_cast<int>(c.G.cols());
  Eigen::MatrixXd Gr(c.G.rows(), n - 1);
  for (int j = 0, t = 0; j < n; ++j)
    if (j != k) Gr.col(t++) = c.G.col(j);
  const Eigen::MatrixXd Nr = UnobservableDirections(Gr, c.options->identifiability);
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(n, Nr.cols());
  for (int j = 0, t = 0; j < n; ++j)
    if (j != k) N.row(j) = Nr.row(t++);
  return Recovered(c, N);
}

// After the planes: `in`'s ranger and frame terms, in their order, at the end of `out`.
void AppendRangerAndFrameTerms(const ParameterSet& in, ParameterSet* out,
                               std::vector<int>* old_to_new) {
  const auto append = [&](int old_index, const std::string& name) {
    (*old_to_new)[old_index] = out->size();
    out->names.push_back(name);
    return out->size() - 1;
  };
  out->ranger = in.ranger;
  if (in.ranger_offset_index >= 0)
    out->ranger_offset_index = append(in.ranger_offset_index, "ranger_offset");
  if (in.ranger_scale_index >= 0)
    out->ranger_scale_index = append(in.ranger_scale_index, "ranger_scale");
  for (int f = 0; f < 2; ++f) {
    out->frames[f] = in.frames[f];
    for (int k = 0; k < 6; ++k)
      if (in.frame_columns[f][k] >= 0)
        out->frame_columns[f][k] = append(in.frame_columns[f][k], FrameTermName(f, k));
  }
}

// The parameter set with one more plane (terms `terms`) after the existing ones, and where each
// old entry went.
ParameterSet WithAddedPlane(const ParameterSet& in, PlaneTerms terms,
                            std::vector<int>* old_to_new) {
  ParameterSet out;
  const int np = in.num_planes() + 1;
  old_to_new->assign(in.size(), -1);
  out.robot_values = in.robot_values;
  for (int k = 0; k < in.num_robot(); ++k) {
    (*old_to_new)[k] = out.size();
    out.names.push_back(in.names[k]);
  }
  out.plane_terms = in.plane_terms;
  out.plane_terms.push_back(terms);
  out.plane_columns.assign(np, PlaneColumns{});
  const auto add = [&](int p, int old_index, const char* term) {
    const int index = out.size();
    if (old_index >= 0) (*old_to_new)[old_index] = index;
    out.names.push_back(PlaneTermName(p, np, term));
    return index;
  };
  for (int p = 0; p < np; ++p) {
    const bool added = p == np - 1;
    const PlaneColumns old = added ? PlaneColumns{} : in.plane_columns[p];
    for (int u = 0; u < 2; ++u)
      if (added ? terms.normal : old.u[u] >= 0)
        out.plane_columns[p].u[u] = add(p, old.u[u], u == 0 ? "u1" : "u2");
    if (added ? terms.offset : old.f >= 0) out.plane_columns[p].f = add(p, old.f, "f");
  }
  AppendRangerAndFrameTerms(in, &out, old_to_new);
  return out;
}

// Configurations whose nominal beam hits `plane` (as plane index p), or an empty set when none
// are found within the budget (the plane is out of reach).
TargetedConfigurations ConfigurationsOn(const Context& c, const Plane& plane, int p, int count) {
  SamplingOptions s;
  s.ranger = c.options->ranger;
  s.max_attempts_per_configuration = 300;
  try {
    const TargetedConfigurations drawn =
        SampleConfigurations(c.model->robot(), plane, count,
                             RandomStream(c.options->seed, 77 + p, 0, RandomPurpose::kPool), s);
    TargetedConfigurations out(drawn.num_joints());
    for (int i = 0; i < drawn.size(); ++i) out.Add(drawn.q(i), p);
    return out;
  } catch (const InputError&) {
    return TargetedConfigurations(c.model->robot().num_links());
  }
}

// Adding `plane` with `terms`, read at its own configurations `extra`.
std::vector<int> RecoveredByAdding(const Context& c, const Plane& plane, PlaneTerms terms,
                                   const TargetedConfigurations& extra) {
  const MeasurementModel& model = *c.model;
  std::vector<int> old_to_new;
  ParameterSet ps = WithAddedPlane(model.parameters(), terms, &old_to_new);
  std::vector<Plane> planes(model.nominal_planes().begin(), model.nominal_planes().end());
  planes.push_back(plane);
  const MeasurementModel augmented(model.robot(), PlaneSet(planes, {}), ps);
  TargetedConfigurations all(c.configs->num_joints());
  for (int i = 0; i < c.configs->size(); ++i) all.AddFrom(*c.configs, i);
  for (int i = 0; i < extra.size(); ++i) all.AddFrom(extra, i);
  const Eigen::MatrixXd Na =
      UnobservableDirections(IdentificationJacobian(augmented, all), c.options->identifiability);
  Eigen::MatrixXd N(model.num_parameters(), Na.cols());
  for (int j = 0; j < model.num_parameters(); ++j) N.row(j) = Na.row(old_to_new[j]);
  return Recovered(c, N);
}

// A plane facing base axis `axis` that the arm can read: tried at a few distances on both sides
// of the base, as fractions of the arm's nominal reach.
bool ReachablePlane(const Context& c, int axis, int count, Plane* plane,
                    TargetedConfigurations* configs) {
  double reach = 0;
  const RobotModel& robot = c.model->robot();
  for (int j = 0; j < robot.num_links(); ++j)
    reach += std::hypot(robot.links()[j].nominal[kA], robot.links()[j].nominal[kD]);
  for (double fraction : {0.4, 0.7, 0.2})
    for (double side : {-1.0, 1.0}) {
      double n[3] = {0, 0, 0};
      n[axis] = 1;
      *plane = Plane::FromCoefficients(n[0], n[1], n[2], -side * fraction * reach);
      *configs = ConfigurationsOn(c, *plane, c.model->num_planes(), count);
      if (configs->size() > 0) return true;
    }
  return false;
}

void AddFixRemedies(const Context& c, const IdentifiabilityReport& report, RemedyReport* out) {
  const ParameterSet& ps = c.model->parameters();
  std::vector<std::string> candidates;  // every parameter in a lost direction, in found order
  for (const auto& v : c.lost)
    for (int j = 0; j < v.size(); ++j)
      if (v[j] != 0 &&
          std::find(candidates.begin(), candidates.end(), ps.names[j]) == candidates.end())
        candidates.push_back(ps.names[j]);
  // The analysis's own suggestions first, so that the cheapest fix is the one it suggests.
  std::stable_partition(candidates.begin(), candidates.end(), [&](const std::string& name) {
    return std::find(report.suggested_fixed.begin(), report.suggested_fixed.end(), name) !=
           report.suggested_fixed.end();
  });
  for (int pass = 0; pass < 2; ++pass)
    for (const auto& name : candidates) {
      const int k = ps.Find(name);
      const bool offset = name.size() > 2 && name.compare(name.size() - 2, 2, "_f") == 0 &&
                          name.rfind("plane", 0) == 0;
      if (offset != (pass == 1)) continue;
      Remedy r;
      r.kind = offset ? Remedy::Kind::kKnowPlaneOffset : Remedy::Kind::kFixParameter;
      r.parameter = name;
      r.action = offset ? "know the plane's offset (measure it; fix " + name + ")"
                        : "fix " + name + " (it keeps its nominal value)";
      r.recovers = RecoveredByFixing(c, k);
      out->remedies.push_back(r);
    }
}

void AddPlaneRemedies(const Context& c, RemedyReport* out) {
  if (c.model->num_planes() >= kMaxPlanes) return;
  const int count =
      std::max(c.options->configurations_per_added_plane, c.model->num_parameters() + 3);
  PlaneTerms estimated;  // the added plane's terms: as estimated as the planes already there
  for (const auto& t : c.model->parameters().plane_terms) {
    estimated.normal = estimated.normal || t.normal;
    estimated.offset = estimated.offset || t.offset;
  }
  const char* axes[3] = {"x0", "y0", "z0"};
  std::vector<Remedy> known;
  for (int axis = 0; axis < 3; ++axis) {
    Plane plane;
    TargetedConfigurations extra(c.configs->num_joints());
    if (!ReachablePlane(c, axis, count, &plane, &extra)) {
      out->unreachable.push_back(std::string("a plane facing ") + axes[axis]);
      continue;
    }
    std::ostringstream where;
    where.precision(4);
    where << "(the plane " << axes[axis] << " = " << -plane.offset << " m), " << extra.size()
          << " poses on it";
    Remedy add;
    add.kind = Remedy::Kind::kAddPlane;
    add.plane = plane;
    add.action = "add a plane facing " + std::string(axes[axis]) + " " + where.str() +
                 (estimated.normal || estimated.offset
                      ? ", its terms estimated (" + estimated.ToString() + ")"
                      : ", its position known like the others'");
    add.recovers = RecoveredByAdding(c, plane, estimated, extra);
    out->remedies.push_back(add);
    if (!estimated.normal && !estimated.offset) continue;  // the plane above is already known
    Remedy ref;
    ref.kind = Remedy::Kind::kAddKnownDistance;
    ref.plane = plane;
    ref.action = "add a known distance: readings against a reference surface of known position " +
                 where.str();
    ref.recovers = RecoveredByAdding(c, plane, PlaneTerms{}, extra);
    known.push_back(ref);
  }
  out->remedies.insert(out->remedies.end(), known.begin(), known.end());
}

}  // namespace

RemedyReport FindRemedies(const MeasurementModel& model, const TargetedConfigurations& configs,
                          const IdentifiabilityReport& report, const RemedyOptions& options) {
  RemedyReport out;
  if (report.full_rank()) return out;
  Context c{&model, &configs, &options, IdentificationJacobian(model, configs), {}, {}};
  c.weights = c.G.colwise().norm().transpose();
  for (int j = 0; j < c.weights.size(); ++j)
    if (!(c.weights[j] > 0)) c.weights[j] = 1;
  const ParameterSet& ps = model.parameters();
  for (const auto& name : report.unidentifiable) {
    c.lost.push_back(Eigen::VectorXd::Unit(ps.size(), ps.Find(name)));
    out.lost.push_back(name + " (no effect on any reading)");
  }
  for (const auto& d : report.dependencies) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(ps.size());
    for (std::size_t k = 0; k < d.terms.size(); ++k)
      v[ps.Find(d.terms[k].first)] = d.terms[k].second;
    const std::string full = d.ToString();
    out.lost.push_back(full.substr(0, full.find("  (")));
    c.lost.push_back(v);
  }
  AddFixRemedies(c, report, &out);
  AddPlaneRemedies(c, &out);
  out.cheapest.assign(out.lost.size(), -1);
  for (std::size_t r = out.remedies.size(); r-- > 0;)
    for (int d : out.remedies[r].recovers) out.cheapest[d] = static_cast<int>(r);
  return out;
}

}  // namespace lrcal
