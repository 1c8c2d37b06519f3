#include "lrcal/design/random_baseline.h"

#include "lrcal/core/random.h"
#include "lrcal/design/block_selection.h"

namespace lrcal {

namespace {

Eigen::MatrixXd NormalMatrixOfRows(const Eigen::MatrixXd& G, const std::vector<int>& rows) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(G.cols(), G.cols());
  for (int r : rows) A += G.row(r).transpose() * G.row(r);
  return A;
}

}  // namespace

const SettingSpec& RandomBaselineSetting() {
  static const SettingSpec spec{"baseline",
                                "count",
                                "baseline",
                                "",
                                1,
                                "",
                                1,
                                1e6,
                                false,
                                true,
                                "random designs",
                                "",
                                "random designs for the baseline"};
  return spec;
}

std::vector<BaselineIndex> CompareWithRandomDesigns(const Eigen::MatrixXd& G,
                                                    const std::vector<int>& chosen, int count,
                                                    std::uint64_t seed,
                                                    int rows_per_configuration) {
  RandomBaselineSetting().Check(count);
  const int k = static_cast<int>(chosen.size());
  constexpr std::size_t kCriteria = std::size(kBaselineCriteria);
  const std::vector<DesignCriterion> criteria(std::begin(kBaselineCriteria),
                                              std::end(kBaselineCriteria));
  std::vector<std::vector<double>> random_scores(kCriteria);
  SelectionOptions random_options;
  random_options.method = SelectionMethod::kRandom;
  // The rows of configurations `configs` (all rows_per_configuration of each).
  const auto rows_of = [&](const std::vector<int>& configs) {
    if (rows_per_configuration == 1) return configs;
    std::vector<int> rows;
    for (int i : configs)
      for (int r = 0; r < rows_per_configuration; ++r)
        rows.push_back(i * rows_per_configuration + r);
    return rows;
  };
  for (int b = 0; b < count; ++b) {
    const SelectionResult r = SelectBlocks(
        G, rows_per_configuration, k, random_options,
        RandomStream(seed, 2, static_cast<std::uint64_t>(b), RandomPurpose::kSelection));
    const std::vector<double> scores =
        CriterionScores(NormalMatrixOfRows(G, rows_of(r.indices)), k, criteria);
    for (std::size_t c = 0; c < kCriteria; ++c) random_scores[c].push_back(scores[c]);
  }
  const std::vector<double> chosen_scores =
      CriterionScores(NormalMatrixOfRows(G, rows_of(chosen)), k, criteria);
  std::vector<BaselineIndex> out(kCriteria);
  for (std::size_t c = 0; c < kCriteria; ++c) {
    out[c].criterion = kBaselineCriteria[c];
    out[c].chosen = chosen_scores[c];
    out[c].random = Describe(random_scores[c]);
    out[c].percentile = PercentileRank(random_scores[c], out[c].chosen);
  }
  return out;
}

}  // namespace lrcal
