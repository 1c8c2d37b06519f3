// lrcal compensate: the commands a controller planned on the nominal model, corrected so that
// the calibrated arm reaches the tool poses they were planned for (kinematics/compensation.h).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>

#include "cli_common.h"
#include "lrcal/core/json.h"
#include "lrcal/io/compensation_data.h"
#include "lrcal/io/urdf.h"

namespace lrcal::cli {

namespace {

// What the summary says: how far the plans miss on the calibrated arm before, what remains, how
// much the commands move, which are outside their ranges.
struct CompensationSummary {
  int count = 0, converged = 0;
  double miss_rms = 0, miss_worst = 0;               // m, before compensation
  double position_worst = 0, orientation_worst = 0;  // m, rad, after
  double largest_change = 0;                         // rad (or m)
  std::vector<int> outside;                          // 1-based rows
  std::vector<int> unreached;                        // 1-based rows
};

CompensationSummary Summarise(const RobotModel& calibrated, const CompensationTargets& targets,
                              const std::vector<Pose<double>>& goals,
                              const std::vector<Compensation>& results) {
  CompensationSummary s;
  s.count = static_cast<int>(results.size());
  double sum = 0;
  for (int i = 0; i < s.count; ++i) {
    const auto u = static_cast<std::size_t>(i);
    const Compensation& c = results[u];
    const Pose<double> before = ForwardKinematics<double>(
        calibrated, calibrated.nominal_values().data(), targets.plans.q(i));
    const double miss = (before.p_BT - goals[u].p_BT).norm();
    sum += miss * miss;
    s.miss_worst = std::max(s.miss_worst, miss);
    s.position_worst = std::max(s.position_worst, c.position_error);
    s.orientation_worst = std::max(s.orientation_worst, c.orientation_error);
    for (int j = 0; j < calibrated.num_links(); ++j)
      s.largest_change =
          std::max(s.largest_change,
                   std::abs(std::remainder(c.q[static_cast<std::size_t>(j)] - targets.plans.q(i)[j],
                                           2 * 3.141592653589793)));
    if (c.converged) ++s.converged;
    if (!c.converged) s.unreached.push_back(i + 1);
    if (!c.within_limits) s.outside.push_back(i + 1);
  }
  s.miss_rms = s.count ? std::sqrt(sum / s.count) : 0;
  return s;
}

std::string Rows(const std::vector<int>& rows) {
  std::string out;
  for (std::size_t k = 0; k < rows.size() && k < 20; ++k)
    out += (k ? ", " : "") + std::to_string(rows[k]);
  return rows.size() > 20 ? out + ", ..." : out;
}

// The tool poses to reach: the file's, or the nominal model's at the planned commands.
std::vector<Pose<double>> Goals(const CompensationTargets& targets,
                                const std::optional<RobotFile>& nominal, const std::string& file) {
  std::vector<Pose<double>> goals = targets.poses;
  if (!goals.empty()) return goals;
  if (!nominal)
    throw InputError("--nominal", "missing: " + file +
                                      " gives no target poses (x, y, z), so the targets are the "
                                      "nominal model's tool poses at its commands: name that "
                                      "model with --nominal");
  for (int i = 0; i < targets.plans.size(); ++i)
    goals.push_back(ForwardKinematics<double>(
        nominal->robot, nominal->robot.nominal_values().data(), targets.plans.q(i)));
  return goals;
}

// The summary on standard error (the commands go to standard output or --out).
void PrintSummary(const po::variables_map& vm, const CompensationSummary& s, bool orientation) {
  if (ResolveFormat(vm) == Format::kJson) {
    std::cerr << Json{{"targets", s.count},
                      {"reached", s.converged},
                      {"orientation", orientation},
                      {"miss_before_rms_mm", s.miss_rms * 1e3},
                      {"miss_before_worst_mm", s.miss_worst * 1e3},
                      {"position_error_worst_mm", s.position_worst * 1e3},
                      {"orientation_error_worst_mrad", s.orientation_worst * 1e3},
                      {"largest_command_change_mrad", s.largest_change * 1e3},
                      {"outside_limits", s.outside},
                      {"unreached", s.unreached}}
                     .dump(2)
              << "\n";
  } else {
    std::cerr << "lrcal compensate: " << s.count << " targets ("
              << (orientation ? "tool poses" : "tool positions") << "); uncompensated, the "
              << "calibrated arm misses them by " << s.miss_rms * 1e3 << " mm RMS ("
              << s.miss_worst * 1e3 << " mm worst); compensated, " << s.converged
              << " reached (worst remaining " << s.position_worst * 1e3 << " mm, "
              << s.orientation_worst * 1e3 << " mrad), the commands moving by up to "
              << s.largest_change * 1e3 << " mrad\n";
    if (!s.unreached.empty())
      std::cerr << "lrcal compensate: not reached (a singular posture, or out of reach): rows "
                << Rows(s.unreached) << "\n";
    if (!s.outside.empty())
      std::cerr << "lrcal compensate: outside the joint ranges (within_limits = 0): rows "
                << Rows(s.outside) << "\n";
  }
}

}  // namespace

int CompensateCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal compensate options");
  o.add_options()("robot", po::value<std::string>()->required(),
                  "the calibrated robot file (identify --write-robot), or a calibrated URDF")(
      "tool-link", po::value<std::string>(), "URDF robots: the tool link")(
      "base-link", po::value<std::string>(), "URDF robots: the chain's base link (default: root)")(
      "nominal", po::value<std::string>(),
      "the robot file or URDF the commands were planned on: its tool poses at them are the "
      "targets when --targets gives no x, y, z")(
      "targets", po::value<std::string>()->required(),
      "CSV of planned commands (q1..qN or the URDF's joint names), optionally with the tool "
      "poses to reach (x, y, z in m, base frame; qx, qy, qz, qw)")(
      "out", po::value<std::string>(),
      "CSV of the compensated commands (default: standard output)")(
      "format", po::value<std::string>()->default_value("text"), "summary: text or json");
  po::variables_map vm;
  if (!Parse("compensate", "--robot CAL --targets T.csv [--nominal R] [--out C.csv]", o, args, &vm))
    return 0;
  if (vm.count("out")) CheckOutputFile(vm["out"].as<std::string>(), "--out");
  // --tool-link names the link of whichever of --robot and --nominal is a URDF.
  const RobotFile calibrated = LoadRobotWithToolLink(vm["robot"].as<std::string>(), vm);
  std::optional<RobotFile> nominal;
  if (vm.count("nominal")) nominal = LoadNominalRobot(vm, calibrated);
  const std::string file = vm["targets"].as<std::string>();
  const CompensationTargets targets =
      ReadCompensationTargets(file, nominal ? nominal->robot : calibrated.robot);
  const std::vector<Pose<double>> goals = Goals(targets, nominal, file);
  const bool orientation = targets.poses.empty() || targets.orientation;
  std::vector<Compensation> results;
  for (int i = 0; i < targets.plans.size(); ++i)
    results.push_back(Compensate(calibrated.robot, goals[static_cast<std::size_t>(i)],
                                 targets.plans.q(i), orientation));
  const CompensationSummary s = Summarise(calibrated.robot, targets, goals, results);
  if (vm.count("out"))
    WriteCompensation(vm["out"].as<std::string>(), results, calibrated.robot.num_links());
  else
    std::cout << CompensationCsvText(results, calibrated.robot.num_links());
  PrintSummary(vm, s, orientation);
  return s.unreached.empty() ? 0 : 1;
}

}  // namespace lrcal::cli
