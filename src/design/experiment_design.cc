#include "lrcal/design/experiment_design.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "design/bound_order.h"
#include "lrcal/core/error.h"
#include "lrcal/design/design_certificate.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/measurement/ranger_measurement.h"

namespace lrcal {

namespace {

constexpr double kMinusInf = -std::numeric_limits<double>::infinity();

// Score from the eigenvalues (ascending) of GᵀG of m configurations.
double ScoreFromEigenvalues(const Eigen::VectorXd& lambda, int m, DesignCriterion criterion) {
  const int n = static_cast<int>(lambda.size());
  const double lmin = lambda[0], lmax = lambda[n - 1];
  if (!(lmin > 1e-300)) {
    return criterion == DesignCriterion::kD || criterion == DesignCriterion::kA ? kMinusInf : 0.0;
  }
  switch (criterion) {
    case DesignCriterion::kE:
      return std::sqrt(lmin);
    case DesignCriterion::kD:
      return lambda.array().log().sum();
    case DesignCriterion::kA:
      return -lambda.cwiseInverse().sum();
    case DesignCriterion::kO1:
      return std::exp(0.5 * lambda.array().log().sum() / n) / std::sqrt(static_cast<double>(m));
    case DesignCriterion::kO2:
      return std::sqrt(lmin / lmax);
    case DesignCriterion::kO4:
      return lmin / std::sqrt(lmax);
    case DesignCriterion::kO5:
      return 1.0 / lambda.cwiseSqrt().cwiseInverse().sum();
  }
  return kMinusInf;
}

// The root of f(μ) = 1 + rho·Σ z_i²/(λ_i − μ) in (lo, hi), where f is monotone: safeguarded
// Newton (a bisection step whenever Newton would leave the bracket), typically 4–8 iterations.
double SecularRoot(const Eigen::VectorXd& lambda, const Eigen::VectorXd& z2,
                   const std::vector<int>& active, double rho, double lo, double hi) {
  const double eps = std::numeric_limits<double>::epsilon();
  double mu = 0.5 * (lo + hi);
  for (int iter = 0; iter < 100; ++iter) {
    double f = 1, df = 0;
    for (int i : active) {
      const double inv = 1.0 / (lambda[i] - mu);
      f += rho * z2[i] * inv;
      df += rho * z2[i] * inv * inv;
    }
    // rho > 0: f increasing on the interval; rho < 0: decreasing.
    if (rho > 0 ? f < 0 : f > 0)
      lo = mu;
    else
      hi = mu;
    double next = mu - f / df;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::fabs(next - mu) <= 4 * eps * std::fabs(next) || hi - lo <= 4 * eps * std::fabs(hi))
      return next;
    mu = next;
  }
  return mu;
}

// The candidates' what-if scores for A ± g·gᵀ, from A's eigendecomposition.
class Spectrum {
 public:
  void Compute(const Eigen::MatrixXd& A) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A);
    lambda_ = eig.eigenvalues();
    Q_ = eig.eigenvectors();
    log_det_ = 0;
    inv_trace_ = 0;
    for (int i = 0; i < lambda_.size(); ++i) {
      log_det_ += std::log(std::max(lambda_[i], 1e-300));
      inv_trace_ += 1.0 / std::max(lambda_[i], 1e-300);
    }
  }

  // Upper bounds on λ_min(A + rho·g_r·g_rᵀ) for the rows r of G listed: the Rayleigh quotients
  // of A's eigenvectors q_l after the update, min_l λ_l + rho·(q_lᵀg_r)². Exact evaluations
  // (Score) can skip every row whose bound is below the best score found.
  Eigen::VectorXd MinEigenvalueBounds(const Eigen::MatrixXd& G, const std::vector<int>& rows,
                                      double rho) const {
    const Eigen::MatrixXd Z = G(rows, Eigen::all) * Q_;  // one product for every row
    return ((rho * Z.array().square()).rowwise() + lambda_.transpose().array())
        .rowwise()
        .minCoeff()
        .matrix();
  }
  const Eigen::VectorXd& eigenvalues() const { return lambda_; }
  const Eigen::MatrixXd& eigenvectors() const { return Q_; }

  // Score of A + rho·g·gᵀ, a design of m configurations.
  double Score(const Eigen::VectorXd& g, double rho, int m, DesignCriterion criterion) {
    z_.noalias() = Q_.transpose() * g;
    z2_ = z_.cwiseAbs2();
    switch (criterion) {
      case DesignCriterion::kD:
      case DesignCriterion::kO1:
        return DeterminantScore(rho, m, criterion);
      case DesignCriterion::kA:
        return TraceScore(rho);
      case DesignCriterion::kO5:
        mu_ = RankOneUpdatedEigenvalues(lambda_, z_, rho);
        return ScoreFromEigenvalues(mu_, m, criterion);
      default:
        return ExtremeEigenvalueScore(rho, criterion);
    }
  }

 private:
  // D and O1 by the matrix determinant lemma.
  double DeterminantScore(double rho, int m, DesignCriterion criterion) const {
    const int n = static_cast<int>(lambda_.size());
    double s = 0;
    for (int i = 0; i < n; ++i) s += z2_[i] / lambda_[i];
    const double factor = 1 + rho * s;
    if (!(factor > 0) || !(lambda_[0] > 1e-300))
      return criterion == DesignCriterion::kD ? kMinusInf : 0.0;
    const double log_det = log_det_ + std::log(factor);
    return criterion == DesignCriterion::kD
               ? log_det
               : std::exp(0.5 * log_det / n) / std::sqrt(static_cast<double>(m));
  }

  // A by Sherman–Morrison.
  double TraceScore(double rho) const {
    const int n = static_cast<int>(lambda_.size());
    double s1 = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
      s1 += z2_[i] / lambda_[i];
      s2 += z2_[i] / (lambda_[i] * lambda_[i]);
    }
    const double factor = 1 + rho * s1;
    if (!(factor > 0) || !(lambda_[0] > 1e-300)) return kMinusInf;
    return -(inv_trace_ - rho * s2 / factor);
  }

  // E, O2, O4: the extreme eigenvalues of the update from the secular equation; eigenvalues
  // whose direction g does not touch (z_i ≈ 0) are deflated and stay as they are.
  double ExtremeEigenvalueScore(double rho, DesignCriterion criterion) {
    const int n = static_cast<int>(lambda_.size());
    const double zz = z2_.sum();
    active_.clear();
    double mu_min = std::numeric_limits<double>::infinity(), mu_max = -mu_min;
    const double tol = 1e-26 * (zz + std::fabs(lambda_[n - 1]));
    for (int i = 0; i < n; ++i) {
      if (z2_[i] > tol) {
        active_.push_back(i);
      } else {
        mu_min = std::min(mu_min, lambda_[i]);
        mu_max = std::max(mu_max, lambda_[i]);
      }
    }
    if (!active_.empty()) {
      mu_min = std::min(mu_min, SmallestRoot(rho, zz));
      if (criterion == DesignCriterion::kO2 || criterion == DesignCriterion::kO4)
        mu_max = std::max(mu_max, LargestRoot(rho, zz));
    }
    if (!(mu_min > 1e-300)) return 0.0;
    switch (criterion) {
      case DesignCriterion::kE:
        return std::sqrt(mu_min);
      case DesignCriterion::kO2:
        return std::sqrt(mu_min / mu_max);
      case DesignCriterion::kO4:
        return mu_min / std::sqrt(mu_max);
      default:
        return kMinusInf;
    }
  }

  // The smallest and largest roots of the secular equation, bracketed by the interlacing of
  // the old and new eigenvalues (rank-one update of sign rho).
  double SmallestRoot(double rho, double zz) const {
    const int a = static_cast<int>(active_.size());
    const int j0 = active_[0];
    const double lo = rho > 0 ? lambda_[j0] : lambda_[j0] - zz;
    const double hi = rho > 0 ? (a > 1 ? lambda_[active_[1]] : lambda_[j0] + zz) : lambda_[j0];
    return SecularRoot(lambda_, z2_, active_, rho, lo, hi);
  }
  double LargestRoot(double rho, double zz) const {
    const int a = static_cast<int>(active_.size());
    const int jl = active_[a - 1];
    const double lo = rho > 0 ? lambda_[jl] : (a > 1 ? lambda_[active_[a - 2]] : lambda_[jl] - zz);
    const double hi = rho > 0 ? lambda_[jl] + zz : lambda_[jl];
    return SecularRoot(lambda_, z2_, active_, rho, lo, hi);
  }

  Eigen::VectorXd lambda_, z_, z2_, mu_;
  Eigen::MatrixXd Q_;
  std::vector<int> active_;
  double log_det_ = 0, inv_trace_ = 0;
};

// E-optimality: the best of A + rho·g_r·g_rᵀ over `rows` by exact scores, evaluated in the
// order of their Rayleigh bounds (MinEigenvalueBounds) and stopped when the next bound cannot
// beat the best (BestInBoundOrder). Returns the position in `rows`, or -1 if none scores above
// `floor`.
int BestByBoundedScores(const Spectrum& spectrum, Spectrum* scorer, const Eigen::MatrixXd& G,
                        const std::vector<int>& rows, double rho, int m, double floor,
                        long long* evaluations) {
  const Eigen::VectorXd bounds = spectrum.MinEigenvalueBounds(G, rows, rho);
  // A bound in σ units, widened by rounding (relative 1e-12 of the largest eigenvalue).
  const double slack = 1e-12 * std::fabs(spectrum.eigenvalues().maxCoeff());
  return BestInBoundOrder(
      bounds, [&](int pos) { return std::sqrt(std::max(bounds[pos] + slack, 0.0)); },
      [&](int pos, double) {
        return scorer->Score(G.row(rows[pos]).transpose(), rho, m, DesignCriterion::kE);
      },
      floor, evaluations);
}

// λ_min(Λ + su·u·uᵀ + sv·v·vᵀ) for Λ = diag(lambda) (ascending) and signs su, sv = ±1, by
// bisection on the eigenvalue count: with S = diag(su, sv) and C(μ) = S + [u v]ᵀ(Λ − μ)⁻¹[u v],
// Haynsworth's inertia additivity gives #{eigenvalues < μ} = #{λ_l < μ} + pos(C(μ)) − pos(S),
// so no eigenvector is needed. Starts from [λ_1 − ‖u‖² (and − ‖v‖²) for negative signs, hi]
// (hi an upper bound) and stops early, returning a value below `give_up`, once the root is known
// to lie below it.
double RankTwoMinEigenvalue(const Eigen::VectorXd& lambda, const Eigen::RowVectorXd& u, int su,
                            const Eigen::RowVectorXd& v, int sv, double hi, double give_up) {
  const int n = static_cast<int>(lambda.size());
  double lo = lambda[0] - (su < 0 ? u.squaredNorm() : 0) - (sv < 0 ? v.squaredNorm() : 0);
  const double tol = 4 * std::numeric_limits<double>::epsilon() *
                     std::max(std::fabs(lambda[n - 1]), std::fabs(lo));
  const int positive_s = (su > 0) + (sv > 0);
  while (hi - lo > tol) {
    if (hi < give_up) return hi;
    const double mu = 0.5 * (lo + hi);
    double a = 0, b = 0, c = 0;
    int below = 0;
    for (int l = 0; l < n; ++l) {
      double d = lambda[l] - mu;
      if (d == 0) d = std::numeric_limits<double>::min();  // μ on a pole: nudge
      below += d < 0;
      const double t = 1.0 / d;
      a += u[l] * u[l] * t;
      b += u[l] * v[l] * t;
      c += v[l] * v[l] * t;
    }
    const double c11 = su + a, c22 = sv + c, det = c11 * c22 - b * b;
    const int positive = det < 0 ? 1 : (c11 + c22 > 0 ? 2 : 0);
    if (below + positive - positive_s >= 1)
      hi = mu;  // an eigenvalue below μ
    else
      lo = mu;
  }
  return hi;
}

// E-optimality, a greedy step ahead without a new eigendecomposition: the position in `rows`
// of the best λ_min(A + rho·g_f·g_fᵀ + rho·g_r·g_rᵀ) (g_f the row `first` just chosen), from
// A's spectrum by RankTwoMinEigenvalue in the order of the Rayleigh bounds; ties: the lowest
// position; -1 if `rows` is empty.
int BestSecondStep(const Spectrum& spectrum, const Eigen::MatrixXd& G, const std::vector<int>& rows,
                   int first, int rho, long long* evaluations) {
  const Eigen::MatrixXd& Q = spectrum.eigenvectors();
  const Eigen::VectorXd& lambda = spectrum.eigenvalues();
  const Eigen::RowVectorXd u = G.row(first) * Q;
  const Eigen::MatrixXd Z = G(rows, Eigen::all) * Q;
  const Eigen::VectorXd bounds = ((rho * Z.array().square()).rowwise() +
                                  (lambda.transpose().array() + rho * u.array().square()))
                                     .rowwise()
                                     .minCoeff()
                                     .matrix();
  const double slack = 1e-12 * std::fabs(lambda.maxCoeff());
  return BestInBoundOrder(
      bounds, [&](int pos) { return bounds[pos] + slack; },
      [&](int pos, double best) {
        return RankTwoMinEigenvalue(lambda, u, rho, Z.row(pos), rho, bounds[pos] + slack, best);
      },
      kMinusInf, evaluations);
}

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

Eigen::MatrixXd NormalMatrixOf(const Eigen::MatrixXd& G, const std::vector<int>& rows) {
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

std::vector<int> Backward(const Eigen::MatrixXd& G, int k, DesignCriterion criterion,
                          long long* evaluations) {
  const int N = static_cast<int>(G.rows());
  std::vector<int> kept(N);
  std::iota(kept.begin(), kept.end(), 0);
  Eigen::MatrixXd A = NormalMatrixOf(G, kept);
  Spectrum spectrum;
  while (static_cast<int>(kept.size()) > k) {
    spectrum.Compute(A);
    if (criterion == DesignCriterion::kE) {
      const int best_pos =
          BestByBoundedScores(spectrum, &spectrum, G, kept, -1.0, static_cast<int>(kept.size()) - 1,
                              kMinusInf, evaluations);
      const int drop = best_pos < 0 ? 0 : best_pos;
      const int first = kept[drop];
      A.noalias() -= G.row(first).transpose() * G.row(first);
      kept.erase(kept.begin() + drop);
      if (static_cast<int>(kept.size()) > k) {  // the next step from the same spectrum
        const int second = BestSecondStep(spectrum, G, kept, first, -1, evaluations);
        const int drop2 = second < 0 ? 0 : second;
        A.noalias() -= G.row(kept[drop2]).transpose() * G.row(kept[drop2]);
        kept.erase(kept.begin() + drop2);
      }
      continue;
    }
    double best = -std::numeric_limits<double>::infinity();
    int best_pos = 0;
    for (int pos = 0; pos < static_cast<int>(kept.size()); ++pos) {
      const double s = spectrum.Score(G.row(kept[pos]).transpose(), -1.0,
                                      static_cast<int>(kept.size()) - 1, criterion);
      ++*evaluations;
      if (s > best) {  // ties: the lowest index is dropped first
        best = s;
        best_pos = pos;
      }
    }
    A.noalias() -= G.row(kept[best_pos]).transpose() * G.row(kept[best_pos]);
    kept.erase(kept.begin() + best_pos);
  }
  return kept;
}

// Greedy forward's state: the design so far and its information matrix.
struct ForwardState {
  const Eigen::MatrixXd& G;
  Eigen::MatrixXd A;
  std::vector<bool> chosen;
  std::vector<int> out;
  long long* evaluations;

  void Add(int j) {
    chosen[j] = true;
    out.push_back(j);
    A.noalias() += G.row(j).transpose() * G.row(j);
  }
  std::vector<int> Free() const {
    std::vector<int> free;
    for (int j = 0; j < static_cast<int>(G.rows()); ++j)
      if (!chosen[j]) free.push_back(j);
    return free;
  }
};

// D: log det(A + g·gᵀ) = log det A + log(1 + gᵀA⁻¹g), so the largest ‖L⁻¹g‖ (A = LLᵀ) wins.
void ForwardStepD(ForwardState* f) {
  const Eigen::LLT<Eigen::MatrixXd> llt(f->A);
  const Eigen::VectorXd gain =
      llt.matrixL().solve(f->G.transpose()).colwise().squaredNorm().transpose();
  int best_j = -1;
  for (int j = 0; j < static_cast<int>(f->G.rows()); ++j) {
    ++*f->evaluations;
    if (!f->chosen[j] && (best_j < 0 || gain[j] > gain[best_j])) best_j = j;
  }
  f->Add(best_j);
}

// E: a step by bounded scores, and the next one from the same spectrum (BestSecondStep).
void ForwardStepsE(ForwardState* f, int k, Spectrum* spectrum) {
  spectrum->Compute(f->A);
  std::vector<int> free = f->Free();
  const int best_pos = std::max(
      0, BestByBoundedScores(*spectrum, spectrum, f->G, free, 1.0,
                             static_cast<int>(f->out.size()) + 1, kMinusInf, f->evaluations));
  const int first = free[best_pos];
  f->Add(first);
  if (static_cast<int>(f->out.size()) >= k) return;
  free.erase(free.begin() + best_pos);
  const int second = BestSecondStep(*spectrum, f->G, free, first, 1, f->evaluations);
  f->Add(free[std::max(0, second)]);
}

// Other criteria: every free candidate's what-if score.
void ForwardStep(ForwardState* f, DesignCriterion c, Spectrum* spectrum) {
  spectrum->Compute(f->A);
  double best = -std::numeric_limits<double>::infinity();
  int best_j = -1;
  for (int j = 0; j < static_cast<int>(f->G.rows()); ++j) {
    if (f->chosen[j]) continue;
    const double s =
        spectrum->Score(f->G.row(j).transpose(), 1.0, static_cast<int>(f->out.size()) + 1, c);
    ++*f->evaluations;
    if (s > best || best_j < 0) {
      best = s;
      best_j = j;
    }
  }
  f->Add(best_j);
}

std::vector<int> Forward(const Eigen::MatrixXd& G, int k, DesignCriterion criterion,
                         long long* evaluations) {
  const int N = static_cast<int>(G.rows()), n = static_cast<int>(G.cols());
  // A small ridge keeps the first n additions well defined; they use D-optimality, which
  // rewards every new direction (σ-based criteria stay 0 until the design has rank n).
  const double ridge = 1e-9 * G.squaredNorm() / std::max(n, 1);
  ForwardState f{
      G, ridge * Eigen::MatrixXd::Identity(n, n), std::vector<bool>(N, false), {}, evaluations};
  Spectrum spectrum;
  while (static_cast<int>(f.out.size()) < k) {
    const DesignCriterion c = static_cast<int>(f.out.size()) < n ? DesignCriterion::kD : criterion;
    if (c == DesignCriterion::kD)
      ForwardStepD(&f);
    else if (c == DesignCriterion::kE)
      ForwardStepsE(&f, k, &spectrum);
    else
      ForwardStep(&f, c, &spectrum);
  }
  std::sort(f.out.begin(), f.out.end());
  return f.out;
}

// E-optimality swaps in the eigenbasis of the design's A = QΛQᵀ: with z_r = Qᵀg_r (the rows of
// Z = G·Q), swapping design row i for candidate j gives λ_min(Λ − z_i z_iᵀ + z_j z_jᵀ), bounded
// above by min_l λ_l − z_il² + z_jl² (the Rayleigh quotients of A's eigenvectors). Candidates are
// evaluated exactly (RankTwoMinEigenvalue) in the order of their bounds until no bound can beat
// the best, so a design row costs no eigendecomposition; A's is refreshed after each accepted
// swap.
struct SwapSpectrum {
  bool valid = false;
  Eigen::VectorXd lambda;
  Eigen::MatrixXd Z, Z2;  // (q_lᵀg_r) and its square, N × n

  void Compute(const Eigen::MatrixXd& G, const Eigen::MatrixXd& A) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A);
    lambda = eig.eigenvalues();
    Z.noalias() = G * eig.eigenvectors();
    Z2 = Z.array().square().matrix();
    valid = true;
  }

  // The candidate in `outside` whose swap for design row i gives the largest λ_min above
  // `floor` (in λ units), or -1; ties: the lowest index.
  int BestSwap(int i, const std::vector<int>& outside, double floor, long long* evaluations) const {
    const double slack = 1e-12 * std::fabs(lambda.maxCoeff());
    const Eigen::RowVectorXd base = lambda.transpose() - Z2.row(i);
    // Positions in `outside` (ascending, so the lowest position is the lowest index).
    Eigen::VectorXd bounds(static_cast<Eigen::Index>(outside.size()));
    for (std::size_t p = 0; p < outside.size(); ++p)
      bounds[static_cast<Eigen::Index>(p)] = (base + Z2.row(outside[p])).minCoeff() + slack;
    const int pos = BestInBoundOrder(
        bounds, [&](int p) { return bounds[p]; },
        [&](int p, double best) {
          return RankTwoMinEigenvalue(lambda, Z.row(i), -1, Z.row(outside[p]), 1, bounds[p], best);
        },
        floor, evaluations);
    return pos < 0 ? -1 : outside[pos];
  }
};

// The state of an exchange search: the design, its normal matrix and score.
struct ExchangeState {
  const Eigen::MatrixXd& G;
  DesignCriterion criterion;
  std::vector<int> design;
  std::vector<bool> in;
  Eigen::MatrixXd A;
  double current = 0;
  Spectrum spectrum;
  // E: A's eigendecomposition for the swaps (SwapSpectrum), refreshed after each accepted swap.
  SwapSpectrum swaps;
  long long* evaluations;
  // D and A: the swaps' quadratic forms (SwapForms), refreshed after each accepted swap.
  struct SwapForms {
    bool valid = false, usable = false;
    Eigen::MatrixXd H1, H2;  // G·A⁻¹·Gᵀ and G·A⁻²·Gᵀ (A only), N × N
    double log_det = 0, inv_trace = 0;
  } forms;
};

// D and A: Fedorov's swap formulas. With h = G·A⁻¹·Gᵀ, swapping design row i for candidate j
// multiplies det A by r = (1 − h_ii)(1 + h_jj) + h_ij² (the swap keeps A positive definite iff
// r > 0), and by Woodbury with M = [[h_ii − 1, h_ij], [h_ij, 1 + h_jj]] and q = G·A⁻²·Gᵀ,
// tr(A')⁻¹ = tr A⁻¹ − ((1 + h_jj)·q_ii − 2·h_ij·q_ij + (h_ii − 1)·q_jj) / det M: O(1) a swap.
void ComputeSwapForms(ExchangeState* x) {
  auto& f = x->forms;
  f.valid = true;
  const Eigen::LLT<Eigen::MatrixXd> llt(x->A);
  f.usable = llt.info() == Eigen::Success;
  if (!f.usable) return;
  const Eigen::MatrixXd W = llt.matrixL().solve(x->G.transpose());  // L⁻¹Gᵀ, n × N
  f.H1.noalias() = W.transpose() * W;
  f.log_det = 2 * llt.matrixLLT().diagonal().array().log().sum();
  if (x->criterion == DesignCriterion::kA) {
    const Eigen::MatrixXd V = llt.matrixU().solve(W);  // A⁻¹Gᵀ
    f.H2.noalias() = V.transpose() * V;
    const Eigen::MatrixXd Linv =
        llt.matrixL().solve(Eigen::MatrixXd::Identity(x->A.rows(), x->A.cols()));
    f.inv_trace = Linv.squaredNorm();
  }
}

// The score (D: log det; A: −tr A⁻¹) after swapping design row i for candidate j, from SwapForms;
// −∞ when the swap leaves A singular.
double SwapScore(const ExchangeState& x, int i, int j) {
  const auto& f = x.forms;
  const double hii = f.H1(i, i), hjj = f.H1(j, j), hij = f.H1(i, j);
  const double r = (1 - hii) * (1 + hjj) + hij * hij;
  if (!(r > 0)) return kMinusInf;
  if (x.criterion == DesignCriterion::kD) return f.log_det + std::log(r);
  const double change =
      ((1 + hjj) * f.H2(i, i) - 2 * hij * f.H2(i, j) + (hii - 1) * f.H2(j, j)) / -r;
  return -(f.inv_trace - change);
}

// A with design row i swapped for candidate j.
Eigen::MatrixXd SwappedNormalMatrix(const ExchangeState& x, int i, int j) {
  Eigen::MatrixXd A = x.A;
  A.noalias() -= x.G.row(i).transpose() * x.G.row(i);
  A.noalias() += x.G.row(j).transpose() * x.G.row(j);
  return A;
}

// Makes the swap of design[pos] for candidate j, whose normal matrix is A and exact score
// `exact`; the swap data of the old design are stale.
void AcceptSwap(ExchangeState* x, int pos, int j, Eigen::MatrixXd A, double exact) {
  x->in[x->design[pos]] = false;
  x->in[j] = true;
  x->design[pos] = j;
  x->A = std::move(A);
  x->current = exact;
  x->swaps.valid = false;
  x->forms.valid = false;
}

// E: replaces design[pos] by its best improving swap (SwapSpectrum); true if it did.
bool ImproveAtE(ExchangeState* x, int pos, const std::vector<int>& outside) {
  const int i = x->design[pos];
  // A swap must improve σ_min by more than the evaluation's rounding (relative 1e-10).
  const double floor = x->current + 1e-10 * std::fabs(x->current);
  if (!x->swaps.valid) x->swaps.Compute(x->G, x->A);
  const int best_in = x->swaps.BestSwap(i, outside, floor * floor, x->evaluations);
  if (best_in < 0) return false;
  Eigen::MatrixXd A = SwappedNormalMatrix(*x, i, best_in);
  SwapSpectrum fresh;
  fresh.Compute(x->G, A);
  const double exact =
      ScoreFromEigenvalues(fresh.lambda, static_cast<int>(x->design.size()), DesignCriterion::kE);
  if (!(exact > x->current)) return false;  // the evaluation was wrong at rounding level
  AcceptSwap(x, pos, best_in, std::move(A), exact);
  x->swaps = std::move(fresh);  // the new design's spectrum, already computed
  return true;
}

// D and A: replaces design[pos] by its best improving swap (SwapScore); true if it did.
bool ImproveAtDA(ExchangeState* x, int pos, const std::vector<int>& outside, double floor) {
  const int i = x->design[pos], k = static_cast<int>(x->design.size());
  double best = floor;
  int best_in = -1;
  for (int j : outside) {
    const double s = SwapScore(*x, i, j);
    ++*x->evaluations;
    if (s > best) {
      best = s;
      best_in = j;
    }
  }
  if (best_in < 0) return false;
  Eigen::MatrixXd A = SwappedNormalMatrix(*x, i, best_in);
  const double exact = CriterionScore(A, k, x->criterion);
  if (!(exact > x->current)) return false;  // the formula was wrong at rounding level
  AcceptSwap(x, pos, best_in, std::move(A), exact);
  return true;
}

// Replaces design[pos] by its best improving replacement, if there is one; true if it did.
bool ImproveAt(ExchangeState* x, int pos) {
  const int i = x->design[pos], k = static_cast<int>(x->design.size());
  std::vector<int> outside;
  for (int j = 0; j < static_cast<int>(x->G.rows()); ++j)
    if (!x->in[j]) outside.push_back(j);
  if (x->criterion == DesignCriterion::kE) return ImproveAtE(x, pos, outside);
  // A swap must improve by more than the what-if's rounding (relative 1e-10).
  const double floor = x->current + 1e-10 * std::fabs(x->current);
  if (x->criterion == DesignCriterion::kD || x->criterion == DesignCriterion::kA) {
    if (!x->forms.valid) ComputeSwapForms(x);
    if (x->forms.usable) return ImproveAtDA(x, pos, outside, floor);
  }
  Eigen::MatrixXd without = x->A - x->G.row(i).transpose() * x->G.row(i);
  x->spectrum.Compute(without);
  double best = floor;
  int best_in = -1;
  for (int j : outside) {
    const double s = x->spectrum.Score(x->G.row(j).transpose(), 1.0, k, x->criterion);
    ++*x->evaluations;
    if (s > best) {
      best = s;
      best_in = j;
    }
  }
  if (best_in < 0) return false;
  without.noalias() += x->G.row(best_in).transpose() * x->G.row(best_in);
  const double exact = CriterionScore(without, k, x->criterion);
  if (!(exact > x->current)) return false;  // the what-if was wrong at rounding level
  AcceptSwap(x, pos, best_in, std::move(without), exact);
  return true;
}

// Single swaps (one out, one in), DETMAX style: sweep over the design, and for each member take
// the best improving replacement at once; stop after a sweep with no improvement.
std::vector<int> Exchange(const Eigen::MatrixXd& G, std::vector<int> design,
                          DesignCriterion criterion, long long* evaluations) {
  ExchangeState x{
      G,  criterion,   design, std::vector<bool>(G.rows(), false), NormalMatrixOf(G, design), 0, {},
      {}, evaluations, {}};
  for (int i : design) x.in[i] = true;
  x.current = CriterionScore(x.A, static_cast<int>(design.size()), criterion);
  for (int sweep = 0; sweep < 1000; ++sweep) {
    bool improved = false;
    for (int pos = 0; pos < static_cast<int>(x.design.size()); ++pos)
      improved = ImproveAt(&x, pos) || improved;
    if (!improved) break;
  }
  std::sort(x.design.begin(), x.design.end());
  return x.design;
}

}  // namespace

Eigen::VectorXd RankOneUpdatedEigenvalues(const Eigen::VectorXd& lambda, const Eigen::VectorXd& z,
                                          double rho) {
  const int n = static_cast<int>(lambda.size());
  const Eigen::VectorXd z2 = z.cwiseAbs2();
  const double zz = z2.sum();
  const double tol = 1e-26 * (zz + std::fabs(lambda[n - 1]));
  std::vector<int> active;
  std::vector<double> mu;
  for (int i = 0; i < n; ++i) {
    if (z2[i] > tol)
      active.push_back(i);
    else
      mu.push_back(lambda[i]);
  }
  const int a = static_cast<int>(active.size());
  for (int t = 0; t < a; ++t) {
    double lo, hi;
    if (rho > 0) {
      lo = lambda[active[t]];
      hi = t + 1 < a ? lambda[active[t + 1]] : lambda[active[t]] + zz;
    } else {
      lo = t > 0 ? lambda[active[t - 1]] : lambda[active[0]] - zz;
      hi = lambda[active[t]];
    }
    mu.push_back(lo == hi ? lo : SecularRoot(lambda, z2, active, rho, lo, hi));
  }
  std::sort(mu.begin(), mu.end());
  return Eigen::Map<Eigen::VectorXd>(mu.data(), n);
}

double CriterionScore(const Eigen::MatrixXd& A, int m, DesignCriterion criterion) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A, Eigen::EigenvaluesOnly);
  return ScoreFromEigenvalues(eig.eigenvalues(), m, criterion);
}

std::vector<double> CriterionScores(const Eigen::MatrixXd& A, int m,
                                    const std::vector<DesignCriterion>& criteria) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A, Eigen::EigenvaluesOnly);
  std::vector<double> scores;
  scores.reserve(criteria.size());
  for (DesignCriterion c : criteria)
    scores.push_back(ScoreFromEigenvalues(eig.eigenvalues(), m, c));
  return scores;
}

Eigen::VectorXd ExpectedErrors(const ParameterSet& parameters, double angle, double length) {
  return ExpectedErrors(parameters.names, angle, length);
}

Eigen::VectorXd ExpectedErrors(const std::vector<std::string>& names, double angle, double length) {
  Eigen::VectorXd expected(static_cast<Eigen::Index>(names.size()));
  for (std::size_t k = 0; k < names.size(); ++k)
    expected[static_cast<Eigen::Index>(k)] = IsAngularName(names[k]) ? angle : length;
  return expected;
}

Eigen::MatrixXd TaskWeightedJacobian(const Eigen::MatrixXd& G,
                                     const Eigen::MatrixXd& position_rows) {
  const int n = static_cast<int>(G.cols());
  Eigen::MatrixXd W = position_rows.transpose() * position_rows;
  W.diagonal().array() += 1e-9 * W.trace() / n + 1e-300;
  const Eigen::LLT<Eigen::MatrixXd> llt(W);
  // G·L⁻ᵀ = (L⁻¹·Gᵀ)ᵀ
  return llt.matrixL().solve(G.transpose()).transpose();
}

Eigen::MatrixXd DesignJacobian(const MeasurementKind& kind, const TargetedConfigurations& pool,
                               DesignScaling scaling, double angle, double length) {
  return ScaleColumns(MeasurementJacobian(kind, pool), scaling,
                      ExpectedErrors(kind.parameter_names(), angle, length));
}

Eigen::MatrixXd DesignJacobian(const MeasurementModel& model, const TargetedConfigurations& pool,
                               DesignScaling scaling, double angle, double length) {
  return DesignJacobian(RangerMeasurement(model), pool, scaling, angle, length);
}

Eigen::MatrixXd ScaleColumns(const Eigen::MatrixXd& G, DesignScaling scaling,
                             const Eigen::VectorXd& expected) {
  switch (scaling) {
    case DesignScaling::kSI:
      return G;
    case DesignScaling::kUnitColumns: {
      Eigen::VectorXd norms = G.colwise().norm().transpose();
      for (int j = 0; j < norms.size(); ++j)
        if (!(norms[j] > 0)) norms[j] = 1;  // a zero column stays zero
      return G * norms.cwiseInverse().asDiagonal();
    }
    case DesignScaling::kExpectedErrors:
      if (expected.size() != G.cols())
        throw InputError("scaling", "expected-error scaling needs one magnitude per parameter");
      return G * expected.asDiagonal();
  }
  return G;
}

namespace {

void CheckSelectionSize(int N, int n, int k) {
  if (N == 0) throw InputError("selection", "the candidate pool is empty");
  if (k > N)
    throw InputError("selection", "cannot select " + std::to_string(k) + " of " +
                                      std::to_string(N) + " candidates");
  if (k < n)
    throw InputError("selection", "selecting " + std::to_string(k) + " configurations for " +
                                      std::to_string(n) +
                                      " parameters: need at least as many configurations as "
                                      "parameters");
}

// The paper's case 1: the best of `samples` random subsets.
void SelectSampled(const Eigen::MatrixXd& G, int k, const SelectionOptions& options,
                   const RandomStream& stream, SelectionResult* best) {
  const int N = static_cast<int>(G.rows());
  for (int s = 0; s < options.samples; ++s) {
    std::vector<int> subset = RandomSubset(N, k, stream, static_cast<std::uint64_t>(s) * N);
    const double score = CriterionScore(NormalMatrixOf(G, subset), k, options.criterion);
    ++best->evaluations;
    if (score > best->score) {
      best->score = score;
      best->indices = subset;
    }
  }
}

// Every k-subset, enumerated by its left-out set (N − k candidates) in lexicographic order.
void SelectExhaustive(const Eigen::MatrixXd& G, int k, const SelectionOptions& options,
                      SelectionResult* best) {
  const int N = static_cast<int>(G.rows());
  const double count = Binomial(N, k);
  if (count > options.exhaustive_limit)
    throw InputError("selection", "exhaustive search over C(" + std::to_string(N) + "," +
                                      std::to_string(k) + ") = " + std::to_string(count) +
                                      " subsets is beyond the limit; use exchange or backward");
  std::vector<int> all(N);
  std::iota(all.begin(), all.end(), 0);
  const Eigen::MatrixXd A_all = NormalMatrixOf(G, all);
  const int drop = N - k;
  std::vector<int> out(drop);
  std::iota(out.begin(), out.end(), 0);
  while (true) {
    Eigen::MatrixXd A = A_all;
    for (int r : out) A.noalias() -= G.row(r).transpose() * G.row(r);
    const double score = CriterionScore(A, k, options.criterion);
    ++best->evaluations;
    if (score > best->score) {
      best->score = score;
      best->indices.clear();
      for (int i = 0, o = 0; i < N; ++i) {
        if (o < drop && out[o] == i) {
          ++o;
          continue;
        }
        best->indices.push_back(i);
      }
    }
    int i = drop - 1;
    while (i >= 0 && out[i] == N - drop + i) --i;
    if (i < 0) return;
    ++out[i];
    for (int j = i + 1; j < drop; ++j) out[j] = out[j - 1] + 1;
  }
}

// `design` with ⌈k/10⌉ (at least 2) of its members swapped for candidates outside it, both
// drawn from the stream: an iterated-local-search kick from a local optimum.
std::vector<int> PerturbedDesign(std::vector<int> design, int N, const RandomStream& stream,
                                 std::uint64_t first) {
  const int k = static_cast<int>(design.size());
  std::vector<bool> in(N, false);
  for (int i : design) in[i] = true;
  std::vector<int> outside;
  for (int j = 0; j < N; ++j)
    if (!in[j]) outside.push_back(j);
  const int swaps = std::min({std::max(2, (k + 9) / 10), k, static_cast<int>(outside.size())});
  const std::vector<int> out = RandomSubset(k, swaps, stream, first);
  const std::vector<int> into =
      RandomSubset(static_cast<int>(outside.size()), swaps, stream, first + k);
  for (int t = 0; t < swaps; ++t) design[out[t]] = outside[into[t]];
  std::sort(design.begin(), design.end());
  return design;
}

// Projected-gradient steps of the relaxation whose rounded solution starts an exchange: a start,
// not a bound, so fewer than the certificate's: 50 cost 2.5 ms on the paper's 101 × 25, and 300
// (15 ms) gave neither consistently better nor worse exchange ends at k = 26–42 on four pools.
constexpr int kRoundingIterations = 50;

// Exchange from several starts: the backward-greedy design, the forward-greedy design and the
// relaxation's rounded solution, then (restarts − 1) kicks of the best design so far
// (PerturbedDesign); the best end wins, so the result is at least as good as greedy (forward or
// backward) followed by swaps.
void SelectExchange(const Eigen::MatrixXd& G, int k, const SelectionOptions& options,
                    const RandomStream& stream, SelectionResult* best) {
  const int N = static_cast<int>(G.rows());
  const int kicks = std::max(1, options.restarts) - 1;
  best->start_score = -std::numeric_limits<double>::infinity();
  for (int r = 0; r < 3 + kicks; ++r) {
    std::vector<int> start;
    if (r == 0) {
      start = Backward(G, k, options.criterion, &best->evaluations);
    } else if (r == 1) {
      start = Forward(G, k, options.criterion, &best->evaluations);
    } else if (r == 2) {
      start = RelaxedDesign(G, k, options.criterion, kRoundingIterations);
      if (start.empty()) continue;  // no relaxation for this criterion
    } else {
      start = PerturbedDesign(best->indices, N, stream, static_cast<std::uint64_t>(r) * 2 * N);
    }
    best->start_score =
        std::max(best->start_score, CriterionScore(NormalMatrixOf(G, start), k, options.criterion));
    std::vector<int> end = Exchange(G, start, options.criterion, &best->evaluations);
    const double score = CriterionScore(NormalMatrixOf(G, end), k, options.criterion);
    if (score > best->score) {
      best->score = score;
      best->indices = end;
    }
  }
}

}  // namespace

SelectionResult SelectConfigurations(const Eigen::MatrixXd& G, int k,
                                     const SelectionOptions& options, const RandomStream& stream) {
  options.Validate();
  CheckSelectionSize(static_cast<int>(G.rows()), static_cast<int>(G.cols()), k);
  SelectionResult best;
  best.score = -std::numeric_limits<double>::infinity();
  switch (options.method) {
    case SelectionMethod::kRandom:
      best.indices = RandomSubset(static_cast<int>(G.rows()), k, stream, 0);
      best.evaluations = 1;
      break;
    case SelectionMethod::kSampled:
      SelectSampled(G, k, options, stream, &best);
      break;
    case SelectionMethod::kExhaustive:
      SelectExhaustive(G, k, options, &best);
      break;
    case SelectionMethod::kBackward:
      best.indices = Backward(G, k, options.criterion, &best.evaluations);
      break;
    case SelectionMethod::kGreedy:
      best.indices = Forward(G, k, options.criterion, &best.evaluations);
      break;
    case SelectionMethod::kExchange:
      SelectExchange(G, k, options, stream, &best);
      break;
  }
  best.score = CriterionScore(NormalMatrixOf(G, best.indices), k, options.criterion);
  return best;
}

}  // namespace lrcal
