// Aggregation of trial records into per-cell statistics, always in the canonical order (trials
// ascending within a cell) so that the numbers do not depend on scheduling.
//
// Per cell: trials ok / failed by reason; per parameter the bias (mean error) with its Monte-Carlo
// standard error (std/√n), the empirical std, the predicted std (σ·√diag(GᵀWG)⁻¹ at nominal) and
// their ratio; the empirical covariance and correlation; and for each validation metric (RMS and
// max position / orientation error per axis) of the identified and the nominal model: mean, std,
// p5, p50, p95, max. Percentiles interpolate linearly between order statistics (Hyndman–Fan
// type 7, numpy's default).
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "lrcal/core/descriptive_statistics.h"
#include "lrcal/study/stopping.h"
#include "lrcal/study/trial_store.h"

namespace lrcal {

struct ParameterStats {
  std::string name;
  double bias = 0, bias_se = 0, std = 0, predicted_std = 0, ratio = 0;  ///< SI
  /// Standard errors of std (as Distribution::std_se) and of ratio (std_se / predicted_std: the
  /// prediction is exact).
  double std_se = 0, ratio_se = 0;
  /// The prediction at the true parameters (the Cramér–Rao bound of the simulated experiment),
  /// and the empirical std's ratio to it with its SE; NaN when the cell has none (random truth
  /// or redrawn designs).
  double predicted_std_truth = 0, ratio_truth = 0, ratio_truth_se = 0;
};

/// How a cell's trial count came about under a stop_when rule (stopping.h).
struct CellStop {
  bool rule = false;          ///< the study has a stop_when rule
  bool decided = false;       ///< the stopping point is known (every trial before it recorded)
  bool precise = false;       ///< the criteria held there (else the cell reached the maximum)
  long long trials_used = 0;  ///< the stopping point (the maximum until decided)
  StopPrecision precision;    ///< at the last boundary evaluated
};

struct CellSummary {
  StoredCell cell;
  /// Trials summarised (trials 0 … trials−1 when complete) and those that identified.
  long long trials = 0, ok = 0;
  CellStop stop;
  std::map<std::string, long long> failed;  ///< status → count
  std::vector<ParameterStats> parameters;
  Eigen::MatrixXd covariance, correlation;  ///< empirical, SI
  std::array<Distribution, 12> validation;  ///< identified model, SI (layout: trial.h)
  std::array<Distribution, 12> nominal;     ///< nominal model, SI
  /// Percentile ranks (PercentileRank) of the probes asked for (SummaryProbes): per validation
  /// metric and per parameter error; NaN where no probe was given.
  std::array<double, 12> validation_probe_rank{};
  std::vector<double> error_probe_rank;
  /// p5, p50, p95 of each parameter's error (SI), when SummaryProbes::error_quantiles.
  std::vector<std::array<double, 3>> error_quantiles;
  Distribution iterations, sigma_hat;
  /// σ_min of each ok trial's design: one value for a fixed design, a distribution when the
  /// pool or the selection is redrawn per trial.
  Distribution design_sigma_min;
  /// Per ok trial, the mean over x, y and z of each validation metric of the identified model
  /// (rms_pos, rms_ori, max_pos, max_ori; SI): a single calibration's figure. Mean, std and their
  /// standard errors only (no quantiles).
  std::array<Distribution, 4> axis_mean;
  /// validation.coverage: per ok trial, the share of the validation poses within the stated 95 %
  /// radius, the data part and the total (TrialRecord::coverage); n = 0 without it.
  Distribution coverage, coverage_total;
};

/// Values to place among a cell's trials while it is summarised (the paper's published numbers):
/// NaN (or a short vector) where there is none.
struct SummaryProbes {
  std::array<double, 12> validation;  ///< SI, per validation metric of the identified model
  std::vector<double> errors;         ///< SI, per parameter error
  bool error_quantiles = false;       ///< also the p5, p50, p95 of every parameter error
  SummaryProbes() { validation.fill(std::numeric_limits<double>::quiet_NaN()); }
};

/// Summarises one cell from the store: its trials with index < `end` (a stop_when cell's
/// stopping point; every recorded trial by default).
///
/// Memory does not grow with the trial count: the store is read in a few passes in canonical
/// order (sums, then the centred moments and the covariance lanes, then the order statistics by
/// radix selection: histograms of the values' leading bits bracket each wanted rank, and only
/// the few values inside a bracket are kept). The numbers are the same bits as sorting every
/// value in memory (Describe; tested).
CellSummary SummarizeCell(const TrialStore& store, const StoredCell& cell,
                          long long end = std::numeric_limits<long long>::max(),
                          const SummaryProbes* probes = nullptr);

}  // namespace lrcal
