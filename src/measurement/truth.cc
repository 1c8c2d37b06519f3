#include "lrcal/measurement/truth.h"

#include <string>

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

}  // namespace lrcal
