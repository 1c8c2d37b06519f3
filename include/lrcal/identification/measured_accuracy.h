// How accurate a model is where a tracker measured the tool, with data not used in its
// calibration: the validation the slides make against a laser tracker.
//
// The instrument's frame is unknown (a tracker stands wherever it was put) and so, usually, is
// where its reflector sits on the tool. Both are registered to the measured points by least
// squares with the arm held at the model (PointMeasurement with every link value fixed: the
// instrument's six terms and each target's three estimated); each point's error is then the
// measured position minus the registered model's prediction, in the instrument's frame. The
// registration absorbs what a rigid motion of the instrument or a shift of a target can explain
// (an error of the base or of the tool's last offset), as any tracker validation does: the errors
// left are those of the arm's geometry.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/point_measurement.h"

namespace lrcal {

struct MeasuredAccuracy {
  int num_points = 0;
  /// Measured minus predicted position of each point (m, the instrument's frame), in the order
  /// of the measured values.
  std::vector<Eigen::Vector3d> errors;
  double rms = 0;        ///< m, √ of the mean squared 3-D error
  double worst = 0;      ///< m, the largest 3-D error
  int worst_index = -1;  ///< the point (0-based) with the largest error
  /// The registered instrument frame (in the robot's base frame) and target offsets (tool frame).
  RigidTransform instrument;
  std::vector<Eigen::Vector3d> targets;
  /// The registered terms (instrument_x … and the targets'), fewer when some are not determined
  /// by the points (they keep their nominal values).
  std::vector<std::string> registered;
  /// Text for `lrcal accuracy --measured`: the registration, RMS and worst in mm.
  std::string ToString() const;
};

/// Registers `setup`'s instrument frame and targets to `points` (values of a point kind on
/// `robot`, as ReadTrackerMeasurements gives them) with the arm held at `robot`, and returns
/// each point's error. Throws InputError when fewer points than registered terms are given
/// (at least 3 per target plus 2) or the registration fails.
MeasuredAccuracy AccuracyAtMeasuredPoints(const RobotModel& robot, const PointSetup& setup,
                                          const MeasuredValues& points);

/// The point kind that registers `setup` on `robot`: every link value of the robot fixed.
PointMeasurement RegistrationKind(const RobotModel& robot, const PointSetup& setup);

}  // namespace lrcal
