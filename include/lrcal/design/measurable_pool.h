// Candidate configurations for the kinds whose measurements are not free draws over the
// workspace: a line scanner's fan must meet its planes (scanner_measurement.h), a probe's tip must
// touch its plane (contact_measurement.h) and a ball on the tool must be seated in its socket
// (socket_measurement.h). What a study's pool and `lrcal design` take for those kinds.
//
// Both draw in batches, batch b from RandomStream(seed, stream, b, kPool) (SampleConfigurations
// under `options`), and keep a draw when the kind can measure it at its nominal terms, until
// `count` are kept. The result is a pure function of its arguments.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lrcal/design/configuration_sampling.h"
#include "lrcal/measurement/scanner_measurement.h"
#include "lrcal/measurement/socket_measurement.h"

namespace lrcal {

/// At most this many batches are drawn before a pool that cannot be filled is refused.
inline constexpr int kMaxPoolBatches = 50;

/// `counts[p]` configurations per plane p of `scanner` (tagged p): the ranger's draws, aimed at
/// the plane within `options`' limits (require_beam_hit is set), kept where every beam of the fan
/// meets its plane at the scanner's nominal terms (MissReasons "ok"). `report` (if given) counts
/// the draws tried and those kept. Throws InputError ("pool") when kMaxPoolBatches batches do not
/// give the counts (a fan too wide for the planes).
TargetedConfigurations SampleScannerConfigurations(const ScannerMeasurement& scanner,
                                                   const std::vector<int>& counts,
                                                   std::uint64_t seed, std::uint64_t stream,
                                                   SamplingOptions options,
                                                   SamplingReport* report = nullptr);

/// `count` configurations with `socket`'s nominal ball seated in its nominal sockets, the sockets
/// in turn (configuration i tagged i mod K, K the sockets): draws over the workspace
/// (require_beam_hit is cleared) each moved by SeatToolPoint to the next socket, kept when it
/// seats, lies in the joint ranges (after whole turns) and the arm's Jacobian there keeps
/// σ_min ≥ options.min_jacobian_singular_value. Throws InputError ("pool") when kMaxPoolBatches
/// batches do not give `count` (a socket out of reach).
TargetedConfigurations SampleSocketConfigurations(const SocketMeasurement& socket, int count,
                                                  std::uint64_t seed, std::uint64_t stream,
                                                  SamplingOptions options,
                                                  SamplingReport* report = nullptr);

/// The configurations of `configs` where `kind` measures at its nominal terms (MissReasons
/// "ok": a scanner's every beam on its plane), tags kept. `report` (if given) counts them and,
/// by reason, those left out; `reasons` (if given) gets each configuration's.
TargetedConfigurations MeasurableConfigurations(const MeasurementKind& kind,
                                                const TargetedConfigurations& configs,
                                                SamplingReport* report = nullptr,
                                                std::vector<std::string>* reasons = nullptr);

/// `starts` moved by kind.LinearisationConfigurations (a contact's or a socket's seating on the
/// nominal arm, each to its tag's plane or socket), kept where the move satisfied the kind's
/// constraints (every value of its measurement at the nominal terms within 1e-9 of 0: m or rad)
/// and lies in `robot`'s joint ranges (the kind's arm) after whole turns of the revolute joints.
/// `report` (if given) counts the starts and, by reason, those left out ("not seated", "outside the
/// joint ranges"); `reasons` (if given) gets each start's ("ok" where kept).
TargetedConfigurations SeatedConfigurations(const RobotModel& robot, const MeasurementKind& kind,
                                            const TargetedConfigurations& starts,
                                            SamplingReport* report = nullptr,
                                            std::vector<std::string>* reasons = nullptr);

}  // namespace lrcal
