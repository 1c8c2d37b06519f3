// The second-order check of a fit's covariance (linearisation_check.h).
#include "lrcal/identification/linearisation_check.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "lrcal/core/text_table.h"

namespace lrcal {

namespace {

// The rows' predictions at e + x; false (and a message) where undefined.
class Predictions {
 public:
  Predictions(MeasurementEvaluator& evaluator, const Eigen::VectorXd& e)
      : evaluator_(evaluator), e_(e), point_(e.size()) {}
  bool At(const Eigen::VectorXd& x, Eigen::VectorXd* y) {
    point_ = e_ + x;
    y->resize(evaluator_.num_rows());
    return evaluator_.Predict(point_.data(), y->data(), nullptr) && y->allFinite();
  }

 private:
  MeasurementEvaluator& evaluator_;
  const Eigen::VectorXd& e_;
  Eigen::VectorXd point_;
};

}  // namespace

LinearisationCheck CheckLinearisation(MeasurementEvaluator& evaluator,
                                      const std::vector<double>& weights, const Eigen::VectorXd& e,
                                      const Eigen::MatrixXd& covariance, double sigma) {
  LinearisationCheck check;
  const int m = evaluator.num_rows(), n = evaluator.num_parameters();
  check.num_parameters = n;
  if (n == 0 || !(sigma > 0) || covariance.rows() != n || !covariance.allFinite()) {
    check.message = "no covariance to check";
    return check;
  }
  // P·u in the coordinates of an orthonormal basis of √W·G's columns: Qᵀ·(√w ∘ u).
  Eigen::VectorXd y0(m);
  Eigen::MatrixXd G(m, n);
  if (!evaluator.Predict(e.data(), y0.data(), G.data())) {
    check.message = "the prediction is undefined at the estimate";
    return check;
  }
  const Eigen::VectorXd root_w =
      Eigen::Map<const Eigen::VectorXd>(weights.data(), m).cwiseMax(0.0).cwiseSqrt();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(root_w.asDiagonal() * G);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(m, n);
  const auto project = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
    return Q.transpose() * root_w.cwiseProduct(u);
  };

  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(covariance);
  // Directions in decreasing uncertainty; one standard deviation along each.
  std::vector<Eigen::VectorXd> step;
  for (int k = n - 1; k >= 0; --k)
    step.push_back(std::sqrt(std::max(eigen.eigenvalues()[k], 0.0)) * eigen.eigenvectors().col(k));
  const int weakest = std::min(n, LinearisationCheck::kMaxFullTerms);

  Predictions f(evaluator, e);
  std::vector<Eigen::VectorXd> plus(static_cast<std::size_t>(n)), minus(plus.size());
  Eigen::VectorXd mean_term = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd score = Eigen::VectorXd::Zero(n);  // per direction, the weaker of each pair
  double square_terms = 0;
  for (int j = 0; j < n; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (!f.At(step[uj], &plus[uj]) || !f.At(-step[uj], &minus[uj])) {
      check.message = "a prediction is undefined one standard deviation from the estimate";
      return check;
    }
    const Eigen::VectorXd p = project(0.5 * (plus[uj] + minus[uj] - 2 * y0));
    mean_term += p;
    square_terms += p.squaredNorm();
    score[j] += p.squaredNorm();
    ++check.pairs;
  }
  Eigen::VectorXd pp, pm, mp, mm;
  for (int j = 0; j < weakest; ++j)
    for (int k = j + 1; k < n; ++k) {
      const Eigen::VectorXd& a = step[static_cast<std::size_t>(j)];
      const Eigen::VectorXd& b = step[static_cast<std::size_t>(k)];
      if (!f.At(a + b, &pp) || !f.At(a - b, &pm) || !f.At(b - a, &mp) || !f.At(-a - b, &mm)) {
        check.message = "a prediction is undefined one standard deviation from the estimate";
        return check;
      }
      // c_jk = ½·f''[a, b]; the ordered pairs (j, k) and (k, j) both count.
      const double term = 2 * project(0.125 * (pp - pm - mp + mm)).squaredNorm();
      square_terms += term;
      score[j] += term;
      ++check.pairs;
    }
  check.excess = (mean_term.squaredNorm() + 2 * square_terms) / (sigma * sigma);
  Eigen::Index worst = 0;
  score.maxCoeff(&worst);
  check.worst_direction_sigma = step[static_cast<std::size_t>(worst)].norm();
  check.worst_direction =
      step[static_cast<std::size_t>(worst)] / std::max(check.worst_direction_sigma, 1e-300);
  check.computed = true;
  return check;
}

std::string LinearisationCheck::Explain(const std::vector<std::string>& names) const {
  if (num_parameters == 0) return "";
  std::ostringstream out;
  if (!computed) {
    out << "linearisation check: not computed (" << message << ")\n";
    return out.str();
  }
  out << "linearisation check: the model's curvature over the estimate's uncertainty adds about "
      << Fixed(excess, 2) << " to the expected chi2(" << num_parameters << ") of its error (";
  if (RelativeExcess() < 10)
    out << Fixed(100 * RelativeExcess(), 1) << " %): ";
  else
    out << Fixed(RelativeExcess(), 0) << " times " << num_parameters << "): ";
  if (Holds())
    out << "the linearised covariance holds\n";
  else
    out << "the covariance is optimistic, most in the best-determined combinations of terms;\n"
           "  spread the configurations wider, or fix or give priors to the least certain terms";
  if (!Holds() && names.size() == static_cast<std::size_t>(worst_direction.size())) {
    // The worst direction's largest components, in decreasing size (at most three).
    std::vector<int> order(names.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return std::fabs(worst_direction[a]) > std::fabs(worst_direction[b]);
    });
    out << "\n  (most of it from the uncertainty along";
    for (std::size_t k = 0; k < std::min<std::size_t>(3, order.size()); ++k)
      out << (k ? ", " : " ") << names[static_cast<std::size_t>(order[k])] << " "
          << Fixed(worst_direction[order[k]], 2);
    out << ")";
  }
  if (!Holds()) out << "\n";
  return out.str();
}

}  // namespace lrcal
