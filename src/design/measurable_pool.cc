#include "lrcal/design/measurable_pool.h"

#include <cmath>
#include <functional>
#include <string>

#include "lrcal/core/error.h"
#include "lrcal/core/random.h"
#include "lrcal/kinematics/joint_constraints.h"

namespace lrcal {

namespace {

// `count` configurations: batches drawn by `draw(b)`, draw i of a batch kept where
// `keep(drawn, i, kept_so_far, &q)` returns its tag (≥ 0; it may move q).
TargetedConfigurations FillPool(
    int count, int num_joints, const std::string& what,
    const std::function<TargetedConfigurations(std::uint64_t batch)>& draw,
    const std::function<int(const TargetedConfigurations& drawn, int i, int slot,
                            std::vector<double>* q)>& keep,
    SamplingReport* report) {
  TargetedConfigurations pool(num_joints);
  std::vector<double> q;
  int attempts = 0;
  for (int batch = 0; batch < kMaxPoolBatches && pool.size() < count; ++batch) {
    const TargetedConfigurations drawn = draw(static_cast<std::uint64_t>(batch));
    for (int i = 0; i < drawn.size() && pool.size() < count; ++i) {
      ++attempts;
      q.assign(drawn.q(i), drawn.q(i) + drawn.num_joints());
      const int tag = keep(drawn, i, pool.size(), &q);
      if (tag >= 0) pool.Add(q, tag);
    }
  }
  if (report) {
    report->requested = count;
    report->accepted = pool.size();
    report->attempts = attempts;
    if (attempts > pool.size()) report->rejected[what] = attempts - pool.size();
  }
  if (pool.size() < count)
    throw InputError("pool", "only " + std::to_string(pool.size()) + " of " +
                                 std::to_string(attempts) + " drawn configurations kept (" + what +
                                 "): fewer than the " + std::to_string(count) + " asked for");
  return pool;
}

}  // namespace

TargetedConfigurations SampleScannerConfigurations(const ScannerMeasurement& scanner,
                                                   const std::vector<int>& counts,
                                                   std::uint64_t seed, std::uint64_t stream,
                                                   SamplingOptions options,
                                                   SamplingReport* report) {
  options.require_beam_hit = true;
  int count = 0;
  for (int n : counts) count += n;
  const std::vector<double> zero(static_cast<std::size_t>(scanner.num_parameters()), 0.0);
  std::vector<std::string> reasons;  // of the batch drawn last: every beam's verdict
  return FillPool(
      count, scanner.robot().num_links(), "a beam of the fan off its plane",
      [&](std::uint64_t batch) {
        TargetedConfigurations drawn =
            SampleConfigurations(scanner.robot(), scanner.setup().planes, counts,
                                 RandomStream(seed, stream, batch, RandomPurpose::kPool), options);
        reasons = scanner.MissReasons(drawn, zero.data());
        return drawn;
      },
      [&](const TargetedConfigurations& drawn, int i, int, std::vector<double>*) {
        return reasons[static_cast<std::size_t>(i)] == "ok" ? drawn.target(i) : -1;
      },
      report);
}

TargetedConfigurations SampleSocketConfigurations(const SocketMeasurement& socket, int count,
                                                  std::uint64_t seed, std::uint64_t stream,
                                                  SamplingOptions options, SamplingReport* report) {
  options.require_beam_hit = false;
  const RobotModel& robot = socket.robot();
  const std::vector<Eigen::Vector3d>& sockets = socket.nominal_positions();
  const auto num_sockets = static_cast<int>(sockets.size());
  return FillPool(
      count, robot.num_links(), "not seated in its socket",
      [&](std::uint64_t batch) {
        return SampleConfigurations(robot, Plane{}, count,
                                    RandomStream(seed, stream, batch, RandomPurpose::kPool),
                                    options);
      },
      [&](const TargetedConfigurations&, int, int slot, std::vector<double>* q) {
        const int k = slot % num_sockets;
        const bool seated =
            SeatToolPoint(robot, socket.setup().tool_point, sockets[static_cast<std::size_t>(k)],
                          q->data()) &&
            WrapIntoJointRanges(robot, q->data()) &&
            IsWellConditioned(robot, q->data(), options.min_jacobian_singular_value);
        return seated ? k : -1;
      },
      report);
}

TargetedConfigurations MeasurableConfigurations(const MeasurementKind& kind,
                                                const TargetedConfigurations& configs,
                                                SamplingReport* report,
                                                std::vector<std::string>* reasons) {
  const std::vector<double> zero(static_cast<std::size_t>(kind.num_parameters()), 0.0);
  const std::vector<std::string> why = kind.MissReasons(configs, zero.data());
  std::vector<int> kept;
  SamplingReport r;
  r.requested = r.attempts = configs.size();
  for (int i = 0; i < configs.size(); ++i) {
    if (why[static_cast<std::size_t>(i)] == "ok")
      kept.push_back(i);
    else
      ++r.rejected[why[static_cast<std::size_t>(i)]];
  }
  r.accepted = static_cast<int>(kept.size());
  if (report) *report = r;
  if (reasons) *reasons = why;
  return configs.Subset(kept);
}

TargetedConfigurations SeatedConfigurations(const RobotModel& robot, const MeasurementKind& kind,
                                            const TargetedConfigurations& starts,
                                            SamplingReport* report,
                                            std::vector<std::string>* reasons) {
  constexpr double kSeated = 1e-9;  // m or rad: SeatOnPlane and SeatToolPoint reach 1e-12
  const TargetedConfigurations moved = kind.LinearisationConfigurations(starts);
  const int k = kind.rows_per_configuration();
  const std::vector<double> zero(static_cast<std::size_t>(kind.num_parameters()), 0.0);
  std::vector<double> y(static_cast<std::size_t>(moved.size() * k));
  kind.Bind(moved)->Predict(zero.data(), y.data(), nullptr);
  TargetedConfigurations kept(moved.num_joints());
  std::vector<double> q;
  SamplingReport r;
  r.requested = r.attempts = moved.size();
  if (reasons) reasons->assign(static_cast<std::size_t>(moved.size()), "ok");
  for (int i = 0; i < moved.size(); ++i) {
    bool seated = true;
    for (int row = 0; row < k; ++row)
      seated = seated && std::abs(y[static_cast<std::size_t>(i * k + row)]) <= kSeated;
    q.assign(moved.q(i), moved.q(i) + moved.num_joints());
    const char* reason = !seated                                 ? "not seated"
                         : !WrapIntoJointRanges(robot, q.data()) ? "outside the joint ranges"
                                                                 : nullptr;
    if (!reason) {
      kept.Add(q, moved.target(i));
      continue;
    }
    ++r.rejected[reason];
    if (reasons) (*reasons)[static_cast<std::size_t>(i)] = reason;
  }
  r.accepted = kept.size();
  if (report) *report = r;
  return kept;
}

}  // namespace lrcal
