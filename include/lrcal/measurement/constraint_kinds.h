// What the constraint kinds (socket_measurement.h, contact_measurement.h: measured values that
// say "the tool is at its socket, on its plane" rather than readings) share.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

/// `configs` with each configuration moved by `seat(q, target)` (q: its joint values, changed in
/// place; true when the move succeeded), tags kept; one that `seat` cannot move is kept as it
/// is. What a constraint kind's LinearisationConfigurations does with its own seating.
TargetedConfigurations SeatEach(const TargetedConfigurations& configs,
                                const std::function<bool(double* q, int target)>& seat);

/// `fixed` with `names` added (each once): a kind's Without. Throws InputError ("fix") naming
/// the first of `names` that is not in `all` (every term of the `kind` measurement).
std::vector<std::string> HeldTerms(const std::vector<std::string>& fixed,
                                   const std::vector<std::string>& names,
                                   const std::vector<std::string>& all, const std::string& kind);

}  // namespace lrcal
