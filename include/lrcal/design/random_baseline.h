// The random-design baseline: how a chosen design compares, by every observability index, with
// designs of the same size drawn at random from the same pool. A design method is worth its cost
// when its choice sits far in the random designs' upper tail.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "lrcal/core/descriptive_statistics.h"
#include "lrcal/core/settings.h"
#include "lrcal/design/experiment_design.h"

namespace lrcal {

/// The criteria the baseline compares (O3 is E).
inline constexpr DesignCriterion kBaselineCriteria[] = {
    DesignCriterion::kE,  DesignCriterion::kD,  DesignCriterion::kA, DesignCriterion::kO1,
    DesignCriterion::kO2, DesignCriterion::kO4, DesignCriterion::kO5};

/// One index of the chosen design against the random ones.
struct BaselineIndex {
  DesignCriterion criterion = DesignCriterion::kE;
  double chosen = 0;      ///< the chosen design's score (CriterionScore of its GᵀG)
  Distribution random;    ///< the scores of the random designs
  double percentile = 0;  ///< where `chosen` falls among them (PercentileRank, %)
};

/// The number of random designs (`baseline.count`: --baseline, baseline=): 1 to 1,000,000.
const SettingSpec& RandomBaselineSetting();

/// Every index of configurations `chosen` of G (rows_per_configuration rows each, N·k × n)
/// against `count` random designs of as many configurations, drawn from `seed`'s selection
/// stream 2 (design b is draw b; SelectBlocks' random method). With one row per configuration
/// this is the ranger's baseline, bit for bit. Throws SettingError for a count out of range.
std::vector<BaselineIndex> CompareWithRandomDesigns(const Eigen::MatrixXd& G,
                                                    const std::vector<int>& chosen, int count,
                                                    std::uint64_t seed,
                                                    int rows_per_configuration = 1);

}  // namespace lrcal
