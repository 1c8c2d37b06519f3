// Robot files: a robot model and the measurement set-up that travels with it.
//
// A robot YAML file (format: docs/FILE_FORMATS.md) gives the links of the chain and the base and
// tool transforms around it (kinematics layer) and, optionally, the plane the ranger measures and
// the ranger's limits (measurement layer). The robot model itself knows nothing of planes or files;
// this reader splits the file into the two.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/identification/prior.h"
#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/environment_measurement.h"
#include "lrcal/measurement/plane.h"
#include "lrcal/measurement/truth.h"

namespace lrcal {

/// Where a calibrated model came from, written into its robot file's `calibration:` section.
struct CalibrationRecord {
  std::string data_file;                ///< the measurement CSV, as given
  std::string data_fnv1a;               ///< FNV-1a of its bytes
  std::string date;                     ///< UTC, ISO 8601
  std::string lrcal;                    ///< lrcal's version
  double sigma = 0;                     ///< m, σ of one reading the covariance assumes
  std::string sigma_source;             ///< "given" (--sigma-mm) or "residual" (σ̂)
  std::vector<std::string> parameters;  ///< the estimated quantities
  Eigen::VectorXd estimate;             ///< their values, SI
  Eigen::MatrixXd covariance;           ///< their covariance, SI (empty if undefined)
  /// What the calibration held at nominal (total_accuracy.h): the terms, their prior σ (SI),
  /// those whose σ is the stated default, and how each moves the estimate (parameters × held).
  /// Empty in records written before lrcal stated totals: then the total is the data part.
  std::vector<std::string> held;
  Eigen::VectorXd held_sigma;
  std::vector<std::string> held_defaulted;
  Eigen::MatrixXd estimate_shift;
};

/// A robot YAML link's `couple: {joint: j, multiplier: m, offset: o}`: the link's joint has no
/// value of its own; it turns (slides) by m·q_j + o with the joint of link j — a mimic joint, a
/// coupled torso joint, a transmission. Its offset's error is the link's θ0 (d0), its
/// multiplier's a term of its own (chain_measurement.h).
struct FileCoupling {
  int link = 0;     ///< the coupled link (0-based)
  int follows = 0;  ///< the link whose joint it follows (0-based; itself not coupled)
  double multiplier = 1.0;
  double offset = 0.0;  ///< rad (m for a prismatic link)
};

/// What a robot file holds.
struct RobotFile {
  RobotModel robot;
  /// The planes of the file's measurement set-up (plane: one, planes: a list), if it gives them.
  std::optional<PlaneSet> planes;
  RangerSpec ranger;  ///< the ranger's limits (defaults unless the file gives them)
  std::string path;   ///< where it was read from
  /// The file's `true_errors:` (the links' and the ranger's: ranger_offset_mm,
  /// ranger_scale_ppm): the real arm and ranger simulations read from. Not part of `robot`.
  Truth truth;
  /// The file's `tolerances:` (prior standard deviations around its nominal values, by class for
  /// every link and by name per link, plane and ranger term): what `identify --prior` uses.
  /// Empty when the file has none; never written back (a calibrated file's record has the
  /// posterior covariance instead).
  PriorSigmas tolerances;
  /// The record of a calibrated robot file (identify --write-robot), if it has one: what
  /// `lrcal accuracy` propagates to poses.
  std::optional<CalibrationRecord> calibration;
  /// A robot YAML file's coupled links (LoadCoupledRobotFile only: LoadRobotFile refuses them).
  std::vector<FileCoupling> couplings{};
  /// What the arm is beyond its geometry, as a calibration knows it (environment_measurement.h):
  /// the file's `masses:`, `compliance.nominal` (stiff without it), `thermal:`'s coefficients and
  /// `environment:` (the defaults of data without environment columns).
  NonGeometricModel non_geometric{};
  /// The same for the simulated arm: `compliance.true` and `thermal:`'s true_* coefficients in
  /// place of the nominal ones (the nominal ones where the file gives no true value).
  NonGeometricModel true_non_geometric{};
};

/// The priors a calibration uses: `rig`'s tolerances when `use_tolerances` (an InputError at
/// `tolerances_option` if it has none), with `prior_sigma` (PriorSigmas::Parse's text, errors at
/// `prior_sigma_option`; "" for none) replacing the same keys. What `identify --prior
/// --prior-sigma ...` and Python's prior=, prior_sigma= mean.
PriorSigmas PriorsFor(const RobotFile& rig, bool use_tolerances, const std::string& prior_sigma,
                      const std::string& tolerances_option, const std::string& prior_sigma_option);

/// Reads a robot YAML file whose links may be coupled (`couple:`), as LoadRobotFile reads one
/// without: a coupled arm is calibrated as a tree of one chain (io/urdf.h LoadRobotChains).
/// Throws InputError naming the file, line and key for a coupling of no link, of itself, of a
/// coupled link, or with a multiplier or offset that is not a finite number.
RobotFile LoadCoupledRobotFile(const std::string& path);

/// Reads a robot YAML file, or a URDF (a path ending in .urdf: io/urdf.h, the chain from
/// `base_link` — empty: the root — to `tool_link`, the ranger's link, empty for the URDF's only
/// end link). Throws InputError naming the file, line and key on any problem, and for a
/// `tool_link` or `base_link` given with a YAML file. A `calibration:` mapping (written by
/// WriteCalibratedRobotFile) is read into `calibration`, not into the model.
RobotFile LoadRobotFile(const std::string& path, const std::string& tool_link = "",
                        const std::string& base_link = "");

/// The robot YAML text of `rig` with `link_values` (5N, SI) as its nominal values, named `name`:
/// links, base and tool transforms, `planes` if given, the ranger's limits and `record` if given.
/// Numbers with 17 significant digits; true errors are not written.
std::string RobotFileText(const RobotFile& rig, const Eigen::VectorXd& link_values,
                          const std::optional<PlaneSet>& planes, const std::string& name,
                          const CalibrationRecord* record = nullptr);

/// Writes a robot file for the calibrated model: `rig`'s links with `link_values` (5N, SI) as
/// their nominal values and no true errors, `planes` as its planes, `rig`'s ranger limits, and the
/// record. Numbers are written with 17 significant digits, so reading the file back gives the
/// same doubles. Written atomically (a temporary file renamed); throws StorageError.
void WriteCalibratedRobotFile(const std::string& path, const RobotFile& rig,
                              const Eigen::VectorXd& link_values, const PlaneSet& planes,
                              const CalibrationRecord& record);

/// Resolves a robot argument: a path to a YAML file, or a short name of a shipped robot
/// ("paper" → studies/robots/paper.yaml in the working directory or in lrcal's data folder,
/// core/data_dir.h). A relative path is taken relative to `relative_to` when given (a study
/// file's folder), else to the working directory. Throws InputError for an unknown name.
std::string ResolveRobotPath(const std::string& name_or_path, const std::string& relative_to = "");

}  // namespace lrcal
