#include "lrcal/experiment_design.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "lrcal/error.h"

namespace lrcal {

DesignCriterion ParseDesignCriterion(const std::string& t, const std::string& source) {
  if (t == "E" || t == "O3") return DesignCriterion::kE;
  if (t == "D") return DesignCriterion::kD;
  if (t == "A") return DesignCriterion::kA;
  if (t == "O1") return DesignCriterion::kO1;
  if (t == "O2") return DesignCriterion::kO2;
  if (t == "O4") return DesignCriterion::kO4;
  if (t == "O5") return DesignCriterion::kO5;
  throw InputError(source, "unknown criterion '" + t + "'; expected E, D, A, O1, O2, O3, O4 or O5");
}

const char* DesignCriterionName(DesignCriterion c) {
  switch (c) {
    case DesignCriterion::kE: return "E";
    case DesignCriterion::kD: return "D";
    case DesignCriterion::kA: return "A";
    case DesignCriterion::kO1: return "O1";
    case DesignCriterion::kO2: return "O2";
    case DesignCriterion::kO4: return "O4";
    case DesignCriterion::kO5: return "O5";
  }
  return "?";
}

SelectionMethod ParseSelectionMethod(const std::string& t, const std::string& source) {
  if (t == "exhaustive") return SelectionMethod::kExhaustive;
  if (t == "greedy" || t == "backward") return SelectionMethod::kGreedy;
  if (t == "sampled") return SelectionMethod::kSampled;
  if (t == "random") return SelectionMethod::kRandom;
  throw InputError(source,
                   "unknown selection method '" + t + "'; expected exhaustive, greedy, sampled or random");
}

const char* SelectionMethodName(SelectionMethod m) {
  switch (m) {
    case SelectionMethod::kExhaustive: return "exhaustive";
    case SelectionMethod::kGreedy: return "greedy";
    case SelectionMethod::kSampled: return "sampled";
    case SelectionMethod::kRandom: return "random";
  }
  return "?";
}

double CriterionScore(const Eigen::MatrixXd& A, int m, DesignCriterion criterion) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A, Eigen::EigenvaluesOnly);
  const Eigen::VectorXd& lambda = eig.eigenvalues();  // ascending
  const int n = static_cast<int>(lambda.size());
  const double minus_inf = -std::numeric_limits<double>::infinity();
  const double lmin = lambda[0], lmax = lambda[n - 1];
  if (!(lmin > 1e-300)) {
    // Singular: the σ-based indices are 0 (their worst value); log det and −trace(A⁻¹) are −∞.
    return criterion == DesignCriterion::kD || criterion == DesignCriterion::kA ? minus_inf : 0.0;
  }
  switch (criterion) {
    case DesignCriterion::kE: return std::sqrt(lmin);
    case DesignCriterion::kD: return lambda.array().log().sum();
    case DesignCriterion::kA: return -lambda.cwiseInverse().sum();
    case DesignCriterion::kO1:
      return std::exp(0.5 * lambda.array().log().sum() / n) / std::sqrt(static_cast<double>(m));
    case DesignCriterion::kO2: return std::sqrt(lmin / lmax);
    case DesignCriterion::kO4: return lmin / std::sqrt(lmax);
    case DesignCriterion::kO5: return 1.0 / lambda.cwiseSqrt().cwiseInverse().sum();
  }
  return minus_inf;
}

namespace {

// k distinct indices of 0..N-1 by a partial Fisher–Yates shuffle on the stream's draws.
std::vector<int> RandomSubset(int N, int k, const RandomStream& stream, std::uint64_t first) {
  std::vector<int> p(N);
  std::iota(p.begin(), p.end(), 0);
  for (int i = 0; i < k; ++i) {
    int j = i + static_cast<int>(stream.Uniform(first + i) * (N - i));
    if (j >= N) j = N - 1;  // u01 may return exactly 1
    std::swap(p[i], p[j]);
  }
  p.resize(k);
  std::sort(p.begin(), p.end());
  return p;
}

Eigen::MatrixXd NormalMatrix(const Eigen::MatrixXd& G, const std::vector<int>& rows) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(G.cols(), G.cols());
  for (int r : rows) A.selfadjointView<Eigen::Lower>().rankUpdate(G.row(r).transpose());
  A.triangularView<Eigen::StrictlyUpper>() = A.transpose();
  return A;
}

double Binomial(int n, int k) {
  double c = 1;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
  return c;
}

}  // namespace

SelectionResult SelectConfigurations(const Eigen::MatrixXd& G, int k,
                                     const SelectionOptions& options, const RandomStream& stream) {
  const int N = static_cast<int>(G.rows());
  const int n = static_cast<int>(G.cols());
  if (N == 0) throw InputError("selection", "the candidate pool is empty");
  if (k > N)
    throw InputError("selection", "cannot select " + std::to_string(k) + " of " +
                                      std::to_string(N) + " candidates");
  if (k < n)
    throw InputError("selection", "selecting " + std::to_string(k) + " configurations for " +
                                      std::to_string(n) +
                                      " parameters: need at least as many configurations as "
                                      "parameters");
  SelectionResult best;
  best.score = -std::numeric_limits<double>::infinity();
  switch (options.method) {
    case SelectionMethod::kRandom: {
      best.indices = RandomSubset(N, k, stream, 0);
      best.score = CriterionScore(NormalMatrix(G, best.indices), k, options.criterion);
      best.evaluations = 1;
      break;
    }
    case SelectionMethod::kSampled: {
      for (int s = 0; s < options.samples; ++s) {
        std::vector<int> subset = RandomSubset(N, k, stream, static_cast<std::uint64_t>(s) * N);
        double score = CriterionScore(NormalMatrix(G, subset), k, options.criterion);
        ++best.evaluations;
        if (score > best.score) {
          best.score = score;
          best.indices = subset;
        }
      }
      break;
    }
    case SelectionMethod::kExhaustive: {
      const double count = Binomial(N, k);
      if (count > options.exhaustive_limit)
        throw InputError("selection", "exhaustive search over C(" + std::to_string(N) + "," +
                                          std::to_string(k) + ") = " + std::to_string(count) +
                                          " subsets is beyond the limit; use greedy or sampled");
      // Enumerate the N−k left out (fewer when k is close to N), removing rank-one terms.
      const Eigen::MatrixXd A_all = NormalMatrix(G, [&] {
        std::vector<int> all(N);
        std::iota(all.begin(), all.end(), 0);
        return all;
      }());
      const int drop = N - k;
      std::vector<int> out(drop);
      std::iota(out.begin(), out.end(), 0);
      while (true) {
        Eigen::MatrixXd A = A_all;
        for (int r : out) A.noalias() -= G.row(r).transpose() * G.row(r);
        double score = CriterionScore(A, k, options.criterion);
        ++best.evaluations;
        if (score > best.score) {
          best.score = score;
          best.indices.clear();
          for (int i = 0, o = 0; i < N; ++i) {
            if (o < drop && out[o] == i) { ++o; continue; }
            best.indices.push_back(i);
          }
        }
        int i = drop - 1;  // next combination of `drop` out of N
        while (i >= 0 && out[i] == N - drop + i) --i;
        if (i < 0) break;
        ++out[i];
        for (int j = i + 1; j < drop; ++j) out[j] = out[j - 1] + 1;
      }
      break;
    }
    case SelectionMethod::kGreedy: {
      std::vector<int> kept(N);
      std::iota(kept.begin(), kept.end(), 0);
      Eigen::MatrixXd A = NormalMatrix(G, kept);
      while (static_cast<int>(kept.size()) > k) {
        double best_score = -std::numeric_limits<double>::infinity();
        int best_pos = 0;
        for (int pos = 0; pos < static_cast<int>(kept.size()); ++pos) {
          const int r = kept[pos];
          Eigen::MatrixXd Ar = A - G.row(r).transpose() * G.row(r);
          double score = CriterionScore(Ar, static_cast<int>(kept.size()) - 1, options.criterion);
          ++best.evaluations;
          if (score > best_score) {  // ties: the lowest index is dropped first
            best_score = score;
            best_pos = pos;
          }
        }
        A.noalias() -= G.row(kept[best_pos]).transpose() * G.row(kept[best_pos]);
        kept.erase(kept.begin() + best_pos);
      }
      best.indices = kept;
      best.score = CriterionScore(NormalMatrix(G, kept), k, options.criterion);
      break;
    }
  }
  return best;
}

}  // namespace lrcal
