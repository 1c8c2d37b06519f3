#include "lrcal/design/block_selection.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "design/bound_order.h"
#include "lrcal/core/error.h"

namespace lrcal {

namespace {

constexpr double kNoBlockScore = -std::numeric_limits<double>::infinity();

// The candidates' information blocks B_iᵀB_i and their scoring.
class BlockInformation {
 public:
  BlockInformation(const Eigen::MatrixXd& G, int rows, DesignCriterion criterion)
      : n_(static_cast<int>(G.cols())), criterion_(criterion) {
    const auto N = static_cast<int>(G.rows() / rows);
    info_.reserve(static_cast<std::size_t>(N));
    for (int i = 0; i < N; ++i) {
      const Eigen::MatrixXd B = G.middleRows(static_cast<Eigen::Index>(i) * rows, rows);
      info_.push_back(B.transpose() * B);
    }
  }
  int size() const { return static_cast<int>(info_.size()); }
  int num_parameters() const { return n_; }
  DesignCriterion criterion() const { return criterion_; }
  const Eigen::MatrixXd& operator[](int i) const { return info_[static_cast<std::size_t>(i)]; }
  Eigen::MatrixXd Sum(const std::vector<int>& chosen) const {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n_, n_);
    for (int i : chosen) A += info_[static_cast<std::size_t>(i)];
    return A;
  }
  double Score(const Eigen::MatrixXd& A, int m, long long* evaluations) const {
    ++*evaluations;
    return CriterionScore(A, m, criterion_);
  }

 private:
  int n_;
  DesignCriterion criterion_;
  std::vector<Eigen::MatrixXd> info_;
};

std::vector<int> RandomBlocks(int N, int k, const RandomStream& stream, std::uint64_t first) {
  std::vector<int> p(static_cast<std::size_t>(N));
  std::iota(p.begin(), p.end(), 0);
  for (int i = 0; i < k; ++i) {
    int j = i + static_cast<int>(stream.Uniform(first + static_cast<std::uint64_t>(i)) * (N - i));
    if (j >= N) j = N - 1;  // u01 may return exactly 1
    std::swap(p[static_cast<std::size_t>(i)], p[static_cast<std::size_t>(j)]);
  }
  p.resize(static_cast<std::size_t>(k));
  std::sort(p.begin(), p.end());
  return p;
}

// E: the block whose removal keeps the largest √λ_min, found in the order of upper bounds. With
// V the eigenvectors of A's kBoundDirections smallest eigenvalues Λ, λ_min(A − B) ≤
// λ_min(Vᵀ(A − B)V) = λ_min(Λ − VᵀBV) (Cauchy interlacing: a compression's smallest eigenvalue is
// at least the matrix's), a kBoundDirections² eigenproblem per candidate; widened by rounding
// (1e-12 of A's largest eigenvalue), as the ranger's bounded selection is. The same choice as
// scoring every candidate (ties to the lowest position): BestInBoundOrder.
std::size_t BestEDrop(const BlockInformation& b, const Eigen::MatrixXd& A,
                      const std::vector<int>& design, int m, long long* evaluations) {
  constexpr int kBoundDirections = 4;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A);
  const int d = std::min(kBoundDirections, static_cast<int>(A.rows()));
  const Eigen::MatrixXd V = eig.eigenvectors().leftCols(d);
  const Eigen::MatrixXd L = eig.eigenvalues().head(d).asDiagonal();
  const double slack = 1e-12 * std::fabs(eig.eigenvalues().maxCoeff());
  Eigen::VectorXd bounds(static_cast<Eigen::Index>(design.size()));
  for (std::size_t p = 0; p < design.size(); ++p) {
    const Eigen::MatrixXd C = L - V.transpose() * b[design[p]] * V;
    bounds[static_cast<Eigen::Index>(p)] =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(C, Eigen::EigenvaluesOnly).eigenvalues()[0];
  }
  const int pos = BestInBoundOrder(
      bounds, [&](int p) { return std::sqrt(std::max(bounds[p] + slack, 0.0)); },
      [&](int p, double) {
        return CriterionScore(A - b[design[static_cast<std::size_t>(p)]], m, DesignCriterion::kE);
      },
      kNoBlockScore, evaluations);
  return static_cast<std::size_t>(std::max(pos, 0));
}

std::vector<int> BackwardBlocks(const BlockInformation& b, int k, long long* evaluations) {
  std::vector<int> design(static_cast<std::size_t>(b.size()));
  std::iota(design.begin(), design.end(), 0);
  Eigen::MatrixXd A = b.Sum(design);
  while (static_cast<int>(design.size()) > k) {
    const int m = static_cast<int>(design.size()) - 1;
    std::size_t drop = 0;
    if (b.criterion() == DesignCriterion::kE) {
      drop = BestEDrop(b, A, design, m, evaluations);
    } else {
      double best = kNoBlockScore;
      for (std::size_t p = 0; p < design.size(); ++p) {
        const double score = b.Score(A - b[design[p]], m, evaluations);
        if (score > best) {
          best = score;
          drop = p;
        }
      }
    }
    A -= b[design[drop]];
    design.erase(design.begin() + static_cast<std::ptrdiff_t>(drop));
  }
  return design;
}

// log det(A + εI): the forward steps' score while A is singular.
double RidgedLogDet(const Eigen::MatrixXd& A, double ridge, long long* evaluations) {
  ++*evaluations;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A, Eigen::EigenvaluesOnly);
  return (eig.eigenvalues().array().max(0.0) + ridge).log().sum();
}

std::vector<int> ForwardBlocks(const BlockInformation& b, int k, long long* evaluations) {
  const int N = b.size(), n = b.num_parameters();
  std::vector<int> all(static_cast<std::size_t>(N));
  std::iota(all.begin(), all.end(), 0);
  const double ridge = 1e-9 * std::max(b.Sum(all).trace() / n, 1e-300);
  std::vector<bool> in(static_cast<std::size_t>(N), false);
  std::vector<int> design;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  bool singular = true;
  while (static_cast<int>(design.size()) < k) {
    const int m = static_cast<int>(design.size()) + 1;
    double best = kNoBlockScore;
    int add = -1;
    for (int i = 0; i < N; ++i) {
      if (in[static_cast<std::size_t>(i)]) continue;
      const Eigen::MatrixXd Ai = A + b[i];
      const double score =
          singular ? RidgedLogDet(Ai, ridge, evaluations) : b.Score(Ai, m, evaluations);
      if (score > best || add < 0) {
        best = score;
        add = i;
      }
    }
    A += b[add];
    in[static_cast<std::size_t>(add)] = true;
    design.push_back(add);
    if (singular) {
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A, Eigen::EigenvaluesOnly);
      singular = !(eig.eigenvalues()[0] > ridge);
    }
  }
  std::sort(design.begin(), design.end());
  return design;
}

// Best single swaps from `design` until none raises the score by more than 1e-12 (relative).
std::vector<int> ExchangeBlocks(const BlockInformation& b, std::vector<int> design,
                                long long* evaluations) {
  const int N = b.size(), k = static_cast<int>(design.size());
  Eigen::MatrixXd A = b.Sum(design);
  double current = b.Score(A, k, evaluations);
  for (int pass = 0; pass < 100; ++pass) {
    std::vector<bool> in(static_cast<std::size_t>(N), false);
    for (int i : design) in[static_cast<std::size_t>(i)] = true;
    double best = current + 1e-12 * std::max(1.0, std::fabs(current));
    int out_pos = -1, into = -1;
    for (int p = 0; p < k; ++p) {
      const Eigen::MatrixXd without = A - b[design[static_cast<std::size_t>(p)]];
      for (int j = 0; j < N; ++j) {
        if (in[static_cast<std::size_t>(j)]) continue;
        const double score = b.Score(without + b[j], k, evaluations);
        if (score > best) {
          best = score;
          out_pos = p;
          into = j;
        }
      }
    }
    if (out_pos < 0) break;
    A += b[into] - b[design[static_cast<std::size_t>(out_pos)]];
    design[static_cast<std::size_t>(out_pos)] = into;
    current = best;
  }
  std::sort(design.begin(), design.end());
  return design;
}

void CheckBlockSelection(const Eigen::MatrixXd& G, int rows, int k) {
  if (rows < 1 || G.rows() % rows != 0)
    throw InputError("selection", "the design Jacobian's " + std::to_string(G.rows()) +
                                      " rows are not whole configurations of " +
                                      std::to_string(rows) + " values");
  const auto N = static_cast<int>(G.rows() / rows);
  const auto n = static_cast<int>(G.cols());
  if (N == 0) throw InputError("selection", "the candidate pool is empty");
  if (k > N)
    throw InputError("selection", "cannot select " + std::to_string(k) + " of " +
                                      std::to_string(N) + " candidates");
  if (k * rows < n)
    throw InputError("selection", "selecting " + std::to_string(k) + " configurations of " +
                                      std::to_string(rows) + " values for " + std::to_string(n) +
                                      " parameters: need at least as many values as parameters");
}

}  // namespace

SelectionResult SelectBlocks(const Eigen::MatrixXd& G, int rows_per_configuration, int k,
                             const SelectionOptions& options, const RandomStream& stream) {
  if (rows_per_configuration == 1) return SelectConfigurations(G, k, options, stream);
  options.Validate();
  CheckBlockSelection(G, rows_per_configuration, k);
  SelectionResult out;
  if (options.method == SelectionMethod::kRandom) {
    // One draw needs only its own blocks' information (a random baseline draws hundreds).
    out.indices = RandomBlocks(static_cast<int>(G.rows() / rows_per_configuration), k, stream, 0);
    out.evaluations = 1;
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(G.cols(), G.cols());
    for (int i : out.indices) {
      const Eigen::MatrixXd B = G.middleRows(static_cast<Eigen::Index>(i) * rows_per_configuration,
                                             rows_per_configuration);
      const Eigen::MatrixXd information = B.transpose() * B;  // as BlockInformation's
      A += information;
    }
    out.score = CriterionScore(A, k, options.criterion);
    return out;
  }
  const BlockInformation blocks(G, rows_per_configuration, options.criterion);
  const int N = blocks.size();
  out.score = kNoBlockScore;
  switch (options.method) {
    case SelectionMethod::kRandom:  // above
      break;
    case SelectionMethod::kSampled:
      for (int s = 0; s < options.samples; ++s) {
        std::vector<int> subset =
            RandomBlocks(N, k, stream, static_cast<std::uint64_t>(s) * static_cast<unsigned>(N));
        const double score = blocks.Score(blocks.Sum(subset), k, &out.evaluations);
        if (score > out.score || out.indices.empty()) {
          out.score = score;
          out.indices = std::move(subset);
        }
      }
      break;
    case SelectionMethod::kGreedy:
      out.indices = ForwardBlocks(blocks, k, &out.evaluations);
      break;
    case SelectionMethod::kBackward:
      out.indices = BackwardBlocks(blocks, k, &out.evaluations);
      break;
    case SelectionMethod::kExchange: {
      std::vector<int> start = BackwardBlocks(blocks, k, &out.evaluations);
      out.start_score = CriterionScore(blocks.Sum(start), k, options.criterion);
      out.indices = ExchangeBlocks(blocks, std::move(start), &out.evaluations);
      break;
    }
    case SelectionMethod::kExhaustive:
      throw InputError("selection",
                       "exhaustive search chooses configurations of one value (a ranger's "
                       "reading); for " +
                           std::to_string(rows_per_configuration) +
                           " values per configuration use backward, greedy, exchange, sampled "
                           "or random");
  }
  out.score = CriterionScore(blocks.Sum(out.indices), k, options.criterion);
  return out;
}

}  // namespace lrcal
