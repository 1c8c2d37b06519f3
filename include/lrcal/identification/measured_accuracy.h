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
#include "lrcal/measurement/socket_measurement.h"

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

/// How consistent a model is with socket data not used in its calibration (MUKCa's figures of
/// merit): where the model puts the tool point at each configuration of a socket should be one
/// point, and the sockets' centres should be their known distance apart. Nothing is registered:
/// the sockets' centres are the means of the model's predictions.
struct SocketConsistency {
  struct Socket {
    int id = 0;
    int count = 0;            ///< configurations in this socket
    Eigen::Vector3d centre;   ///< m, base frame: the mean predicted tool point
    double rms_spread = 0;    ///< m, √ of the mean squared distance from the centre
    double worst_spread = 0;  ///< m, the largest distance from the centre
  };
  struct Distance {
    SocketDistance known;
    double predicted = 0;  ///< m, between the two centres
    double error = 0;      ///< m, predicted − known
  };
  std::vector<Socket> sockets;
  std::vector<Distance> distances;
  /// m: √ of the mean squared distance from its socket's centre over every configuration.
  double rms_spread = 0;
  /// A table per socket and per known distance, in mm.
  std::string ToString() const;
};

/// The consistency of `robot` (its nominal values: a calibrated robot file's estimates) with the
/// tool point `tool_point` (m, tool frame) at `configs` (tags: indices into `ids`, as
/// ReadSocketData gives them). Throws InputError when a known distance names a socket without
/// configurations.
SocketConsistency ConsistencyAtSockets(const RobotModel& robot, const Eigen::Vector3d& tool_point,
                                       const TargetedConfigurations& configs,
                                       const std::vector<int>& ids,
                                       const std::vector<SocketDistance>& distances);

}  // namespace lrcal
