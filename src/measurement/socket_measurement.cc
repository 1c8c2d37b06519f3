#include "lrcal/measurement/socket_measurement.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/joint_constraints.h"
#include "lrcal/measurement/constraint_kinds.h"

namespace lrcal {

namespace {

// A non-negative integer id, or -1.
int ParseId(const std::string& text) {
  double v;
  if (!ParseDecimal(text, &v) || v < 0 || v > 1e9 || v != std::floor(v)) return -1;
  return static_cast<int>(v);
}

class SocketEvaluator : public MeasurementEvaluator {
 public:
  SocketEvaluator(const SocketMeasurement& kind, const TargetedConfigurations& configs)
      : kind_(kind), sockets_(configs.targets()), retagged_(configs.num_joints()) {
    retagged_.Reserve(configs.size());
    for (int i = 0; i < configs.size(); ++i) retagged_.AddFrom(configs, i, 0);
    arm_ = kind.arm().Bind(retagged_);
  }
  int num_rows() const override { return 3 * retagged_.size(); }
  int num_parameters() const override { return kind_.num_parameters(); }
  bool Predict(const double* e, double* y, double* J) override {
    const int m = num_rows(), first = kind_.first_socket_column();
    // The arm's columns come first and share J's leading dimension.
    if (!arm_->Predict(e, y, J)) return false;
    kind_.SocketsAt(e, &positions_, J ? &derivative_ : nullptr);
    for (int i = 0; i < retagged_.size(); ++i) {
      const auto s = static_cast<std::size_t>(sockets_[static_cast<std::size_t>(i)]);
      for (int c = 0; c < 3; ++c) y[3 * i + c] -= positions_[s][c];
      if (!J) continue;
      for (int t = 0; t < kind_.num_socket_terms(); ++t)
        for (int c = 0; c < 3; ++c)
          J[static_cast<std::size_t>(first + t) * m + 3 * i + c] = -derivative_[s](c, t);
    }
    return true;
  }

 private:
  const SocketMeasurement& kind_;
  const std::vector<int> sockets_;
  TargetedConfigurations retagged_;
  std::unique_ptr<MeasurementEvaluator> arm_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<Eigen::MatrixXd> derivative_;
};

}  // namespace

std::string SocketTermName(int id, const std::string& term) {
  return "socket" + std::to_string(id) + "_" + term;
}

SocketDistance SocketDistance::Parse(const std::string& text, const std::string& source) {
  const std::string where = "'" + text + "'";
  const std::size_t eq = text.find('=');
  const std::vector<std::string> ids =
      SplitList(eq == std::string::npos ? std::string() : text.substr(0, eq));
  SocketDistance d;
  if (eq == std::string::npos || ids.size() != 2)
    throw InputError(source, where +
                                 ": expected A,B=METRES (two socket ids and their distance "
                                 "in m, e.g. 0,1=0.05)");
  d.a = ParseId(ids[0]);
  d.b = ParseId(ids[1]);
  if (d.a < 0 || d.b < 0 || d.a == d.b)
    throw InputError(source, where + ": expected two distinct socket ids (integers ≥ 0)");
  if (!ParseDecimal(text.substr(eq + 1), &d.metres) || !std::isfinite(d.metres) || d.metres <= 0)
    throw InputError(source, where + ": expected a distance in m, finite and > 0, after '='");
  return d;
}

int SocketSetup::IndexOf(int id) const {
  const auto it = std::find(ids.begin(), ids.end(), id);
  return it == ids.end() ? -1 : static_cast<int>(it - ids.begin());
}

SocketSetup SocketSetup::Numbered(std::vector<Eigen::Vector3d> positions,
                                  const Eigen::Vector3d& tool_point,
                                  std::vector<SocketDistance> distances) {
  SocketSetup setup;
  setup.ids.resize(positions.size());
  std::iota(setup.ids.begin(), setup.ids.end(), 0);
  setup.positions = std::move(positions);
  setup.tool_point = tool_point;
  setup.distances = std::move(distances);
  return setup;
}

namespace {

// The ids, positions and tool point of `setup` (SocketSetup::Validate's first half).
void ValidateSockets(const SocketSetup& setup) {
  const std::vector<int>& ids = setup.ids;
  if (ids.empty() || static_cast<int>(ids.size()) > SocketSetup::kMaxSockets)
    throw InputError("socket.ids", "expected 1 to " + std::to_string(SocketSetup::kMaxSockets) +
                                       " sockets, got " + std::to_string(ids.size()));
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] < 0)
      throw InputError("socket.ids", "expected ids ≥ 0, got " + std::to_string(ids[k]));
    if (std::find(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(k), ids[k]) !=
        ids.begin() + static_cast<std::ptrdiff_t>(k))
      throw InputError("socket.ids", "socket " + std::to_string(ids[k]) + " is listed twice");
  }
  if (setup.positions.size() != ids.size())
    throw InputError("socket.positions", "expected one position per socket (" +
                                             std::to_string(ids.size()) + "), got " +
                                             std::to_string(setup.positions.size()));
  for (std::size_t k = 0; k < setup.positions.size(); ++k)
    if (!setup.positions[k].allFinite())
      throw InputError("socket.positions[" + std::to_string(k) + "]",
                       "expected a finite position in the base frame (m)");
  if (!setup.tool_point.allFinite())
    throw InputError("socket.tool_point", "expected a finite offset in the tool frame (m)");
}

}  // namespace

void SocketSetup::Validate() const {
  ValidateSockets(*this);
  // Union-find over the sockets: a distance joining two sockets already joined closes a cycle.
  std::vector<int> root(ids.size()), placed(ids.size(), 0);
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&](int k) {
    while (root[static_cast<std::size_t>(k)] != k) k = root[static_cast<std::size_t>(k)];
    return k;
  };
  for (std::size_t k = 0; k < distances.size(); ++k) {
    const SocketDistance& d = distances[k];
    const std::string field = "socket.distances[" + std::to_string(k) + "]";
    const int a = IndexOf(d.a), b = IndexOf(d.b);
    if (a < 0 || b < 0)
      throw InputError(field, "socket " + std::to_string(a < 0 ? d.a : d.b) +
                                  " has no configuration in the data");
    if (a == b || !std::isfinite(d.metres) || d.metres <= 0)
      throw InputError(field, "expected two distinct sockets and a distance > 0 (m)");
    if (find(a) == find(b))
      throw InputError(field, "the known distances between sockets " + std::to_string(d.a) +
                                  " and " + std::to_string(d.b) +
                                  " close a cycle: give the distances of a tree (each known "
                                  "distance places one more socket)");
    if (placed[static_cast<std::size_t>(b)]++)
      throw InputError(field, "socket " + std::to_string(d.b) +
                                  " is already placed by a known distance: write this one as " +
                                  std::to_string(d.b) + "," + std::to_string(d.a) + "=…");
    root[static_cast<std::size_t>(find(b))] = find(a);
  }
}

SocketMeasurement::SocketMeasurement(const RobotModel& robot, SocketSetup setup,
                                     const std::vector<std::string>& fixed,
                                     const std::string& source)
    : arm_(ToolPointKind(robot, setup.tool_point, fixed, source)),
      setup_(std::move(setup)),
      fixed_(fixed) {
  setup_.Validate();
  const std::vector<std::string> socket_terms = SocketTermNames();
  for (const std::string& name : fixed)
    if (name.rfind("socket", 0) == 0 &&
        std::find(socket_terms.begin(), socket_terms.end(), name) == socket_terms.end())
      throw InputError(source, "'" + name +
                                   "' is not a term of the socket measurement: expected "
                                   "a robot parameter, target_x … target_z, or " +
                                   socket_terms.front() + " … " + socket_terms.back());
  const auto is_fixed = [&](const std::string& name) {
    return std::find(fixed.begin(), fixed.end(), name) != fixed.end();
  };
  names_ = arm_.parameter_names();
  OrderSockets();
  nominal_ = setup_.positions;
  const int first = first_socket_column();
  for (int k : order_) {
    Placement& p = placement_[static_cast<std::size_t>(k)];
    const int id = setup_.ids[static_cast<std::size_t>(k)];
    const bool free = p.parent < 0;
    if (!free) PlaceByDistance(k);
    const char* const position_terms[3] = {"x", "y", "z"};
    const char* const chart_terms[2] = {"u1", "u2"};
    for (int c = 0; c < (free ? 3 : 2); ++c) {
      const std::string name = SocketTermName(id, free ? position_terms[c] : chart_terms[c]);
      if (is_fixed(name)) continue;
      p.column[c] = static_cast<int>(names_.size()) - first;
      names_.push_back(name);
    }
  }
}

void SocketMeasurement::OrderSockets() {
  const int n = static_cast<int>(setup_.ids.size());
  placement_.assign(static_cast<std::size_t>(n), Placement{});
  for (const SocketDistance& d : setup_.distances) {
    Placement& p = placement_[static_cast<std::size_t>(setup_.IndexOf(d.b))];
    p.parent = setup_.IndexOf(d.a);
    p.distance = d.metres;
  }
  // Parents before children: repeatedly take the sockets whose parent is placed.
  std::vector<bool> done(static_cast<std::size_t>(n), false);
  while (static_cast<int>(order_.size()) < n)
    for (int k = 0; k < n; ++k) {
      const Placement& p = placement_[static_cast<std::size_t>(k)];
      if (done[static_cast<std::size_t>(k)] ||
          (p.parent >= 0 && !done[static_cast<std::size_t>(p.parent)]))
        continue;
      done[static_cast<std::size_t>(k)] = true;
      order_.push_back(k);
    }
}

void SocketMeasurement::PlaceByDistance(int k) {
  Placement& p = placement_[static_cast<std::size_t>(k)];
  const Eigen::Vector3d& from = nominal_[static_cast<std::size_t>(p.parent)];
  const Eigen::Vector3d v = setup_.positions[static_cast<std::size_t>(k)] - from;
  // Sockets given at one point (no nominal direction): any direction, x.
  p.direction = v.norm() > 0 ? Eigen::Vector3d(v.normalized()) : Eigen::Vector3d::UnitX();
  // A tangent basis: the axis least aligned with the direction, orthogonalised.
  Eigen::Index smallest;
  p.direction.cwiseAbs().minCoeff(&smallest);
  const Eigen::Vector3d axis = Eigen::Vector3d::Unit(smallest);
  p.tangent1 = (axis - axis.dot(p.direction) * p.direction).normalized();
  p.tangent2 = p.direction.cross(p.tangent1);
  nominal_[static_cast<std::size_t>(k)] = from + p.distance * p.direction;
}

std::vector<std::string> SocketMeasurement::SocketTermNames() const {
  std::vector<bool> placed(setup_.ids.size(), false);
  for (const SocketDistance& d : setup_.distances) {
    const int b = setup_.IndexOf(d.b);
    if (b >= 0) placed[static_cast<std::size_t>(b)] = true;
  }
  std::vector<std::string> names;
  for (std::size_t k = 0; k < setup_.ids.size(); ++k) {
    const std::vector<std::string> terms =
        placed[k] ? std::vector<std::string>{"u1", "u2"} : std::vector<std::string>{"x", "y", "z"};
    for (const std::string& term : terms) names.push_back(SocketTermName(setup_.ids[k], term));
  }
  return names;
}

std::vector<std::string> SocketMeasurement::AllTermNames() const {
  std::vector<std::string> names;
  for (const std::string& name : arm_.AllTermNames())
    if (std::find(InstrumentTermNames().begin(), InstrumentTermNames().end(), name) ==
        InstrumentTermNames().end())
      names.push_back(name);
  for (const std::string& name : SocketTermNames()) names.push_back(name);
  return names;
}

Eigen::VectorXd SocketMeasurement::NominalValues() const {
  Eigen::VectorXd nominal = Eigen::VectorXd::Zero(num_parameters());
  nominal.head(first_socket_column()) = arm_.NominalValues();
  const int first = first_socket_column();
  for (std::size_t k = 0; k < placement_.size(); ++k) {
    const Placement& p = placement_[k];
    if (p.parent >= 0) continue;  // chart coordinates: nominal 0
    for (int c = 0; c < 3; ++c)
      if (p.column[c] >= 0) nominal[first + p.column[c]] = nominal_[k][c];
  }
  return nominal;
}

void SocketMeasurement::SocketsAt(const double* e, std::vector<Eigen::Vector3d>* positions,
                                  std::vector<Eigen::MatrixXd>* derivative) const {
  const double* s = e + first_socket_column();
  positions->assign(nominal_.size(), Eigen::Vector3d::Zero());
  if (derivative) derivative->assign(nominal_.size(), Eigen::MatrixXd::Zero(3, num_socket_terms()));
  for (int k : order_) {
    const auto u = static_cast<std::size_t>(k);
    Eigen::MatrixXd* d = derivative ? &(*derivative)[u] : nullptr;
    const Placement& p = placement_[u];
    if (p.parent < 0) {
      (*positions)[u] = nominal_[u];
      for (int c = 0; c < 3; ++c) {
        if (p.column[c] < 0) continue;
        (*positions)[u][c] += s[p.column[c]];
        if (d) (*d)(c, p.column[c]) = 1;
      }
    } else {
      const auto parent = static_cast<std::size_t>(p.parent);
      PlacedSocketAt(p, s, (*positions)[parent], d ? &(*derivative)[parent] : nullptr,
                     &(*positions)[u], d);
    }
  }
}

void SocketMeasurement::PlacedSocketAt(const Placement& p, const double* s,
                                       const Eigen::Vector3d& parent,
                                       const Eigen::MatrixXd* parent_derivative,
                                       Eigen::Vector3d* position,
                                       Eigen::MatrixXd* derivative) const {
  // u_b = v/|v|, v = u0 + c1·t1 + c2·t2; ∂u_b/∂c = (I − u·uᵀ)·t/|v|.
  const double c1 = p.column[0] >= 0 ? s[p.column[0]] : 0.0;
  const double c2 = p.column[1] >= 0 ? s[p.column[1]] : 0.0;
  const Eigen::Vector3d v = p.direction + c1 * p.tangent1 + c2 * p.tangent2;
  const double norm = v.norm();
  const Eigen::Vector3d direction = v / norm;
  *position = parent + p.distance * direction;
  if (!derivative) return;
  *derivative = *parent_derivative;
  const Eigen::Matrix3d project =
      (Eigen::Matrix3d::Identity() - direction * direction.transpose()) * (p.distance / norm);
  if (p.column[0] >= 0) derivative->col(p.column[0]) += project * p.tangent1;
  if (p.column[1] >= 0) derivative->col(p.column[1]) += project * p.tangent2;
}

std::unique_ptr<MeasurementEvaluator> SocketMeasurement::Bind(
    const TargetedConfigurations& configs) const {
  if (configs.num_targets_referenced() > static_cast<int>(setup_.ids.size()))
    throw InputError("configurations", "a configuration is in socket index " +
                                           std::to_string(configs.num_targets_referenced() - 1) +
                                           " but the set-up has " +
                                           std::to_string(setup_.ids.size()) + " socket(s)");
  return std::make_unique<SocketEvaluator>(*this, configs);
}

std::vector<std::string> SocketMeasurement::MissReasons(const TargetedConfigurations& configs,
                                                        const double*) const {
  return std::vector<std::string>(configs.size(), "ok");
}

std::unique_ptr<MeasurementKind> SocketMeasurement::Without(
    const std::vector<std::string>& names) const {
  return std::make_unique<SocketMeasurement>(robot(), setup_,
                                             HeldTerms(fixed_, names, AllTermNames(), name()));
}

TargetedConfigurations SocketMeasurement::LinearisationConfigurations(
    const TargetedConfigurations& configs) const {
  return SeatEach(configs, [&](double* q, int k) {
    return k < static_cast<int>(nominal_.size()) && configs.num_joints() == robot().num_links() &&
           SeatToolPoint(robot(), setup_.tool_point, nominal_[static_cast<std::size_t>(k)], q);
  });
}

std::vector<Eigen::Vector3d> SocketPositionsFromData(const RobotModel& robot,
                                                     const Eigen::Vector3d& tool_point,
                                                     const TargetedConfigurations& configs,
                                                     int num_sockets) {
  std::vector<Eigen::Vector3d> sum(static_cast<std::size_t>(num_sockets), Eigen::Vector3d::Zero());
  std::vector<int> count(static_cast<std::size_t>(num_sockets), 0);
  for (int i = 0; i < configs.size(); ++i) {
    const auto s = static_cast<std::size_t>(configs.target(i));
    if (configs.target(i) >= num_sockets) continue;
    const Pose<double> pose =
        ForwardKinematics<double>(robot, robot.nominal_values().data(), configs.q(i));
    sum[s] += pose.p_BT + pose.R_BT * tool_point;
    ++count[s];
  }
  for (std::size_t s = 0; s < sum.size(); ++s) {
    if (count[s] == 0)
      throw InputError("configurations", "socket index " + std::to_string(s) +
                                             " has no configuration: every socket needs at "
                                             "least one");
    sum[s] /= count[s];
  }
  return sum;
}

bool SeatToolPoint(const RobotModel& robot, const Eigen::Vector3d& tool_point,
                   const Eigen::Vector3d& target, double* q) {
  return SolveJointConstraints(
      robot, 3,
      [&](const Pose<double>& pose, const Eigen::Matrix<double, 6, Eigen::Dynamic>& G,
          Eigen::VectorXd* r, Eigen::MatrixXd* J) {
        // The point's velocity per joint: the origin's, plus ω × (R_BT·t).
        const Eigen::Vector3d offset = pose.R_BT * tool_point;
        *r = pose.p_BT + offset - target;
        for (int j = 0; j < static_cast<int>(G.cols()); ++j)
          J->col(j) = G.col(j).head<3>() + G.col(j).tail<3>().cross(offset);
      },
      q);
}

int SimulateSocketMeasurements(const SocketMeasurement& truth, const TargetedConfigurations& starts,
                               const NoiseModel& noise, const RandomStream& stream,
                               MeasuredValues* data, std::vector<std::string>* misses) {
  noise.Validate();
  if (noise.encoder_sigma > 0 || noise.form_sigma > 0 || noise.outlier_fraction > 0 ||
      noise.ranger_offset != 0 || noise.ranger_scale != 0 || !noise.average.IsMean())
    throw InputError("noise",
                     "the socket measurement takes sigma (the play of the tool point in its "
                     "socket, m) and repetitions; the ranger's disturbances and averaging do not "
                     "apply");
  if (starts.num_targets_referenced() > static_cast<int>(truth.setup().ids.size()))
    throw InputError("configurations", "a configuration is in socket index " +
                                           std::to_string(starts.num_targets_referenced() - 1) +
                                           " but the set-up has " +
                                           std::to_string(truth.setup().ids.size()) + " socket(s)");
  const int R = noise.repetitions, nj = starts.num_joints();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(truth.num_parameters());
  std::vector<Eigen::Vector3d> sockets;
  truth.SocketsAt(zero.data(), &sockets);
  Eigen::Vector3d tool_point = truth.setup().tool_point;
  *data = MeasuredValues{TargetedConfigurations(nj), {}, {}};
  if (misses) misses->assign(static_cast<std::size_t>(starts.size()), "ok");
  int missed = 0;
  std::vector<double> q(static_cast<std::size_t>(nj));
  double z[3];
  for (int i = 0; i < starts.size(); ++i) {
    stream.Normals(3 * static_cast<std::uint64_t>(i), 3, z);
    const Eigen::Vector3d play =
        noise.sigma / std::sqrt(static_cast<double>(R)) * Eigen::Vector3d(z[0], z[1], z[2]);
    std::copy(starts.q(i), starts.q(i) + nj, q.begin());
    const auto s = static_cast<std::size_t>(starts.target(i));
    const char* reason = nullptr;
    if (!SeatToolPoint(truth.robot(), tool_point, sockets[s] + play, q.data()))
      reason = "out of reach";
    else if (!WrapIntoJointRanges(truth.robot(), q.data()))
      reason = "outside the joint ranges";
    if (reason) {
      ++missed;
      if (misses) (*misses)[static_cast<std::size_t>(i)] = reason;
      continue;
    }
    data->configs.Add(q.data(), starts.target(i));
    data->y.insert(data->y.end(), 3, 0.0);
    data->repetitions.push_back(R);
  }
  return missed;
}

SocketSetup SocketSetupFromData(const RobotModel& robot, const std::vector<int>& ids,
                                const TargetedConfigurations& configs,
                                const Eigen::Vector3d& tool_point,
                                const std::vector<SocketDistance>& distances,
                                const std::string& distances_source) {
  SocketSetup setup;
  setup.ids = ids;
  setup.tool_point = tool_point;
  setup.positions =
      SocketPositionsFromData(robot, tool_point, configs, static_cast<int>(ids.size()));
  setup.distances = distances;
  for (const SocketDistance& d : distances)
    for (int id : {d.a, d.b})
      if (setup.IndexOf(id) < 0)
        throw InputError(distances_source, "socket " + std::to_string(id) +
                                               " has no configuration in the data (they name " +
                                               std::to_string(ids.size()) + " socket(s))");
  try {
    setup.Validate();
  } catch (const InputError& e) {
    // A cycle or a socket placed twice: named by the distance as given.
    const std::string prefix = "socket.distances[";
    if (e.where().rfind(prefix, 0) != 0) throw;
    const std::size_t k = std::stoul(e.where().substr(prefix.size()));
    const SocketDistance& d = distances[k];
    std::ostringstream item;
    item.precision(15);
    item << d.a << "," << d.b << "=" << d.metres;
    throw InputError(distances_source + " '" + item.str() + "'",
                     std::string(e.what()).substr(e.where().size() + 2));
  }
  return setup;
}

}  // namespace lrcal
