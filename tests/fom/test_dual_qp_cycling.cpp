// fom::DualQpSolver on dense SPD Delassus matrices that are not M-matrices, where the
// primal–dual active-set iteration may cycle and hands over to Lawson–Hanson
// (NnlsQp): every returned λ must satisfy the LCP λ ≥ 0, w = Gλ − h ≥ 0, λᵀw = 0 to
// the solver's tolerance, and the hand-over must actually happen on some of them.
#define BOOST_TEST_MODULE fom_dual_qp_cycling
#include <Eigen/Dense>
#include <boost/test/unit_test.hpp>
#include <random>

#include "common/random_problems.hpp"
#include <contactrom/fom/dual_qp.hpp>

using contactrom::Status;
using contactrom::fom::DualQpSolver;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// Worst violation of the LCP, relative to max(|h|∞, |Gλ|∞).
double lcp_violation(const MatrixXd& g, const VectorXd& h, const VectorXd& lambda) {
  const VectorXd w = g * lambda - h;
  const double scale = std::max(h.lpNorm<Eigen::Infinity>(), (g * lambda).lpNorm<Eigen::Infinity>());
  double worst = std::max(0.0, -lambda.minCoeff()) / std::max(lambda.lpNorm<Eigen::Infinity>(), 1e-300);
  worst = std::max(worst, std::max(0.0, -w.minCoeff()) / scale);
  for (Eigen::Index i = 0; i < h.size(); ++i)
    if (lambda(i) > 0.0) worst = std::max(worst, std::abs(w(i)) / scale);
  return worst;
}

}  // namespace

BOOST_AUTO_TEST_CASE(solutions_satisfy_the_lcp_with_and_without_the_lawson_hanson_fallback) {
  std::mt19937_64 gen(2024);
  int fallbacks = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int n = 3 + trial % 6;
    // G = AᵀA + 10⁻³ I with a square Gaussian A: SPD, far from an M-matrix, often
    // ill-conditioned (PDAS cycles on about one problem in a few thousand).
    const MatrixXd a = contactrom::test::gaussian(n, n, gen);
    const MatrixXd g = a.transpose() * a + 1e-3 * MatrixXd::Identity(n, n);
    const VectorXd h = contactrom::test::gaussian(n, 1, gen).col(0);
    DualQpSolver qp;
    const VectorXd lambda = qp.solve(g, h, {}, VectorXd());
    BOOST_REQUIRE_MESSAGE(qp.info() == Status::Success, "trial " << trial << ": " << qp.info());
    BOOST_TEST(lcp_violation(g, h, lambda) < 1e-9, "trial " << trial << (qp.used_fallback() ? " (fallback)" : ""));
    fallbacks += qp.used_fallback() ? 1 : 0;
  }
  BOOST_TEST_MESSAGE(fallbacks << " of 20000 problems went to Lawson-Hanson");
  BOOST_TEST(fallbacks > 0);
}

BOOST_AUTO_TEST_CASE(rows_that_are_not_eligible_stay_at_zero_in_the_fallback_too) {
  std::mt19937_64 gen(7);
  int checked = 0;
  for (int trial = 0; trial < 50000 && checked < 3; ++trial) {
    const int n = 4;
    const MatrixXd a = contactrom::test::gaussian(n, n, gen);
    const MatrixXd g = a.transpose() * a + 1e-3 * MatrixXd::Identity(n, n);
    const VectorXd h = contactrom::test::gaussian(n, 1, gen).col(0);
    std::vector<char> eligible(n, 1);
    eligible[1] = 0;
    DualQpSolver qp;
    const VectorXd lambda = qp.solve(g, h, eligible, VectorXd());
    BOOST_REQUIRE(qp.info() == Status::Success);
    BOOST_TEST(lambda(1) == 0.0);
    // The LCP of the eligible rows.
    const std::vector<int> rows = {0, 2, 3};
    MatrixXd g_e(3, 3);
    VectorXd h_e(3), lambda_e(3);
    for (int i = 0; i < 3; ++i) {
      h_e(i) = h(rows[i]), lambda_e(i) = lambda(rows[i]);
      for (int j = 0; j < 3; ++j) g_e(i, j) = g(rows[i], rows[j]);
    }
    BOOST_TEST(lcp_violation(g_e, h_e, lambda_e) < 1e-9);
    checked += qp.used_fallback() ? 1 : 0;
  }
  BOOST_TEST(checked > 0);
}
