#include "lrcal/measurement/truth.h"

#include <string>
#include <utility>
#include <vector>

#include "lrcal/core/error.h"

namespace lrcal {

Eigen::VectorXd Truth::LinkErrors(const RobotModel& robot) const {
  if (link_errors.size() == 0) return Eigen::VectorXd::Zero(robot.num_values());
  if (link_errors.size() != robot.num_values())
    throw InputError("true_errors", "expected " + std::to_string(robot.num_values()) +
                                        " link value errors for '" + robot.name() + "', got " +
                                        std::to_string(link_errors.size()));
  for (int k = 0; k < robot.num_values(); ++k)
    if (link_errors[k] != 0 && !robot.links()[k / kValuesPerLink].is_parameter[k % kValuesPerLink])
      throw InputError("true_errors", "true error given for '" + robot.ValueName(k) +
                                          "', which is fixed (not a parameter) on this robot");
  return link_errors;
}

Eigen::VectorXd Truth::LinkValues(const RobotModel& robot) const {
  return robot.nominal_values() + LinkErrors(robot);
}

RobotModel Truth::TrueRobot(const RobotModel& robot) const {
  const Eigen::VectorXd errors = LinkErrors(robot);
  std::vector<Link> links = robot.links();
  for (int index = 0; index < robot.num_values(); ++index)
    links[index / kValuesPerLink].nominal[index % kValuesPerLink] += errors[index];
  RobotModel out(robot.name(), std::move(links), robot.source, robot.base(), robot.tool());
  out.source = robot.source;
  return out;
}

}  // namespace lrcal
