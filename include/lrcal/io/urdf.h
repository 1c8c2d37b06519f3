// URDF in and out (format: docs/URDF.md).
//
// In: the serial chain of a URDF file (read with Debian's urdfdom) from its root link to a tool
// link, converted to lrcal's D-H + β chain with base and tool transforms
// (kinematics/dh_conversion.h): forward kinematics identical to the URDF's own. The tool link's
// frame is the ranger's (origin where the beam starts, +Z along the beam). A URDF carries no
// plane, ranger limits or true errors: planes come from --plane, the ranger's limits are lrcal's
// defaults.
//
// Out: a URDF of a robot model at given link values (the calibrated model): one joint per link
// about (along) its z axis, joint origins holding the rest of each D-H transform, and a fixed
// joint to a link `tool` holding the tool transform. Read back, it gives the same forward
// kinematics (tests: 1e-12).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "lrcal/core/random.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/chain_measurement.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

/// True if `path` names a URDF file (ends in .urdf, any case).
bool IsUrdfPath(const std::string& path);

/// The most links a URDF may have (its tree is checked before it is built: no cycle, no joint
/// that is its own parent, at most this many links).
inline constexpr int kMaxUrdfLinks = 1000;

/// Reads a URDF's chain from `base_link` (empty: the root link) to `tool_link` (empty: the URDF's
/// only leaf link other than the base link). The chain is the path through the tree: up from the
/// base link to the two links' last common ancestor, then down to the tool link. A joint passed
/// against the URDF's direction (child to parent: a humanoid's leg from the sole up) keeps its
/// name, value and range, and turns the rest of the chain the other way (its axis reversed in the
/// D-H + β model), so forward kinematics equals the URDF's pose of the tool link relative to the
/// base link at every configuration (tests: 1e-12); the base link's frame is the model's base
/// frame B. Revolute, continuous (range ±π), prismatic and fixed joints; anything else, a mimic
/// joint, an unknown or ambiguous link, the same link at both ends, a cycle among the joints, a
/// joint whose parent is its child and more than kMaxUrdfLinks links are InputErrors naming the
/// file and the joint or link.
RobotFile LoadUrdfRobotFile(const std::string& path, const std::string& tool_link = "",
                            const std::string& base_link = "");

/// A tree robot's chains from one base link to several tool links: two arms on a torso, a leg and
/// each arm of a humanoid.
struct UrdfChains {
  /// The robot's joints on any of the chains, each once: the first chain's in its order, then
  /// each later chain's joints the earlier ones lack. A configuration of the whole robot is a
  /// value per joint in this order.
  std::vector<std::string> joint_names;
  std::vector<RobotFile> chains;        ///< per tool link, the chain LoadUrdfRobotFile reads
  std::vector<ChainOfTree> placements;  ///< per tool link, where its chain sits (label: the link)
  std::vector<double> q_min, q_max;     ///< per joint of joint_names, its range (rad, or m)
  /// The chains' labels in order: their tool links ("tool" for a robot YAML file's chain).
  std::vector<std::string> tool_links() const;
};

/// True when the chain LoadUrdfRobotFile would read has a mimic joint on it (which it refuses):
/// such a chain is read with LoadUrdfChains, its mimic joint a coupling.
bool UrdfChainIsCoupled(const std::string& path, const std::string& tool_link = "",
                        const std::string& base_link = "");

/// The chains of `path` from `base_link` (empty: the root) to each of `tool_links` (at least one,
/// each once). A mimic joint on a chain is a coupled link (ChainOfTree::couplings: the URDF's
/// multiplier and offset), following the joint it mimics, which is a joint of the robot's vector
/// even when no chain passes it; mimic joints are not in joint_names. A link of chain c (from its
/// joint k to joint k + 1) is the same D-H link in every chain with the same joints 1 … k + 1: its
/// values are labelled "" when every chain has it, else with the first such chain's tool link
/// (ChainOfTree::link_labels); a chain's last link and tool are its own. Throws InputError naming
/// the file for what LoadUrdfRobotFile refuses and for a repeated tool link.
UrdfChains LoadUrdfChains(const std::string& path, const std::vector<std::string>& tool_links,
                          const std::string& base_link = "");

/// Chain `chain` of `tree`'s data file as ReadRobotCsv reads it for the chain's robot (its joint
/// columns by name, or q1..qN in the chain's order), where a coupled link's column (a mimic
/// joint, which robots do not always log) may be missing when the file names joints: it is
/// filled from the joint it follows (multiplier · q + offset), whose column must then be there.
CsvTable ReadChainCsv(const std::string& path, const UrdfChains& tree, int chain);

/// A whole tree's configurations CSV: a column per joint of `tree`, named as in joint_names (the
/// order of the columns is free; other columns are ignored), and an optional `plane` column
/// resolved against `planes`. Throws InputError naming the file, line and column for a missing
/// joint column and, as CheckJointRanges does, for a value outside its joint's range.
TargetedConfigurations ReadTreeConfigurations(const std::string& path, const UrdfChains& tree,
                                              const PlaneSet* planes = nullptr);

/// The chains of any robot file: a URDF's (LoadUrdfChains), or a robot YAML file's one chain
/// (`tool_links` empty or one empty name, no `base_link`) with its `couple:` links as couplings
/// (robot_file.h FileCoupling): its label "tool", its joints those of the links that are not
/// coupled, named as the links' joints are (q<k> for link k when the file names none).
UrdfChains LoadRobotChains(const std::string& path, const std::vector<std::string>& tool_links,
                           const std::string& base_link = "");
/// True when the chain LoadRobotFile would read has a coupled joint on it (a URDF's mimic joint,
/// a robot YAML file's couple:): such a chain is read with LoadRobotChains.
bool RobotChainIsCoupled(const std::string& path, const std::string& tool_link = "",
                         const std::string& base_link = "");

/// `count` configurations of the whole tree, each joint uniform in its range: the draws of
/// `stream` at indices i·J + j (J joints).
TargetedConfigurations UniformTreeConfigurations(const UrdfChains& tree, int count,
                                                 const RandomStream& stream);

/// A URDF document for `robot` with `link_values` (5N, SI) as its geometry; numbers with 17
/// significant digits.
std::string UrdfText(const RobotModel& robot, const Eigen::VectorXd& link_values);

/// The most a model may differ from the URDF it is written into by UrdfLikeText, at the tool link
/// over the configurations it checks (m; rad for the orientation): even a poorly conditioned
/// calibration moves the tool by centimetres, a model of another robot or tool link by more.
inline constexpr double kUrdfLikeMismatch = 0.5;

/// The user's own URDF (`original`) with the chain from its root to `tool_link` (empty: its only
/// end link) set to `robot` at `link_values` (5N, SI; the calibrated model of that chain, with its
/// base and tool transforms): every element of the file is kept — names, the tree, other
/// branches, meshes, inertials, limits, continuous and mimic joints, comments — and only the
/// `<origin>` of the chain's movable joints and of the first fixed joint after the last movable
/// one (which carries the tool) changes. Each joint keeps its `<axis>`, and its frame keeps its
/// place relative to the model's frame before it (a slide along and a turn about the joint's axis,
/// taken from the URDF's own model), so link frames, meshes and inertials move only by what the
/// calibration moved. Forward kinematics from
/// the root to the tool link then equals `robot`'s at `link_values` (tests: 1e-12); numbers are
/// written with 17 significant digits. Throws InputError naming the file when the chain's movable
/// joints differ from the robot's links in number or kind, when the tool link is the last movable
/// joint's own child and the model's tool is off that joint's axis (a fixed joint is needed to
/// carry it), or when the model's tool is more than kUrdfLikeMismatch from the URDF's own at the
/// zero configuration or at eight others (a model of another robot or tool link).
std::string UrdfLikeText(const std::string& original, const std::string& tool_link,
                         const RobotModel& robot, const Eigen::VectorXd& link_values);

/// The D-H table of `robot` at `link_values` as CSV: one row per link (link, joint, theta0_rad,
/// d_m, a_m, alpha_rad, beta_rad, q_min, q_max, parameters), preceded by `#` comment lines with
/// the base and tool transforms (xyz m, rpy rad).
std::string DhTableText(const RobotModel& robot, const Eigen::VectorXd& link_values);

/// `rig` (its nominal values) for the robot's software, as `lrcal export --format` writes it:
/// "urdf" (UrdfText), "dh-table" (DhTableText) or "yaml" (a robot file with `planes` and the
/// calibration record). Throws SettingError (`format`) for another format.
std::string RobotExportText(const RobotFile& rig, const std::string& format,
                            const std::optional<PlaneSet>& planes);

}  // namespace lrcal
