// The Python module lrcal._lrcal (pybind11): the library's calibration core and the Monte-Carlo
// runner on numpy arrays. src/python/lrcal/__init__.py re-exports it and adds load_run.
//
// Conventions, as in the C++ library: SI units (m, rad), joint arrays N×joints (one row per
// configuration), the robot file's plane unless `plane` is given. Every InputError of the library
// becomes lrcal.InputError (a ValueError) with the same message as the command line's, naming
// the file, line or argument; a StorageError becomes lrcal.StorageError (an OSError). Long
// computations run with the GIL released.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Geometry>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "lrcal/core/data_dir.h"
#include "lrcal/core/error.h"
#include "lrcal/core/hash.h"
#include "lrcal/core/random.h"
#include "lrcal/core/strings.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/design/design_choice.h"
#include "lrcal/design/experiment_design.h"
#include "lrcal/design/measurable_pool.h"
#include "lrcal/identification/cross_validation.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/identification/measured_accuracy.h"
#include "lrcal/identification/total_accuracy.h"
#include "lrcal/io/calibration_record.h"
#include "lrcal/io/contact_data.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/kinematics_report.h"
#include "lrcal/io/result_json.h"
#include "lrcal/io/robot_data.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/io/socket_data.h"
#include "lrcal/io/tracker_data.h"
#include "lrcal/io/urdf.h"
#include "lrcal/kinematics/compensation.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/measurement/chain_measurement.h"
#include "lrcal/measurement/contact_measurement.h"
#include "lrcal/measurement/measurement_set.h"
#include "lrcal/measurement/mixed_measurement.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/measurement/pose_measurement.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/scanner_measurement.h"
#include "lrcal/measurement/simulation.h"
#include "lrcal/measurement/truth.h"
#include "lrcal/paper/paper_case.h"
#include "lrcal/report/accuracy_plan.h"
#include "lrcal/report/calibration_report.h"
#include "lrcal/report/report_data.h"
#include "lrcal/report/run_tables.h"
#include "lrcal/study/run_directory.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/study.h"
#include "lrcal/study/study_plan.h"
#include "lrcal/study/trial_replay.h"

namespace py = pybind11;

namespace lrcal::python {

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// --- errors ---------------------------------------------------------------------------------

PyObject* g_error = nullptr;          // lrcal.Error(Exception)
PyObject* g_input_error = nullptr;    // lrcal.InputError(Error, ValueError)
PyObject* g_storage_error = nullptr;  // lrcal.StorageError(Error, OSError)

// Raises `type` with `message`, and the attribute `where` (file:line, key or argument) if known.
void SetError(PyObject* type, const char* message, const std::string& where) {
  PyObject* instance = PyObject_CallFunction(type, "s", message);
  if (!instance) return;  // the call set its own error
  PyObject* where_str = PyUnicode_FromString(where.c_str());
  if (where_str) {
    PyObject_SetAttrString(instance, "where", where_str);
    Py_DECREF(where_str);
  }
  PyErr_SetObject(type, instance);
  Py_DECREF(instance);
}

void RegisterErrors(py::module_& m) {
  g_error =
      PyErr_NewExceptionWithDoc("lrcal.Error", "Base of lrcal's errors.", PyExc_Exception, nullptr);
  py::object input_bases = py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError));
  g_input_error = PyErr_NewExceptionWithDoc(
      "lrcal.InputError",
      "Bad input (a file, a setting, an argument); the message names where and what was expected "
      "(the command line's exit code 2). Attribute `where`: the file:line, key or argument.",
      input_bases.ptr(), nullptr);
  py::object storage_bases = py::make_tuple(py::handle(g_error), py::handle(PyExc_OSError));
  g_storage_error = PyErr_NewExceptionWithDoc(
      "lrcal.StorageError",
      "Results could not be written (a full disk, an I/O error); what was committed is intact "
      "(the command line's exit code 5).",
      storage_bases.ptr(), nullptr);
  m.add_object("Error", py::handle(g_error));
  m.add_object("InputError", py::handle(g_input_error));
  m.add_object("StorageError", py::handle(g_storage_error));
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const SettingError& e) {  // a library check: in Python's words (sigma_mm=)
      const InputError respelled = e.Respelled(Frontend::kPython);
      SetError(g_input_error, respelled.what(), respelled.where());
    } catch (const InputError& e) {
      SetError(g_input_error, e.what(), e.where());
    } catch (const StorageError& e) {
      SetError(g_storage_error, e.what(), "");
    }
  });
}

// --- argument conversion --------------------------------------------------------------------

// A joint array: N×joints (or one configuration as a vector of `joints`), finite values.
ConfigurationSet ToConfigurations(const Array& q, int joints, const char* name) {
  const py::buffer_info b = q.request();
  const bool vector = b.ndim == 1 && b.shape[0] == joints;
  if (!vector && !(b.ndim == 2 && b.shape[1] == joints))
    throw InputError(name, "expected an array of shape (N, " + std::to_string(joints) +
                               "): one row of joint values (rad) per configuration");
  const auto rows = static_cast<int>(vector ? 1 : b.shape[0]);
  const double* data = static_cast<const double*>(b.ptr);
  ConfigurationSet configs(joints);
  configs.Reserve(rows);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < joints; ++j)
      if (!std::isfinite(data[i * joints + j]))
        throw InputError(name, "row " + std::to_string(i) + ", joint " + std::to_string(j + 1) +
                                   ": expected a finite joint value, got " +
                                   FormatExact(data[i * joints + j]));
    configs.Add(data + static_cast<std::ptrdiff_t>(i) * joints);
  }
  return configs;
}

std::vector<double> ToVector(const Array& a, const char* name) {
  const py::buffer_info b = a.request();
  if (b.ndim != 1) throw InputError(name, "expected a one-dimensional array");
  const double* data = static_cast<const double*>(b.ptr);
  return std::vector<double>(data, data + b.shape[0]);
}

// One plane given as an lrcal.Plane or four numbers (nx, ny, nz, f).
Plane ToPlane(const py::object& plane) {
  if (py::isinstance<Plane>(plane)) return plane.cast<Plane>();
  std::vector<double> c;
  try {
    c = plane.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw InputError("plane",
                     "expected None, an lrcal.Plane, four numbers (nx, ny, nz, f) or a list of "
                     "lrcal.Plane");
  }
  if (c.size() != 4)
    throw InputError("plane",
                     "expected four numbers (nx, ny, nz, f), got " + std::to_string(c.size()));
  return Plane::FromCoefficients(c[0], c[1], c[2], c[3], "plane");
}

// `fix`: a list of names or one comma-separated string.
std::vector<std::string> ToNames(const py::object& fix) {
  if (fix.is_none()) return {};
  if (py::isinstance<py::str>(fix)) return SplitList(fix.cast<std::string>());
  try {
    return fix.cast<std::vector<std::string>>();
  } catch (const py::cast_error&) {
    throw InputError("fix", "expected a list of parameter names or one comma-separated string");
  }
}

// The ranger's and the frames' terms asked for (estimate_ranger=, estimate_base=,
// estimate_tool=); a text alone is the ranger's (the functions without frame terms).
struct OtherTerms {
  OtherTerms(std::string ranger_terms) : ranger(std::move(ranger_terms)) {}  // NOLINT: implicit
  OtherTerms(std::string ranger_terms, std::string base_terms, std::string tool_terms)
      : ranger(std::move(ranger_terms)), base(std::move(base_terms)), tool(std::move(tool_terms)) {}
  std::string ranger, base = "none", tool = "none";
};

// The parameter set of `num_planes` planes (estimate_plane for each), the ranger's and the
// frames' terms: what --estimate-plane, --estimate-ranger, --estimate-base, --estimate-tool and
// --fix give the command line.
ParameterSet ResolveParameters(const RobotModel& robot, int num_planes,
                               const std::string& estimate_plane, const OtherTerms& other,
                               const py::object& fix) {
  return MakeParameterSet(
      robot,
      std::vector<PlaneTerms>(num_planes, PlaneTerms::Parse(estimate_plane, "estimate_plane")),
      ToNames(fix), "fix", RangerTerms::Parse(other.ranger, "estimate_ranger"),
      FrameTerms::Parse(other.base, "estimate_base"),
      FrameTerms::Parse(other.tool, "estimate_tool"));
}

// The 5N link values of `model`: "nominal", "true", or an array of 5N values (SI).
Eigen::VectorXd ResolveLinkValues(const RobotFile& rig, const py::object& model) {
  const RobotModel& robot = rig.robot;
  if (py::isinstance<py::str>(model)) {
    const std::string which = model.cast<std::string>();
    if (which == "nominal") return robot.nominal_values();
    if (which == "true") return rig.truth.LinkValues(robot);
    throw InputError("model", "expected 'nominal', 'true' or an array of " +
                                  std::to_string(robot.num_values()) + " link values, got '" +
                                  which + "'");
  }
  const std::vector<double> v = ToVector(model.cast<Array>(), "model");
  if (static_cast<int>(v.size()) != robot.num_values())
    throw InputError("model", "expected " + std::to_string(robot.num_values()) +
                                  " link values (theta, alpha, a, d, beta per link), got " +
                                  std::to_string(v.size()));
  return Eigen::Map<const Eigen::VectorXd>(v.data(), robot.num_values());
}

std::uint64_t ToSeed(long long seed) {
  if (seed < 0) throw InputError("seed", "expected a non-negative integer");
  return static_cast<std::uint64_t>(seed);
}

py::array_t<double> ToArray(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

py::array_t<double> ToArray(const TargetedConfigurations& configs) {
  py::array_t<double> out(
      {static_cast<py::ssize_t>(configs.size()), static_cast<py::ssize_t>(configs.num_joints())});
  auto w = out.mutable_unchecked<2>();
  for (int i = 0; i < configs.size(); ++i)
    for (int j = 0; j < configs.num_joints(); ++j) w(i, j) = configs.q(i)[j];
  return out;
}

// --- results --------------------------------------------------------------------------------

/// Readings as a measurement CSV holds them: one row per single reading.
struct Readings {
  py::array_t<double> q;                             ///< M×joints
  py::array_t<double> h;                             ///< M, m
  py::array_t<int> configuration;                    ///< M, 0-based index of the configuration read
  std::vector<std::pair<int, std::string>> skipped;  ///< (configuration, why) without a reading
  py::object plane_of = py::none();  ///< M, the plane (from 1) each reading is of; None: one plane
};

/// A chosen design.
struct Design {
  std::vector<int> indices;  ///< rows of the pool given, ascending
  DesignChoice choice;       ///< what ChooseDesign found (indices into the usable candidates)
  std::string criterion, method, scaling;
  std::vector<std::pair<int, std::string>> rejected;  ///< pool rows whose beam misses
  std::string json;  ///< `lrcal design --format json`'s fields (DesignChoiceJson)
  std::string sensor = "ranger";
  std::vector<std::string> held;  ///< a tracker's terms held at nominal (the pool cannot see them)
};

// --- functions ------------------------------------------------------------------------------

RobotFile LoadRobot(const std::string& name_or_path, const std::string& tool_link,
                    const std::string& base_link) {
  return LoadRobotFile(ResolveRobotPath(name_or_path), tool_link, base_link);
}

PlaneSet ResolvePlanes(const RobotFile& rig, const py::object& planes);
TargetedConfigurations WithPlanes(const ConfigurationSet& q, const py::object& plane_of,
                                  int num_planes);

// One plane number (from 1) per configuration, as a CSV's plane column.
py::array_t<int> PlaneNumbers(const TargetedConfigurations& configs) {
  py::array_t<int> out(configs.size());
  auto w = out.mutable_unchecked<1>();
  for (int i = 0; i < configs.size(); ++i) w(i) = configs.target(i) + 1;
  return out;
}

py::array_t<double> ForwardKinematicsPy(const RobotFile& rig, const Array& q,
                                        const py::object& model) {
  const RobotModel& robot = rig.robot;
  const ConfigurationSet configs = ToConfigurations(q, robot.num_links(), "q");
  const Eigen::VectorXd values = ResolveLinkValues(rig, model);
  py::array_t<double> out(
      {static_cast<py::ssize_t>(configs.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto w = out.mutable_unchecked<3>();
  for (int i = 0; i < configs.size(); ++i) {
    const Pose<double> pose = ForwardKinematics<double>(robot, values.data(), configs.q(i));
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) w(i, r, c) = pose.R_BT(r, c);
      w(i, r, 3) = pose.p_BT[r];
      w(i, 3, r) = 0;
    }
    w(i, 3, 3) = 1;
  }
  return out;
}

py::object LaserReadingsPy(const RobotFile& rig, const Array& q, const py::object& plane_arg,
                           const py::object& model, bool return_status,
                           const py::object& plane_of) {
  const RobotModel& robot = rig.robot;
  const PlaneSet planes = ResolvePlanes(rig, plane_arg);
  const TargetedConfigurations configs =
      WithPlanes(ToConfigurations(q, robot.num_links(), "q"), plane_of, planes.size());
  const Eigen::VectorXd values = ResolveLinkValues(rig, model);
  std::vector<double> h;
  std::vector<BeamMiss> misses;
  ExactReadings(robot, values, planes, rig.ranger, configs, &h, &misses);
  std::vector<std::string> status;
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (misses[i] != BeamMiss::kNone) h[i] = std::numeric_limits<double>::quiet_NaN();
    status.emplace_back(BeamMissName(misses[i]));
  }
  if (!return_status) return ToArray(h);
  return py::make_tuple(ToArray(h), py::cast(status));
}

py::object SampleConfigurationsPy(const RobotFile& rig, int count, long long seed,
                                  const py::object& plane_arg, bool validation,
                                  double min_singular_value, bool return_planes) {
  if (count < 1 || count > 1000000)
    throw InputError("count",
                     "expected 1 to 1,000,000 configurations, got " + std::to_string(count));
  const PlaneSet planes = ResolvePlanes(rig, plane_arg);
  if (planes.size() > 1 && !return_planes)
    throw InputError("return_planes",
                     std::to_string(planes.size()) +
                         " planes: count configurations are drawn per plane; pass "
                         "return_planes=True to receive (q, plane_of), the plane each is aimed "
                         "at (as lrcal sample's plane column)");
  SamplingOptions options;
  options.ranger = rig.ranger;
  options.min_jacobian_singular_value = min_singular_value;
  options.require_beam_hit = !validation;
  options.Validate();
  const RandomStream stream(ToSeed(seed), 0, 0,
                            validation ? RandomPurpose::kValidation : RandomPurpose::kPool);
  TargetedConfigurations configs;
  {
    py::gil_scoped_release release;
    configs = planes.size() == 1
                  ? SampleConfigurations(rig.robot, planes[0], count, stream, options)
                  : SampleConfigurations(rig.robot, planes, std::vector<int>(planes.size(), count),
                                         stream, options);
  }
  if (!return_planes) return ToArray(configs);
  return py::make_tuple(ToArray(configs), PlaneNumbers(configs));
}

// The noise settings as simulate() takes them: sigma_mm, repetitions, encoder_sigma_mrad,
// form_sigma_mm, outlier_fraction, outlier_sigma_mm (NoiseModel::Settings(), in that order).
struct NoiseArgs {
  double sigma_mm;
  long long repetitions;
  double encoder_sigma_mrad, form_sigma_mm, outlier_fraction, outlier_sigma_mm;
};

// The noise model from its settings in their units (checked by the schema, named as Python
// names them); `sigma` (m), the earlier spelling of sigma_mm, still accepted.
NoiseModel ToNoiseModel(const NoiseArgs& a, const py::object& sigma_m) {
  const auto& fields = NoiseModel::Settings();
  std::vector<double> values = {a.sigma_mm,           static_cast<double>(a.repetitions),
                                a.encoder_sigma_mrad, a.form_sigma_mm,
                                a.outlier_fraction,   a.outlier_sigma_mm};
  if (!sigma_m.is_none()) {
    if (a.sigma_mm != fields[0].Default())
      throw InputError("sigma", "give sigma_mm (mm) or sigma (m, the earlier spelling), not both");
    values[0] = sigma_m.cast<double>() / fields[0].spec.to_si;
  }
  NoiseModel noise;
  for (std::size_t k = 0; k < fields.size(); ++k) {
    const double si = values[k] * fields[k].spec.to_si;
    if (!fields[k].spec.Allows(si))
      throw SettingError(fields[k].spec, si).Respelled(Frontend::kPython);
    fields[k].Set(&noise, si);
  }
  return noise;
}

Readings SimulatePy(const RobotFile& rig, const Array& q, const NoiseArgs& noise_args,
                    long long seed, const py::object& plane_arg, const py::object& model,
                    const py::object& sigma_m, const py::object& plane_of) {
  const RobotModel& robot = rig.robot;
  const PlaneSet planes = ResolvePlanes(rig, plane_arg);
  const TargetedConfigurations configs =
      WithPlanes(ToConfigurations(q, robot.num_links(), "q"), plane_of, planes.size());
  const Eigen::VectorXd values = ResolveLinkValues(rig, model);
  NoiseModel noise = ToNoiseModel(noise_args, sigma_m);
  // The robot file's true ranger errors are part of its true model (as lrcal simulate reads).
  if (py::isinstance<py::str>(model) && model.cast<std::string>() == "true") {
    noise.ranger_offset = rig.truth.ranger_offset;
    noise.ranger_scale = rig.truth.ranger_scale;
  }
  MeasurementSet data;
  std::vector<BeamMiss> misses;
  std::vector<double> raw;
  {
    py::gil_scoped_release release;
    SimulateReadings(robot, values, planes, rig.ranger, configs, noise,
                     RandomStream(ToSeed(seed), 0, 0, RandomPurpose::kNoise), &data, &misses, &raw);
  }
  // The kept configurations in order, `repetitions` readings each (as lrcal simulate writes).
  Readings out;
  std::vector<int> kept;
  for (int i = 0; i < configs.size(); ++i) {
    if (misses[i] == BeamMiss::kNone) {
      kept.push_back(i);
    } else {
      out.skipped.emplace_back(i, BeamMissName(misses[i]));
    }
  }
  const auto m = static_cast<py::ssize_t>(raw.size());
  const int n = robot.num_links();
  out.q = py::array_t<double>({m, static_cast<py::ssize_t>(n)});
  out.h = ToArray(raw);
  out.configuration = py::array_t<int>(m);
  auto wq = out.q.mutable_unchecked<2>();
  auto wc = out.configuration.mutable_unchecked<1>();
  for (py::ssize_t r = 0; r < m; ++r) {
    const int i = kept[static_cast<std::size_t>(r / noise.repetitions)];
    for (int j = 0; j < n; ++j) wq(r, j) = configs.q(i)[j];
    wc(r) = i;
  }
  if (planes.size() > 1) {
    py::array_t<int> tags(m);
    auto wt = tags.mutable_unchecked<1>();
    for (py::ssize_t r = 0; r < m; ++r) wt(r) = configs.target(wc(r)) + 1;
    out.plane_of = std::move(tags);
  }
  return out;
}

// A setting given in its unit (`value`, e.g. sigma_mm; `default_value` when not given) or, in
// the earlier spelling, in SI (`value_si`, e.g. sigma in m; None when not given): the SI value,
// checked by the spec.
double SettingValue(const SettingSpec& spec, double default_value, double value,
                    const py::object& value_si, const char* earlier) {
  double si = value * spec.to_si;
  if (!value_si.is_none()) {
    if (value != default_value)
      throw InputError(earlier, std::string("give ") + spec.name + " (" + spec.unit + ") or " +
                                    earlier + " (" + spec.si_unit +
                                    ", the earlier spelling), not both");
    si = value_si.cast<double>();
  }
  if (!spec.Allows(si)) throw SettingError(spec, si).Respelled(Frontend::kPython);
  return si;
}

// The same for a setting of IdentificationOptions (its default from the schema).
double SettingValue(const SettingField<IdentificationOptions>& field, double value,
                    const py::object& value_si, const char* earlier) {
  return SettingValue(field.spec, field.Default(), value, value_si, earlier);
}

struct IdentifyArgs {
  std::string solver, loss;
  double loss_scale_mm, sigma_mm;
  long long max_iterations;
  py::object loss_scale, sigma;           // the earlier spellings, in m (None: not given)
  std::string prior_sigma;                // as --prior-sigma; "" = no priors
  bool prior = false;                     // as --prior: the robot file's tolerances
  double encoder_sigma_mrad = 0;          // as --encoder-sigma-mrad: errors in variables
  std::string average = "mean";           // as --average: mean, median or trimmed:F
  std::string estimate_ranger = "none";   // as --estimate-ranger
  std::string estimate_base = "none";     // as --estimate-base
  std::string estimate_tool = "none";     // as --estimate-tool
  py::object plane_of = py::none();       // one plane number (from 1) per reading, or None
  py::object holdout = py::none();        // as --holdout K, or None
  py::object predict_at = py::none();     // as --predict-at: poses (M, joints), or None
  py::object configuration = py::none();  // one label per reading (a CSV's configuration column)
  double loss_scale_sigma = 0;            // as --loss-scale-sigma (0: loss_scale_mm is the scale)
  py::object write_robot = py::none();    // as --write-robot: the calibrated robot file, or None
  py::object report = py::none();         // as --report: the report's folder, or None
  py::object data_file = py::none();      // the file q and h were read from, for the record
};

// identify's `configuration`: one label per reading (any value, as text), none empty.
std::optional<std::vector<std::string>> ConfigurationLabels(const py::object& labels,
                                                            std::size_t readings) {
  if (labels.is_none()) return std::nullopt;
  std::vector<std::string> out;
  for (const py::handle item : labels) {
    out.push_back(py::str(item).cast<std::string>());
    if (out.back().empty())
      throw InputError("configuration[" + std::to_string(out.size() - 1) + "]",
                       "empty: expected the label of the configuration this reading was taken at");
  }
  if (out.size() != readings)
    throw InputError("configuration", "expected one label per reading (" +
                                          std::to_string(readings) + "), got " +
                                          std::to_string(out.size()));
  return out;
}

// A JSON text as Python objects (what the command prints with --format json).
py::object FromJson(const std::string& json) {
  return py::module_::import("json").attr("loads")(json);
}

// The readings' configurations with the plane each is aimed at: `plane_of` has one plane number
// (from 1, in `planes`' order) per reading, as a measurement CSV's plane column; it may be left
// out with one plane only.
TargetedConfigurations WithPlanes(const ConfigurationSet& q, const py::object& plane_of,
                                  int num_planes) {
  if (plane_of.is_none()) {
    if (num_planes > 1)
      throw InputError("plane_of", std::to_string(num_planes) +
                                       " planes: give the plane each reading's beam is aimed at, "
                                       "a number from 1 to " +
                                       std::to_string(num_planes) +
                                       " per reading (as a measurement CSV's plane column)");
    return TargetedConfigurations(q);
  }
  std::vector<double> tags;
  try {
    tags = plane_of.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw InputError("plane_of", "expected one plane number (from 1) per reading");
  }
  if (static_cast<int>(tags.size()) != q.size())
    throw InputError("plane_of", "expected one plane number per reading (" +
                                     std::to_string(q.size()) + "), got " +
                                     std::to_string(tags.size()));
  TargetedConfigurations out(q.num_joints());
  out.Reserve(q.size());
  for (int i = 0; i < q.size(); ++i) {
    const double t = tags[i];
    if (!(t >= 1 && t <= num_planes && t == std::floor(t)))
      throw InputError("plane_of[" + std::to_string(i) + "]", "expected a plane number from 1 to " +
                                                                  std::to_string(num_planes) +
                                                                  ", got " + FormatExact(t));
    out.Add(q.q(i), static_cast<int>(t) - 1);
  }
  return out;
}

IdentificationOptions IdentifyOptionsPy(const RobotFile& rig, bool auto_fix,
                                        const IdentifyArgs& a) {
  IdentificationOptions options;
  options.solver = ParseName(kSolverNames, a.solver, "solver", "solver");
  options.loss = ParseName(kRobustLossNames, a.loss, "loss", "loss");
  const auto& fields = IdentificationOptions::Settings();
  options.loss_scale = SettingValue(*FindSetting(fields, "loss_scale_mm"), a.loss_scale_mm,
                                    a.loss_scale, "loss_scale");
  options.sigma = SettingValue(*FindSetting(fields, "sigma_mm"), a.sigma_mm, a.sigma, "sigma");
  // Its range is checked by Validate() below (a SettingError, in Python's words).
  if (a.loss_scale_sigma > 0 &&
      (a.loss_scale_mm != FindSetting(fields, "loss_scale_mm")->Default() ||
       !a.loss_scale.is_none()))
    throw InputError("loss_scale_sigma=",
                     "give the loss scale once: in mm (loss_scale_mm=) or in multiples of sigma "
                     "(loss_scale_sigma=), not both");
  options.loss_scale_sigma = a.loss_scale_sigma;
  const auto& iterations = *FindSetting(fields, "max_iterations");
  const double max_iterations = static_cast<double>(a.max_iterations);
  if (!iterations.spec.Allows(max_iterations))
    throw SettingError(iterations.spec, max_iterations).Respelled(Frontend::kPython);
  options.max_iterations = static_cast<int>(a.max_iterations);
  options.fix_dependent_parameters = auto_fix;
  options.priors = PriorsFor(rig, a.prior, a.prior_sigma, "prior=", "prior_sigma=");
  options.encoder_sigma = a.encoder_sigma_mrad * 1e-3;
  options.check_linearisation = true;  // as lrcal identify
  options.Validate();
  return options;
}

// What identify(holdout=, predict_at=) add to the result, as the command line's JSON has them.
struct IdentifyExtras {
  std::optional<CrossValidation> holdout;
  std::optional<AccuracyPrediction> accuracy;
  ConfigurationSet poses;
};

// The configurations q (with the plane each is aimed at) and the model with its parameter set:
// what identify (one configuration per reading), identifiability and prior_information take, as
// the command line's --data or --configs, --plane,
// --estimate-plane, --estimate-ranger and --fix give them.
struct ConfigsAndModel {
  TargetedConfigurations configs;
  std::unique_ptr<MeasurementModel> model;
};
ConfigsAndModel ResolveConfigsAndModel(const RobotFile& rig, const Array& q,
                                       const py::object& plane_arg, const py::object& plane_of,
                                       const std::string& estimate_plane,
                                       const OtherTerms& estimate_ranger, const py::object& fix) {
  const RobotModel& robot = rig.robot;
  const PlaneSet planes = ResolvePlanes(rig, plane_arg);
  ConfigsAndModel out;
  out.configs = WithPlanes(ToConfigurations(q, robot.num_links(), "q"), plane_of, planes.size());
  CheckJointRanges(out.configs, robot, "q");
  out.model = std::make_unique<MeasurementModel>(
      robot, planes, ResolveParameters(robot, planes.size(), estimate_plane, estimate_ranger, fix));
  return out;
}

// Where identify()'s readings came from, for the calibrated file's record: data_file= (hashed)
// or the arrays themselves (described, and hashed as their float64 bytes).
DataSource ReadingsSource(const py::object& data_file, const TargetedConfigurations& configs,
                          const std::vector<double>& h) {
  if (!data_file.is_none()) return DataSource::File(py::str(data_file).cast<std::string>());
  std::string bytes;
  for (int i = 0; i < configs.size(); ++i)
    bytes.append(reinterpret_cast<const char*>(configs.q(i)),
                 sizeof(double) * static_cast<std::size_t>(configs.num_joints()));
  bytes.append(reinterpret_cast<const char*>(h.data()), sizeof(double) * h.size());
  return {"Python arrays: " + std::to_string(h.size()) + " readings (identify(q, h))",
          HashHex(bytes)};
}

// identify(write_robot=, report=) as paths ("" when not asked for).
struct IdentifyFiles {
  std::string robot, report;
  bool any() const { return !robot.empty() || !report.empty(); }
};

// What --write-robot and --report write (the report's HTML page is drawn by the caller, with the
// GIL); runs without the GIL.
void WriteIdentifyFiles(const IdentifyFiles& files, const RobotFile& rig,
                        const MeasurementModel& model, const MeasurementSet& data,
                        const IdentificationSummary& s, const IdentificationOptions& options,
                        const UnestimatedTerms& held, const DataSource& source, int folds) {
  if (!files.robot.empty() && s.IsSolutionUsable())
    WriteCalibratedRobot(files.robot, source, rig, model, s, options, held);
  if (files.report.empty()) return;
  CalibrationReportInputs in{source, &rig, &model, &data, &s, options};
  in.held = held;
  in.holdout = folds;
  try {
    WriteCalibrationReportData(files.report, in);
  } catch (const SettingError& e) {
    throw e.Respelled(Frontend::kPython);
  }
}

IdentificationSummary IdentifyPy(const RobotFile& rig, const Array& q, const Array& h,
                                 const py::object& plane_arg, const std::string& estimate_plane,
                                 const py::object& fix, bool auto_fix, const IdentifyArgs& a,
                                 IdentifyExtras* extras) {
  const RobotModel& robot = rig.robot;
  const ConfigsAndModel set =
      ResolveConfigsAndModel(rig, q, plane_arg, a.plane_of, estimate_plane,
                             {a.estimate_ranger, a.estimate_base, a.estimate_tool}, fix);
  const std::vector<double> readings = ToVector(h, "h");
  const auto labels = ConfigurationLabels(a.configuration, readings.size());
  const MeasurementSet data = GroupReadings(
      set.configs, readings, &rig.ranger,
      [](int r) { return r < 0 ? std::string("q, h") : "h[" + std::to_string(r) + "]"; },
      labels ? &*labels : nullptr, Averaging::Parse(a.average));
  const MeasurementModel& model = *set.model;
  const IdentificationOptions options = IdentifyOptionsPy(rig, auto_fix, a);
  std::optional<int> folds;
  if (!a.holdout.is_none()) folds = a.holdout.cast<int>();
  const bool predict = !a.predict_at.is_none();
  if (predict) {
    extras->poses = ToConfigurations(a.predict_at.cast<Array>(), robot.num_links(), "predict_at");
    CheckJointRanges(extras->poses, robot, "predict_at");
  }
  IdentifyFiles files;
  if (!a.write_robot.is_none()) files.robot = py::str(a.write_robot).cast<std::string>();
  if (!a.report.is_none()) files.report = py::str(a.report).cast<std::string>();
  if (!a.write_robot.is_none()) CheckOutputFile(files.robot, "write_robot=");
  const DataSource source =
      files.any() ? ReadingsSource(a.data_file, set.configs, readings) : DataSource{};
  py::gil_scoped_release release;
  IdentificationSummary s = Identify(model, data, options);
  // What is known of the held terms: the robot file's tolerances, prior_sigma over them.
  const UnestimatedTerms held =
      s.IsSolutionUsable() && (predict || files.any())
          ? FindUnestimatedTerms(
                SolvedModel(model, s), s, data, options,
                PriorsFor(rig, !rig.tolerances.empty(), a.prior_sigma, "prior=", "prior_sigma="))
          : UnestimatedTerms{};
  if (files.any())
    WriteIdentifyFiles(files, rig, model, data, s, options, held, source, folds.value_or(0));
  if (!s.IsSolutionUsable()) return s;
  if (folds) {
    try {
      extras->holdout = CrossValidate(model, data, *folds, options);
    } catch (const SettingError& e) {
      throw e.Respelled(Frontend::kPython);
    }
  }
  if (predict) {
    extras->accuracy = PredictAccuracyAfterFit(model, s, options, held, extras->poses);
    if (!extras->accuracy)
      throw InputError("predict_at",
                       "the covariance is undefined (as many configurations as parameters); "
                       "give sigma_mm");
  }
  return s;
}

// --- trackers (point_measurement.h, pose_measurement.h) ----------------------------------------

// A transform from (x, y, z) or (x, y, z, roll, pitch, yaw) (m, rad; URDF's rpy order).
RigidTransform ToXyzRpy(const py::object& value, const std::string& where, bool allow_three) {
  std::vector<double> v;
  try {
    v = value.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    v.clear();
  }
  if (v.size() != 6 && !(allow_three && v.size() == 3))
    throw InputError(where, allow_three ? "expected (x, y, z) in m or (x, y, z, roll, pitch, "
                                          "yaw) in m and rad"
                                        : "expected (x, y, z, roll, pitch, yaw) in m and rad");
  v.resize(6, 0.0);
  return RigidTransform::FromXyzRpy(Eigen::Vector3d(v[0], v[1], v[2]),
                                    Eigen::Vector3d(v[3], v[4], v[5]));
}

// The tracker's kind on `robot`: sensor "point" or "pose", instrument= (6 numbers; None: the base
// frame), targets= (a list of 3 or 6 numbers each; None: one target at the tool frame's origin)
// and fix=, as the command line's --sensor, --instrument, --target and --fix.
std::unique_ptr<PointMeasurement> ToTrackerKind(const RobotModel& robot, const std::string& sensor,
                                                const py::object& instrument,
                                                const py::object& targets, const py::object& fix) {
  if (sensor != "point" && sensor != "pose")
    throw InputError("sensor",
                     "'" + CellExcerpt(sensor) + "' is not a tracker: expected 'point' or 'pose'");
  PointSetup setup;
  if (!instrument.is_none()) setup.instrument = ToXyzRpy(instrument, "instrument", false);
  if (!targets.is_none()) {
    setup.targets.clear();
    int k = 0;
    for (const py::handle target : targets) {
      const RigidTransform t = ToXyzRpy(py::reinterpret_borrow<py::object>(target),
                                        "targets[" + std::to_string(k++) + "]", true);
      setup.targets.push_back(t.translation);
      setup.target_orientations.push_back(t.rotation);
      if (sensor == "point" && !t.rotation.isIdentity(0))
        throw InputError("targets[" + std::to_string(k - 1) + "]",
                         "an orientation is given but sensor='point' reads positions only");
    }
    if (sensor == "point") setup.target_orientations.clear();
  }
  if (sensor == "pose") return std::make_unique<PoseMeasurement>(robot, setup, ToNames(fix), "fix");
  return std::make_unique<PointMeasurement>(robot, setup, ToNames(fix), "fix");
}

// q (N, joints) with the target each row sees: target_of (N numbers from 1; None: target 1, which
// needs a single target), joint ranges checked.
TargetedConfigurations ToTrackerConfigurations(const RobotModel& robot, const Array& q,
                                               const py::object& target_of, int num_targets) {
  const ConfigurationSet poses = ToConfigurations(q, robot.num_links(), "q");
  CheckJointRanges(poses, robot, "q");
  if (target_of.is_none() && num_targets > 1)
    throw InputError("target_of", std::to_string(num_targets) +
                                      " targets: give the target each row sees, a number from 1 "
                                      "to " +
                                      std::to_string(num_targets) + " per row");
  std::vector<double> tags(static_cast<std::size_t>(poses.size()), 1.0);
  if (!target_of.is_none()) tags = ToVector(target_of.cast<Array>(), "target_of");
  if (static_cast<int>(tags.size()) != poses.size())
    throw InputError("target_of", "expected one target number per row (" +
                                      std::to_string(poses.size()) + "), got " +
                                      std::to_string(tags.size()));
  TargetedConfigurations configs(robot.num_links());
  for (int i = 0; i < poses.size(); ++i) {
    const double t = tags[static_cast<std::size_t>(i)];
    if (!(t >= 1 && t <= num_targets && t == std::floor(t)))
      throw InputError("target_of[" + std::to_string(i) + "]",
                       "expected a target number from 1 to " + std::to_string(num_targets));
    configs.AddFrom(poses, i, static_cast<int>(t) - 1);
  }
  return configs;
}

// The ranger's arguments mean nothing to a tracker: refused by name unless at their defaults.
void RefuseRangerArguments(const std::string& sensor,
                           const std::vector<std::pair<std::string, bool>>& given) {
  for (const auto& [name, is_given] : given)
    if (is_given)
      throw InputError(name, "is the ranger's; sensor='" + sensor + "' does not take it");
}

// identifiability(sensor='point'|'pose', ...).
IdentifiabilityReport TrackerIdentifiabilityPy(const RobotFile& rig, const Array& q,
                                               const std::string& sensor,
                                               const py::object& instrument,
                                               const py::object& targets,
                                               const py::object& target_of, const py::object& fix,
                                               double rank_tolerance) {
  const std::unique_ptr<PointMeasurement> kind =
      ToTrackerKind(rig.robot, sensor, instrument, targets, fix);
  const TargetedConfigurations configs = ToTrackerConfigurations(
      rig.robot, q, target_of, static_cast<int>(kind->setup().targets.size()));
  IdentifiabilityOptions options;
  options.rank_tolerance = rank_tolerance;
  options.Validate();
  py::gil_scoped_release release;
  return AnalyzeIdentifiability(*kind, configs, nullptr, options);
}

// The noise of simulate_tracker: σ per position component (mm), per orientation component (mrad).
struct TrackerNoiseArgs {
  double sigma_mm, sigma_mrad;
  long long repetitions, seed;
};

// simulate_tracker: the true arm's (the robot file's true errors) tracker values at q.
py::dict SimulateTrackerPy(const RobotFile& rig, const Array& q, const std::string& sensor,
                           const py::object& instrument, const py::object& targets,
                           const py::object& target_of, const TrackerNoiseArgs& a) {
  const std::unique_ptr<PointMeasurement> nominal =
      ToTrackerKind(rig.robot, sensor, instrument, targets, py::none());
  const RobotModel true_robot = rig.truth.TrueRobot(rig.robot);
  const std::unique_ptr<PointMeasurement> truth = TrackerKindOn(true_robot, *nominal);
  const TargetedConfigurations configs = ToTrackerConfigurations(
      rig.robot, q, target_of, static_cast<int>(nominal->setup().targets.size()));
  NoiseModel noise;
  noise.sigma = a.sigma_mm * 1e-3;
  noise.sigma_angle = a.sigma_mrad * 1e-3;
  if (a.repetitions < 1 || a.repetitions > 1000000)
    throw InputError("repetitions", "expected 1 to 1,000,000 readings per configuration");
  noise.repetitions = static_cast<int>(a.repetitions);
  MeasuredValues data;  // every reading drawn, as lrcal simulate --sensor draws them
  SimulateMeasurements(*truth, configs, noise,
                       RandomStream(ToSeed(a.seed), 0, 0, RandomPurpose::kNoise), &data);
  const int k = nominal->rows_per_configuration();
  py::array_t<double> xyz({static_cast<py::ssize_t>(data.size()), py::ssize_t{3}});
  auto w = xyz.mutable_unchecked<2>();
  for (int i = 0; i < data.size(); ++i)
    for (int c = 0; c < 3; ++c) w(i, c) = data.y[static_cast<std::size_t>(i * k + c)];
  py::dict out;
  out["q"] = ToArray(data.configs);
  out["target_of"] = PlaneNumbers(data.configs);
  out["xyz"] = xyz;
  out["repetitions"] = data.repetitions;
  if (const auto* pose = dynamic_cast<const PoseMeasurement*>(nominal.get())) {
    py::array_t<double> quaternion({static_cast<py::ssize_t>(data.size()), py::ssize_t{4}});
    auto wq = quaternion.mutable_unchecked<2>();
    for (int i = 0; i < data.size(); ++i) {
      const double* phi = &data.y[static_cast<std::size_t>(i * k + 3)];
      const Eigen::Quaterniond qt(pose->OrientationOf(data.configs.q(i), data.configs.target(i),
                                                      Eigen::Vector3d(phi[0], phi[1], phi[2])));
      wq(i, 0) = qt.x();
      wq(i, 1) = qt.y();
      wq(i, 2) = qt.z();
      wq(i, 3) = qt.w();
    }
    out["quaternion"] = quaternion;
  }
  return out;
}

// The options of every kind's identify_* function: the solver by name, sigma_mm (0: none given),
// auto_fix, and the linearisation check lrcal identify makes.
IdentificationOptions KindFitOptions(const std::string& solver, double sigma_mm, bool auto_fix) {
  IdentificationOptions options;
  options.solver = ParseName(kSolverNames, solver, "solver", "solver");
  options.sigma = sigma_mm * 1e-3;
  options.fix_dependent_parameters = auto_fix;
  options.check_linearisation = true;  // as lrcal identify
  options.Validate();
  return options;
}

// A kind's fit as Python receives it: an lrcal.Identification whose `holdout` is the K-fold
// cross-validation of holdout=K and whose `accuracy` is the calibrated arm's predicted accuracy at
// predict_at=poses (None when not asked for or the fit is not usable), with the keys of `lrcal
// identify --sensor ... --holdout K --predict-at F --format json`.
py::object FitKindPy(const RobotFile& rig, const MeasurementKind& kind, const MeasuredValues& data,
                     const IdentificationOptions& options, const py::object& holdout,
                     const py::object& predict_at) {
  const int folds = holdout.is_none() ? 0 : holdout.cast<int>();  // 0: not asked for
  if (!holdout.is_none() && (folds < 2 || folds > data.size()))   // refused before the fit
    throw InputError("holdout", "expected 2 to " + std::to_string(data.size()) +
                                    " folds (the number of configurations), got " +
                                    std::to_string(folds));
  ConfigurationSet poses;
  if (!predict_at.is_none()) {
    poses = ToConfigurations(predict_at.cast<Array>(), rig.robot.num_links(), "predict_at");
    CheckJointRanges(poses, rig.robot, "predict_at");
  }
  const PlaneSet planes = ResolvePlanes(rig, py::none());
  IdentificationSummary summary;
  std::optional<CrossValidation> cv;
  std::optional<AccuracyPrediction> accuracy;
  {
    py::gil_scoped_release release;
    summary = Identify(kind, data, options);
    try {
      if (folds > 0 && summary.IsSolutionUsable()) cv = CrossValidate(kind, data, folds, options);
    } catch (const SettingError& e) {
      throw e.Respelled(Frontend::kPython);
    }
    if (!predict_at.is_none() && summary.IsSolutionUsable()) {
      const RobotFile calibrated = TrackerCalibratedRobot(DataSource{"Python arrays", ""}, rig,
                                                          kind, data, summary, options);
      if (!calibrated.calibration || calibrated.calibration->covariance.size() == 0)
        throw InputError("predict_at",
                         "the covariance is undefined (as many values as terms); give sigma_mm");
      accuracy = PredictCalibratedAccuracy(calibrated, planes, poses);
    }
  }
  py::object result = py::cast(std::move(summary));
  result.attr("holdout") = cv ? FromJson(CrossValidationJson(*cv).dump()) : py::none();
  result.attr("accuracy") =
      accuracy ? FromJson(PoseAccuracyJson(*accuracy, poses).dump()) : py::none();
  return result;
}

// identify_tracker's arguments besides the robot, q, xyz and the sensor.
struct TrackerFitArgs {
  py::object quaternion, instrument, targets, target_of, repetitions, fix;
  bool auto_fix;
  double sigma_mm, sigma_mrad;
  std::string solver;
  py::object holdout = py::none(), predict_at = py::none();
};

// An (N, columns) array's values, row by row (InputError naming `name` for another shape).
std::vector<double> ToRows(const Array& a, int columns, int rows, const char* name) {
  if (a.ndim() != 2 || a.shape(0) != rows || a.shape(1) != columns)
    throw InputError(name, "expected an array of shape (" + std::to_string(rows) + ", " +
                               std::to_string(columns) + "), one row per row of q");
  return std::vector<double>(a.data(), a.data() + a.size());
}

// The measured values of identify_tracker: xyz (N, 3) m, a pose's quaternion (N, 4) as (qx, qy,
// qz, qw), repetitions (N, optional).
MeasuredValues ToTrackerValues(const PointMeasurement& kind, TargetedConfigurations configs,
                               const Array& xyz, const TrackerFitArgs& a) {
  const auto* pose = dynamic_cast<const PoseMeasurement*>(&kind);
  const std::vector<double> p = ToRows(xyz, 3, configs.size(), "xyz");
  if (!pose && !a.quaternion.is_none())
    throw InputError("quaternion", "is the pose's; sensor='point' reads positions only");
  if (pose && a.quaternion.is_none())
    throw InputError("quaternion", "sensor='pose' needs (N, 4) orientations (qx, qy, qz, qw)");
  const std::vector<double> quat =
      pose ? ToRows(a.quaternion.cast<Array>(), 4, configs.size(), "quaternion")
           : std::vector<double>{};
  MeasuredValues data{std::move(configs), {}, {}};
  for (int i = 0; i < data.size(); ++i) {
    for (int c = 0; c < 3; ++c) data.y.push_back(p[static_cast<std::size_t>(3 * i + c)]);
    if (!pose) continue;
    const Eigen::Vector3d phi =
        QuaternionOrientationValue(*pose, data.configs, i, &quat[static_cast<std::size_t>(4 * i)],
                                   "quaternion[" + std::to_string(i) + "]");
    for (int c = 0; c < 3; ++c) data.y.push_back(phi[c]);
  }
  data.repetitions.assign(static_cast<std::size_t>(data.size()), 1);
  if (!a.repetitions.is_none()) data.repetitions = a.repetitions.cast<std::vector<int>>();
  if (static_cast<int>(data.repetitions.size()) != data.size())
    throw InputError("repetitions", "expected one count per row of q");
  for (int r : data.repetitions)
    if (r < 1) throw InputError("repetitions", "expected counts of at least 1");
  return data;
}

// identify_tracker: the tracker's terms from its values, as identify --sensor point|pose.
py::object IdentifyTrackerPy(const RobotFile& rig, const Array& q, const Array& xyz,
                             const std::string& sensor, const TrackerFitArgs& a) {
  const std::unique_ptr<PointMeasurement> kind =
      ToTrackerKind(rig.robot, sensor, a.instrument, a.targets, a.fix);
  MeasuredValues data =
      ToTrackerValues(*kind,
                      ToTrackerConfigurations(rig.robot, q, a.target_of,
                                              static_cast<int>(kind->setup().targets.size())),
                      xyz, a);
  const IdentificationOptions options = KindFitOptions(a.solver, a.sigma_mm, a.auto_fix);
  if (sensor == "pose")
    WeighAngleRows(*kind, options.sigma > 0 ? options.sigma : NoiseModel{}.sigma,
                   a.sigma_mrad * 1e-3, &data);
  return FitKindPy(rig, *kind, data, options, a.holdout, a.predict_at);
}

// identifiability(sensor='socket')'s own arguments.
struct SocketArgs {
  py::object socket_of, distances, tool_point;
};

// Socket seatings from Python: q (N, joints), socket_of (N ids ≥ 0), repetitions (N or None).
SocketData ToSocketData(const RobotModel& robot, const Array& q, const py::object& socket_of,
                        const py::object& repetitions) {
  const ConfigurationSet configs = ToConfigurations(q, robot.num_links(), "q");
  CheckJointRanges(configs, robot, "q");
  if (socket_of.is_none())
    throw InputError("socket_of", "give each row's socket id (N whole numbers ≥ 0)");
  std::vector<int> ids;
  for (double v : ToVector(socket_of.cast<Array>(), "socket_of")) {
    if (!(v >= 0 && v <= 1e9 && v == std::floor(v)))
      throw InputError("socket_of", "expected whole numbers from 0 to 1000000000");
    ids.push_back(static_cast<int>(v));
  }
  std::vector<int> counts(static_cast<std::size_t>(configs.size()), 1);
  if (!repetitions.is_none()) counts = repetitions.cast<std::vector<int>>();
  return MakeSocketData(configs, ids, counts, "socket_of/repetitions");
}

// socket_distances=[(a, b, metres), ...] or None.
std::vector<SocketDistance> ToSocketDistances(const py::object& distances) {
  std::vector<SocketDistance> out;
  if (distances.is_none()) return out;
  int k = 0;
  for (const py::handle item : distances) {
    const auto t = py::reinterpret_borrow<py::object>(item).cast<std::tuple<int, int, double>>();
    const std::string text = std::to_string(std::get<0>(t)) + "," + std::to_string(std::get<1>(t)) +
                             "=" + FormatExact(std::get<2>(t));
    out.push_back(SocketDistance::Parse(text, "socket_distances[" + std::to_string(k++) + "]"));
  }
  return out;
}

Eigen::Vector3d ToToolPoint(const py::object& tool_point) {
  if (tool_point.is_none()) return Eigen::Vector3d::Zero();
  const RigidTransform t = ToXyzRpy(tool_point, "tool_point", true);
  if (!t.rotation.isIdentity(0)) throw InputError("tool_point", "expected (x, y, z) in m");
  return t.translation;
}

// The socket kind for `data`, as identify --sensor socket builds it.
std::unique_ptr<SocketMeasurement> ToSocketKind(const RobotModel& robot, const SocketData& data,
                                                const py::object& tool_point,
                                                const py::object& distances,
                                                const py::object& fix) {
  return std::make_unique<SocketMeasurement>(
      robot,
      SocketSetupFromData(robot, data.ids, data.values.configs, ToToolPoint(tool_point),
                          ToSocketDistances(distances), "socket_distances"),
      ToNames(fix), "fix");
}

// Contacts from Python: q (N, joints) on planes (plane_of: from 1, as for the ranger), the kind
// as identify --sensor contact builds it.
struct ContactArgs {
  py::object plane, plane_of, tool_point, fix;
  std::string estimate_plane;
  bool flush;
};

std::unique_ptr<ContactMeasurement> ToContactKind(const RobotModel& robot, const PlaneSet& planes,
                                                  const ContactArgs& a) {
  ContactSetup setup;
  setup.planes = planes;
  setup.tool_point = ToToolPoint(a.tool_point);
  setup.flush = a.flush;
  setup.plane_terms.assign(static_cast<std::size_t>(planes.size()),
                           PlaneTerms::Parse(a.estimate_plane, "estimate_plane"));
  return std::make_unique<ContactMeasurement>(robot, setup, ToNames(a.fix), "fix");
}

TargetedConfigurations ToContactConfigurations(const RobotModel& robot, const Array& q,
                                               const py::object& plane_of, int num_planes) {
  TargetedConfigurations configs =
      WithPlanes(ToConfigurations(q, robot.num_links(), "q"), plane_of, num_planes);
  CheckJointRanges(configs, robot, "q");
  return configs;
}

// A line scanner from Python (scanner_measurement.h): beams= and fan_deg= (the fan), scanner=
// (its frame in the tool frame, x, y, z, roll, pitch, yaw; None: the tool frame), the ranger's
// plane arguments, as --sensor scanner builds it (the robot file's ranger limits).
struct ScannerArgs {
  py::object plane, plane_of, scanner, fix;
  std::string estimate_plane;
  long long beams;
  double fan_deg;
};

std::unique_ptr<ScannerMeasurement> ToScannerKind(const RobotFile& rig, const RobotModel& robot,
                                                  const PlaneSet& planes, const ScannerArgs& a) {
  ScannerSetup setup;
  setup.planes = planes;
  setup.range = rig.ranger;
  if (!a.scanner.is_none()) {
    const RigidTransform frame = ToXyzRpy(a.scanner, "scanner", false);
    setup.origin = frame.translation;
    setup.orientation = frame.rotation;
  }
  setup.beam_angles = ScannerSetup::FanOf(a.beams, a.fan_deg, "beams", "fan_deg");
  setup.plane_terms.assign(static_cast<std::size_t>(planes.size()),
                           PlaneTerms::Parse(a.estimate_plane, "estimate_plane"));
  return std::make_unique<ScannerMeasurement>(robot, setup, ToNames(a.fix), "fix");
}

// The rank analysis of `kind` at `configs` with the given rank tolerance, the GIL released.
IdentifiabilityReport AnalyzeKindPy(const MeasurementKind& kind,
                                    const TargetedConfigurations& configs, double rank_tolerance) {
  IdentifiabilityOptions options;
  options.rank_tolerance = rank_tolerance;
  options.Validate();
  py::gil_scoped_release release;
  return AnalyzeIdentifiability(kind, configs, nullptr, options);
}

// identifiability(sensor='contact' or 'scanner'): the kinds that see the ranger's planes (a's
// plane, plane_of, estimate_plane and fix; a contact's tool point and flush).
IdentifiabilityReport PlaneKindIdentifiabilityPy(const RobotFile& rig, const Array& q,
                                                 const std::string& sensor,
                                                 const py::object& tool_point, bool flush,
                                                 const ScannerArgs& a, double rank_tolerance) {
  const PlaneSet planes = ResolvePlanes(rig, a.plane);
  const TargetedConfigurations configs =
      ToContactConfigurations(rig.robot, q, a.plane_of, planes.size());
  if (sensor == "contact")
    return AnalyzeKindPy(
        *ToContactKind(rig.robot, planes,
                       {a.plane, a.plane_of, tool_point, a.fix, a.estimate_plane, flush}),
        configs, rank_tolerance);
  return AnalyzeKindPy(*ToScannerKind(rig, rig.robot, planes, a), configs, rank_tolerance);
}

// identifiability(): the arguments of a sensor other than `sensor`, refused by name (contact and
// scanner arguments first; the sockets' when the sensor is the ranger or a tracker).
void RefuseOtherSensorsArguments(const std::string& sensor, const SocketArgs& sockets, bool flush,
                                 const ScannerArgs& scanner) {
  if (sensor != "contact" && flush)
    throw InputError("flush", "is the contact sensor's: give sensor='contact'");
  if (sensor != "scanner" &&
      !(scanner.scanner.is_none() && scanner.beams == 1 && scanner.fan_deg == 0))
    throw InputError(!scanner.scanner.is_none() ? "scanner"
                     : scanner.beams != 1       ? "beams"
                                                : "fan_deg",
                     "is the scanner sensor's: give sensor='scanner'");
  if (sensor == "socket" || sensor == "contact" || sensor == "scanner") return;
  if (!(sockets.socket_of.is_none() && sockets.distances.is_none() && sockets.tool_point.is_none()))
    throw InputError(!sockets.socket_of.is_none()   ? "socket_of"
                     : !sockets.distances.is_none() ? "socket_distances"
                                                    : "tool_point",
                     sockets.socket_of.is_none() && sockets.distances.is_none()
                         ? "is a constraint sensor's: give sensor='socket' or sensor='contact'"
                         : "is the socket sensor's: give sensor='socket'");
}

IdentifiabilityReport IdentifiabilityPy(
    const RobotFile& rig, const Array& q, const py::object& plane_arg,
    const std::string& estimate_plane, const py::object& fix, double rank_tolerance,
    const py::object& plane_of, const std::string& estimate_ranger,
    const std::string& estimate_base, const std::string& estimate_tool, const std::string& sensor,
    const py::object& instrument, const py::object& targets, const py::object& target_of,
    const SocketArgs& sockets, bool flush, const ScannerArgs& scanner) {
  RefuseOtherSensorsArguments(sensor, sockets, flush, scanner);
  if (sensor == "contact" || sensor == "scanner") {
    RefuseRangerArguments(sensor,
                          {{"estimate_ranger", estimate_ranger != "none"},
                           {"estimate_base", estimate_base != "none"},
                           {"estimate_tool", estimate_tool != "none"},
                           {"instrument", !instrument.is_none()},
                           {"targets", !targets.is_none()},
                           {"target_of", !target_of.is_none()},
                           {"socket_of", !sockets.socket_of.is_none()},
                           {"socket_distances", !sockets.distances.is_none()},
                           {"tool_point", sensor == "scanner" && !sockets.tool_point.is_none()}});
    ScannerArgs a = scanner;
    a.plane = plane_arg;
    a.plane_of = plane_of;
    a.fix = fix;
    a.estimate_plane = estimate_plane;
    return PlaneKindIdentifiabilityPy(rig, q, sensor, sockets.tool_point, flush, a, rank_tolerance);
  }
  if (sensor == "socket") {
    RefuseRangerArguments(sensor, {{"plane", !plane_arg.is_none()},
                                   {"plane_of", !plane_of.is_none()},
                                   {"estimate_plane", estimate_plane != "none"},
                                   {"estimate_ranger", estimate_ranger != "none"},
                                   {"estimate_base", estimate_base != "none"},
                                   {"estimate_tool", estimate_tool != "none"},
                                   {"instrument", !instrument.is_none()},
                                   {"targets", !targets.is_none()},
                                   {"target_of", !target_of.is_none()}});
    const SocketData data = ToSocketData(rig.robot, q, sockets.socket_of, py::none());
    const std::unique_ptr<SocketMeasurement> kind =
        ToSocketKind(rig.robot, data, sockets.tool_point, sockets.distances, fix);
    IdentifiabilityOptions options;
    options.rank_tolerance = rank_tolerance;
    options.Validate();
    py::gil_scoped_release release;
    return AnalyzeIdentifiability(*kind, data.values.configs, nullptr, options);
  }
  if (sensor != "ranger") {
    RefuseRangerArguments(sensor, {{"plane", !plane_arg.is_none()},
                                   {"plane_of", !plane_of.is_none()},
                                   {"estimate_plane", estimate_plane != "none"},
                                   {"estimate_ranger", estimate_ranger != "none"},
                                   {"estimate_base", estimate_base != "none"},
                                   {"estimate_tool", estimate_tool != "none"}});
    return TrackerIdentifiabilityPy(rig, q, sensor, instrument, targets, target_of, fix,
                                    rank_tolerance);
  }
  if (!instrument.is_none() || !targets.is_none() || !target_of.is_none())
    throw InputError(!instrument.is_none() ? "instrument"
                     : !targets.is_none()  ? "targets"
                                           : "target_of",
                     "is a tracker's: give sensor='point' or sensor='pose'");
  const ConfigsAndModel set =
      ResolveConfigsAndModel(rig, q, plane_arg, plane_of, estimate_plane,
                             {estimate_ranger, estimate_base, estimate_tool}, fix);
  const TargetedConfigurations& configs = set.configs;
  const MeasurementModel& model = *set.model;
  IdentifiabilityOptions options;
  options.rank_tolerance = rank_tolerance;
  options.Validate();
  py::gil_scoped_release release;
  return AnalyzeIdentifiability(model, configs, nullptr, options);
}

PriorInformation PriorInformationPy(const RobotFile& rig, const Array& q,
                                    const std::string& prior_sigma, bool prior, double sigma_mm,
                                    long long repetitions, const py::object& plane_arg,
                                    const std::string& estimate_plane, const py::object& fix,
                                    const py::object& plane_of,
                                    const std::string& estimate_ranger) {
  const ConfigsAndModel set =
      ResolveConfigsAndModel(rig, q, plane_arg, plane_of, estimate_plane, estimate_ranger, fix);
  const TargetedConfigurations& configs = set.configs;
  const MeasurementModel& model = *set.model;
  const PriorSigmas priors = PriorsFor(rig, prior, prior_sigma, "prior=", "prior_sigma=");
  if (priors.empty())
    throw InputError("prior_sigma=",
                     "give priors (prior_sigma=, or prior=True for the robot "
                     "file's tolerances:)");
  NoiseModel noise;
  const auto& fields = NoiseModel::Settings();
  const auto& sigma = *FindSetting(fields, "sigma_mm");
  const auto& count = *FindSetting(fields, "repetitions");
  noise.sigma = SettingValue(sigma.spec, sigma.Default(), sigma_mm, py::none(), "sigma");
  noise.repetitions = static_cast<int>(SettingValue(
      count.spec, count.Default(), static_cast<double>(repetitions), py::none(), "repetitions"));
  py::gil_scoped_release release;
  return InformationFromPriors(RangerMeasurement(model), configs, noise, priors);
}

struct DesignArgs {
  std::string criterion, method, scaling;
  py::object expected_angle, expected_length;  // the earlier spellings, rad and m (None: not given)
  int restarts, samples;
  long long seed;
  py::object poses;  // criterion I: the task poses (M, joints); None: `workspace` poses
  int workspace, baseline;
  double expected_angle_mrad, expected_length_mm;
  py::object plane_of = py::none();      // with several planes, each candidate's plane (from 1)
  std::string estimate_ranger = "none";  // as --estimate-ranger
  std::string sensor = "ranger";         // or point, pose, scanner, contact, socket (as --sensor)
  py::object instrument = py::none(), targets = py::none();
  // scanner: the fan and its frame; contact, socket: the tool point (flush contacts); socket:
  // each candidate's socket id and the known distances.
  long long beams = 1;
  double fan_deg = 0;
  py::object scanner = py::none(), tool_point = py::none();
  bool flush = false;
  py::object socket_of = py::none(), socket_distances = py::none();
};

DesignRequest ToDesignRequest(const DesignArgs& a, const MeasurementModel& model, int k) {
  DesignRequest request;
  request.count = k;
  request.seed = ToSeed(a.seed);
  request.workspace = a.workspace;  // its range: WorkspacePoses' check, in Python's words
  if (a.criterion == "I") {
    request.task =
        a.poses.is_none()
            ? TaskPosesAt(model, WorkspacePoses(model.robot(), request.workspace, request.seed),
                          "workspace")
            : TaskPosesAt(
                  model,
                  ToConfigurations(a.poses.cast<Array>(), model.robot().num_links(), "poses"),
                  "given");
  } else {
    request.selection.criterion = ParseDesignCriterion(a.criterion, "criterion");
  }
  request.selection.method = ParseSelectionMethod(a.method, "method");
  request.selection.restarts = a.restarts;
  request.selection.samples = a.samples;
  request.selection.Validate();
  request.scaling = ParseDesignScaling(a.scaling, "scaling");
  const auto& fields = DesignRequest::Settings();
  const auto& angle = *FindSetting(fields, "expected_angle_mrad");
  const auto& length = *FindSetting(fields, "expected_length_mm");
  request.expected_angle = SettingValue(angle.spec, angle.Default(), a.expected_angle_mrad,
                                        a.expected_angle, "expected_angle");
  request.expected_length = SettingValue(length.spec, length.Default(), a.expected_length_mm,
                                         a.expected_length, "expected_length");
  request.baseline = a.baseline;  // checked by Validate() (a SettingError in Python's words)
  return request;
}

// The kind of a design other than the ranger's and its usable candidates: a tracker sees the
// whole pool; a scanner's candidates keep every beam on its plane; contacts and sockets are
// seated on the nominal arm (within the joint ranges). `kept`: the pool rows used; rows left out
// go to `rejected` with their reason.
struct KindCandidates {
  std::unique_ptr<MeasurementKind> kind;
  TargetedConfigurations configs;
  std::vector<int> kept;
};

KindCandidates KindCandidatesPy(const RobotFile& rig, const Array& pool_q,
                                const py::object& plane_arg, const std::string& estimate_plane,
                                const py::object& fix, const DesignArgs& a,
                                std::vector<std::pair<int, std::string>>* rejected) {
  const RobotModel& robot = rig.robot;
  KindCandidates out;
  TargetedConfigurations drawn;
  std::vector<std::string> reasons;
  if (a.sensor == "scanner" || a.sensor == "contact") {
    const PlaneSet planes = ResolvePlanes(rig, plane_arg);
    drawn = ToContactConfigurations(robot, pool_q, a.plane_of, planes.size());
    if (a.sensor == "scanner") {
      out.kind = ToScannerKind(
          rig, robot, planes,
          {plane_arg, a.plane_of, a.scanner, fix, estimate_plane, a.beams, a.fan_deg});
      drawn = MeasurableConfigurations(*out.kind, drawn, nullptr, &reasons);
    } else {
      out.kind = ToContactKind(robot, planes,
                               {plane_arg, a.plane_of, a.tool_point, fix, estimate_plane, a.flush});
      drawn = SeatedConfigurations(robot, *out.kind, drawn, nullptr, &reasons);
    }
  } else if (a.sensor == "socket") {
    const SocketData data = ToSocketData(robot, pool_q, a.socket_of, py::none());
    out.kind = ToSocketKind(robot, data, a.tool_point, a.socket_distances, fix);
    drawn = SeatedConfigurations(robot, *out.kind, data.values.configs, nullptr, &reasons);
  } else {
    out.kind = ToTrackerKind(robot, a.sensor, a.instrument, a.targets, fix);
    out.configs = TargetedConfigurations(ToConfigurations(pool_q, robot.num_links(), "pool"));
    for (int i = 0; i < out.configs.size(); ++i) out.kept.push_back(i);
    return out;
  }
  // drawn holds the kept rows; reasons says which rows of the pool they are.
  for (int i = 0; i < static_cast<int>(reasons.size()); ++i)
    if (reasons[static_cast<std::size_t>(i)] == "ok") out.kept.push_back(i);
  out.configs = std::move(drawn);
  for (int i = 0; i < static_cast<int>(reasons.size()); ++i)
    if (reasons[static_cast<std::size_t>(i)] != "ok")
      rejected->emplace_back(i, reasons[static_cast<std::size_t>(i)]);
  if (out.configs.size() == 0)
    throw InputError("pool", "no usable candidate configurations (none where sensor='" + a.sensor +
                                 "' measures)");
  return out;
}

// A design of a sensor other than the ranger: blocks of its values from the candidates where it
// measures, the terms the pool cannot separate held at nominal, as `lrcal design --sensor`.
Design KindDesignPy(const RobotFile& rig, const Array& pool_q, int k, const py::object& plane_arg,
                    const std::string& estimate_plane, const py::object& fix, const DesignArgs& a) {
  const RobotModel& robot = rig.robot;
  const bool planar = a.sensor == "scanner" || a.sensor == "contact";
  for (const auto& [name, value] :
       {std::pair<const char*, const std::string*>{"estimate_plane", &estimate_plane},
        {"estimate_ranger", &a.estimate_ranger}})
    if (*value != "none" && (!planar || std::string(name) == "estimate_ranger"))
      throw InputError(name, "is the ranger's; sensor='" + a.sensor + "' does not take it");
  Design out;
  out.sensor = a.sensor;
  const KindCandidates candidates =
      KindCandidatesPy(rig, pool_q, plane_arg, estimate_plane, fix, a, &out.rejected);
  const MeasurementModel arm(robot, rig.planes ? *rig.planes : PlaneSet(Plane{}),
                             MakeParameterSet(robot, PlaneTerms{}));
  const DesignRequest request = ToDesignRequest(a, arm, k);
  {
    py::gil_scoped_release release;
    out.held = AnalyzeIdentifiability(*candidates.kind, candidates.configs).suggested_fixed;
    out.choice = ChooseDesign(*candidates.kind->Without(out.held), candidates.configs, request);
  }
  for (int i : out.choice.chosen.indices)
    out.indices.push_back(candidates.kept[static_cast<std::size_t>(i)]);
  out.criterion = request.CriterionName();
  out.method = SelectionMethodName(request.selection.method);
  out.scaling = DesignScalingName(request.scaling);
  out.json = DesignChoiceJson(request, out.choice).dump();
  return out;
}

// The arguments of the sensors that `sensor` is not, refused by name.
void RefuseOtherSensorsDesignArgs(const DesignArgs& a) {
  const auto refuse = [&](const char* name, bool given, const char* whose) {
    if (given)
      throw InputError(name,
                       std::string("is ") + whose + "; sensor='" + a.sensor + "' does not take it");
  };
  const std::string& s = a.sensor;
  const bool tracker = s == "point" || s == "pose";
  refuse("instrument", !tracker && !a.instrument.is_none(), "a tracker's");
  refuse("targets", !tracker && !a.targets.is_none(), "a tracker's");
  refuse("beams", s != "scanner" && a.beams != 1, "the scanner sensor's");
  refuse("fan_deg", s != "scanner" && a.fan_deg != 0, "the scanner sensor's");
  refuse("scanner", s != "scanner" && !a.scanner.is_none(), "the scanner sensor's");
  refuse("tool_point", s != "contact" && s != "socket" && !a.tool_point.is_none(),
         "a contact's or a socket's");
  refuse("flush", s != "contact" && a.flush, "the contact sensor's");
  refuse("socket_of", s != "socket" && !a.socket_of.is_none(), "the socket sensor's");
  refuse("socket_distances", s != "socket" && !a.socket_distances.is_none(), "the socket sensor's");
  refuse("plane_of", (tracker || s == "socket") && !a.plane_of.is_none(),
         "the ranger's, a scanner's or a contact's");
}

Design DesignPy(const RobotFile& rig, const Array& pool_q, int k, const py::object& plane_arg,
                const std::string& estimate_plane, const py::object& fix, const DesignArgs& a) {
  if (!IsMeasurementKindName(a.sensor))
    throw InputError("sensor", "'" + a.sensor + "' is not a sensor lrcal models: expected " +
                                   MeasurementKindNameList());
  RefuseOtherSensorsDesignArgs(a);
  if (a.sensor != "ranger") return KindDesignPy(rig, pool_q, k, plane_arg, estimate_plane, fix, a);
  const RobotModel& robot = rig.robot;
  const PlaneSet planes = ResolvePlanes(rig, plane_arg);
  const MeasurementModel model(
      robot, planes,
      ResolveParameters(robot, planes.size(), estimate_plane, a.estimate_ranger, fix));
  const DesignRequest request = ToDesignRequest(a, model, k);
  const CandidatePool pool = UsableCandidates(
      robot, planes, rig.ranger,
      WithPlanes(ToConfigurations(pool_q, robot.num_links(), "pool"), a.plane_of, planes.size()));
  if (pool.configs.size() == 0)
    throw InputError("pool", "no usable candidate configurations (every beam misses the plane)");
  Design out;
  for (std::size_t i = 0; i < pool.misses.size(); ++i)
    if (pool.misses[i] != BeamMiss::kNone)
      out.rejected.emplace_back(static_cast<int>(i), BeamMissName(pool.misses[i]));
  {
    py::gil_scoped_release release;
    out.choice = ChooseDesign(model, pool.configs, request);
  }
  for (int i : out.choice.chosen.indices)
    out.indices.push_back(pool.kept[static_cast<std::size_t>(i)]);
  out.criterion = request.CriterionName();
  out.method = SelectionMethodName(request.selection.method);
  out.scaling = DesignScalingName(request.scaling);
  out.json = DesignChoiceJson(request, out.choice).dump();
  return out;
}

// Runs a study; progress(p) is called about every 0.1 s with a RunProgress. Ctrl-C (or an
// exception in `progress`) stops the run as the command line's first Ctrl-C does: the trials
// done are committed, the session is closed as interrupted, and the exception is raised.
RunResult RunStudyPy(const std::string& study_arg, const std::string& out_dir, int threads,
                     const py::object& progress, const std::optional<std::string>& shard,
                     long long max_trials) {
  const Study study = LoadStudy(ResolveStudyPath(study_arg));
  RunOptions options;
  options.out_dir = out_dir;
  options.threads = threads;
  if (shard) ParseShard(*shard, &options.shard_index, &options.shard_count);
  options.max_new_trials = max_trials;
  options.progress = false;
  options.Validate();
  StopToken stop;
  std::exception_ptr raised;  // a KeyboardInterrupt or the callback's exception
  options.on_progress = [&](const RunProgress& p) {
    py::gil_scoped_acquire gil;
    if (raised) return;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!progress.is_none()) progress(p);
    } catch (...) {
      raised = std::current_exception();
      stop.RequestStop();
    }
  };
  RunResult result;
  {
    py::gil_scoped_release release;
    result = RunStudyAndWriteTables(study, options, nullptr, &stop);
  }
  if (raised) std::rethrow_exception(raised);
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  return result;
}

// --- definitions ----------------------------------------------------------------------------

// Python's shortest round-trip form of a number (for repr).
std::string Num(double v) { return py::repr(py::float_(v)).cast<std::string>(); }

std::string PlaneRepr(const Plane& p) {
  return "lrcal.Plane(normal=(" + Num(p.normal.x()) + ", " + Num(p.normal.y()) + ", " +
         Num(p.normal.z()) + "), offset=" + Num(p.offset) + ")";
}

void DefineRig(py::module_& m) {
  py::class_<Plane>(m, "Plane", R"doc(
A plane n·p + f = 0 in the robot's base frame: unit normal n, offset f (m).

Plane(normal, offset): the normal is normalised (and f with it), as in robot files.
Plane.parse("nx,ny,nz,f") reads the command line's --plane form.)doc")
      .def(py::init([](const std::vector<double>& normal, double offset) {
             if (normal.size() != 3)
               throw InputError("normal", "expected three numbers (nx, ny, nz)");
             return Plane::FromCoefficients(normal[0], normal[1], normal[2], offset, "plane");
           }),
           py::arg("normal"), py::arg("offset"))
      .def_static(
          "parse", [](const std::string& text) { return Plane::Parse(text, "plane"); },
          py::arg("text"), "A plane from 'nx,ny,nz,f' (the --plane form).")
      .def_property_readonly(
          "normal", [](const Plane& p) { return Eigen::Vector3d(p.normal); },
          "Unit normal (3,), base frame.")
      .def_readonly("offset", &Plane::offset, "f (m): the plane is n·p + f = 0.")
      .def("signed_distance", &Plane::SignedDistance, py::arg("point"),
           "n·p + f (m) of a point p (3,) in the base frame.")
      .def("__repr__", &PlaneRepr);

  py::class_<RangerSpec>(m, "Ranger", "The laser ranger's limits (the robot file's ranger:).")
      .def_readonly("min_range", &RangerSpec::min_range, "m; shorter readings are rejected")
      .def_readonly("max_range", &RangerSpec::max_range, "m; longer readings are out of range")
      .def_readonly("max_incidence", &RangerSpec::max_incidence,
                    "rad; largest angle between the beam and the plane normal")
      .def("__repr__", [](const RangerSpec& r) {
        return "lrcal.Ranger(min_range=" + Num(r.min_range) + ", max_range=" + Num(r.max_range) +
               ", max_incidence=" + Num(r.max_incidence) + ")";
      });
}

void DefineRobot(py::module_& m) {
  py::class_<RobotFile>(m, "Robot", R"doc(
A robot file: the arm (D-H links with the twist β, nominal values, simulated true errors, joint
limits), its measurement plane if the file gives one, and the ranger's limits.

Load one with Robot.load(path_or_name): a YAML robot file, a URDF (with tool_link the ranger's
link), or a shipped name ("paper").
Link values are ordered theta, alpha, a, d, beta per link (SI: rad and m).)doc")
      .def_static("load", &LoadRobot, py::arg("path"), py::arg("tool_link") = "",
                  py::arg("base_link") = "", R"doc(
Loads a robot file (YAML) or a URDF (path ending in .urdf; tool_link: the link whose frame is
the ranger's, default the URDF's only end link other than base_link; base_link: the chain's
first link, its frame the base frame, default the root — the path may run up the tree, a
joint passed from child to parent keeping its name and value) by path, or a shipped robot by
name ("paper").
Raises lrcal.InputError naming the file, line and key of anything wrong.)doc")
      .def_property_readonly("name", [](const RobotFile& r) { return r.robot.name(); })
      .def_readonly("path", &RobotFile::path, "Where the file was read from.")
      .def_property_readonly(
          "num_joints", [](const RobotFile& r) { return r.robot.num_links(); },
          "Number of joints (one link each).")
      .def_property_readonly(
          "value_names",
          [](const RobotFile& r) {
            std::vector<std::string> names;
            for (int k = 0; k < r.robot.num_values(); ++k) names.push_back(r.robot.ValueName(k));
            return names;
          },
          "Names of the 5N link values (theta1, alpha1, a1, d1, beta1, theta2, ...).")
      .def_property_readonly(
          "parameter_names",
          [](const RobotFile& r) { return MakeParameterSet(r.robot, PlaneTerms{}).names; },
          "The identifiable link parameters the file declares (identify's default set).")
      .def_property_readonly(
          "nominal_values", [](const RobotFile& r) { return r.robot.nominal_values(); },
          "Nominal link values (5N,), SI.")
      .def_property_readonly(
          "true_errors", [](const RobotFile& r) { return r.truth.LinkErrors(r.robot); },
          "Simulated true errors of the link values (5N,), SI.")
      .def_property_readonly(
          "true_values", [](const RobotFile& r) { return r.truth.LinkValues(r.robot); },
          "nominal_values + true_errors (5N,), SI.")
      .def_property_readonly(
          "joint_limits",
          [](const RobotFile& r) {
            Eigen::MatrixXd limits(r.robot.num_links(), 2);
            for (int i = 0; i < r.robot.num_links(); ++i)
              limits.row(i) << r.robot.links()[i].q_min, r.robot.links()[i].q_max;
            return limits;
          },
          "(N, 2) joint limits q_min, q_max (rad).")
      .def_property_readonly(
          "plane",
          [](const RobotFile& r) -> std::optional<Plane> {
            if (r.planes && r.planes->size() == 1) return (*r.planes)[0];
            return std::nullopt;
          },
          "The file's plane, or None (no plane, or several: see planes).")
      .def_property_readonly(
          "planes",
          [](const RobotFile& r) {
            std::vector<Plane> out;
            if (r.planes) out.assign(r.planes->begin(), r.planes->end());
            return out;
          },
          "The file's planes (a list, empty if it gives none).")
      .def_readonly("ranger", &RobotFile::ranger, "The ranger's limits.")
      .def("__repr__", [](const RobotFile& r) {
        return "lrcal.Robot('" + r.robot.name() + "', " + std::to_string(r.robot.num_links()) +
               " joints, from '" + r.path + "')";
      });
}

void DefinePriorInformation(py::module_& m) {
  py::class_<PriorInformation>(m, "PriorInformation", R"doc(
What readings tell against priors (lrcal.prior_information). Arrays are SI; index k belongs to
names[k]. str() gives the table of `lrcal identifiability --prior-sigma`.)doc")
      .def_readonly("names", &PriorInformation::names)
      .def_readonly("sigma", &PriorInformation::sigma)
      .def_readonly("prior_sigma", &PriorInformation::prior_sigma)
      .def_readonly("posterior_sigma", &PriorInformation::posterior_sigma)
      .def_readonly("posterior_to_prior", &PriorInformation::posterior_to_prior)
      .def_readonly("defined", &PriorInformation::defined)
      .def_property_readonly("set_by_prior", &PriorInformation::SetByPrior)
      .def("__str__", &PriorInformation::ToString);
}

void DefineResults(py::module_& m) {
  py::class_<Readings>(m, "Readings", R"doc(
Simulated single readings, one row per reading (as a measurement CSV holds them):
q (M, joints) rad, h (M,) m, configuration (M,) the 0-based row of the q given,
skipped: [(row, why)] for configurations whose beam missed (no reading); with several planes
plane_of (M,) the plane each reading is of, from 1 (a measurement CSV's plane column), else None.)doc")
      .def_readonly("q", &Readings::q)
      .def_readonly("h", &Readings::h)
      .def_readonly("configuration", &Readings::configuration)
      .def_readonly("skipped", &Readings::skipped)
      .def_readonly("plane_of", &Readings::plane_of);

  py::class_<Dependency>(m, "Dependency",
                         "Moving the parameters along these SI coefficients leaves every reading "
                         "unchanged to first order.")
      .def_readonly("terms", &Dependency::terms, "[(name, coefficient)]; the first has 1.")
      .def("__str__", &Dependency::ToString)
      .def("__repr__", &Dependency::ToString);

  py::class_<IdentifiabilityReport>(m, "Identifiability", R"doc(
What a set of configurations can identify: rank of the identification Jacobian G, singular values
of its unit-norm columns, the parameters with no effect (unidentifiable), the exact dependences,
and the parameters to fix for a full-rank set (suggested_fixed). str() gives the report.)doc")
      .def_readonly("names", &IdentifiabilityReport::names)
      .def_readonly("num_configurations", &IdentifiabilityReport::num_configurations)
      .def_readonly("rank", &IdentifiabilityReport::rank)
      .def_readonly("column_norms", &IdentifiabilityReport::column_norms)
      .def_readonly("singular_values", &IdentifiabilityReport::singular_values)
      .def_readonly("condition_number", &IdentifiabilityReport::condition_number)
      .def_readonly("unidentifiable", &IdentifiabilityReport::unidentifiable)
      .def_readonly("dependencies", &IdentifiabilityReport::dependencies)
      .def_readonly("suggested_fixed", &IdentifiabilityReport::suggested_fixed)
      .def_readonly("explanations", &IdentifiabilityReport::explanations)
      .def_property_readonly("full_rank", &IdentifiabilityReport::full_rank)
      .def("__str__", &IdentifiabilityReport::ToString);

  py::class_<Design>(m, "Design", R"doc(
A chosen design: indices (rows of the pool given, ascending), the criterion's score of the chosen
set, the candidate evaluations spent, and the pool rows rejected because their beam misses.)doc")
      .def_readonly("indices", &Design::indices)
      .def_readonly("sensor", &Design::sensor)
      .def_readonly("held_at_nominal", &Design::held)
      .def_property_readonly("score", [](const Design& d) { return d.choice.chosen.score; })
      .def_property_readonly("evaluations",
                             [](const Design& d) { return d.choice.chosen.evaluations; })
      .def_property_readonly("seconds", [](const Design& d) { return d.choice.seconds; })
      .def_property_readonly("certificate",
                             [](const Design& d) { return d.choice.certificate_statement; })
      .def_property_readonly("efficiency",
                             [](const Design& d) -> py::object {
                               if (!d.choice.certificate.available) return py::none();
                               return py::float_(d.choice.certificate.efficiency);
                             })
      .def_property_readonly("task_rms_per_sigma",
                             [](const Design& d) -> py::object {
                               if (!d.choice.task_rms_per_sigma) return py::none();
                               return py::float_(*d.choice.task_rms_per_sigma);
                             })
      .def_property_readonly(
          "baseline",
          [](const Design& d) {
            py::list rows;
            for (const BaselineIndex& b : d.choice.baseline)
              rows.append(
                  py::dict(py::arg("criterion") = DesignCriterionName(b.criterion),
                           py::arg("chosen") = b.chosen, py::arg("random_mean") = b.random.mean,
                           py::arg("random_p5") = b.random.p5, py::arg("random_p95") = b.random.p95,
                           py::arg("percentile") = b.percentile));
            return rows;
          })
      .def_readonly("json", &Design::json)
      .def_readonly("criterion", &Design::criterion)
      .def_readonly("method", &Design::method)
      .def_readonly("scaling", &Design::scaling)
      .def_readonly("rejected", &Design::rejected)
      .def("__repr__", [](const Design& d) {
        return "lrcal.Design(" + std::to_string(d.indices.size()) + " configurations, " +
               d.criterion + " = " + Num(d.choice.chosen.score) + ")";
      });
}

// Identification.linearisation: the check as identify's JSON has it; None when not computed.
py::object LinearisationDict(const IdentificationSummary& s) {
  const LinearisationCheck& c = s.linearisation;
  if (c.num_parameters == 0) return py::none();
  py::dict d;
  d["computed"] = c.computed;
  d["excess"] = c.excess;
  d["relative_excess"] = c.RelativeExcess();
  d["holds"] = c.Holds();
  d["pairs"] = c.pairs;
  d["message"] = c.message;
  if (c.computed) {
    py::dict direction;
    for (std::size_t k = 0; k < s.names.size(); ++k)
      direction[py::str(s.names[k])] = c.worst_direction[static_cast<Eigen::Index>(k)];
    d["worst_direction"] = direction;
    d["worst_direction_sigma"] = c.worst_direction_sigma;
  }
  return d;
}

void DefineIdentification(py::module_& m) {
  using S = IdentificationSummary;
  py::class_<S>(m, "Identification", py::dynamic_attr(), R"doc(
The result of lrcal.identify. Arrays are SI (m, rad); index k belongs to names[k].
  names, nominal, estimate (= nominal + delta), delta
  std, covariance, correlation: from the residuals (σ̂²·(GᵀWG)⁻¹)
  std_given, covariance_given: with the σ given (empty unless sigma > 0)
  sigma_hat (m), residual_rms (m), initial_cost, final_cost (½Σr², m²), iterations,
  num_configurations, termination ('converged', 'max_iterations', 'rank_deficient',
  'beam_missed', 'numerical_failure', 'invalid_input'), usable, message, fixed (parameters fixed
  for rank), identifiability, solver, loss (in words: 'least squares', 'huber loss, scale 0.3 mm
  (1.5 σ)'); with priors prior_sigma (SI, 0 where none),
  posterior_to_prior (NaN where no prior) and set_by_prior (posterior/prior above 0.9).
holdout and accuracy: what identify(holdout=K) and identify(predict_at=poses) add, as dicts with
the keys of `lrcal identify --holdout K --predict-at F --format json` (None when not asked for).
str() gives the full text report; repr() the one-line summary.)doc")
      .def_readonly("names", &S::names)
      .def_readonly("nominal", &S::nominal)
      .def_readonly("estimate", &S::estimate)
      .def_readonly("delta", &S::delta)
      .def_readonly("std", &S::std_residual)
      .def_readonly("std_given", &S::std_given)
      .def_readonly("covariance", &S::covariance_residual)
      .def_readonly("covariance_given", &S::covariance_given)
      .def_readonly("correlation", &S::correlation)
      .def_readonly("sigma_hat", &S::sigma_hat)
      .def_readonly("initial_cost", &S::initial_cost)
      .def_readonly("final_cost", &S::final_cost)
      .def_readonly("residual_rms", &S::residual_rms)
      .def_readonly("iterations", &S::iterations)
      .def_readonly("num_configurations", &S::num_configurations)
      .def_property_readonly("termination",
                             [](const S& s) { return std::string(TerminationName(s.termination)); })
      .def_property_readonly("usable", &S::IsSolutionUsable)
      .def_readonly("message", &S::message)
      .def_readonly("fixed", &S::fixed)
      .def_readonly("identifiability", &S::identifiability)
      .def_readonly("solver", &S::solver)
      .def_readonly("loss", &S::loss)
      .def_readonly("prior_sigma", &S::prior_sigma)
      .def_readonly("posterior_to_prior", &S::posterior_to_prior)
      .def_property_readonly("set_by_prior", &S::SetByPrior)
      .def_property_readonly(
          "fit",
          [](const S& s) {
            py::dict d;
            d["sigma_given"] = s.fit.sigma_given;
            d["chi2"] = s.fit.chi2;
            d["dof"] = s.fit.dof;
            d["p_value"] = s.fit.p_value;
            d["consistent"] = s.fit.consistent;
            d["standardized"] = s.fit.standardized;
            d["suspects"] = s.fit.suspects;
            d["test"] = s.fit.TestName();
            if (s.fit.robust) {
              d["robust_scale"] = s.fit.robust_scale;
              d["robust_p_value"] = s.fit.robust_p_value;
            }
            if (!s.fit.configuration_labels.empty()) d["suspect_labels"] = s.fit.SuspectLabels();
            return d;
          },
          "The fit check, as identify's JSON 'fit': chi2 against the given sigma_mm, dof, "
          "p_value, consistent (p >= 0.001), standardized residuals and suspects (0-based "
          "configurations with |standardized| > 4), with suspect_labels when the readings were "
          "grouped by configuration labels; test says which check decided `consistent`: chi2, "
          "or robust_scale with a robust loss (robust_scale and robust_p_value).")
      .def_property_readonly(
          "linearisation", &LinearisationDict,
          "The linearisation check (lrcal/identification/linearisation_check.h), as identify's "
          "JSON 'linearisation': excess (what the model's curvature adds to the expected "
          "chi2(n) of the estimate's error), relative_excess (excess/n), holds (computed and "
          "excess <= 0.1 n), worst_direction (term -> component) and its sigma; None when "
          "not computed.")
      .def("__str__", &S::FullReport)
      .def("__repr__", &S::BriefReport);
}

void DefineRun(py::module_& m) {
  py::class_<RunProgress>(m, "RunProgress", "Where a run stands (run_study's progress callback).")
      .def_readonly("done", &RunProgress::done, "trials of the run recorded so far")
      .def_readonly("total", &RunProgress::total, "trials of the run (or shard)")
      .def_readonly("computed", &RunProgress::computed, "computed by this call so far")
      .def_readonly("seconds", &RunProgress::seconds, "since the call started")
      .def_readonly("eta_seconds", &RunProgress::eta_seconds,
                    "seconds left (nan until a trial has finished): each cell's remaining "
                    "trials at its own measured cost, at the run's pace since its trials "
                    "started")
      .def("__repr__", [](const RunProgress& p) {
        return "lrcal.RunProgress(" + std::to_string(p.done) + "/" + std::to_string(p.total) + ")";
      });
  py::class_<RunResult>(m, "RunResult", "What run_study did (as lrcal run prints it).")
      .def_readonly("total", &RunResult::total, "trials of the run (or shard)")
      .def_readonly("done_before", &RunResult::done_before, "already recorded at the start")
      .def_readonly("computed", &RunResult::computed, "computed by this call")
      .def_readonly("interrupted", &RunResult::interrupted)
      .def_readonly("reached_max_trials", &RunResult::reached_max_trials,
                    "stopped because max_trials were computed (call again to continue)")
      .def_readonly("complete", &RunResult::complete, "every trial of the run is recorded")
      .def_readonly("tables_written", &RunResult::tables_written, "OUT/tables/ was written")
      .def_readonly("tables_current", &RunResult::tables_current,
                    "a rerun with nothing new left OUT/tables/ as they were: written from these "
                    "very records by this lrcal")
      .def_readonly("seconds", &RunResult::seconds)
      .def("__repr__", [](const RunResult& r) {
        return "lrcal.RunResult(" + std::to_string(r.done_before + r.computed) + "/" +
               std::to_string(r.total) + " trials, " + (r.complete ? "complete" : "incomplete") +
               ")";
      });
}

void DefineKinematics(py::module_& m) {
  m.def("forward_kinematics", &ForwardKinematicsPy, py::arg("robot"), py::arg("q"),
        py::arg("model") = "nominal", R"doc(
Tool poses in the base frame: (N, 4, 4) homogeneous transforms for q (N, joints) in rad.
model: "nominal", "true" (nominal + the file's true errors) or an array of the 5N link values
(e.g. a calibrated model). The tool z axis (column 2) is the laser beam.)doc");
  m.def("laser_readings", &LaserReadingsPy, py::arg("robot"), py::arg("q"),
        py::arg("plane") = py::none(), py::arg("model") = "nominal",
        py::arg("return_status") = false, py::arg("plane_of") = py::none(), R"doc(
Exact laser readings h (N,) in m of q (N, joints): the distance along the beam to the plane.
NaN where the ranger gives no reading (beam parallel, plane behind, out of range, grazing).
plane: None (the robot file's plane or planes), an lrcal.Plane, (nx, ny, nz, f) or a list of
lrcal.Plane; with several planes plane_of gives each configuration's plane (from 1).
model: as forward_kinematics.
With return_status=True: (h, status), status a list of 'ok' or the reason per configuration.)doc");
  m.def("sample_configurations", &SampleConfigurationsPy, py::arg("robot"), py::arg("count"),
        py::arg("seed") = 1, py::arg("plane") = py::none(), py::arg("validation") = false,
        py::arg("min_singular_value") =
            FindSetting(SamplingOptions::Settings(), "min_singular_value")->Default(),
        py::arg("return_planes") = false, R"doc(
Draws count configurations (count, joints) uniformly within the joint limits whose nominal beam
hits the plane within the ranger's limits and whose geometric Jacobian's smallest singular value
is at least min_singular_value; validation=True drops the beam condition (validation poses).
The same numbers as `lrcal sample --seed SEED [--validation]`.
plane: None (the robot file's plane or planes), an lrcal.Plane, (nx, ny, nz, f) or a list of
lrcal.Plane. With several planes count configurations are drawn per plane, plane 1's first (as
`lrcal sample` with repeated --plane), and return_planes=True is needed: it returns (q, plane_of),
plane_of (N,) the plane each configuration is aimed at, from 1 (the CSV's plane column).)doc");
  // The noise settings' names and defaults are the schema's (NoiseModel::Settings()).
  const auto& noise = NoiseModel::Settings();
  const auto setting = [&](int k) { return py::arg(noise[k].spec.name) = noise[k].Default(); };
  m.def(
      "simulate",
      [](const RobotFile& rig, const Array& q, double sigma_mm, long long repetitions,
         double encoder_sigma_mrad, double form_sigma_mm, double outlier_fraction,
         double outlier_sigma_mm, long long seed, const py::object& plane, const py::object& model,
         const py::object& sigma, const py::object& plane_of) {
        return SimulatePy(rig, q,
                          {sigma_mm, repetitions, encoder_sigma_mrad, form_sigma_mm,
                           outlier_fraction, outlier_sigma_mm},
                          seed, plane, model, sigma, plane_of);
      },
      py::arg("robot"), py::arg("q"), setting(0),
      py::arg(noise[1].spec.name) = static_cast<long long>(noise[1].Default()), setting(2),
      setting(3), setting(4), setting(5), py::arg("seed") = 1, py::arg("plane") = py::none(),
      py::arg("model") = "true", py::arg("sigma") = py::none(), py::arg("plane_of") = py::none(),
      R"doc(
Simulated noisy readings of the arm `model` ("true" by default: nominal + the file's true errors,
its ranger's true offset and scale included) at the configurations q (N, joints): `repetitions` readings per configuration with Gaussian noise
of standard deviation sigma_mm (mm), and a real rig's disturbances as `lrcal simulate` has them:
encoder_sigma_mrad (joint-encoder noise, each joint and reading), form_sigma_mm (plane flatness),
outlier_fraction and outlier_sigma_mm (gross errors). `sigma` (m) is the earlier spelling of
sigma_mm. Returns an lrcal.Readings (q, h, configuration, skipped), the same numbers as
`lrcal simulate --seed SEED` with the same settings.
plane: None (the robot file's plane or planes), an lrcal.Plane, (nx, ny, nz, f) or a list of
lrcal.Plane; with several planes plane_of gives the plane each configuration is aimed at (from 1,
as sample(..., return_planes=True) returns it).)doc");
}

constexpr const char* kIdentifyDoc = R"doc(
Identifies the geometric parameters (and plane terms) from laser readings.

q (M, joints) rad and h (M,) m are single readings; readings at identical joint values are
averaged (weight = their count), exactly as `lrcal identify --data` does with a CSV.
configuration: None, or one label per reading (a measurement CSV's configuration column): the
readings that share a label are one configuration, whatever their recorded joint values, and the
fit check names suspects by label (fit['suspect_labels']).
plane: None (the robot file's plane or planes), an lrcal.Plane, (nx, ny, nz, f) or a list of
lrcal.Plane (several planes, as repeated --plane). plane_of: with several planes, the plane each
reading's beam is aimed at, a number from 1 per reading (a measurement CSV's plane column).
estimate_plane: "none", "normal", "offset" or "normal,offset", for every plane (names plane_u1,
plane_u2, plane_f; with several planes plane1_u1, ...). estimate_ranger: "none", "offset",
"scale" or "offset,scale" (as --estimate-ranger: reading = (1+s) h + o). estimate_base,
estimate_tool: the base's and the tool's transform terms, "none", "all", "xyz", "rpy" or a list
of x, y, z, roll, pitch, yaw (as --estimate-base, --estimate-tool; names base_x ... tool_yaw).
fix: parameter names kept at nominal (a list or "a1,d2"). auto_fix: if the set is rank-deficient,
fix the suggested parameters and go on (else termination is 'rank_deficient').
solver: "lm" (lrcal's) or "ceres"; loss: "none", "huber", "cauchy" (either solver) with scale
loss_scale_mm (mm, as `lrcal identify --loss-scale-mm`) on each configuration's residual, or
loss_scale_sigma (multiples of sigma_mm, as --loss-scale-sigma and a study's
identification.loss_scale_sigma: 1.345 Huber, 2.385 Cauchy for 95 % efficiency) in its place.
sigma_mm: the known σ of one reading (mm, as --sigma-mm) for covariance_given and the fit check;
0 = unknown. loss_scale and sigma (m) are the earlier spellings of the two, still accepted.
max_iterations: 1 to 10,000.
prior_sigma: prior standard deviations as `lrcal identify --prior-sigma` takes them
("theta=1mrad,a=0.5mm,d6=0.2mm": a class or a term, each with its unit); with sigma_mm, the
maximum a-posteriori estimate (prior_sigma, posterior_to_prior and set_by_prior on the result).
prior: True to use the robot file's tolerances: as priors (as --prior); prior_sigma's entries
replace the same keys.
encoder_sigma_mrad: errors in variables (as --encoder-sigma-mrad): the standard deviation of each
recorded joint value (mrad; mm for a prismatic joint), one error per configuration; needs sigma_mm.
average: how the readings at one configuration become its value (as --average): "mean",
"median" or "trimmed:F" (F in (0, 0.5) cut from each end); the weights account for the median's
larger variance under Gaussian noise.
holdout: K-fold cross-validation over the configurations (as --holdout K): result.holdout.
predict_at: poses (M, joints) rad to state the calibrated arm's accuracy at (as --predict-at: the
data part and the total with its sources, the robot file's tolerances and prior_sigma for the
held terms): result.accuracy.
write_robot: a path: the calibrated model written as a robot file with its record (as
--write-robot; every function takes it as a robot). report: a folder: the calibration report (as
--report: report.html, calibration.json, calibrated.yaml and .urdf); result.report is the page's
path. data_file: the measurement file q and h were read from, named and hashed in the calibrated
file's record (else the record names and hashes the arrays).
Joint values outside the robot's joint ranges are refused (degrees for rad?), as the command
line refuses them in a CSV.
Returns an lrcal.Identification; raises lrcal.InputError for bad input.)doc";

// identify_in_environment / identifiability_in_environment (issue 28): each configuration's
// environment from the arrays gravity (m × 3, m/s²) and temperature_c (m, °C), None for the
// robot file's defaults; the ranger inside the non-geometric model.
void SetEnvironments(const py::object& gravity, const py::object& temperature_c,
                     TargetedConfigurations* configs) {
  const int m = configs->size();
  if (!gravity.is_none()) {
    const Array g = gravity.cast<Array>();
    if (g.ndim() != 2 || g.shape(0) != m || g.shape(1) != 3)
      throw InputError("gravity=", "expected an array of " + std::to_string(m) +
                                       " rows of 3 (m/s², base frame), one per row of q");
    for (int i = 0; i < m; ++i) {
      Environment e = configs->environment(i);
      e.gravity = Eigen::Vector3d(g.at(i, 0), g.at(i, 1), g.at(i, 2));
      if (!e.gravity.allFinite()) throw InputError("gravity=", "expected finite numbers");
      configs->SetEnvironment(i, e);
    }
  }
  if (!temperature_c.is_none()) {
    const std::vector<double> t = ToVector(temperature_c.cast<Array>(), "temperature_c");
    if (static_cast<int>(t.size()) != m)
      throw InputError("temperature_c=", "expected one temperature (°C) per row of q");
    for (int i = 0; i < m; ++i) {
      if (!(t[static_cast<std::size_t>(i)] >= -273.15))
        throw InputError("temperature_c=", "expected °C above absolute zero");
      Environment e = configs->environment(i);
      e.temperature_c = t[static_cast<std::size_t>(i)];
      configs->SetEnvironment(i, e);
    }
  }
}

NonGeometricTerms ResolveNonGeometricTerms(const RobotFile& rig, const std::string& compliance,
                                           const std::string& thermal) {
  NonGeometricTerms terms;
  terms.compliance_joints =
      NonGeometricTerms::ParseCompliance(compliance, rig.robot.num_links(), "estimate_compliance=");
  terms.ParseThermal(thermal, "estimate_thermal=");
  if (!terms.compliance_joints.empty() && rig.non_geometric.masses.empty())
    throw InputError("estimate_compliance=",
                     "a joint's compliance is seen through gravity's torque: the robot file " +
                         rig.path + " has no masses:");
  return terms;
}

void DefineEnvironment(py::module_& m) {
  m.def(
      "identify_in_environment",
      [](const RobotFile& rig, const Array& q, const Array& h, const py::object& gravity,
         const py::object& temperature_c, const std::string& estimate_compliance,
         const std::string& estimate_thermal, const py::object& plane,
         const std::string& estimate_ranger, const py::object& fix, bool auto_fix,
         double sigma_mm) {
        ConfigsAndModel set =
            ResolveConfigsAndModel(rig, q, plane, py::none(), "none", {estimate_ranger}, fix);
        SetEnvironments(gravity, temperature_c, &set.configs);
        const std::vector<double> readings = ToVector(h, "h");
        const MeasurementSet data = GroupReadings(set.configs, readings, &rig.ranger, [](int r) {
          return r < 0 ? std::string("q, h") : "h[" + std::to_string(r) + "]";
        });
        const std::unique_ptr<EnvironmentMeasurement> kind = RangerInEnvironment(
            rig.robot, rig.robot, set.model->nominal_planes(), set.model->parameters(), rig.ranger,
            rig.non_geometric, ResolveNonGeometricTerms(rig, estimate_compliance, estimate_thermal),
            "estimate_compliance=/estimate_thermal=");
        IdentificationOptions options;
        if (!(sigma_mm >= 0)) throw InputError("sigma_mm=", "expected sigma >= 0 (mm)");
        options.sigma = sigma_mm * 1e-3;
        options.fix_dependent_parameters = auto_fix;
        py::gil_scoped_release release;
        return Identify(*kind, ToMeasuredValues(data), options);
      },
      py::arg("robot"), py::arg("q"), py::arg("h"), py::arg("gravity") = py::none(),
      py::arg("temperature_c") = py::none(), py::arg("estimate_compliance") = "none",
      py::arg("estimate_thermal") = "none", py::arg("plane") = py::none(),
      py::arg("estimate_ranger") = "none", py::arg("fix") = py::none(), py::arg("auto_fix") = false,
      py::arg("sigma_mm") = 0.0,
      R"doc(Calibrate the ranger's readings h (m) at q with joint compliance and thermal growth,
as `lrcal identify --estimate-compliance ... --estimate-thermal ...`: gravity (m x 3, m/s^2,
base frame) and temperature_c (m, deg C) per reading, None for the robot file's environment:.
Terms c1..cN (rad/(N m)), thermal_links, thermal_ranger (1/K) join the geometric ones.)doc");
  m.def(
      "identifiability_in_environment",
      [](const RobotFile& rig, const Array& q, const py::object& gravity,
         const py::object& temperature_c, const std::string& estimate_compliance,
         const std::string& estimate_thermal, const py::object& plane,
         const std::string& estimate_ranger, const py::object& fix) {
        ConfigsAndModel set =
            ResolveConfigsAndModel(rig, q, plane, py::none(), "none", {estimate_ranger}, fix);
        SetEnvironments(gravity, temperature_c, &set.configs);
        const std::unique_ptr<EnvironmentMeasurement> kind = RangerInEnvironment(
            rig.robot, rig.robot, set.model->nominal_planes(), set.model->parameters(), rig.ranger,
            rig.non_geometric, ResolveNonGeometricTerms(rig, estimate_compliance, estimate_thermal),
            "estimate_compliance=/estimate_thermal=");
        return AnalyzeIdentifiability(*kind, set.configs);
      },
      py::arg("robot"), py::arg("q"), py::arg("gravity") = py::none(),
      py::arg("temperature_c") = py::none(), py::arg("estimate_compliance") = "none",
      py::arg("estimate_thermal") = "none", py::arg("plane") = py::none(),
      py::arg("estimate_ranger") = "none", py::arg("fix") = py::none(),
      R"doc(What configurations q in their environments can identify of the geometry, the joint
compliances and the thermal coefficients, as `lrcal identifiability --estimate-compliance ...`;
.explanations says in words why a compliance or thermal term is lost.)doc");
}

void DefineIdentify(py::module_& m) {
  // The numeric settings' names and defaults are the schema's (IdentificationOptions::Settings()).
  const auto& fields = IdentificationOptions::Settings();
  const auto setting = [&](const char* name) {
    const auto& f = *FindSetting(fields, name);
    return f.spec.integer ? (py::arg(f.spec.name) = static_cast<long long>(f.Default()))
                          : (py::arg(f.spec.name) = f.Default());
  };
  m.def(
      "identify",
      [](const RobotFile& rig, const Array& q, const Array& h, const py::object& plane,
         const std::string& estimate_plane, const py::object& fix, bool auto_fix,
         const std::string& solver, const std::string& loss, double loss_scale_mm, double sigma_mm,
         long long max_iterations, const py::object& loss_scale, const py::object& sigma,
         const std::string& prior_sigma, bool prior, double encoder_sigma_mrad,
         const std::string& average, const py::object& plane_of, const std::string& estimate_ranger,
         const py::object& holdout, const py::object& predict_at, const py::object& configuration,
         double loss_scale_sigma, const py::object& write_robot, const py::object& report,
         const py::object& data_file, const std::string& estimate_base,
         const std::string& estimate_tool) {
        IdentifyExtras extras;
        py::object result = py::cast(IdentifyPy(rig, q, h, plane, estimate_plane, fix, auto_fix,
                                                {solver,
                                                 loss,
                                                 loss_scale_mm,
                                                 sigma_mm,
                                                 max_iterations,
                                                 loss_scale,
                                                 sigma,
                                                 prior_sigma,
                                                 prior,
                                                 encoder_sigma_mrad,
                                                 average,
                                                 estimate_ranger,
                                                 estimate_base,
                                                 estimate_tool,
                                                 plane_of,
                                                 holdout,
                                                 predict_at,
                                                 configuration,
                                                 loss_scale_sigma,
                                                 write_robot,
                                                 report,
                                                 data_file},
                                                &extras));
        // report=: the page drawn from the files just written, as `lrcal identify --report`.
        result.attr("report") = report.is_none()
                                    ? py::object(py::none())
                                    : py::object(py::module_::import("lrcal.report.calibration")
                                                     .attr("build")(py::str(report))
                                                     .cast<py::tuple>()[0]);
        // As `lrcal identify --format json` has them: "holdout" and "accuracy" (None when not
        // asked for, or when the fit is not usable).
        result.attr("holdout") =
            extras.holdout ? FromJson(CrossValidationJson(*extras.holdout).dump()) : py::none();
        result.attr("accuracy") =
            extras.accuracy ? FromJson(PoseAccuracyJson(*extras.accuracy, extras.poses).dump())
                            : py::none();
        return result;
      },
      py::arg("robot"), py::arg("q"), py::arg("h"), py::arg("plane") = py::none(),
      py::arg("estimate_plane") = "none", py::arg("fix") = py::none(), py::arg("auto_fix") = false,
      py::arg("solver") = "lm", py::arg("loss") = "none", setting("loss_scale_mm"),
      setting("sigma_mm"), setting("max_iterations"), py::arg("loss_scale") = py::none(),
      py::arg("sigma") = py::none(), py::arg("prior_sigma") = "", py::arg("prior") = false,
      py::arg("encoder_sigma_mrad") = 0.0, py::arg("average") = Averaging{}.Name(),
      py::arg("plane_of") = py::none(), py::arg("estimate_ranger") = "none",
      py::arg("holdout") = py::none(), py::arg("predict_at") = py::none(),
      py::arg("configuration") = py::none(), setting("loss_scale_sigma"),
      py::arg("write_robot") = py::none(), py::arg("report") = py::none(),
      py::arg("data_file") = py::none(), py::arg("estimate_base") = "none",
      py::arg("estimate_tool") = "none", kIdentifyDoc);
}

// identifiability(): the ranger's parameter set or, with sensor=, a tracker's terms.
void DefineIdentifiability(py::module_& m) {
  m.def(
      "identifiability",
      [](const RobotFile& rig, const Array& q, const py::object& plane,
         const std::string& estimate_plane, const py::object& fix, double rank_tolerance,
         const py::object& plane_of, const std::string& estimate_ranger,
         const std::string& estimate_base, const std::string& estimate_tool,
         const std::string& sensor, const py::object& instrument, const py::object& targets,
         const py::object& target_of, const py::object& socket_of,
         const py::object& socket_distances, const py::object& tool_point, bool flush,
         long long beams, double fan_deg, const py::object& scanner) {
        return IdentifiabilityPy(
            rig, q, plane, estimate_plane, fix, rank_tolerance, plane_of, estimate_ranger,
            estimate_base, estimate_tool, sensor, instrument, targets, target_of,
            {socket_of, socket_distances, tool_point}, flush,
            {py::none(), py::none(), scanner, py::none(), "none", beams, fan_deg});
      },
      py::arg("robot"), py::arg("q"), py::arg("plane") = py::none(),
      py::arg("estimate_plane") = "none", py::arg("fix") = py::none(),
      py::arg("rank_tolerance") =
          FindSetting(IdentifiabilityOptions::Settings(), "rank_tolerance")->Default(),
      py::arg("plane_of") = py::none(), py::arg("estimate_ranger") = "none",
      py::arg("estimate_base") = "none", py::arg("estimate_tool") = "none",
      py::arg("sensor") = "ranger", py::arg("instrument") = py::none(),
      py::arg("targets") = py::none(), py::arg("target_of") = py::none(),
      py::arg("socket_of") = py::none(), py::arg("socket_distances") = py::none(),
      py::arg("tool_point") = py::none(), py::arg("flush") = false, py::arg("beams") = 1,
      py::arg("fan_deg") = 0.0, py::arg("scanner") = py::none(), R"doc(
What the configurations q (N, joints) can identify of the parameter set (plane, plane_of,
estimate_plane, estimate_ranger, estimate_base, estimate_tool, fix as in identify: several
planes too), at the nominal model. Returns an lrcal.Identifiability; str() gives the report of
`lrcal identifiability`. sensor='point' or 'pose' analyses a tracker's terms instead (`lrcal
identifiability --sensor`): instrument=(x, y, z, roll, pitch, yaw) in the base frame (m, rad;
None: the base frame), targets=[(x, y, z), ...] in the tool frame ((x, y, z, roll, pitch, yaw)
for a 6-D probe; None: one at the tool frame's origin), target_of (N numbers from 1) the target
each row sees, fix= as above. sensor='socket' analyses seatings in sockets (`--sensor socket`):
socket_of (N socket ids), socket_distances=[(a, b, metres), ...], tool_point=(x, y, z).
sensor='contact' analyses contacts with planes (`--sensor contact`): plane, plane_of,
estimate_plane and fix as for the ranger, tool_point=(x, y, z) in the tool frame, flush=True for
flush contacts (two tilt rows each). sensor='scanner' analyses a line scanner's fan (`--sensor
scanner`): beams=, fan_deg= (half angle), scanner=(x, y, z, roll, pitch, yaw) in the tool frame.)doc");
}

// The trackers' simulation and fit (point_measurement.h, pose_measurement.h); their
// identifiability is identifiability(sensor=).
void DefineTrackers(py::module_& m) {
  m.def(
      "simulate_tracker",
      [](const RobotFile& rig, const Array& q, const std::string& sensor,
         const py::object& instrument, const py::object& targets, const py::object& target_of,
         double sigma_mm, double sigma_mrad, long long repetitions, long long seed) {
        return SimulateTrackerPy(rig, q, sensor, instrument, targets, target_of,
                                 {sigma_mm, sigma_mrad, repetitions, seed});
      },
      py::arg("robot"), py::arg("q"), py::arg("sensor") = "point",
      py::arg("instrument") = py::none(), py::arg("targets") = py::none(),
      py::arg("target_of") = py::none(), py::arg("sigma_mm") = 0.2, py::arg("sigma_mrad") = 0.2,
      py::arg("repetitions") = 10, py::arg("seed") = 1, R"doc(
What a tracker sees of the true arm (nominal + the robot file's true errors) at q (N, joints):
`lrcal simulate --sensor point|pose`. sensor, instrument, targets and target_of as in
identifiability; each row the mean of `repetitions` readings with noise sigma_mm per position
component and sigma_mrad per orientation component. Returns a dict: q, target_of (from 1),
xyz (N, 3) m in the instrument's frame, repetitions, and for a pose quaternion (N, 4) as
(qx, qy, qz, qw), the target's axes in the instrument's frame.)doc");
  m.def(
      "identify_tracker",
      [](const RobotFile& rig, const Array& q, const Array& xyz, const std::string& sensor,
         const py::object& quaternion, const py::object& instrument, const py::object& targets,
         const py::object& target_of, const py::object& repetitions, const py::object& fix,
         bool auto_fix, double sigma_mm, double sigma_mrad, const std::string& solver,
         const py::object& holdout, const py::object& predict_at) {
        return IdentifyTrackerPy(rig, q, xyz, sensor,
                                 {quaternion, instrument, targets, target_of, repetitions, fix,
                                  auto_fix, sigma_mm, sigma_mrad, solver, holdout, predict_at});
      },
      py::arg("robot"), py::arg("q"), py::arg("xyz"), py::arg("sensor") = "point",
      py::arg("quaternion") = py::none(), py::arg("instrument") = py::none(),
      py::arg("targets") = py::none(), py::arg("target_of") = py::none(),
      py::arg("repetitions") = py::none(), py::arg("fix") = py::none(), py::arg("auto_fix") = false,
      py::arg("sigma_mm") = 0.0, py::arg("sigma_mrad") = 0.2, py::arg("solver") = "lm",
      py::arg("holdout") = py::none(), py::arg("predict_at") = py::none(), R"doc(
The tracker's terms (the arm's link values, the instrument's frame, the targets) from its
values: `lrcal identify --sensor point|pose`. xyz (N, 3) m and, for sensor='pose', quaternion
(N, 4) as simulate_tracker returns them; repetitions (N,) each row's weight (default 1);
sigma_mm (0: unknown, judged from the residuals) and sigma_mrad weigh a pose's orientations
against its positions. holdout=K: K-fold cross-validation of every value (as --holdout K; a pose's
angles apart) in result.holdout (None when not asked for). predict_at=poses (M, joints) rad: the
calibrated arm's predicted accuracy there (as --predict-at; every identify_* function takes it) in
result.accuracy. Returns an lrcal.Identification.)doc");
}

// simulate_sockets: starts seated on the true arm at the true sockets, as simulate --sensor
// socket.
py::dict SimulateSocketsPy(const RobotFile& rig, const Array& q, const py::object& socket_of,
                           const py::object& sockets, const py::object& tool_point,
                           const py::object& distances, double sigma_mm, long long repetitions,
                           long long seed) {
  const SocketData starts = ToSocketData(rig.robot, q, socket_of, py::none());
  SocketSetup setup;
  setup.ids = starts.ids;
  setup.positions.clear();
  for (const py::handle p : sockets) {
    const RigidTransform t = ToXyzRpy(py::reinterpret_borrow<py::object>(p), "sockets", true);
    setup.positions.push_back(t.translation);
  }
  if (setup.positions.size() != starts.ids.size())
    throw InputError("sockets", "socket_of names " + std::to_string(starts.ids.size()) +
                                    " socket(s); give one true (x, y, z) each, in ascending "
                                    "order of id");
  setup.tool_point = ToToolPoint(tool_point);
  setup.distances = ToSocketDistances(distances);
  const RobotModel true_robot = rig.truth.TrueRobot(rig.robot);
  const SocketMeasurement truth(true_robot, setup);
  NoiseModel noise;
  noise.sigma = sigma_mm * 1e-3;
  if (repetitions < 1 || repetitions > 1000000)
    throw InputError("repetitions", "expected 1 to 1,000,000 seatings per configuration");
  noise.repetitions = static_cast<int>(repetitions);
  MeasuredValues data;
  std::vector<std::string> misses;
  SimulateSocketMeasurements(truth, starts.values.configs, noise,
                             RandomStream(ToSeed(seed), 0, 0, RandomPurpose::kNoise), &data,
                             &misses);
  std::vector<int> ids;
  for (int i = 0; i < data.size(); ++i)
    ids.push_back(setup.ids[static_cast<std::size_t>(data.configs.target(i))]);
  py::dict out;
  out["q"] = ToArray(data.configs);
  out["socket_of"] = ids;
  out["repetitions"] = data.repetitions;
  out["misses"] = misses;
  return out;
}

// identify_sockets: as identify --sensor socket.
py::object IdentifySocketsPy(const RobotFile& rig, const Array& q, const py::object& socket_of,
                             const py::object& tool_point, const py::object& distances,
                             const py::object& repetitions, const py::object& fix, bool auto_fix,
                             double sigma_mm, const std::string& solver, const py::object& holdout,
                             const py::object& predict_at) {
  const SocketData data = ToSocketData(rig.robot, q, socket_of, repetitions);
  const std::unique_ptr<SocketMeasurement> kind =
      ToSocketKind(rig.robot, data, tool_point, distances, fix);
  const IdentificationOptions options = KindFitOptions(solver, sigma_mm, auto_fix);
  return FitKindPy(rig, *kind, data.values, options, holdout, predict_at);
}

// socket_consistency: as accuracy --sockets.
py::dict SocketConsistencyPy(const RobotFile& rig, const Array& q, const py::object& socket_of,
                             const py::object& tool_point, const py::object& distances) {
  const SocketData data = ToSocketData(rig.robot, q, socket_of, py::none());
  const SocketConsistency r =
      ConsistencyAtSockets(rig.robot, ToToolPoint(tool_point), data.values.configs, data.ids,
                           ToSocketDistances(distances));
  py::list sockets, known;
  for (const SocketConsistency::Socket& k : r.sockets) {
    py::dict d;
    d["id"] = k.id;
    d["configurations"] = k.count;
    d["centre"] = Eigen::Vector3d(k.centre);
    d["rms_spread"] = k.rms_spread;
    d["worst_spread"] = k.worst_spread;
    sockets.append(d);
  }
  for (const SocketConsistency::Distance& k : r.distances) {
    py::dict d;
    d["sockets"] = py::make_tuple(k.known.a, k.known.b);
    d["known"] = k.known.metres;
    d["predicted"] = k.predicted;
    d["error"] = k.error;
    known.append(d);
  }
  py::dict out;
  out["rms_spread"] = r.rms_spread;
  out["sockets"] = sockets;
  out["distances"] = known;
  return out;
}

// The socket kind (socket_measurement.h): simulation, fit and judgement; its identifiability is
// identifiability(sensor='socket').
void DefineSockets(py::module_& m) {
  m.def("simulate_sockets", &SimulateSocketsPy, py::arg("robot"), py::arg("q"),
        py::arg("socket_of"), py::arg("sockets"), py::arg("tool_point") = py::none(),
        py::arg("socket_distances") = py::none(), py::arg("sigma_mm") = 0.2,
        py::arg("repetitions") = 1, py::arg("seed") = 1, R"doc(
Socket seatings of the true arm (nominal + the robot file's true errors): `lrcal simulate
--sensor socket`. Each row of q (N, joints) is a start, moved until the true tool point
(tool_point, (x, y, z) m in the tool frame; None: the origin) sits in its socket (socket_of: N
ids) at its true position (sockets: one (x, y, z) m in the base frame per id, ascending) plus a
play of sigma_mm per axis (of the mean of `repetitions` seatings). Returns a dict: q, socket_of,
repetitions of the seated rows, and misses (one reason per start: "ok", "out of reach",
"outside the joint ranges").)doc");
  m.def("identify_sockets", &IdentifySocketsPy, py::arg("robot"), py::arg("q"),
        py::arg("socket_of"), py::arg("tool_point") = py::none(),
        py::arg("socket_distances") = py::none(), py::arg("repetitions") = py::none(),
        py::arg("fix") = py::none(), py::arg("auto_fix") = false, py::arg("sigma_mm") = 0.0,
        py::arg("solver") = "lm", py::arg("holdout") = py::none(),
        py::arg("predict_at") = py::none(), R"doc(
The arm's link values, the tool point and the sockets from seatings: `lrcal identify --sensor
socket`. q (N, joints), socket_of (N socket ids); tool_point the nominal offset (None: the tool
frame's origin); socket_distances=[(a, b, metres), ...] known distances (a tree); repetitions
(N,) each row's weight; fix, auto_fix, sigma_mm (the play per axis; 0: judged from the
residuals) and solver as in identify; holdout=K: K-fold cross-validation of every value (as
--holdout K) in result.holdout; predict_at as in identify_tracker. Returns an
lrcal.Identification.)doc");
  m.def("socket_consistency", &SocketConsistencyPy, py::arg("robot"), py::arg("q"),
        py::arg("socket_of"), py::arg("tool_point") = py::none(),
        py::arg("socket_distances") = py::none(), R"doc(
How consistently a model (robot: a calibrated robot file) puts the tool point in each socket,
and the error of the known socket distances: `lrcal accuracy --sockets`. Returns a dict:
rms_spread (m), sockets (id, configurations, centre, rms_spread, worst_spread), distances
(sockets, known, predicted, error; m).)doc");
}

// simulate_contacts: as simulate --sensor contact.
py::dict SimulateContactsPy(const RobotFile& rig, const Array& q, const ContactArgs& a,
                            double sigma_mm, double sigma_mrad, long long repetitions,
                            long long seed) {
  const PlaneSet planes = ResolvePlanes(rig, a.plane);
  const RobotModel true_robot = rig.truth.TrueRobot(rig.robot);
  const std::unique_ptr<ContactMeasurement> truth = ToContactKind(true_robot, planes, a);
  NoiseModel noise;
  noise.sigma = sigma_mm * 1e-3;
  noise.sigma_angle = sigma_mrad * 1e-3;
  if (repetitions < 1 || repetitions > 1000000)
    throw InputError("repetitions", "expected 1 to 1,000,000 contacts per configuration");
  noise.repetitions = static_cast<int>(repetitions);
  MeasuredValues data;
  std::vector<std::string> misses;
  SimulateContactMeasurements(
      *truth, ToContactConfigurations(rig.robot, q, a.plane_of, planes.size()), noise,
      RandomStream(ToSeed(seed), 0, 0, RandomPurpose::kNoise), &data, &misses);
  py::dict out;
  out["q"] = ToArray(data.configs);
  out["plane_of"] = PlaneNumbers(data.configs);
  out["repetitions"] = data.repetitions;
  out["misses"] = misses;
  return out;
}

// identify_contacts: as identify --sensor contact.
py::object IdentifyContactsPy(const RobotFile& rig, const Array& q, const ContactArgs& a,
                              const py::object& repetitions, bool auto_fix, double sigma_mm,
                              double sigma_mrad, const std::string& solver,
                              const py::object& holdout, const py::object& predict_at) {
  const PlaneSet planes = ResolvePlanes(rig, a.plane);
  const std::unique_ptr<ContactMeasurement> kind = ToContactKind(rig.robot, planes, a);
  MeasuredValues data{ToContactConfigurations(rig.robot, q, a.plane_of, planes.size()), {}, {}};
  data.y.assign(static_cast<std::size_t>(kind->rows_per_configuration() * data.size()), 0.0);
  data.repetitions.assign(static_cast<std::size_t>(data.size()), 1);
  if (!repetitions.is_none()) data.repetitions = repetitions.cast<std::vector<int>>();
  if (static_cast<int>(data.repetitions.size()) != data.size())
    throw InputError("repetitions", "expected one count per row of q");
  const IdentificationOptions options = KindFitOptions(solver, sigma_mm, auto_fix);
  if (a.flush)
    WeighAngleRows(*kind, options.sigma > 0 ? options.sigma : NoiseModel{}.sigma, sigma_mrad * 1e-3,
                   &data);
  return FitKindPy(rig, *kind, data, options, holdout, predict_at);
}

// The contact kind (contact_measurement.h): simulation and fit.
void DefineContacts(py::module_& m) {
  m.def(
      "simulate_contacts",
      [](const RobotFile& rig, const Array& q, const py::object& plane, const py::object& plane_of,
         const py::object& tool_point, bool flush, double sigma_mm, double sigma_mrad,
         long long repetitions, long long seed) {
        return SimulateContactsPy(rig, q, {plane, plane_of, tool_point, py::none(), "none", flush},
                                  sigma_mm, sigma_mrad, repetitions, seed);
      },
      py::arg("robot"), py::arg("q"), py::arg("plane") = py::none(),
      py::arg("plane_of") = py::none(), py::arg("tool_point") = py::none(),
      py::arg("flush") = false, py::arg("sigma_mm") = 0.2, py::arg("sigma_mrad") = 0.2,
      py::arg("repetitions") = 1, py::arg("seed") = 1, R"doc(
Contacts of the true arm (nominal + the robot file's true errors) with planes: `lrcal simulate
--sensor contact`. Each row of q (N, joints) is a start on plane plane_of[i] (from 1; plane= as
in identify), moved until the true tool point (tool_point, (x, y, z) m in the tool frame)
touches it, plus a play of sigma_mm along the normal; flush=True also squares the tool's z axis
to the plane, with a tilt of sigma_mrad. Returns a dict: q, plane_of, repetitions of the seated
rows, and misses (a reason per start).)doc");
  m.def(
      "identify_contacts",
      [](const RobotFile& rig, const Array& q, const py::object& plane, const py::object& plane_of,
         const py::object& tool_point, bool flush, const std::string& estimate_plane,
         const py::object& repetitions, const py::object& fix, bool auto_fix, double sigma_mm,
         double sigma_mrad, const std::string& solver, const py::object& holdout,
         const py::object& predict_at) {
        return IdentifyContactsPy(rig, q, {plane, plane_of, tool_point, fix, estimate_plane, flush},
                                  repetitions, auto_fix, sigma_mm, sigma_mrad, solver, holdout,
                                  predict_at);
      },
      py::arg("robot"), py::arg("q"), py::arg("plane") = py::none(),
      py::arg("plane_of") = py::none(), py::arg("tool_point") = py::none(),
      py::arg("flush") = false, py::arg("estimate_plane") = "none",
      py::arg("repetitions") = py::none(), py::arg("fix") = py::none(), py::arg("auto_fix") = false,
      py::arg("sigma_mm") = 0.0, py::arg("sigma_mrad") = 0.2, py::arg("solver") = "lm",
      py::arg("holdout") = py::none(), py::arg("predict_at") = py::none(), R"doc(
The arm's link values, the tool point and the planes' estimated terms from contacts: `lrcal
identify --sensor contact`. q (N, joints) on planes (plane, plane_of as in identify); flush,
tool_point as in simulate_contacts; estimate_plane ("none", "normal", "offset",
"normal,offset") for every plane; repetitions, fix, auto_fix, sigma_mm, sigma_mrad (a flush
contact's tilt rows weigh (sigma_mm/sigma_mrad)^2), solver, holdout and predict_at as in
identify_tracker.
Returns an lrcal.Identification.)doc");
}

// simulate_scanner: as simulate --sensor scanner.
py::dict SimulateScannerPy(const RobotFile& rig, const Array& q, const ScannerArgs& a,
                           double sigma_mm, long long repetitions, long long seed) {
  const PlaneSet planes = ResolvePlanes(rig, a.plane);
  const RobotModel true_robot = rig.truth.TrueRobot(rig.robot);
  const std::unique_ptr<ScannerMeasurement> truth = ToScannerKind(rig, true_robot, planes, a);
  NoiseModel noise;
  noise.sigma = sigma_mm * 1e-3;
  if (repetitions < 1 || repetitions > 1000000)
    throw InputError("repetitions", "expected 1 to 1,000,000 readings per beam");
  noise.repetitions = static_cast<int>(repetitions);
  MeasuredValues data;
  std::vector<std::string> misses;
  SimulateMeasurements(*truth, ToContactConfigurations(rig.robot, q, a.plane_of, planes.size()),
                       noise, RandomStream(ToSeed(seed), 0, 0, RandomPurpose::kNoise), &data,
                       &misses);
  py::array_t<double> h(
      {static_cast<py::ssize_t>(data.size()), static_cast<py::ssize_t>(truth->num_beams())});
  std::copy(data.y.begin(), data.y.end(), h.mutable_data());
  py::dict out;
  out["q"] = ToArray(data.configs);
  out["plane_of"] = PlaneNumbers(data.configs);
  out["h"] = h;
  out["repetitions"] = data.repetitions;
  out["misses"] = misses;
  return out;
}

// identify_scanner: as identify --sensor scanner; h (N, beams).
py::object IdentifyScannerPy(const RobotFile& rig, const Array& q, const Array& h, ScannerArgs a,
                             const py::object& repetitions, bool auto_fix, double sigma_mm,
                             const std::string& solver, const py::object& holdout,
                             const py::object& predict_at) {
  if (h.ndim() != 2)
    throw InputError("h", "expected an (N, beams) array of readings (m), one column per beam");
  a.beams = static_cast<long long>(h.shape(1));
  const PlaneSet planes = ResolvePlanes(rig, a.plane);
  const std::unique_ptr<ScannerMeasurement> kind = ToScannerKind(rig, rig.robot, planes, a);
  MeasuredValues data{ToContactConfigurations(rig.robot, q, a.plane_of, planes.size()), {}, {}};
  data.y = ToRows(h, kind->num_beams(), data.size(), "h");
  data.repetitions.assign(static_cast<std::size_t>(data.size()), 1);
  if (!repetitions.is_none()) data.repetitions = repetitions.cast<std::vector<int>>();
  if (static_cast<int>(data.repetitions.size()) != data.size())
    throw InputError("repetitions", "expected one count per row of q");
  const IdentificationOptions options = KindFitOptions(solver, sigma_mm, auto_fix);
  return FitKindPy(rig, *kind, data, options, holdout, predict_at);
}

// The scanner kind (scanner_measurement.h): simulation and fit.
void DefineScanners(py::module_& m) {
  m.def(
      "simulate_scanner",
      [](const RobotFile& rig, const Array& q, const py::object& plane, const py::object& plane_of,
         long long beams, double fan_deg, const py::object& scanner, double sigma_mm,
         long long repetitions, long long seed) {
        return SimulateScannerPy(rig, q,
                                 {plane, plane_of, scanner, py::none(), "none", beams, fan_deg},
                                 sigma_mm, repetitions, seed);
      },
      py::arg("robot"), py::arg("q"), py::arg("plane") = py::none(),
      py::arg("plane_of") = py::none(), py::arg("beams") = 1, py::arg("fan_deg") = 0.0,
      py::arg("scanner") = py::none(), py::arg("sigma_mm") = 0.2, py::arg("repetitions") = 1,
      py::arg("seed") = 1, R"doc(
A line scanner's readings by the true arm (nominal + the robot file's true errors): `lrcal
simulate --sensor scanner`. beams= beams spread over +-fan_deg (deg) in the x-z plane of the
scanner's frame, scanner=(x, y, z, roll, pitch, yaw) in the tool frame (m, rad; None: the tool
frame), each beam reading its distance to plane plane_of[i] (from 1; plane= as in identify) with
noise sigma_mm, the mean of `repetitions`. Configurations with a beam out of the robot file's
ranger limits are left out. Returns a dict: q, plane_of, h (N, beams; m), repetitions, misses (a
reason per configuration of q).)doc");
  m.def(
      "identify_scanner",
      [](const RobotFile& rig, const Array& q, const Array& h, const py::object& plane,
         const py::object& plane_of, double fan_deg, const py::object& scanner,
         const std::string& estimate_plane, const py::object& repetitions, const py::object& fix,
         bool auto_fix, double sigma_mm, const std::string& solver, const py::object& holdout,
         const py::object& predict_at) {
        return IdentifyScannerPy(rig, q, h,
                                 {plane, plane_of, scanner, fix, estimate_plane, 1, fan_deg},
                                 repetitions, auto_fix, sigma_mm, solver, holdout, predict_at);
      },
      py::arg("robot"), py::arg("q"), py::arg("h"), py::arg("plane") = py::none(),
      py::arg("plane_of") = py::none(), py::arg("fan_deg") = 0.0, py::arg("scanner") = py::none(),
      py::arg("estimate_plane") = "none", py::arg("repetitions") = py::none(),
      py::arg("fix") = py::none(), py::arg("auto_fix") = false, py::arg("sigma_mm") = 0.0,
      py::arg("solver") = "lm", py::arg("holdout") = py::none(), py::arg("predict_at") = py::none(),
      R"doc(
The arm's link values, the scanner's frame (target_x..z, scanner_roll, _pitch, _yaw) and the
planes' estimated terms from a line scanner's readings h (N, beams; m, one column per beam, the
fan as in simulate_scanner): `lrcal identify --sensor scanner`. q, plane, plane_of,
estimate_plane, repetitions, fix, auto_fix, sigma_mm, solver, holdout and predict_at as in
identify_contacts.
Returns an lrcal.Identification.)doc");
}

// One part of identify_mixed: the dict's "sensor" and that kind's arguments (as its own identify_*
// takes them), made without fix (the mixed kind holds the named terms).
struct MixedPy {
  std::shared_ptr<const MeasurementKind> kind;
  MeasuredValues values;
};

py::object PartArg(const py::dict& d, const char* key) {
  return d.contains(key) ? py::reinterpret_borrow<py::object>(d[key]) : py::none();
}

// The repetitions of a part (None: 1 per row of q).
std::vector<int> PartRepetitions(const py::dict& d, int rows) {
  const py::object r = PartArg(d, "repetitions");
  std::vector<int> out = r.is_none() ? std::vector<int>(static_cast<std::size_t>(rows), 1)
                                     : r.cast<std::vector<int>>();
  if (static_cast<int>(out.size()) != rows)
    throw InputError("repetitions", "expected one count per row of q");
  for (int v : out)
    if (v < 1) throw InputError("repetitions", "expected counts of at least 1");
  return out;
}

const std::set<std::string>& MixedPartKeys(const std::string& sensor) {
  static const std::map<std::string, std::set<std::string>> keys = {
      {"point", {"sensor", "q", "xyz", "instrument", "targets", "target_of", "repetitions"}},
      {"pose",
       {"sensor", "q", "xyz", "quaternion", "instrument", "targets", "target_of", "repetitions"}},
      {"socket", {"sensor", "q", "socket_of", "tool_point", "distances", "repetitions"}},
      {"contact",
       {"sensor", "q", "plane", "plane_of", "tool_point", "flush", "estimate_plane",
        "repetitions"}},
      {"scanner",
       {"sensor", "q", "h", "plane", "plane_of", "fan_deg", "scanner", "estimate_plane",
        "repetitions"}},
      {"ranger",
       {"sensor", "q", "h", "plane", "plane_of", "estimate_plane", "estimate_ranger",
        "repetitions"}}};
  const auto it = keys.find(sensor);
  if (it == keys.end())
    throw InputError("sensor", "'" + CellExcerpt(sensor) +
                                   "' is not a kind identify_mixed takes: expected ranger, point, "
                                   "pose, socket, contact or scanner");
  return it->second;
}

// A part's arguments besides the dict: the robot, its q, the plane terms asked for, the noise
// that weighs orientation rows.
struct MixedPartInput {
  const RobotFile& rig;
  const py::dict& d;
  Array q;
  std::string estimate_plane;
  double sigma, sigma_angle;
};

MixedPy TrackerPart(const std::string& sensor, const MixedPartInput& in) {
  const py::dict& d = in.d;
  std::unique_ptr<PointMeasurement> kind = ToTrackerKind(
      in.rig.robot, sensor, PartArg(d, "instrument"), PartArg(d, "targets"), py::none());
  if (!d.contains("xyz")) throw InputError("xyz", "missing: the measured points (N, 3), m");
  const TrackerFitArgs a{PartArg(d, "quaternion"),
                         py::none(),
                         py::none(),
                         py::none(),
                         PartArg(d, "repetitions"),
                         py::none(),
                         false,
                         0,
                         0,
                         "lm"};
  MixedPy out;
  out.values =
      ToTrackerValues(*kind,
                      ToTrackerConfigurations(in.rig.robot, in.q, PartArg(d, "target_of"),
                                              static_cast<int>(kind->setup().targets.size())),
                      d["xyz"].cast<Array>(), a);
  if (sensor == "pose") WeighAngleRows(*kind, in.sigma, in.sigma_angle, &out.values);
  out.kind = std::move(kind);
  return out;
}

MixedPy SocketPart(const MixedPartInput& in) {
  const SocketData data =
      ToSocketData(in.rig.robot, in.q, PartArg(in.d, "socket_of"), PartArg(in.d, "repetitions"));
  MixedPy out;
  out.kind = ToSocketKind(in.rig.robot, data, PartArg(in.d, "tool_point"),
                          PartArg(in.d, "distances"), py::none());
  out.values = data.values;
  return out;
}

// Configurations on planes (plane_of) with their repetitions, the values to be filled.
MeasuredValues OnPlanes(const MixedPartInput& in, const PlaneSet& planes) {
  MeasuredValues v{
      ToContactConfigurations(in.rig.robot, in.q, PartArg(in.d, "plane_of"), planes.size()),
      {},
      {}};
  v.repetitions = PartRepetitions(in.d, v.size());
  return v;
}

MixedPy ContactPart(const MixedPartInput& in) {
  const py::dict& d = in.d;
  const PlaneSet planes = ResolvePlanes(in.rig, PartArg(d, "plane"));
  const bool flush = d.contains("flush") && d["flush"].cast<bool>();
  std::unique_ptr<ContactMeasurement> kind =
      ToContactKind(in.rig.robot, planes,
                    {PartArg(d, "plane"), PartArg(d, "plane_of"), PartArg(d, "tool_point"),
                     py::none(), in.estimate_plane, flush});
  MixedPy out;
  out.values = OnPlanes(in, planes);
  out.values.y.assign(static_cast<std::size_t>(kind->rows_per_configuration() * out.values.size()),
                      0.0);
  if (flush) WeighAngleRows(*kind, in.sigma, in.sigma_angle, &out.values);
  out.kind = std::move(kind);
  return out;
}

MixedPy RangerPart(const MixedPartInput& in) {
  const py::dict& d = in.d;
  if (!d.contains("h")) throw InputError("h", "missing: the readings (N), m");
  const PlaneSet planes = ResolvePlanes(in.rig, PartArg(d, "plane"));
  const std::string ranger_terms =
      d.contains("estimate_ranger") ? d["estimate_ranger"].cast<std::string>() : "none";
  MixedPy out;
  out.kind = std::make_shared<RangerMeasurement>(
      MeasurementModel(in.rig.robot, planes,
                       ResolveParameters(in.rig.robot, planes.size(), in.estimate_plane,
                                         OtherTerms(ranger_terms), py::none())),
      in.rig.ranger);
  out.values = OnPlanes(in, planes);
  out.values.y = ToVector(d["h"].cast<Array>(), "h");
  if (static_cast<int>(out.values.y.size()) != out.values.size())
    throw InputError("h", "expected one reading (m) per row of q");
  return out;
}

MixedPy ScannerPart(const MixedPartInput& in) {
  const py::dict& d = in.d;
  if (!d.contains("h")) throw InputError("h", "missing: the readings (N, beams), m");
  const Array h = d["h"].cast<Array>();
  if (h.ndim() != 2)
    throw InputError("h", "expected an (N, beams) array of readings (m), one column per beam");
  const PlaneSet planes = ResolvePlanes(in.rig, PartArg(d, "plane"));
  std::unique_ptr<ScannerMeasurement> kind =
      ToScannerKind(in.rig, in.rig.robot, planes,
                    {PartArg(d, "plane"), PartArg(d, "plane_of"), PartArg(d, "scanner"), py::none(),
                     in.estimate_plane, static_cast<long long>(h.shape(1)),
                     d.contains("fan_deg") ? d["fan_deg"].cast<double>() : 0.0});
  MixedPy out;
  out.values = OnPlanes(in, planes);
  out.values.y = ToRows(h, kind->num_beams(), out.values.size(), "h");
  out.kind = std::move(kind);
  return out;
}

MixedPy ToMixedPart(const RobotFile& rig, const py::dict& d, double sigma, double sigma_angle) {
  if (!d.contains("sensor")) throw InputError("sensor", "missing: the part's kind");
  const std::string sensor = d["sensor"].cast<std::string>();
  const std::set<std::string>& allowed = MixedPartKeys(sensor);
  for (const auto& item : d) {
    const std::string key = item.first.cast<std::string>();
    if (!allowed.count(key)) throw InputError(key, "is not an argument of a " + sensor + " part");
  }
  if (!d.contains("q")) throw InputError("q", "missing: the part's configurations (N, joints)");
  const MixedPartInput in{
      rig,
      d,
      d["q"].cast<Array>(),
      d.contains("estimate_plane") ? d["estimate_plane"].cast<std::string>() : std::string("none"),
      sigma,
      sigma_angle};
  if (sensor == "point" || sensor == "pose") return TrackerPart(sensor, in);
  if (sensor == "socket") return SocketPart(in);
  if (sensor == "contact") return ContactPart(in);
  if (sensor == "ranger") return RangerPart(in);
  return ScannerPart(in);
}

// identify_mixed: as identify --sensor a,b with one data set per kind.
IdentificationSummary IdentifyMixedPy(const RobotFile& rig, const py::list& parts,
                                      const py::object& fix, bool auto_fix, double sigma_mm,
                                      double sigma_mrad, const std::string& solver) {
  const IdentificationOptions options = KindFitOptions(solver, sigma_mm, auto_fix);
  const double sigma = options.sigma > 0 ? options.sigma : NoiseModel{}.sigma;
  std::vector<std::shared_ptr<const MeasurementKind>> kinds;
  std::vector<MeasuredValues> values;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    try {
      MixedPy p = ToMixedPart(rig, parts[k].cast<py::dict>(), sigma, sigma_mrad * 1e-3);
      kinds.push_back(p.kind);
      values.push_back(std::move(p.values));
    } catch (const InputError& e) {
      throw InputError("parts[" + std::to_string(k) + "]." + e.where(),
                       std::string(e.what()).substr(e.where().empty() ? 0 : e.where().size() + 2));
    }
  }
  const MixedMeasurement mixed(PartsLabelledByKind(kinds));
  const std::vector<std::string> fixed = ToNames(fix);
  const std::unique_ptr<MeasurementKind> kind = mixed.Without(fixed);
  const MeasuredValues data = mixed.Combine(values);
  py::gil_scoped_release release;
  return Identify(*kind, data, options);
}

void DefineMixed(py::module_& m) {
  m.def("identify_mixed", &IdentifyMixedPy, py::arg("robot"), py::arg("parts"),
        py::arg("fix") = py::none(), py::arg("auto_fix") = false, py::arg("sigma_mm") = 0.0,
        py::arg("sigma_mrad") = 0.2, py::arg("solver") = "lm", R"doc(
Several kinds of data of one arm identified together: `lrcal identify --sensor a,b --data ...`.
parts is a list of dicts, one per kind, each with "sensor" ("ranger", "point", "pose", "socket",
"contact" or "scanner") and that kind's arguments as its own identify_* function takes them
(ranger: q, h, plane, plane_of, estimate_plane, estimate_ranger; point/pose: q,
xyz, quaternion, instrument, targets, target_of; socket: q, socket_of, tool_point, distances;
contact: q, plane, plane_of, tool_point, flush, estimate_plane; scanner: q, h, plane, plane_of,
fan_deg, scanner, estimate_plane; every kind: repetitions). The arm's link values, base/tool
frame terms and plane terms are shared; a kind's own term whose name another kind also has is
named with its kind ("point.target_x", "contact.target_x"; a kind given twice: "point1",
"point2"), and fix takes those names. auto_fix, sigma_mm, sigma_mrad (pose and flush-contact
orientation rows weigh (sigma_mm/sigma_mrad)^2) and solver as in identify_tracker. Returns an
lrcal.Identification; its configurations count the measured values, one entry each.)doc");
}

// identify_tree: as identify --tool-link a,b with one data set per chain.
IdentificationSummary IdentifyTreePy(const UrdfChains& tree, const py::list& parts,
                                     const py::object& fix, bool auto_fix, double sigma_mm,
                                     double sigma_mrad, const std::string& solver) {
  if (parts.size() != tree.chains.size())
    throw InputError("parts", "expected one dict per chain of the tree (" +
                                  std::to_string(tree.chains.size()) + "), got " +
                                  std::to_string(parts.size()));
  const IdentificationOptions options = KindFitOptions(solver, sigma_mm, auto_fix);
  const double sigma = options.sigma > 0 ? options.sigma : NoiseModel{}.sigma;
  std::vector<MixedPart> chains;
  std::vector<MeasuredValues> values;
  for (std::size_t c = 0; c < parts.size(); ++c) {
    try {
      MixedPy p = ToMixedPart(tree.chains[c], parts[c].cast<py::dict>(), sigma, sigma_mrad * 1e-3);
      auto chain = std::make_shared<ChainMeasurement>(p.kind, tree.placements[c]);
      p.values.configs = chain->RobotConfigurations(p.values.configs);
      chains.push_back({chain, tree.placements[c].label, true});
      values.push_back(std::move(p.values));
    } catch (const InputError& e) {
      throw InputError("parts[" + std::to_string(c) + "]." + e.where(),
                       std::string(e.what()).substr(e.where().empty() ? 0 : e.where().size() + 2));
    }
  }
  const MixedMeasurement mixed(std::move(chains));
  const std::unique_ptr<MeasurementKind> kind = mixed.Without(ToNames(fix));
  const MeasuredValues data = mixed.Combine(values);
  py::gil_scoped_release release;
  return Identify(*kind, data, options);
}

void DefineTree(py::module_& m) {
  py::class_<UrdfChains>(m, "Tree", R"doc(
A tree robot's chains from one base link to several tool links (a URDF's two arms on a torso, a
humanoid's leg and arms): Tree.load(path, tool_links, base_link=""). Each chain is an
lrcal.Robot (chains), the tree's joints are joint_names (the first chain's, then each later
chain's new ones), and link_labels says, per chain and link, the label its terms carry in a
joint fit ("" where every chain has the link).)doc")
      .def_static(
          "load",
          [](const std::string& path, const std::vector<std::string>& tool_links,
             const std::string& base_link) {
            return LoadRobotChains(ResolveRobotPath(path), tool_links, base_link);
          },
          py::arg("path"), py::arg("tool_links"), py::arg("base_link") = "", R"doc(
Reads the chains of the URDF at path from base_link (default: the root) to each of tool_links:
`lrcal identify --tool-link a,b`; or a robot YAML file's one chain whose links are coupled
(couple:), tool_links [] or [""]. Raises lrcal.InputError naming the file and link.)doc")
      .def_readonly("joint_names", &UrdfChains::joint_names, "The tree's joints, each once.")
      .def_property_readonly(
          "chains", [](const UrdfChains& t) { return t.chains; }, "Each chain as an lrcal.Robot.")
      .def_property_readonly(
          "tool_links", [](const UrdfChains& t) { return t.tool_links(); },
          "The chains' tool links, in order.")
      .def_property_readonly(
          "link_labels",
          [](const UrdfChains& t) {
            std::vector<std::vector<std::string>> labels;
            for (const ChainOfTree& c : t.placements) labels.push_back(c.link_labels);
            return labels;
          },
          "Per chain, per link: the label of its terms in a joint fit (\"\": shared by all).");
  m.def("identify_tree", &IdentifyTreePy, py::arg("tree"), py::arg("parts"),
        py::arg("fix") = py::none(), py::arg("auto_fix") = false, py::arg("sigma_mm") = 0.0,
        py::arg("sigma_mrad") = 0.2, py::arg("solver") = "lm", R"doc(
A tree's chains identified together: `lrcal identify --tool-link a,b --data A --data B`. tree is
an lrcal.Tree; parts a list of dicts, one per chain in its order, each as identify_mixed takes
a part ("sensor" and that kind's arguments; q holds the chain's own joints, in the order of
tree.chains[c]). The links every chain has, the base frame, the planes and what is fixed in the
world (a tracker's frame) are estimated once; a chain's own links and what its tool carries are
named with its tool link ("left_tool.theta4", "left_tool.target_x"), and fix takes those names.
auto_fix, sigma_mm, sigma_mrad and solver as in identify_mixed. Returns an
lrcal.Identification.)doc");
}

// compensate's targets: xyz (N, 3) with quaternion (N, 4) or not, or nominal's tool poses at q.
std::vector<Pose<double>> CompensationGoals(const RobotFile& rig, const ConfigurationSet& plans,
                                            const py::object& xyz, const py::object& quaternion,
                                            const py::object& nominal) {
  std::vector<Pose<double>> goals;
  if (!xyz.is_none()) {
    const std::vector<double> p = ToRows(xyz.cast<Array>(), 3, plans.size(), "xyz");
    const std::vector<double> r =
        quaternion.is_none() ? std::vector<double>{}
                             : ToRows(quaternion.cast<Array>(), 4, plans.size(), "quaternion");
    for (int i = 0; i < plans.size(); ++i) {
      Pose<double> pose;
      pose.p_BT = Eigen::Map<const Eigen::Vector3d>(&p[static_cast<std::size_t>(3 * i)]);
      if (!r.empty()) {
        pose.R_BT = UnitQuaternionRotation(&r[static_cast<std::size_t>(4 * i)],
                                           "quaternion[" + std::to_string(i) + "]");
      }
      goals.push_back(pose);
    }
  } else {
    if (!quaternion.is_none()) throw InputError("quaternion", "needs xyz, the target positions");
    if (nominal.is_none())
      throw InputError("nominal",
                       "missing: without xyz the targets are the nominal model's tool "
                       "poses at q: give that model");
    const RobotFile& plan_model = nominal.cast<const RobotFile&>();
    if (plan_model.robot.num_links() != rig.robot.num_links())
      throw InputError("nominal", "has another number of joints than robot");
    for (int i = 0; i < plans.size(); ++i)
      goals.push_back(ForwardKinematics<double>(
          plan_model.robot, plan_model.robot.nominal_values().data(), plans.q(i)));
  }
  return goals;
}

// compensate: as lrcal compensate.
py::dict CompensatePy(const RobotFile& rig, const Array& q, const py::object& xyz,
                      const py::object& quaternion, const py::object& nominal) {
  const ConfigurationSet plans = ToConfigurations(q, rig.robot.num_links(), "q");
  CheckJointRanges(plans, rig.robot, "q");
  const std::vector<Pose<double>> goals = CompensationGoals(rig, plans, xyz, quaternion, nominal);
  const bool orientation = xyz.is_none() || !quaternion.is_none();
  std::vector<Compensation> results;
  {
    py::gil_scoped_release release;
    for (int i = 0; i < plans.size(); ++i)
      results.push_back(
          Compensate(rig.robot, goals[static_cast<std::size_t>(i)], plans.q(i), orientation));
  }
  const int n = rig.robot.num_links();
  py::array_t<double> out({plans.size(), n});
  std::vector<double> position, turn;
  std::vector<bool> converged, within;
  for (int i = 0; i < plans.size(); ++i) {
    const Compensation& c = results[static_cast<std::size_t>(i)];
    for (int j = 0; j < n; ++j) out.mutable_at(i, j) = c.q[static_cast<std::size_t>(j)];
    position.push_back(c.position_error * 1e3);
    turn.push_back(c.orientation_error * 1e3);
    converged.push_back(c.converged);
    within.push_back(c.within_limits);
  }
  py::dict d;
  d["q"] = out;
  d["position_error_mm"] = ToArray(position);
  d["orientation_error_mrad"] = ToArray(turn);
  d["converged"] = converged;
  d["within_limits"] = within;
  return d;
}

void DefineCompensate(py::module_& m) {
  m.def("compensate", &CompensatePy, py::arg("robot"), py::arg("q"), py::arg("xyz") = py::none(),
        py::arg("quaternion") = py::none(), py::arg("nominal") = py::none(), R"doc(
Joint commands that reach planned tool poses on a calibrated arm: `lrcal compensate`. robot is
the calibrated robot (a robot file written by identify, or a calibrated URDF); q (N, joints) the
commands planned on the nominal model; the targets are xyz (N, 3; m, base frame) with optionally
quaternion (N, 4; qx, qy, qz, qw), or, without xyz, the tool poses of nominal (the robot the
plans were made on) at q. Damped least squares from q, the least joint motion reaching each
target. Returns a dict: q (N, joints) the compensated commands, position_error_mm and
orientation_error_mrad (what remains on the calibrated model), converged and within_limits (per
row).)doc");
}

// design()'s docstring.
constexpr const char* kDesignDoc = R"doc(
Chooses k of the candidate configurations pool (N, joints) by an observability criterion of the
identification Jacobian at the nominal model: `lrcal design --pool`, the same library call
(design/design_choice.h), numbers and checks.
criterion: E (= O3, σ_min), D, A, O1, O2, O4, O5, or I (the task criterion: the predicted RMS
position error at `poses` (M, joints), else at `workspace` poses drawn over the joint ranges).
method: exhaustive, greedy, backward, exchange, sampled, random. scaling of G's columns: si (the
paper), unit, expected (× expected_angle_mrad / expected_length_mm; expected_angle in rad and
expected_length in m are the earlier spellings). The choice is compared with `baseline` random
designs (Design.baseline) and certified (Design.certificate, Design.efficiency). Candidates whose
nominal beam misses the plane are left out (Design.rejected). Returns an lrcal.Design whose
indices are rows of `pool`; Design.json holds `lrcal design --format json`'s fields.
plane: None (the robot file's plane or planes), an lrcal.Plane, (nx, ny, nz, f) or a list of
lrcal.Plane; with several planes plane_of gives each candidate's plane (from 1, the pool CSV's
plane column). estimate_ranger: the ranger terms estimated (as --estimate-ranger).
sensor='point' or 'pose' (with instrument= and targets= as in identifiability) chooses a tracker's
configurations as blocks of 3 or 6 values from the whole pool (no beam to hit), holds the terms
the pool cannot separate at nominal (Design.held_at_nominal) and has no certificate, as
`lrcal design --sensor`. The other kinds likewise, from the candidates where they measure (the
others in Design.rejected with their reason): sensor='scanner' (beams=, fan_deg=, scanner= as in
identifiability; plane, plane_of, estimate_plane as for the ranger) keeps candidates with every
beam on its plane; sensor='contact' (tool_point=, flush=, the planes) and sensor='socket'
(socket_of= each candidate's socket id, tool_point=, socket_distances=) seat each candidate on the
nominal arm and keep those seated within the joint ranges; Design.indices are rows of `pool`,
whose seated configurations the campaign starts from.)doc";

// design(): choosing configurations for any sensor (design/design_choice.h).
void DefineDesign(py::module_& m) {
  m.def(
      "design",
      [](const RobotFile& rig, const Array& pool, int k, const std::string& criterion,
         const std::string& method, const std::string& scaling, const py::object& expected_angle,
         const py::object& expected_length, int restarts, int samples, long long seed,
         const py::object& plane, const std::string& estimate_plane, const py::object& fix,
         const py::object& poses, int workspace, int baseline, double expected_angle_mrad,
         double expected_length_mm, const py::object& plane_of, const std::string& estimate_ranger,
         const std::string& sensor, const py::object& instrument, const py::object& targets,
         long long beams, double fan_deg, const py::object& scanner, const py::object& tool_point,
         bool flush, const py::object& socket_of, const py::object& socket_distances) {
        return DesignPy(rig, pool, k, plane, estimate_plane, fix,
                        DesignArgs{criterion,
                                   method,
                                   scaling,
                                   expected_angle,
                                   expected_length,
                                   restarts,
                                   samples,
                                   seed,
                                   poses,
                                   workspace,
                                   baseline,
                                   expected_angle_mrad,
                                   expected_length_mm,
                                   plane_of,
                                   estimate_ranger,
                                   sensor,
                                   instrument,
                                   targets,
                                   beams,
                                   fan_deg,
                                   scanner,
                                   tool_point,
                                   flush,
                                   socket_of,
                                   socket_distances});
      },
      py::arg("robot"), py::arg("pool"), py::arg("k"), py::arg("criterion") = "E",
      py::arg("method") = "exchange", py::arg("scaling") = "si",
      py::arg("expected_angle") = py::none(), py::arg("expected_length") = py::none(),
      py::arg("restarts") =
          static_cast<int>(FindSetting(SelectionOptions::Settings(), "restarts")->Default()),
      py::arg("samples") =
          static_cast<int>(FindSetting(SelectionOptions::Settings(), "samples")->Default()),
      py::arg("seed") = 1, py::arg("plane") = py::none(), py::arg("estimate_plane") = "none",
      py::arg("fix") = py::none(), py::arg("poses") = py::none(),
      py::arg("workspace") =
          static_cast<int>(FindSetting(DesignRequest::Settings(), "workspace")->Default()),
      py::arg("baseline") =
          static_cast<int>(FindSetting(DesignRequest::Settings(), "baseline")->Default()),
      py::arg("expected_angle_mrad") =
          FindSetting(DesignRequest::Settings(), "expected_angle_mrad")->Default(),
      py::arg("expected_length_mm") =
          FindSetting(DesignRequest::Settings(), "expected_length_mm")->Default(),
      py::arg("plane_of") = py::none(), py::arg("estimate_ranger") = "none",
      py::arg("sensor") = "ranger", py::arg("instrument") = py::none(),
      py::arg("targets") = py::none(), py::arg("beams") = 1, py::arg("fan_deg") = 0.0,
      py::arg("scanner") = py::none(), py::arg("tool_point") = py::none(), py::arg("flush") = false,
      py::arg("socket_of") = py::none(), py::arg("socket_distances") = py::none(), kDesignDoc);
}

void DefineCalibration(py::module_& m) {
  DefineIdentifiability(m);
  DefineTrackers(m);
  DefineSockets(m);
  DefineContacts(m);
  DefineScanners(m);
  DefineMixed(m);
  DefineTree(m);
  DefineCompensate(m);
  DefineIdentify(m);
  DefineEnvironment(m);
  DefineDesign(m);
  m.def("prior_information", &PriorInformationPy, py::arg("robot"), py::arg("q"),
        py::arg("prior_sigma") = "", py::arg("prior") = false,
        py::arg("sigma_mm") = FindSetting(NoiseModel::Settings(), "sigma_mm")->Default(),
        py::arg("repetitions") =
            static_cast<long long>(FindSetting(NoiseModel::Settings(), "repetitions")->Default()),
        py::arg("plane") = py::none(), py::arg("estimate_plane") = "none",
        py::arg("fix") = py::none(), py::arg("plane_of") = py::none(),
        py::arg("estimate_ranger") = "none", R"doc(
What readings at the configurations q (N, joints) would tell against priors, before any reading
is taken: `lrcal identifiability --prior-sigma ... --sigma-mm S --repetitions R`'s table (plane,
plane_of, estimate_plane, estimate_ranger and fix as in identify).
prior_sigma as in identify ("theta=1mrad,a=0.5mm"); prior=True uses the robot file's
tolerances: (prior_sigma's entries replace the same keys). sigma_mm (> 0) and repetitions: the
noise of one reading and the readings averaged per configuration. Returns an
lrcal.PriorInformation: names, prior_sigma, posterior_sigma (SI, inf where unbounded),
posterior_to_prior (NaN without a prior), set_by_prior, defined; str() gives the table.)doc");
}

void DefineStudy(py::module_& m) {
  m.def("run_study", &RunStudyPy, py::arg("study"), py::arg("out_dir"), py::arg("threads") = 0,
        py::arg("progress") = py::none(), py::arg("shard") = py::none(), py::arg("max_trials") = 0,
        R"doc(
Runs (or resumes) a Monte-Carlo study, as `lrcal run STUDY --out OUT_DIR` does, and writes
OUT_DIR/tables/ when every trial is recorded. The same numbers, bit for bit, as the command line
whatever `threads` (0: all cores).

study: a study file or a shipped name ("quick", "paper"). shard: "i/N" to run one shard.
max_trials: stop after this many new trials (0: no limit); call again to continue.
progress: None or a callable taking an lrcal.RunProgress, called about every 0.1 s from this
thread. The trials run with the GIL released, so other Python threads keep running.
Ctrl-C (KeyboardInterrupt) or an exception raised by `progress` stops the run like the command
line's first Ctrl-C: finished trials are kept, and the exception is raised; run again to resume.
Returns an lrcal.RunResult. Read the results with lrcal.load_run(out_dir).)doc");
  m.def(
      "plan_accuracy",
      [](const std::string& study_arg, const std::string& target, double confidence,
         const std::string& cost, const std::optional<std::string>& configurations,
         const std::string& repetitions, const std::optional<std::string>& planes, int trials,
         double stop_precision, const std::optional<long long>& seed,
         const std::optional<std::string>& out_dir, int threads, const std::string& plan_on) {
        const Study study = LoadStudy(ResolveStudyPath(study_arg));
        AccuracyPlanOptions o;
        o.plan_on = ParsePlanBasis(plan_on);
        o.target = AccuracyTarget::Parse(target);
        o.confidence = confidence;
        o.cost = CampaignCosts::Parse(cost);
        if (configurations) o.configurations = *configurations;
        o.repetitions = repetitions;
        if (planes) o.planes = *planes;
        o.trials = trials;
        o.stop_precision = stop_precision;
        if (seed) o.seed = ToSeed(*seed);
        if (out_dir) o.out_dir = *out_dir;
        o.threads = threads;
        std::string json;
        {
          py::gil_scoped_release release;
          json = PlanAccuracy(study, o).ToJson().dump();
        }
        return py::module_::import("json").attr("loads")(json);
      },
      py::arg("study"), py::arg("target"),
      py::arg("confidence") =
          FindSetting(AccuracyPlanOptions::NumericSettings(), "confidence")->Default(),
      py::arg("cost") = CampaignCosts{}.ToString(), py::arg("configurations") = py::none(),
      py::arg("repetitions") = AccuracyPlanOptions{}.repetitions, py::arg("planes") = py::none(),
      py::arg("trials") = static_cast<int>(
          FindSetting(AccuracyPlanOptions::NumericSettings(), "trials")->Default()),
      py::arg("stop_precision") =
          FindSetting(AccuracyPlanOptions::NumericSettings(), "stop_precision")->Default(),
      py::arg("seed") = py::none(), py::arg("out_dir") = py::none(), py::arg("threads") = 0,
      py::arg("plan_on") = NameOf(kPlanBasisNames, AccuracyPlanOptions{}.plan_on), R"doc(
The cheapest campaign that meets an accuracy target, as `lrcal plan-accuracy STUDY --target ...`
(report/accuracy_plan.h: the same search, confirmation run and numbers). target: e.g.
"rms_pos=0.05mm" (also rms_ori, max_pos, max_ori, with mm or mrad); cost:
"configuration=30s,reading=1s[,plane=600s]"; configurations, repetitions, planes: FIRST:LAST[:STEP]
ranges; plan_on: "total" (the reading noise's part plus every term held at nominal at its
tolerance) or "data" (the reading noise's part alone). Returns the plan as `--format json` prints
it: a dict with target, plan_on, defaulted and taken_as_exact (held terms with lrcal's default
tolerance, frame terms taken as exact), search_seconds, campaigns (label, configurations,
repetitions, cost_seconds, predicted (of the plan's basis), predicted_total, predicted_data and
monte_carlo in the target's unit, meets_target, ...), study and run (the confirmation study file
and run folder).)doc");
}

// --- one function per command (the command's library call, its JSON as Python objects) -------

// `planes`: None (the robot file's, one or several), an lrcal.Plane, four numbers, or a list of
// planes.
PlaneSet ResolvePlanes(const RobotFile& rig, const py::object& planes) {
  if (planes.is_none()) {
    if (rig.planes) return *rig.planes;
    throw InputError("plane", "the robot file '" + rig.path +
                                  "' has no plane: pass plane=lrcal.Plane((nx, ny, nz), f)");
  }
  if (py::isinstance<py::list>(planes) && py::len(planes) > 0 &&
      py::isinstance<Plane>(planes.cast<py::list>()[0])) {
    std::vector<Plane> list;
    for (const py::handle p : planes.cast<py::list>()) list.push_back(p.cast<Plane>());
    return PlaneSet(std::move(list), {}, "plane");
  }
  return PlaneSet(ToPlane(planes));
}

py::object KinematicsPy(const RobotFile& rig, const Array& q, const std::string& which,
                        const py::object& plane, const std::string& estimate_plane,
                        const std::string& estimate_ranger, const py::object& fix, bool jacobian) {
  if (which != "nominal" && which != "true")
    throw InputError("model", "expected 'nominal' or 'true', got '" + which + "'");
  const PlaneSet planes = ResolvePlanes(rig, plane);
  const TargetedConfigurations configs(ToConfigurations(q, rig.robot.num_links(), "q"));
  CheckJointRanges(configs, rig.robot, "q");
  const ParameterSet ps =
      ResolveParameters(rig.robot, planes.size(), estimate_plane, estimate_ranger, fix);
  return FromJson(
      ReportKinematics(rig, planes, ps, which == "true", configs, jacobian).rows.dump());
}

py::object AccuracyPy(const RobotFile& rig, const py::object& poses, const py::object& workspace,
                      long long seed, const py::object& plane) {
  if (poses.is_none() == workspace.is_none())
    throw InputError("poses/workspace",
                     "give exactly one: poses (M, joints) or a number of "
                     "poses to draw over the joint ranges");
  const PlaneSet planes = ResolvePlanes(rig, plane);
  ConfigurationSet configs(rig.robot.num_links());
  if (!poses.is_none()) {
    configs = ToConfigurations(poses.cast<Array>(), rig.robot.num_links(), "poses");
    CheckJointRanges(configs, rig.robot, "poses");
  } else {
    configs = WorkspacePoses(rig.robot, workspace.cast<int>(), ToSeed(seed));
  }
  AccuracyPrediction predicted;
  {
    py::gil_scoped_release release;
    predicted = PredictCalibratedAccuracy(rig, planes, configs);
  }
  ResultJson j = PoseAccuracyJson(predicted, configs);
  j["sigma"] = rig.calibration->sigma;
  if (!workspace.is_none()) j["workspace"] = {{"poses", configs.size()}, {"seed", seed}};
  return FromJson(j.dump());
}

void DefineCommands(py::module_& m) {
  m.def("kinematics", &KinematicsPy, py::arg("robot"), py::arg("q"), py::arg("model") = "nominal",
        py::arg("plane") = py::none(), py::arg("estimate_plane") = "none",
        py::arg("estimate_ranger") = "none", py::arg("fix") = py::none(),
        py::arg("jacobian") = false, R"doc(
Tool pose, beam and laser reading per configuration q (M, joints, rad), as `lrcal kinematics
--format json`: a list of dicts with q, position (m), rotation (3x3), beam, h (m; None when the
beam misses), status and, with jacobian=True, jacobian {parameter: dh/de}. model: "nominal" or
"true" (the robot file's simulated true values). plane: None (the robot file's planes), an
lrcal.Plane, four numbers or a list of planes; estimate_plane, estimate_ranger, fix as in identify.
Joint values outside the robot's joint ranges are refused (degrees for rad?).)doc");
  m.def("accuracy", &AccuracyPy, py::arg("robot"), py::arg("poses") = py::none(),
        py::arg("workspace") = py::none(), py::arg("seed") = 1, py::arg("plane") = py::none(),
        R"doc(
The predicted accuracy of a calibrated robot file (written by identify --write-robot) at poses
(M, joints, rad) or at `workspace` poses drawn over the joint ranges (seed), as `lrcal accuracy
--format json`: a dict with poses [{q, position_std (m), orientation_std (rad),
position_radius_95 (m)}], rms_position, p95_position_radius_95, worst (1-based) and sigma (m).)doc");
  m.def(
      "export",
      [](const RobotFile& rig, const std::string& format, const py::object& plane) {
        return RobotExportText(
            rig, format,
            plane.is_none() ? rig.planes : std::optional<PlaneSet>(ResolvePlanes(rig, plane)));
      },
      py::arg("robot"), py::arg("format") = "urdf", py::arg("plane") = py::none(), R"doc(
The robot (its nominal values: a calibrated file's are the estimates) as text for the robot's
software, as `lrcal export --format`: "urdf", "dh-table" (CSV) or "yaml" (a robot file with its
calibration record; plane: the planes to write instead of the file's).)doc");
  m.def(
      "plan",
      [](const std::string& study, int threads) {
        const Study s = LoadStudy(ResolveStudyPath(study));
        std::string json;
        {
          py::gil_scoped_release release;
          json = PlanStudy(s, threads).ToJson().dump();
        }
        return FromJson(json);
      },
      py::arg("study"), py::arg("threads") = 0, R"doc(
A dry run of a study, as `lrcal plan --format json`: every cell prepared and a few trials timed.
Returns a dict with study, threads, total_trials, estimate_seconds and cells [{label, id, trials,
prepare_seconds, seconds_per_trial, estimate_seconds, settings}].)doc");
  m.def(
      "paper",
      [](const RobotFile& rig, long long seed, const std::string& case1_selection, int samples) {
        PaperCaseOptions options;
        options.seed = ToSeed(seed);
        options.case1_selection.method = ParseSelectionMethod(case1_selection, "case1_selection");
        options.case1_selection.samples = samples;
        options.case1_selection.Validate();
        std::string json, text;
        {
          py::gil_scoped_release release;
          const PaperCasesResult r = RunPaperCases(rig, options);
          json = PaperCasesJson(r, options).dump();
          text = PaperCasesText(rig.robot, r, options);
        }
        py::dict out = FromJson(json);
        out["text"] = text;
        return out;
      },
      py::arg("robot"), py::arg("seed") = 1, py::arg("case1_selection") = "backward",
      py::arg("samples") =
          static_cast<int>(FindSetting(SelectionOptions::Settings(), "samples")->Default()),
      R"doc(
The paper's case 1 and case 2, one realisation, as `lrcal paper --format json`: on the robot
file's arm, its simulated truth and its one plane, a pool of 101 candidates, case 1 choosing 50
(case1_selection: backward, exchange, greedy, sampled as the paper did with `samples` random
subsets, or random) and case 2 100 by E-optimality, each identified and validated. Returns the
command's JSON as a dict (per case the selection, termination, estimates in SI with their standard
deviations, the validation metrics) and "text", the command's tables beside the slides'.)doc");
}

// A run directory's commands: replay a trial, its status, its report.
void DefineRunCommands(py::module_& m) {
  m.def(
      "replay_trial",
      [](const std::string& run_dir, const std::string& cell, long long trial) {
        std::string json, text;
        {
          py::gil_scoped_release release;
          const TrialReplay t = ReplayTrial(run_dir, cell, trial);
          json = t.ToJson().dump();
          text = t.ToText();
        }
        py::dict out = FromJson(json);
        out["text"] = text;
        return out;
      },
      py::arg("run_dir"), py::arg("cell"), py::arg("trial"), R"doc(
Replays one recorded trial of a run, as `lrcal trial RUN_DIR --cell CELL --trial N --format json`:
a dict with the recomputed record, whether it is identical to the stored one (identical,
differences), the failure's reason, every configuration with its mean reading and residuals, and
the estimate (SI); "text" holds the command's text output. cell: its id or label.)doc");
  m.def(
      "status",
      [](const std::string& run_dir) {
        const RunStatusInfo info = GetRunStatus(run_dir);
        py::dict out = FromJson(info.json.dump());
        out["text"] = info.text;
        return out;
      },
      py::arg("run_dir"), R"doc(
A run directory's progress, as `lrcal status RUN_DIR --format json`: a dict with done and total
trials, complete, cells [{id, label, done, total, stopped_early}], last_session {start, end,
state (running, stopped: its process is gone, completed, interrupted, max_trials, ...),
trials_computed, seconds, trials_per_second}, to_finish and report (the commands that finish or
report it) and "text", the command's text. Safe on a run in progress.)doc");
}

// Shard run directories merged, and a run's tables rewritten.
void DefineMergeCommands(py::module_& m) {
  m.def(
      "merge",
      [](const std::vector<std::string>& shards, const std::string& out) {
        std::string json, text;
        bool complete = false;
        {
          py::gil_scoped_release release;
          const MergeOutcome merged = MergeRunsAndReport(shards, out);
          json = merged.status.json.dump();
          text = merged.text;
          complete = merged.complete;
        }
        py::dict d;
        d["complete"] = complete;
        d["status"] = FromJson(json);
        d["text"] = text;
        return d;
      },
      py::arg("shards"), py::arg("out"), R"doc(
Combines shard run directories into the run directory `out`, as `lrcal merge SHARD... --out OUT`:
when every trial of the study is there the tables are written. Returns a dict: complete (whether
they were), status (lrcal.status of `out`) and "text", the command's output (with the shards to
finish when not complete).)doc");
  m.def(
      "aggregate",
      [](const std::string& run_dir) {
        {
          py::gil_scoped_release release;
          WriteRunTables(run_dir);
        }
        return run_dir + "/tables/summary.md";
      },
      py::arg("run_dir"), R"doc(
Rewrites the tables of a run directory from its trial store, as `lrcal aggregate RUN_DIR`; returns
the path of its summary.md.)doc");
}

// The report's helpers for the package's Python part (lrcal.report).
void DefineReportHelpers(py::module_& m) {
  m.def(
      "_prepare_report",
      [](const std::string& run_dir) {
        const ReportData d = PrepareReportData(run_dir);
        return py::dict(py::arg("dir") = d.dir, py::arg("done") = d.done,
                        py::arg("expected") = d.expected, py::arg("complete") = d.complete,
                        py::arg("note") = d.note);
      },
      py::arg("run_dir"));
  m.def(
      "_remove_report_snapshot",
      [](const std::string& dir) {
        ReportData d;
        d.dir = dir;
        RemoveReportSnapshot(d);
      },
      py::arg("report_dir"));
}

}  // namespace

}  // namespace lrcal::python

PYBIND11_MODULE(_lrcal, m) {
  namespace lp = lrcal::python;
  m.doc() = "lrcal's C++ core (see the package lrcal for the documented interface).";
  lp::RegisterErrors(m);
  lp::DefineRig(m);
  lp::DefineRobot(m);
  lp::DefineResults(m);
  lp::DefinePriorInformation(m);
  lp::DefineIdentification(m);
  lp::DefineRun(m);
  lp::DefineKinematics(m);
  lp::DefineCalibration(m);
  lp::DefineStudy(m);
  lp::DefineCommands(m);
  lp::DefineRunCommands(m);
  lp::DefineMergeCommands(m);
  lp::DefineReportHelpers(m);
  m.def("set_data_directory", &lrcal::SetEmbeddedDataDirectory, py::arg("path"),
        "Registers where lrcal's shipped data is (the package does this on import).");
  m.def(
      "data_directory", [] { return lrcal::DataDirectory(); },
      "The folder of lrcal's shipped robots, studies and analysis scripts ($LRCAL_DATA_DIR "
      "overrides).");
  m.attr("__version__") = LRCAL_VERSION;
}
