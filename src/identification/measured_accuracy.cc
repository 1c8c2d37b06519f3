#include "lrcal/identification/measured_accuracy.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/identification/identification.h"
#include "lrcal/kinematics/forward_kinematics.h"

namespace lrcal {

PointMeasurement RegistrationKind(const RobotModel& robot, const PointSetup& setup) {
  std::vector<std::string> links;
  for (int index = 0; index < robot.num_values(); ++index)
    if (robot.links()[index / kValuesPerLink].is_parameter[index % kValuesPerLink])
      links.push_back(LinkValueFullName(index));
  return PointMeasurement(robot, setup, links);
}

MeasuredAccuracy AccuracyAtMeasuredPoints(const RobotModel& robot, const PointSetup& setup,
                                          const MeasuredValues& points) {
  const PointMeasurement kind = RegistrationKind(robot, setup);
  const int needed = kind.num_parameters() / 3 + 2;
  if (points.size() < needed)
    throw InputError("measured points", "expected at least " + std::to_string(needed) +
                                            " points to register the instrument and " +
                                            std::to_string(setup.targets.size()) +
                                            " target(s), got " + std::to_string(points.size()));
  IdentificationOptions options;
  options.fix_dependent_parameters = true;
  const IdentificationSummary s = Identify(kind, points, options);
  if (!s.IsSolutionUsable())
    throw InputError("measured points",
                     "the instrument's frame could not be registered to "
                     "them: " +
                         s.message);
  // The registered kind (terms the points do not determine held at nominal) at its estimate.
  std::vector<std::string> held = kind.fixed();
  for (const std::string& name : kind.parameter_names())
    if (std::find(s.names.begin(), s.names.end(), name) == s.names.end()) held.push_back(name);
  const PointMeasurement registered(robot, setup, held);
  std::vector<double> y(static_cast<std::size_t>(3 * points.size()));
  registered.Bind(points.configs)->Predict(s.delta.data(), y.data(), nullptr);
  MeasuredAccuracy out;
  out.num_points = points.size();
  out.registered = s.names;
  double sum2 = 0;
  for (int i = 0; i < points.size(); ++i) {
    const auto r = static_cast<std::size_t>(3 * i);
    const Eigen::Vector3d error(points.y[r] - y[r], points.y[r + 1] - y[r + 1],
                                points.y[r + 2] - y[r + 2]);
    out.errors.push_back(error);
    sum2 += error.squaredNorm();
    if (error.norm() > out.worst || out.worst_index < 0) {
      out.worst = error.norm();
      out.worst_index = i;
    }
  }
  out.rms = std::sqrt(sum2 / points.size());
  PointMeasurement::State state;
  registered.StateAt(s.delta.data(), &state);
  out.instrument.rotation = state.R_BI;
  out.instrument.translation = state.p_BI;
  out.targets = state.targets;
  return out;
}

std::string MeasuredAccuracy::ToString() const {
  std::ostringstream out;
  out << "the instrument's frame and the target offsets registered to the " << num_points
      << " points (" << registered.size() << " terms), the arm held at the model\n";
  const Eigen::Vector3d rpy = instrument.Rpy();
  out << "registered instrument (base frame): x " << Fixed(instrument.translation.x() * 1e3, 3)
      << " mm, y " << Fixed(instrument.translation.y() * 1e3, 3) << " mm, z "
      << Fixed(instrument.translation.z() * 1e3, 3) << " mm, roll " << Fixed(rpy.x() * 1e3, 3)
      << " mrad, pitch " << Fixed(rpy.y() * 1e3, 3) << " mrad, yaw " << Fixed(rpy.z() * 1e3, 3)
      << " mrad\n";
  out << "error at the measured points: RMS " << Fixed(rms * 1e3, 4) << " mm, worst "
      << Fixed(worst * 1e3, 4) << " mm (point " << worst_index + 1 << ")\n";
  return out.str();
}

SocketConsistency ConsistencyAtSockets(const RobotModel& robot, const Eigen::Vector3d& tool_point,
                                       const TargetedConfigurations& configs,
                                       const std::vector<int>& ids,
                                       const std::vector<SocketDistance>& distances) {
  SocketConsistency out;
  const int n = static_cast<int>(ids.size());
  std::vector<std::vector<Eigen::Vector3d>> points(static_cast<std::size_t>(n));
  for (int i = 0; i < configs.size(); ++i) {
    if (configs.target(i) >= n)
      throw InputError("configurations", "a configuration is in socket index " +
                                             std::to_string(configs.target(i)) + " of " +
                                             std::to_string(n));
    const Pose<double> pose =
        ForwardKinematics<double>(robot, robot.nominal_values().data(), configs.q(i));
    points[static_cast<std::size_t>(configs.target(i))].push_back(pose.p_BT +
                                                                  pose.R_BT * tool_point);
  }
  double total = 0;
  int count = 0;
  for (int k = 0; k < n; ++k) {
    const std::vector<Eigen::Vector3d>& p = points[static_cast<std::size_t>(k)];
    SocketConsistency::Socket s;
    s.id = ids[static_cast<std::size_t>(k)];
    s.count = static_cast<int>(p.size());
    s.centre = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& v : p) s.centre += v;
    if (s.count > 0) s.centre /= s.count;
    double sum = 0;
    for (const Eigen::Vector3d& v : p) {
      const double d = (v - s.centre).norm();
      sum += d * d;
      s.worst_spread = std::max(s.worst_spread, d);
    }
    s.rms_spread = s.count > 0 ? std::sqrt(sum / s.count) : 0;
    total += sum;
    count += s.count;
    out.sockets.push_back(s);
  }
  out.rms_spread = count > 0 ? std::sqrt(total / count) : 0;
  for (const SocketDistance& d : distances) {
    const auto index = [&](int id) {
      const auto it = std::find(ids.begin(), ids.end(), id);
      if (it == ids.end() || points[static_cast<std::size_t>(it - ids.begin())].empty())
        throw InputError("--socket-distance",
                         "socket " + std::to_string(id) + " has no configuration in the data");
      return static_cast<std::size_t>(it - ids.begin());
    };
    SocketConsistency::Distance r;
    r.known = d;
    r.predicted = (out.sockets[index(d.a)].centre - out.sockets[index(d.b)].centre).norm();
    r.error = r.predicted - d.metres;
    out.distances.push_back(r);
  }
  return out;
}

std::string SocketConsistency::ToString() const {
  std::ostringstream out;
  Table t({"socket", "configurations", "RMS spread [mm]", "worst spread [mm]"},
          "Where the model puts the tool point in each socket (spread about the mean)");
  for (const Socket& s : sockets)
    t.AddRow({std::to_string(s.id), std::to_string(s.count), Fixed(s.rms_spread * 1e3, 4),
              Fixed(s.worst_spread * 1e3, 4)});
  out << t.ToText();
  out << "RMS spread over every configuration: " << Fixed(rms_spread * 1e3, 4) << " mm\n";
  if (distances.empty()) return out.str();
  Table d({"sockets", "known [mm]", "predicted [mm]", "error [mm]"},
          "The sockets' known distances against the model's centres");
  for (const Distance& r : distances)
    d.AddRow({std::to_string(r.known.a) + "-" + std::to_string(r.known.b),
              Fixed(r.known.metres * 1e3, 4), Fixed(r.predicted * 1e3, 4),
              Fixed(r.error * 1e3, 4)});
  out << d.ToText();
  return out.str();
}

}  // namespace lrcal
