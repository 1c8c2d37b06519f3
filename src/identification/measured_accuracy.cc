#include "lrcal/identification/measured_accuracy.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/identification/identification.h"

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

}  // namespace lrcal
