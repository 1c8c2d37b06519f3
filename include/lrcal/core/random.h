// Counter-based random numbers (Random123's Philox4x64-10): every draw is *addressed*, never
// taken from a running sequence, so a trial's numbers do not depend on which thread, shard, rank
// or restart computes it.
//
// Address of a draw: key = (study seed, stream), counter = (trial, purpose, block, 0), where one
// counter block yields four 64-bit words. Standard normals come from Random123's Box–Muller
// transform (pairs of words → pairs of normals), uniforms from its u01 (in (0, 1]). Neither
// std::normal_distribution nor std::seed_seq is used: their results are implementation-defined.
// random_test.cc pins Philox against Random123's published known-answer vectors and the normal
// transform against fixed values.
//
// Common random numbers: the stream is chosen by the *purpose* of the draw, not by the study cell,
// so two cells that differ only in σ (or in the number of configurations) see the same standard
// normals for the same trial index. Comparisons between cells then carry less Monte-Carlo noise.
#pragma once

#include <cstdint>

namespace lrcal {

/// What a stream of draws is for (part of its address).
enum class RandomPurpose : std::uint32_t {
  kNoise = 1,         ///< reading noise: index = configuration·R + repetition
  kPool = 2,          ///< candidate configurations: index = attempt·joints + joint
  kValidation = 3,    ///< validation configurations
  kTruth = 4,         ///< per-trial parameter errors
  kSelection = 5,     ///< random selection / exchange restarts
  kPrediction = 6,    ///< draws of the linearised prediction of the validation metrics
  kEncoder = 7,       ///< joint-encoder errors: index = (configuration·R + repetition)·joints + j
  kPlaneForm = 8,     ///< plane flatness deviation at a configuration's hit point: index = slot
  kOutlier = 9,       ///< gross errors: 2·(configuration·R + repetition) (+1 for the size)
  kSensitivity = 10,  ///< sensitivity plans (Saltelli's A, B; Morris' trajectories), bootstrap
  kAveraging = 11,    ///< averaging.h's variance factors: trial = readings, index = set·n + r
  kFitCheck = 12,     ///< the robust fit check's null draws: index = draw·rows + row
};

class RandomStream {
 public:
  /// `stream` separates independent families (e.g. a cell-specific pool); 0 for common numbers.
  RandomStream(std::uint64_t seed, std::uint64_t stream, std::uint64_t trial, RandomPurpose purpose)
      : seed_(seed),
        stream_(stream),
        trial_(trial),
        purpose_(static_cast<std::uint64_t>(purpose)) {}

  /// The four raw words of counter block `block`.
  void Block(std::uint64_t block, std::uint64_t out[4]) const;
  /// Uniform in (0, 1] at draw `index`.
  double Uniform(std::uint64_t index) const;
  /// Standard normal at draw `index`.
  double Normal(std::uint64_t index) const;
  /// Fills out[0..count) with the standard normals at indices first .. first+count-1.
  void Normals(std::uint64_t first, int count, double* out) const;
  /// The same (seed, stream, trial) for another purpose: a sibling family of draws.
  RandomStream WithPurpose(RandomPurpose purpose) const {
    return RandomStream(seed_, stream_, trial_, purpose);
  }

 private:
  std::uint64_t seed_, stream_, trial_, purpose_;
};

/// RandomStream::Normal for a run of indices drawn one by one, mostly in increasing order (a
/// trial's noise at its design's slots): neighbouring indices share a counter block (four
/// words) and a Box–Muller pair (two normals), which are kept from the last draw instead of
/// being computed again. Returns exactly Normal(index), whatever the order.
class NormalDraws {
 public:
  explicit NormalDraws(const RandomStream& stream) : stream_(stream) {}
  double operator()(std::uint64_t index);

 private:
  RandomStream stream_;
  bool have_block_ = false, have_pair_ = false;
  std::uint64_t block_ = 0, pair_ = 0;  // index / 4 and index / 2 of what is kept
  std::uint64_t words_[4] = {0, 0, 0, 0};
  double z_[2] = {0, 0};
};

/// Philox4x64-10 of (counter, key), exposed for the known-answer test.
void Philox4x64(const std::uint64_t counter[4], const std::uint64_t key[2], std::uint64_t out[4]);

}  // namespace lrcal
