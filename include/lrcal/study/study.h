// Study files: what a Monte-Carlo study repeats, and over which settings it sweeps.
//
// A study file (YAML, schema in docs/STUDIES.md) gives base settings — robot, plane, truth,
// noise, candidate pool, selection, validation set, identification — plus `trials` per cell, a
// `seed`, and optional sweep axes. Each axis names a settings key ("noise.sigma_mm", "selection",
// or "." for the whole settings) and a list of values (a map value is merged into that key). Axes
// combine as a product or zipped. Every combination is a *cell*, identified by a hash of its
// resolved settings (not by its position), so that adding a sweep value later keeps the existing
// cells and their results.
//
// Everything is validated before anything runs: unknown keys, wrong types and impossible values
// are InputErrors naming the file, the line and the key (for sweep values, the line of the value).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lrcal/core/json.h"
#include "lrcal/design/experiment_design.h"
#include "lrcal/identification/identification.h"
#include "lrcal/measurement/noise_model.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/measurement/plane.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/measurement/socket_measurement.h"
#include "lrcal/study/stopping.h"
#include "lrcal/study/truth_options.h"

namespace lrcal {

/// sensor: what a cell's campaign measures with (docs/STUDIES.md, "Sensors"). The ranger is
/// the paper's set-up and lrcal's default; a tracker's point or pose (point_measurement.h,
/// pose_measurement.h) reads a target on the tool in an instrument's frame, whose six terms and
/// the target's are estimated with the arm's; a contact (contact_measurement.h) seats a tool point
/// on the cell's planes and reads nothing; a scanner (scanner_measurement.h) is a fan of ranger
/// beams on the tool, each reading its distance to the cell's plane; a socket
/// (socket_measurement.h) seats a tool point in fixed sockets, whose positions are estimated.
struct StudySensor {
  std::string kind = "ranger";  ///< ranger, scanner, point, pose, contact or socket
  /// point, pose: the instrument's frame in B and the one target; contact, socket: targets[0]
  /// is the tool point that touches the cell's planes or sits in its sockets (m, tool frame).
  PointSetup tracker;
  bool flush = false;  ///< contact: every contact flush (two more values each)
  /// scanner: its frame S in the tool frame (sensor.target: the beams' origin, and the fan in
  /// S's x–z plane) and each beam's angle from S's z axis (rad: sensor.beams spread evenly
  /// over ±sensor.fan_deg).
  RigidTransform scanner_frame;
  std::vector<double> beam_angles{0.0};
  /// socket: the sockets' true (and nominal) positions in B (m; sensor.sockets, ids 0, 1, …
  /// in order) and the known distances between them (sensor.socket_distances).
  std::vector<Eigen::Vector3d> sockets;
  std::vector<SocketDistance> socket_distances;
  double sigma_angle = 0;  ///< rad, pose: σ of each orientation component of a reading
  /// The campaign cost of one reading, in the study's own unit (sensor.cost_per_reading); a
  /// cell's campaign costs selection.count × noise.repetitions × this.
  double cost_per_reading = 1;
  /// sensor.budget: when given, the cell's selection.count is ⌊budget / (cost_per_reading ×
  /// noise.repetitions × tool links)⌋ (a tree cell reads each of its tools at a configuration),
  /// so that cells of different sensors compare at equal campaign cost.
  std::optional<double> budget;
  bool IsRanger() const { return kind == "ranger"; }
};

/// The typed settings of one cell (all SI except where a name says otherwise), parsed from the
/// resolved settings JSON. The defaults live in one place, StudyDefaults(); the initial values
/// here are only neutral zeros.
struct CellSettings {
  std::string robot;  ///< robot file path (YAML or URDF) or shipped name
  /// URDF robots: the ranger's link (empty: the only end link); several, comma-separated
  /// ("left_tool,right_tool"), make a tree cell: every chain measured at each whole-robot
  /// configuration, their common joints' terms shared (tree_trial.cc).
  std::string tool_link;
  std::string base_link;         ///< URDF robots: the chain's first link (empty: the root)
  bool plane_from_robot = true;  ///< plane: robot
  PlaneSet planes;               ///< when !plane_from_robot: one plane or several
  /// Several planes: each one's share of the pool and validation draws (empty: equal shares).
  std::vector<double> plane_shares;
  /// Several planes: each one's estimated terms ("" = identification.estimate_plane).
  std::vector<std::string> plane_estimate;
  /// truth: the simulated arm and ranger (truth_options.h).
  TruthOptions truth;
  /// noise: the reading noise and a real rig's disturbances (noise_model.h; its settings, their
  /// units, defaults and ranges are NoiseModel::Settings()). The ranger's errors are the
  /// truth's (TruthOptions::ranger_offset, ranger_scale).
  NoiseModel noise;
  // Candidate pool.
  int pool_size = 0;
  /// pool.file: the candidates from a CSV of configurations (q1..qN, rad), as written in the
  /// study (relative to its folder); empty when the pool is drawn. The file's hash is part of
  /// the settings (pool.file_fnv1a), hence of the cell id.
  std::string pool_file;
  bool pool_redraw = false;  ///< new pool every trial (else one pool per cell, shared by trials)
  double min_singular_value = 0;
  // Selection.
  int select_count = 0;
  SelectionOptions selection;
  DesignScaling scaling = DesignScaling::kSI;  ///< column scaling of G before selection
  /// selection.criterion: I, the task criterion: minimise the predicted mean-square position
  /// error over the validation configurations, tr(W·(GᵀG)⁻¹) with W = Σ_j J_jᵀJ_j of the
  /// validation poses' position Jacobians (I-optimality for pose accuracy). Selected as
  /// A-optimality on G·L⁻ᵀ, W = LLᵀ; `selection.criterion` is then kA.
  bool task_criterion = false;
  /// Select anew in every trial (from the cell's pool): a random or sampled design then varies
  /// from trial to trial, which is the honest baseline for "how much does the design buy".
  bool selection_redraw = false;
  // Validation.
  int validation_size = 0;
  /// validation.file: the validation configurations from a CSV (as pool_file); empty: drawn.
  std::string validation_file;
  /// A tree cell: the tool link whose poses the validation judges (validation.tool_link; empty:
  /// the first of tool_link).
  std::string validation_tool_link;
  /// validation.coverage: record in every trial the share of the validation poses whose true
  /// position error lies within the 95 % radius the cell's prediction states, the data part and
  /// the total (TrialRecord::coverage). Needs the cell's one design (no pool or selection redraw).
  bool coverage = false;
  // Identification.
  PlaneTerms plane_terms;
  RangerTerms ranger_terms;  ///< identification.estimate_ranger
  std::vector<std::string> fixed;
  bool fix_dependent = false;  ///< on rank deficiency: fix the suggested parameters (else fail)
  IdentificationOptions identification;
  /// sensor: the ranger (the default) or a tracker's point or pose.
  StudySensor sensor;
  /// environment: where the calibration's readings and the validation poses are taken
  /// (measurement/environment.h): a gravity vector (m/s², base frame) and a list of temperatures
  /// (°C) the configurations take in turn. Not given: the robot file's defaults for both.
  struct EnvironmentPhase {
    Eigen::Vector3d gravity = Eigen::Vector3d::Constant(std::nan(""));
    std::vector<double> temperatures_c;  ///< empty: the robot file's
  };
  EnvironmentPhase calibration_environment, validation_environment;
  /// identification.estimate: what the calibrated model has (geometric, compliance, thermal; any
  /// combination). Only the ranger takes compliance and thermal (environment_measurement.h).
  bool estimate_geometric = true, estimate_compliance = false, estimate_thermal = false;
  /// True for a ranger cell with environment: or identification.estimate given: its trials run
  /// on the non-geometric model (the kind pipeline, src/study/tracker_trial.cc).
  bool in_environment = false;
  /// Which of the paper's cases this cell reproduces (1, 2; 0 = none): its report places the
  /// published numbers in our distributions.
  int paper_case = 0;

  /// tool_link's links, in order (empty: none given).
  std::vector<std::string> ToolLinks() const;
  /// Several tool links: a tree cell.
  bool IsTree() const { return ToolLinks().size() > 1; }
};

struct Cell {
  std::string id;     ///< 16 hex digits: FNV-1a of CellIdentity(settings) as canonical JSON
  std::string label;  ///< human label from the axis labels/values ("case 1", "sigma_mm=0.1")
  int order = 0;      ///< position in the study's canonical order
  Json settings;      ///< resolved settings (canonical JSON)
  CellSettings typed;
  std::map<std::string, std::string> axis_values;  ///< axis key → value label
};

struct Study {
  std::string path;
  /// The study file's folder: relative robot paths in the file are taken relative to it.
  std::string folder() const;
  std::string name;
  std::string description;
  std::uint64_t seed = 0;
  /// Trials per cell; with stop_when, the maximum.
  int trials = 0;
  /// Adaptive stopping (stopping.h); off unless the study file has `stop_when`.
  StopWhen stop_when;
  Json base;   ///< resolved base settings (before sweeps)
  Json sweep;  ///< the sweep section as given (canonical JSON)
  /// The sensitivity section (method, samples, levels, bootstrap, metric, inputs) with its
  /// defaults, and plan_cells: the cell id of each plan point in the plan's order (sensitivity.h).
  /// Null for a study without one.
  Json sensitivity;
  std::vector<std::string> axis_keys;
  std::vector<Cell> cells;
  /// The whole resolved study (name, seed, trials, stop_when if on, base, sweep): what a run
  /// directory records.
  Json ToJson() const;
  long long total_trials() const { return static_cast<long long>(trials) * cells.size(); }
};

/// The defaults of every study setting (the schema's one source of them), as the JSON that
/// cell settings are resolved from: a study file's settings are merged into it.
const Json& StudyDefaults();

/// Loads, validates and expands a study file. Throws InputError.
Study LoadStudy(const std::string& path);

/// The part of a cell's resolved settings that identifies it: its id and its random streams
/// (pool, validation set, prediction draws) are functions of this. Files count by content, not
/// by where they are: pool.file and validation.file are left out (their *.file_fnv1a stay), and
/// a robot given as a file path becomes "file" (its robot_file_fnv1a stays); a shipped robot
/// name stays as written. So a study gives the same numbers wherever it and its files are.
Json CellIdentity(const Json& settings);

/// A file named in a study (pool.file, validation.file): relative paths are taken relative to
/// the study file's folder.
std::string ResolveStudyFile(const std::string& file, const std::string& folder);

/// Resolves a study argument: a path, or a shipped name ("quick" → studies/quick.yaml).
std::string ResolveStudyPath(const std::string& name_or_path);

}  // namespace lrcal
