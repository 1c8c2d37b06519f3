#include "lrcal/design/design_certificate.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "lrcal/core/settings.h"
#include "lrcal/core/text_table.h"

namespace lrcal {

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// The sum of the k largest entries.
double TopKSum(const Eigen::VectorXd& v, int k) {
  std::vector<double> x(v.data(), v.data() + v.size());
  std::nth_element(x.begin(), x.begin() + (k - 1), x.end(), std::greater<double>());
  double sum = 0;
  for (int i = 0; i < k; ++i) sum += x[i];
  return sum;
}

// The Euclidean projection of y onto {w : 0 ≤ w ≤ 1, Σ w = k}: clamp(y − τ, 0, 1) with τ found
// by bisection (Σ clamp(y − τ) falls as τ grows).
Eigen::VectorXd ProjectCappedSimplex(const Eigen::VectorXd& y, int k) {
  double lo = y.minCoeff() - 1, hi = y.maxCoeff();
  const auto total = [&](double tau) { return (y.array() - tau).max(0.0).min(1.0).sum(); };
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (total(mid) > k) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return (y.array() - 0.5 * (lo + hi)).max(0.0).min(1.0).matrix();
}

bool Certifiable(DesignCriterion c) {
  return c == DesignCriterion::kE || c == DesignCriterion::kD || c == DesignCriterion::kA;
}

// One relaxation step's value of the bound and the ascent direction, for w (M = M(w)).
struct Step {
  double bound = kInf;
  Eigen::VectorXd gradient;
};

// E: λ_min; bounds from Z = v₁v₁ᵀ and from the soft-min mixture of eigenvectors (whose weights
// are also the smoothed objective's gradient).
Step StepE(const Eigen::MatrixXd& G, const Eigen::MatrixXd& M, int k, int t) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(M);
  const Eigen::VectorXd& lambda = eigen.eigenvalues();
  const Eigen::MatrixXd GV2 = (G * eigen.eigenvectors()).array().square().matrix();
  Step s;
  s.bound = TopKSum(GV2.col(0), k);
  const double tau = std::max(1e-12, 0.05 * std::fabs(lambda[0]) / std::sqrt(t + 1.0));
  Eigen::VectorXd p = (-(lambda.array() - lambda[0]) / tau).exp().matrix();
  p /= p.sum();
  s.gradient = GV2 * p;
  s.bound = std::min(s.bound, TopKSum(s.gradient, k));
  return s;
}

// M⁻¹ by Cholesky, with log det M; false when M is not positive definite.
bool SpdInverse(const Eigen::MatrixXd& M, Eigen::MatrixXd* inverse, double* logdet) {
  const Eigen::LLT<Eigen::MatrixXd> llt(M);
  if (llt.info() != Eigen::Success) return false;
  *inverse = llt.solve(Eigen::MatrixXd::Identity(M.rows(), M.cols()));
  *logdet = 2 * llt.matrixLLT().diagonal().array().log().sum();
  return true;
}

// D: log det M, ∇ᵢ = gᵢᵀM⁻¹gᵢ, Σ wᵢ∇ᵢ = n.
Step StepD(const Eigen::MatrixXd& G, const Eigen::MatrixXd& M, int k) {
  Step s;
  Eigen::MatrixXd Minv;
  double logdet = 0;
  if (!SpdInverse(M, &Minv, &logdet)) return s;
  s.gradient = ((G * Minv).array() * G.array()).rowwise().sum().matrix();
  s.bound = logdet + TopKSum(s.gradient, k) - static_cast<double>(M.rows());
  return s;
}

// A: −tr M⁻¹, ∇ᵢ = gᵢᵀM⁻²gᵢ, Σ wᵢ∇ᵢ = tr M⁻¹.
Step StepA(const Eigen::MatrixXd& G, const Eigen::MatrixXd& M, int k) {
  Step s;
  Eigen::MatrixXd Minv;
  double logdet = 0;
  if (!SpdInverse(M, &Minv, &logdet)) return s;
  s.gradient = ((G * (Minv * Minv)).array() * G.array()).rowwise().sum().matrix();
  const double trace = Minv.trace();
  s.bound = -trace + TopKSum(s.gradient, k) - trace;
  return s;
}

// The relaxation's best bound in the criterion's own units (E: λ_min, not yet σ).
double RelaxationBound(const Eigen::MatrixXd& G, int k, DesignCriterion criterion, int iterations,
                       int* used, Eigen::VectorXd* weights = nullptr) {
  const int N = static_cast<int>(G.rows());
  Eigen::VectorXd w = Eigen::VectorXd::Constant(N, static_cast<double>(k) / N);
  double best = kInf;
  int t = 0;
  for (; t < iterations; ++t) {
    const Eigen::MatrixXd M = G.transpose() * (G.array().colwise() * w.array()).matrix();
    const Step s = criterion == DesignCriterion::kE   ? StepE(G, M, k, t)
                   : criterion == DesignCriterion::kD ? StepD(G, M, k)
                                                      : StepA(G, M, k);
    best = std::min(best, s.bound);
    if (s.gradient.size() == 0) break;  // a singular relaxation (rank-deficient pool)
    const double scale = s.gradient.cwiseAbs().maxCoeff();
    if (!(scale > 0)) break;
    w = ProjectCappedSimplex(w + (0.5 / std::sqrt(t + 1.0)) * s.gradient / scale, k);
  }
  *used = t;
  if (weights) *weights = w;
  return best;
}

}  // namespace

double DesignUpperBound(const Eigen::MatrixXd& G, int k, DesignCriterion criterion,
                        int iterations) {
  if (!Certifiable(criterion) || k < G.cols() || k > G.rows()) return kNan;
  int used = 0;
  const double bound = RelaxationBound(G, k, criterion, iterations, &used);
  if (!std::isfinite(bound)) return kNan;
  return criterion == DesignCriterion::kE ? std::sqrt(std::max(bound, 0.0)) : bound;
}

std::vector<int> RelaxedDesign(const Eigen::MatrixXd& G, int k, DesignCriterion criterion,
                               int iterations) {
  if (!Certifiable(criterion) || k < G.cols() || k > G.rows()) return {};
  int used = 0;
  Eigen::VectorXd w;
  RelaxationBound(G, k, criterion, iterations, &used, &w);
  if (w.size() != G.rows()) return {};
  std::vector<int> order(static_cast<std::size_t>(G.rows()));
  for (int i = 0; i < G.rows(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return w[a] > w[b]; });
  order.resize(static_cast<std::size_t>(k));
  std::sort(order.begin(), order.end());
  return order;
}

DesignCertificate CertifyDesign(const Eigen::MatrixXd& G, const std::vector<int>& chosen,
                                DesignCriterion criterion, int iterations) {
  DesignCertificate c;
  const int k = static_cast<int>(chosen.size()), n = static_cast<int>(G.cols());
  Eigen::MatrixXd Gs(k, n);
  for (int i = 0; i < k; ++i) Gs.row(i) = G.row(chosen[i]);
  c.achieved = CriterionScore(Gs.transpose() * Gs, k, criterion);
  if (!Certifiable(criterion) || k < n || k > G.rows()) return c;
  int used = 0;
  double bound = RelaxationBound(G, k, criterion, iterations, &used);
  c.iterations = used;
  if (!std::isfinite(bound)) return c;
  if (criterion == DesignCriterion::kE) bound = std::sqrt(std::max(bound, 0.0));
  // The design itself is feasible: a bound can never be below it (guards rounding).
  c.bound = std::max(bound, c.achieved);
  c.available = true;
  switch (criterion) {
    case DesignCriterion::kE:
      c.efficiency = c.bound > 0 ? c.achieved / c.bound : 0;
      break;
    case DesignCriterion::kD:
      c.efficiency = std::exp((c.achieved - c.bound) / n);
      break;
    default:  // A: −tr; the best trace is ≥ −bound
      c.efficiency = c.achieved < 0 ? c.bound / c.achieved : 0;
      break;
  }
  return c;
}

std::string DesignCertificate::ToString(DesignCriterion criterion, int k, int candidates) const {
  const std::string name = DesignCriterionName(criterion);
  if (!available)
    return "no certificate for criterion " + name +
           " (the relaxation bound exists for E, D and A, with at least as many configurations "
           "as parameters)";
  std::ostringstream out;
  const std::string what = criterion == DesignCriterion::kE   ? "σ_min"
                           : criterion == DesignCriterion::kD ? "log det GᵀG"
                                                              : "−tr (GᵀG)⁻¹";
  out << "the chosen design reaches " << Fixed(100 * efficiency, 1) << " % of the best possible "
      << name << " (" << what << " ≤ " << std::setprecision(6) << bound << " for any " << k
      << " of these " << candidates << " candidates";
  if (criterion == DesignCriterion::kD) out << "; efficiency exp((log det − bound)/n)";
  if (criterion == DesignCriterion::kA) out << "; efficiency best trace bound / trace";
  out << ")";
  return out.str();
}

}  // namespace lrcal
