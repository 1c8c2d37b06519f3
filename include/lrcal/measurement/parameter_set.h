// Which quantities an identification estimates: a subset of the robot's geometric parameters and,
// optionally, each plane's normal (two chart coordinates, plane.h) and offset f.
//
// The estimate vector e is laid out as
//   [Δ(robot link values, robot file order)
//    | for each plane p: u1, u2 (if its normal) | Δf (if its offset)
//    | ranger offset o | ranger scale s
//    | base x, y, z, roll, pitch, yaw | tool x, y, z, roll, pitch, yaw]
// in SI units (rad, m; u and s are dimensionless, u ≈ rad). Its names are the link value names
// ("theta1", ...), then the plane terms, then "ranger_offset", "ranger_scale", then the frame
// terms "base_x" ... "base_yaw", "tool_x" ... "tool_yaw" (FrameTerms). With one plane
// the plane terms are "plane_u1", "plane_u2", "plane_f"; with several they are numbered from 1:
// "plane1_u1", "plane1_u2", "plane1_f", "plane2_u1", ... (PlaneTermName).
// The ranger reads (1 + s)·h + o for a geometric distance h (measurement_model.h); nominally
// o = s = 0.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

/// Which plane terms are estimated along with the robot.
struct PlaneTerms {
  bool normal = false;
  bool offset = false;
  /// Parses "none", "normal", "offset", "normal,offset" (or "both"). Throws InputError.
  static PlaneTerms Parse(const std::string& text, const std::string& source = "--estimate-plane");
  std::string ToString() const;
};

/// Which ranger terms are estimated: the zero offset o (m) and the scale error s.
struct RangerTerms {
  bool offset = false;
  bool scale = false;
  /// Parses "none", "offset", "scale", "offset,scale". Throws InputError.
  static RangerTerms Parse(const std::string& text,
                           const std::string& source = "--estimate-ranger");
  std::string ToString() const;
};

/// Which terms of one of the fixed transforms around the chain (robot_model.h) are estimated:
/// the base (frame 0 in B) or the tool (T in the last frame N). A frame's estimate moves its
/// nominal transform (R0, p0) to
///   p = p0 + (x, y, z)   (m, in the parent frame: B for the base, N for the tool)
///   R = R0·Rz(yaw)·Ry(pitch)·Rx(roll)   (rad: about the frame's own axes, URDF's order)
/// so the calibrated robot file simply gets the new transform (written as xyz/rpy).
struct FrameTerms {
  /// x, y, z, roll, pitch, yaw (kFrameTermNames' order).
  std::array<bool, 6> estimated{};
  /// Parses "none", "all", or a comma list of x, y, z, roll, pitch, yaw, "xyz" (the three
  /// shifts) and "rpy" (the three rotations). Throws InputError naming `source`.
  static FrameTerms Parse(const std::string& text, const std::string& source);
  /// The canonical text: "none", "all", "xyz", "rpy" or the list (Parse's inverse).
  std::string ToString() const;
};
/// "x", "y", "z", "roll", "pitch", "yaw".
inline constexpr const char* kFrameTermNames[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
/// The frames whose terms can be estimated: "base" and "tool".
inline constexpr const char* kFrameNames[2] = {"base", "tool"};
/// "base_x", "tool_yaw", ...: frame f (0 base, 1 tool), term k (kFrameTermNames).
std::string FrameTermName(int frame, int k);
/// True for "base_x" ... "tool_yaw".
bool IsFrameTermName(const std::string& name);

/// Where one plane's terms are in e.
struct PlaneColumns {
  /// Index in e of chart coordinate u1 (c = 0) or u2 (c = 1), or -1 when it is not estimated.
  /// Each can be fixed on its own (e.g. `--fix plane_u1`), the other staying free.
  int u[2] = {-1, -1};
  /// Index of Δf in e, or -1 when the offset is not estimated.
  int f = -1;
  bool EstimatesNormal() const { return u[0] >= 0 || u[1] >= 0; }
};

/// The name of plane p's term `term` ("u1", "u2" or "f") among `num_planes` planes: "plane_u1"
/// with one plane, "plane2_u1" (p = 1) with several.
std::string PlaneTermName(int p, int num_planes, const std::string& term);

struct ParameterSet {
  std::vector<int> robot_values;  ///< indices into the robot's 5N link values
  /// The terms asked for, one entry per plane of the set-up (its size is the number of planes).
  std::vector<PlaneTerms> plane_terms{PlaneTerms{}};
  /// Where each plane's estimated terms are in e (one entry per plane).
  std::vector<PlaneColumns> plane_columns{PlaneColumns{}};
  std::vector<std::string> names;  ///< one per entry of e

  int size() const { return static_cast<int>(names.size()); }
  int num_robot() const { return static_cast<int>(robot_values.size()); }
  int num_planes() const { return static_cast<int>(plane_columns.size()); }
  /// True if any plane term is estimated.
  bool EstimatesPlanes() const;
  RangerTerms ranger;
  /// Indices in e of the ranger's offset o and scale s, or -1 when not estimated.
  int ranger_offset_index = -1;
  int ranger_scale_index = -1;
  /// The frame terms asked for: [0] the base, [1] the tool.
  FrameTerms frames[2];
  /// Index in e of frame f's term k (kFrameTermNames), or -1 when it is not estimated.
  int frame_columns[2][6] = {{-1, -1, -1, -1, -1, -1}, {-1, -1, -1, -1, -1, -1}};
  /// True if any base or tool term is estimated.
  bool EstimatesFrames() const;
  /// True for the entries measured in rad (angles, chart coordinates); false for metres.
  bool IsAngular(int k) const;
  /// Index of a name, or -1.
  int Find(const std::string& name) const;
};

/// All of the robot's geometric parameters except `fixed`, plus the chosen plane terms (one
/// plane). Throws InputError (where = `source`) for an unknown or non-parameter name in `fixed`.
ParameterSet MakeParameterSet(const RobotModel& robot, PlaneTerms plane,
                              const std::vector<std::string>& fixed = {},
                              const std::string& source = "fix", RangerTerms ranger = {},
                              FrameTerms base = {}, FrameTerms tool = {});

/// The same with several planes: `planes` has one entry per plane (1 ≤ size ≤ kMaxPlanes).
ParameterSet MakeParameterSet(const RobotModel& robot, const std::vector<PlaneTerms>& planes,
                              const std::vector<std::string>& fixed,
                              const std::string& source = "fix", RangerTerms ranger = {},
                              FrameTerms base = {}, FrameTerms tool = {});

/// `in` without the parameters `names` (robot parameters or plane terms): what remains when
/// an identifiability analysis says to fix them. Throws InputError for an unknown name.
ParameterSet WithoutParameters(const RobotModel& robot, const ParameterSet& in,
                               const std::vector<std::string>& names);

/// A term's name without its label: "theta4" of "left_tool.theta4" (a chain's or a mixed part's
/// own term, chain_measurement.h, mixed_measurement.h); a name without a dot as it is.
std::string UnlabelledName(const std::string& name);

/// True for names of quantities in rad (theta*, alpha*, beta*, plane*_u*, a frame's *_roll,
/// *_pitch, *_yaw); false for metres (and for the dimensionless ranger_scale: see DisplayUnitOf).
/// A label before a dot ("left_tool.theta4": a chain's or a mixed part's own term) is skipped.
bool IsAngularName(const std::string& name);

/// How a quantity is shown to users: "mrad" (×1e3 from rad), "mm" (×1e3 from m) or, for the
/// ranger's scale error, "ppm" (×1e6); a joint's compliance c3 in "urad/(N m)" (×1e6 from
/// rad/(N·m)) and a thermal coefficient in "ppm/K" (×1e6 from 1/K).
struct DisplayUnit {
  const char* unit;
  double factor;
};
DisplayUnit DisplayUnitOf(const std::string& name);

}  // namespace lrcal
