#include "lrcal/io/calibration_record.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <sstream>

#include "lrcal/build_info.h"
#include "lrcal/core/error.h"
#include "lrcal/core/hash.h"
#include "lrcal/core/json.h"
#include "lrcal/core/settings.h"
#include "lrcal/measurement/contact_measurement.h"
#include "lrcal/measurement/pose_measurement.h"
#include "lrcal/measurement/scanner_measurement.h"
#include "lrcal/measurement/socket_measurement.h"

namespace lrcal {

DataSource DataSource::File(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return {path, HashHex(bytes.str())};
}

CalibrationRecord MakeCalibrationRecord(const DataSource& data, const IdentificationSummary& s,
                                        const IdentificationOptions& options,
                                        const UnestimatedTerms& held) {
  CalibrationRecord r;
  r.data_file = data.name;
  r.data_fnv1a = data.fnv1a;
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &utc);
  r.date = date;
  r.lrcal = std::string(LRCAL_VERSION) + " (" + LRCAL_GIT_COMMIT + ")";
  const SigmaUsed used = ChooseSigma(s, options);
  r.sigma = used.sigma;
  r.sigma_source = used.source == "given" ? "given (--sigma-mm)"
                   : options.sigma > 0    ? "residual (sigma_hat; the chi-squared check rejected "
                                            "the given sigma)"
                                          : "residual (sigma_hat)";
  r.parameters = s.names;
  r.estimate = s.estimate;
  if (std::isfinite(used.sigma)) r.covariance = CovarianceFor(s, used);
  r.held = held.names;
  r.held_sigma = held.sigma;
  r.held_defaulted = held.defaulted;
  r.estimate_shift = held.estimate_shift;
  return r;
}

namespace {

// The link terms a tracker's fit held (every link value the robot marks, not in s.names): their σ
// from the rig's tolerances or the defaults, and S = ∂ê/∂u over all of the fit's terms (its
// instrument and targets included) at the estimate, as FindUnestimatedTerms does for the ranger.
UnestimatedTerms TrackerHeldTerms(const RobotFile& rig, const MeasurementKind& kind,
                                  const MeasuredValues& values, const IdentificationSummary& s,
                                  const IdentificationOptions& options) {
  const RobotModel& robot = rig.robot;
  // Every term of the kind, nothing fixed: the columns of the estimated and the held terms.
  std::unique_ptr<MeasurementKind> unfixed;
  if (const auto* socket = dynamic_cast<const SocketMeasurement*>(&kind)) {
    unfixed = std::make_unique<SocketMeasurement>(socket->robot(), socket->setup());
  } else if (const auto* contact = dynamic_cast<const ContactMeasurement*>(&kind)) {
    unfixed = std::make_unique<ContactMeasurement>(contact->robot(), contact->setup());
  } else if (const auto* scanner = dynamic_cast<const ScannerMeasurement*>(&kind)) {
    unfixed = std::make_unique<ScannerMeasurement>(scanner->robot(), scanner->setup());
  } else {
    const auto& point = dynamic_cast<const PointMeasurement&>(kind);
    unfixed = dynamic_cast<const PoseMeasurement*>(&kind)
                  ? std::make_unique<PoseMeasurement>(point.robot(), point.setup())
                  : std::make_unique<PointMeasurement>(point.robot(), point.setup());
  }
  const MeasurementKind& full = *unfixed;
  const std::vector<std::string>& names = full.parameter_names();
  std::vector<int> est, held;
  UnestimatedTerms out;
  const DefaultTolerances defaults;
  for (int c = 0; c < static_cast<int>(names.size()); ++c) {
    const bool estimated = std::find(s.names.begin(), s.names.end(), names[c]) != s.names.end();
    if (estimated) {
      est.push_back(c);
    } else if (robot.FindValue(names[c]) >= 0) {
      held.push_back(c);
      out.names.push_back(names[c]);
    }
  }
  const int k = static_cast<int>(held.size()), n = static_cast<int>(s.names.size());
  out.sigma.resize(k);
  for (int c = 0; c < k; ++c) {
    out.sigma[c] = rig.tolerances.SigmaOf(out.names[c]);
    if (!(out.sigma[c] > 0)) {
      out.sigma[c] = defaults.Of(out.names[c]);
      out.defaulted.push_back(out.names[c]);
    }
  }
  out.estimate_shift = Eigen::MatrixXd::Zero(n, k);
  if (k == 0) return out;
  Eigen::VectorXd e_all = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(names.size()));
  for (int i = 0; i < n; ++i) {
    const auto it = std::find(names.begin(), names.end(), s.names[i]);
    e_all[it - names.begin()] = s.delta[i];
  }
  const Eigen::MatrixXd G_all = MeasurementJacobian(full, values.configs, e_all.data());
  const std::vector<double> rows = values.RowWeights(full.rows_per_configuration());
  const Eigen::VectorXd w = Eigen::Map<const Eigen::VectorXd>(rows.data(), rows.size());
  // The fit's columns in s.names' order.
  Eigen::MatrixXd G(G_all.rows(), n), Gu(G_all.rows(), k);
  for (int i = 0; i < n; ++i) {
    const auto it = std::find(names.begin(), names.end(), s.names[i]);
    G.col(i) = G_all.col(it - names.begin());
  }
  for (int c = 0; c < k; ++c) Gu.col(c) = G_all.col(held[c]);
  // With priors the fit solved the augmented rows (prior.h): their weights (σ/σ_k)² join the
  // normal matrix, so a term only the prior sets still has a finite shift.
  Eigen::MatrixXd A = G.transpose() * w.asDiagonal() * G;
  if (!options.priors.empty()) {
    const Eigen::VectorXd prior = options.priors.SigmasOf(s.names);
    for (int i = 0; i < n; ++i)
      if (prior[i] > 0) A(i, i) += (options.sigma / prior[i]) * (options.sigma / prior[i]);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
  if (ldlt.info() != Eigen::Success)
    throw std::logic_error("tracker record: the estimated terms' normal matrix is singular");
  out.estimate_shift = ldlt.solve(G.transpose() * w.asDiagonal() * Gu);
  return out;
}

}  // namespace

namespace {

// A kind's fit as the arm's calibration: the estimated link values and the record of the link
// terms alone (WriteTrackerCalibratedRobot).
struct ArmCalibration {
  Eigen::VectorXd link_values;
  CalibrationRecord record;
};

ArmCalibration ArmCalibrationOf(const DataSource& data, const RobotFile& rig,
                                const MeasurementKind& kind, const MeasuredValues& values,
                                const IdentificationSummary& s,
                                const IdentificationOptions& options) {
  const RobotModel& robot = rig.robot;
  ArmCalibration out{robot.nominal_values(), {}};
  const UnestimatedTerms held = TrackerHeldTerms(rig, kind, values, s, options);
  const CalibrationRecord all = MakeCalibrationRecord(data, s, options, held);
  std::vector<Eigen::Index> links;
  for (std::size_t k = 0; k < s.names.size(); ++k) {
    const int index = robot.FindValue(s.names[k]);
    if (index < 0) continue;  // the instrument's, the targets' and the sockets' terms
    links.push_back(static_cast<Eigen::Index>(k));
    out.link_values[index] = s.estimate[static_cast<Eigen::Index>(k)];
  }
  CalibrationRecord& record = out.record;
  record = all;
  record.parameters.clear();
  record.estimate.resize(static_cast<Eigen::Index>(links.size()));
  for (std::size_t k = 0; k < links.size(); ++k) {
    record.parameters.push_back(s.names[static_cast<std::size_t>(links[k])]);
    record.estimate[static_cast<Eigen::Index>(k)] = all.estimate[links[k]];
  }
  if (all.covariance.size() > 0) record.covariance = all.covariance(links, links);
  if (all.estimate_shift.size() > 0) record.estimate_shift = all.estimate_shift(links, Eigen::all);
  return out;
}

}  // namespace

void WriteTrackerCalibratedRobot(const std::string& path, const DataSource& data,
                                 const RobotFile& rig, const MeasurementKind& kind,
                                 const MeasuredValues& values, const IdentificationSummary& s,
                                 const IdentificationOptions& options) {
  const ArmCalibration arm = ArmCalibrationOf(data, rig, kind, values, s, options);
  const std::string header =
      "# A calibrated robot: written by lrcal identify --sensor " + std::string(kind.name()) +
      " --write-robot from " + data.name +
      ".\n# Nominal values are the estimates (SI: rad, m); the record below says "
      "from what (the arm's terms; the instrument's frame, the targets and the sockets are the "
      "campaign's).\n";
  WriteFileAtomically(path,
                      header + RobotFileText(rig, arm.link_values, rig.planes,
                                             rig.robot.name() + " (calibrated)", &arm.record));
}

RobotFile TrackerCalibratedRobot(const DataSource& data, const RobotFile& rig,
                                 const MeasurementKind& kind, const MeasuredValues& values,
                                 const IdentificationSummary& s,
                                 const IdentificationOptions& options) {
  ArmCalibration arm = ArmCalibrationOf(data, rig, kind, values, s, options);
  std::vector<Link> links = rig.robot.links();
  for (std::size_t i = 0; i < links.size(); ++i)
    for (int v = 0; v < kValuesPerLink; ++v)
      links[i].nominal[static_cast<std::size_t>(v)] =
          arm.link_values[static_cast<Eigen::Index>(kValuesPerLink * i) + v];
  RobotFile out = rig;
  out.robot = RobotModel(rig.robot.name() + " (calibrated)", std::move(links), rig.robot.source,
                         rig.robot.base(), rig.robot.tool());
  out.robot.source = rig.robot.source;
  out.calibration = std::move(arm.record);
  out.truth = {};
  out.tolerances = {};
  return out;
}

void WriteCalibratedRobot(const std::string& path, const DataSource& data, const RobotFile& rig,
                          const MeasurementModel& model, const IdentificationSummary& s,
                          const IdentificationOptions& options, const UnestimatedTerms& held) {
  const MeasurementModel solved = SolvedModel(model, s);
  // Estimated base and tool terms become the calibrated file's base: and tool: transforms.
  RobotFile calibrated = rig;
  if (solved.parameters().EstimatesFrames()) calibrated.robot = solved.RobotAt(s.delta.data());
  WriteCalibratedRobotFile(path, calibrated, solved.LinkValues(s.delta.data()),
                           solved.PlanesAt(s.delta.data()),
                           MakeCalibrationRecord(data, s, options, held));
}

ParameterSet RecordParameterSet(const RobotModel& robot, const CalibrationRecord& r, int num_planes,
                                const std::string& source) {
  const auto named = [&](const std::string& name) {
    return std::find(r.parameters.begin(), r.parameters.end(), name) != r.parameters.end();
  };
  std::vector<PlaneTerms> planes(num_planes);
  std::vector<std::string> fixed;
  for (int p = 0; p < num_planes; ++p) {
    const std::string u1 = PlaneTermName(p, num_planes, "u1"),
                      u2 = PlaneTermName(p, num_planes, "u2");
    planes[p].normal = named(u1) || named(u2);
    planes[p].offset = named(PlaneTermName(p, num_planes, "f"));
    if (planes[p].normal && !named(u1)) fixed.push_back(u1);
    if (planes[p].normal && !named(u2)) fixed.push_back(u2);
  }
  RangerTerms ranger;
  ranger.offset = named("ranger_offset");
  ranger.scale = named("ranger_scale");
  for (int k : robot.parameter_indices())
    if (!named(robot.ValueName(k))) fixed.push_back(robot.ValueName(k));
  FrameTerms frames[2];
  for (int f = 0; f < 2; ++f)
    for (int k = 0; k < 6; ++k) frames[f].estimated[k] = named(FrameTermName(f, k));
  return MakeParameterSet(robot, planes, fixed, source, ranger, frames[0], frames[1]);
}

namespace {

// Where each of `ps`'s names is among the record's parameters (InputError naming `source` when
// the record names a parameter `ps` lacks or misses one).
std::vector<int> RecordOrder(const CalibrationRecord& r, const ParameterSet& ps,
                             const std::string& source) {
  const int n = ps.size();
  if (n != static_cast<int>(r.parameters.size()))
    throw InputError(source, "names a parameter this robot does not have");
  std::vector<int> at(n);
  for (int k = 0; k < n; ++k) {
    at[k] = -1;
    for (int i = 0; i < n; ++i)
      if (r.parameters[i] == ps.names[k]) at[k] = i;
    if (at[k] < 0) throw InputError(source, "missing " + ps.names[k]);
  }
  return at;
}

}  // namespace

Eigen::MatrixXd RecordCovariance(const CalibrationRecord& r, const ParameterSet& ps,
                                 const std::string& source) {
  const int n = ps.size();
  const std::vector<int> at = RecordOrder(r, ps, source);
  Eigen::MatrixXd C(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) C(a, b) = r.covariance(at[a], at[b]);
  return C;
}

AccuracyPrediction PredictCalibratedAccuracy(const RobotFile& rig, const PlaneSet& planes,
                                             const ConfigurationSet& poses) {
  if (!rig.calibration || rig.calibration->covariance.size() == 0)
    throw SettingError(SettingSpec::Named("setup", "robot", "robot", "a calibrated robot file"),
                       "'" + rig.path +
                           "' has no calibration record with a covariance: write one with lrcal "
                           "identify --write-robot (give sigma_mm, or more configurations than "
                           "parameters)");
  const CalibrationRecord& r = *rig.calibration;
  const std::string source = rig.path + " calibration.parameters";
  const ParameterSet ps = RecordParameterSet(rig.robot, r, planes.size(), source);
  const Eigen::MatrixXd C = RecordCovariance(r, ps, source);
  const MeasurementModel model(rig.robot, planes, ps);
  UnestimatedTerms held;
  held.names = r.held;
  held.sigma = r.held_sigma;
  held.defaulted = r.held_defaulted;
  held.estimate_shift = r.held.empty() ? Eigen::MatrixXd(ps.size(), 0) : r.estimate_shift;
  const ParameterSet all = CompleteParameterSet(rig.robot, planes.size());
  for (const std::string& name : all.names)  // neither estimated nor held: taken as exact
    if (IsFrameTermName(name) && ps.Find(name) < 0 &&
        std::find(held.names.begin(), held.names.end(), name) == held.names.end())
      held.exact.push_back(name);
  for (const std::string& name : held.names)
    if (all.Find(name) < 0 || ps.Find(name) >= 0)
      throw InputError(rig.path + " calibration.held",
                       "'" + name + "' is not a term this set-up holds at nominal");
  // The shift's rows follow the record's parameters; reorder them like the covariance.
  if (!held.empty()) {
    const std::vector<int> at = RecordOrder(r, ps, source);
    for (int a = 0; a < ps.size(); ++a) held.estimate_shift.row(a) = r.estimate_shift.row(at[a]);
  }
  const std::vector<double> zero(ps.size(), 0.0);  // the file's nominal values are the estimates
  AccuracyPrediction p = PredictTotalAccuracy(model, zero.data(), C, held, poses);
  p.sigma_used.sigma = r.sigma;
  p.sigma_used.source = r.sigma_source.rfind("given", 0) == 0 ? "given" : "residual";
  p.sigma_used.reason =
      r.sigma_source.empty() ? "the record's sigma" : "the record's sigma: " + r.sigma_source;
  return p;
}

}  // namespace lrcal
