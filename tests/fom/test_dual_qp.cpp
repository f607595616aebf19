// Tests of fom/dual_qp.hpp, the bound-constrained dual contact QP
// min_{λ ≥ 0} ½λᵀGλ − hᵀλ: closed forms (one row, diagonal G, a 2 × 2 case solved by
// hand), the edge cases no contact and full contact, the KKT conditions and
// agreement with a brute-force enumeration of all 2ⁿ active sets on seeded random
// QPs, a cycle of the primal–dual active set that hands over to Lawson–Hanson, rows
// that may not become active, semi-definite G, and honest statuses.
#define BOOST_TEST_MODULE fom_dual_qp
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "common/random_problems.hpp"
#include <contactrom/fom/dual_qp.hpp>

using contactrom::Status;
using contactrom::fom::DualQpOptions;
using contactrom::fom::DualQpSolver;
using contactrom::test::gaussian;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// Largest violation of the LCP λ ≥ 0, w = Gλ − h ≥ 0, λᵢwᵢ = 0 on the rows that
/// may be active (λᵢ = 0 required elsewhere), relative to |h|∞ (λ scaled by |G|).
double kkt_violation(const MatrixXd& g, const VectorXd& h, const VectorXd& lambda,
                     const std::vector<char>& eligible = {}) {
  const VectorXd w = g * lambda - h;
  const double scale = std::max(h.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
  const double gnorm = std::max(g.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
  double violation = 0.0;
  for (Eigen::Index i = 0; i < h.size(); ++i) {
    if (!std::isfinite(lambda(i))) return std::numeric_limits<double>::infinity();
    const bool may = eligible.empty() || eligible[static_cast<size_t>(i)];
    if (!may) {
      violation = std::max(violation, std::abs(lambda(i)) * gnorm / scale);
      continue;
    }
    violation = std::max(violation, -lambda(i) * gnorm / scale);
    violation = std::max(violation, -w(i) / scale);
    violation = std::max(violation, std::min(lambda(i) * gnorm, std::abs(w(i))) / scale);
  }
  return violation;
}

/// The rows and columns `set` of G, and the rows `set` of h.
void principal(const MatrixXd& g, const VectorXd& h, const std::vector<int>& set, MatrixXd& gs, VectorXd& hs) {
  const int m = static_cast<int>(set.size());
  gs.resize(m, m);
  hs.resize(m);
  for (int a = 0; a < m; ++a) {
    hs(a) = h(set[a]);
    for (int b = 0; b < m; ++b) gs(a, b) = g(set[a], set[b]);
  }
}

/// The LCP solution by enumeration of every active set S: λ_S = G_SS⁻¹ h_S ≥ 0 and
/// w ≥ 0 off S. For a positive definite G exactly one S qualifies (up to rows with
/// λᵢ = wᵢ = 0); the first one found is returned, `found` counts them.
VectorXd brute_force(const MatrixXd& g, const VectorXd& h, int& found) {
  const int n = static_cast<int>(h.size());
  VectorXd best = VectorXd::Zero(n);
  found = 0;
  for (unsigned mask = 0; mask < (1u << n); ++mask) {
    std::vector<int> set;
    for (int i = 0; i < n; ++i)
      if (mask & (1u << i)) set.push_back(i);
    const int m = static_cast<int>(set.size());
    MatrixXd gs;
    VectorXd hs;
    principal(g, h, set, gs, hs);
    VectorXd lambda = VectorXd::Zero(n);
    if (m > 0) {
      const VectorXd z = gs.llt().solve(hs);
      for (int a = 0; a < m; ++a) lambda(set[a]) = z(a);
    }
    if (kkt_violation(g, h, lambda) <= 1e-10) {
      if (found == 0) best = lambda;
      ++found;
    }
  }
  return best;
}

/// Random symmetric positive definite n × n matrix with off-diagonal entries of both
/// signs (not an M-matrix, so the primal–dual active set may cycle).
MatrixXd random_spd(int n, std::mt19937_64& gen) {
  const MatrixXd a = gaussian(n, n, gen);
  return a * a.transpose() + 0.1 * MatrixXd::Identity(n, n);
}

}  // namespace

BOOST_AUTO_TEST_CASE(one_row_is_the_positive_part_of_h_over_g) {
  for (double h : {-2.0, 0.0, 3.0}) {
    DualQpSolver solver;
    const VectorXd lambda = solver.solve(MatrixXd::Constant(1, 1, 4.0), VectorXd::Constant(1, h), {}, VectorXd());
    BOOST_TEST(solver.info() == Status::Success);
    BOOST_TEST(lambda(0) == std::max(h / 4.0, 0.0), "h = " << h);
  }
}

BOOST_AUTO_TEST_CASE(diagonal_g_decouples_the_rows) {
  const VectorXd d = (VectorXd(5) << 1.0, 2.0, 0.5, 4.0, 3.0).finished();
  const VectorXd h = (VectorXd(5) << 1.0, -1.0, 2.0, 0.0, -3.0).finished();
  DualQpSolver solver;
  const VectorXd lambda = solver.solve(d.asDiagonal().toDenseMatrix(), h, {}, VectorXd());
  BOOST_TEST(solver.info() == Status::Success);
  const VectorXd expected = (VectorXd(5) << 1.0, 0.0, 4.0, 0.0, 0.0).finished();
  BOOST_TEST((lambda - expected).cwiseAbs().maxCoeff() <= 1e-15);
}

BOOST_AUTO_TEST_CASE(two_rows_where_the_second_separates) {
  // G = [1 0.9; 0.9 1], h = (1, 0.5): both rows penetrate at λ = 0, but with both
  // active λ₂ = (0.5 − 0.9)/0.19 < 0; the solution is λ = (1, 0), w₂ = 0.9 − 0.5 = 0.4.
  const MatrixXd g = (MatrixXd(2, 2) << 1.0, 0.9, 0.9, 1.0).finished();
  const VectorXd h(VectorXd::Map(std::vector<double>{1.0, 0.5}.data(), 2));
  DualQpSolver solver;
  const VectorXd lambda = solver.solve(g, h, {}, VectorXd());
  BOOST_TEST(solver.info() == Status::Success);
  BOOST_TEST(std::abs(lambda(0) - 1.0) <= 1e-15);
  BOOST_TEST(lambda(1) == 0.0);
  BOOST_TEST(std::abs((g * lambda - h)(1) - 0.4) <= 1e-15);
  BOOST_TEST(solver.iterations() >= 2);  // the first set {1, 2} had to change

  // One active-set change allowed: not converged, and said so.
  DualQpOptions capped;
  capped.max_iterations = 1;
  DualQpSolver short_solver(capped);
  (void)short_solver.solve(g, h, {}, VectorXd());
  BOOST_TEST(short_solver.info() == Status::NoConvergence);
}

BOOST_AUTO_TEST_CASE(no_contact_gives_zero_multipliers) {
  // h ≤ 0: no row penetrates at λ = 0, which is then optimal.
  std::mt19937_64 gen(11);
  const MatrixXd g = random_spd(6, gen);
  const VectorXd h = -gaussian(6, 1, gen).cwiseAbs();
  DualQpSolver solver;
  const VectorXd lambda = solver.solve(g, h, {}, VectorXd());
  BOOST_TEST(solver.info() == Status::Success);
  BOOST_TEST(lambda.cwiseAbs().maxCoeff() == 0.0);
}

BOOST_AUTO_TEST_CASE(empty_problem_has_no_multipliers) {
  DualQpSolver solver;
  const VectorXd none = solver.solve(MatrixXd(0, 0), VectorXd(0), {}, VectorXd());
  BOOST_TEST(solver.info() == Status::Success);
  BOOST_TEST(none.size() == 0);
}

BOOST_AUTO_TEST_CASE(full_contact_solves_the_linear_system) {
  // h = Gλ* with λ* > 0: every row active, λ = G⁻¹h.
  std::mt19937_64 gen(12);
  for (int trial = 0; trial < 10; ++trial) {
    const MatrixXd g = random_spd(7, gen);
    const VectorXd expected = VectorXd::Constant(7, 1.0) + gaussian(7, 1, gen).cwiseAbs();
    DualQpSolver solver;
    const VectorXd lambda = solver.solve(g, g * expected, {}, VectorXd());
    BOOST_TEST(solver.info() == Status::Success);
    BOOST_TEST((lambda - expected).norm() <= 1e-9 * expected.norm(), "trial " << trial);
  }
}

BOOST_AUTO_TEST_CASE(random_qps_agree_with_brute_force_enumeration) {
  std::mt19937_64 gen(13);
  int fallbacks = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 7;  // 2 … 8 rows: at most 256 active sets
    const MatrixXd g = random_spd(n, gen);
    const VectorXd h = gaussian(n, 1, gen);
    int found = 0;
    const VectorXd expected = brute_force(g, h, found);
    BOOST_REQUIRE(found >= 1);
    DualQpSolver solver;
    const VectorXd lambda = solver.solve(g, h, {}, VectorXd());
    fallbacks += solver.used_fallback();
    BOOST_TEST_CONTEXT("trial " << trial << ", n = " << n) {
      BOOST_TEST(solver.info() == Status::Success);
      BOOST_TEST(kkt_violation(g, h, lambda) <= 1e-12);
      BOOST_TEST((lambda - expected).norm() <= 1e-9 * std::max(expected.norm(), 1.0));
      // Warm-started from a random support: the same solution.
      const VectorXd warm = gaussian(n, 1, gen);
      const VectorXd again = DualQpSolver().solve(g, h, {}, warm);
      BOOST_TEST((again - expected).norm() <= 1e-9 * std::max(expected.norm(), 1.0));
    }
  }
  BOOST_TEST_MESSAGE("Lawson-Hanson fallback used in " << fallbacks << " of 200 random QPs");
}

BOOST_AUTO_TEST_CASE(a_pdas_cycle_falls_back_to_lawson_hanson) {
  // G (positive definite, not an M-matrix) and h below make the primal–dual active
  // set cycle: it starts from the penetrating rows {1, 2}; there λ₂ = −68/1420 < 0
  // and w₀ = −0.24 < 0, so the next set is {0, 1}; there λ₀ = −28/532 and
  // λ₁ = −30/532 are both negative and w₂ > 0, so the next set is ∅; at λ = 0 rows 1
  // and 2 penetrate again. The repeated set hands over to Lawson–Hanson, whose
  // result must be the LCP solution.
  const MatrixXd g = (MatrixXd(3, 3) << 181, -98, -93, -98, 56, 62, -93, 62, 94).finished();
  const VectorXd h = (VectorXd(3) << -4, 2, 1).finished();
  DualQpSolver solver;
  const VectorXd lambda = solver.solve(g, h, {}, VectorXd());
  BOOST_TEST(solver.used_fallback());
  BOOST_TEST(solver.info() == Status::Success);
  BOOST_TEST(kkt_violation(g, h, lambda) <= 1e-12);
  int found = 0;
  const VectorXd expected = brute_force(g, h, found);
  BOOST_TEST(found == 1);
  BOOST_TEST((lambda - expected).norm() <= 1e-12 * std::max(expected.norm(), 1.0));
}

BOOST_AUTO_TEST_CASE(ineligible_rows_stay_at_zero) {
  // Rows that may not become active are dropped from the QP: the solution is the
  // brute-force one of the eligible rows alone, with λ = 0 elsewhere.
  std::mt19937_64 gen(14);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 6;
    const MatrixXd g = random_spd(n, gen);
    const VectorXd h = gaussian(n, 1, gen).cwiseAbs();  // every row penetrates at λ = 0
    std::vector<char> eligible(n, 1);
    eligible[static_cast<size_t>(trial % n)] = 0;
    eligible[static_cast<size_t>((trial + 2) % n)] = 0;
    std::vector<int> keep;
    for (int i = 0; i < n; ++i)
      if (eligible[static_cast<size_t>(i)]) keep.push_back(i);
    const int k = static_cast<int>(keep.size());
    MatrixXd gk;
    VectorXd hk;
    principal(g, h, keep, gk, hk);
    int found = 0;
    const VectorXd expected = brute_force(gk, hk, found);
    DualQpSolver solver;
    const VectorXd lambda = solver.solve(g, h, eligible, VectorXd());
    BOOST_TEST_CONTEXT("trial " << trial) {
      BOOST_TEST(solver.info() == Status::Success);
      BOOST_TEST(kkt_violation(g, h, lambda, eligible) <= 1e-12);
      for (int a = 0; a < k; ++a) BOOST_TEST(std::abs(lambda(keep[a]) - expected(a)) <= 1e-9 * (1.0 + expected.norm()));
    }
  }
}

BOOST_AUTO_TEST_CASE(a_row_with_zero_diagonal_cannot_be_active) {
  // An unpaired contact row is a zero row of C: zero row and column of G. It
  // penetrates (h > 0) but no multiplier can act on it.
  MatrixXd g = MatrixXd::Zero(3, 3);
  g(0, 0) = 2.0, g(2, 2) = 1.0, g(0, 2) = g(2, 0) = 0.5;
  const VectorXd h = (VectorXd(3) << 1.0, 5.0, -1.0).finished();
  DualQpSolver solver;
  const VectorXd lambda = solver.solve(g, h, {}, VectorXd());
  BOOST_TEST(solver.info() == Status::Success);
  BOOST_TEST(lambda(1) == 0.0);
  // The others: row 0 alone active, λ₀ = 1/2, w₂ = 0.5·0.5 + 1 > 0.
  BOOST_TEST(std::abs(lambda(0) - 0.5) <= 1e-15);
  BOOST_TEST(lambda(2) == 0.0);
}

// On a singular active subsystem PDAS takes the least-squares multipliers; a stable
// active set whose rows keep a gap must not be reported as a solution.
BOOST_AUTO_TEST_CASE(semi_definite_g_meets_the_kkt_conditions) {
  // G = AAᵀ with A n × k, k < n (dependent contact rows): λ need not be unique, but
  // the KKT conditions and the optimal value are. h is built from a planted
  // complementary pair (λ*, w*), so the QP is bounded and λ* is optimal. A result
  // that misses them may not be reported as Success.
  std::mt19937_64 gen(15);
  int dishonest = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 8, k = 3;
    const MatrixXd a = gaussian(n, k, gen);
    const MatrixXd g = a * a.transpose();
    VectorXd planted = VectorXd::Zero(n), w = VectorXd::Zero(n);
    for (int i = 0; i < n; ++i) (i % 3 == trial % 3 ? planted(i) : w(i)) = 1.0 + static_cast<double>(i % 2);
    const VectorXd h = g * planted - w;
    DualQpSolver solver;
    const VectorXd lambda = solver.solve(g, h, {}, VectorXd());
    const auto objective = [&](const VectorXd& l) { return 0.5 * l.dot(g * l) - h.dot(l); };
    const bool optimal = kkt_violation(g, h, lambda) <= 1e-9 &&
                         std::abs(objective(lambda) - objective(planted)) <= 1e-9 * (1.0 + std::abs(objective(planted)));
    if (solver.info() == Status::Success && !optimal) {
      ++dishonest;
      BOOST_TEST_MESSAGE("trial " << trial << ": Success with KKT violation " << kkt_violation(g, h, lambda));
    }
  }
  BOOST_TEST(dishonest == 0, dishonest << " of 40 semi-definite QPs reported Success without meeting the KKT conditions");
}

BOOST_AUTO_TEST_CASE(inconsistent_input_is_invalid_input) {
  DualQpSolver solver;
  (void)solver.solve(MatrixXd::Identity(3, 3), VectorXd::Ones(2), {}, VectorXd());
  BOOST_TEST(solver.info() == Status::InvalidInput);
  (void)solver.solve(MatrixXd::Identity(2, 2), VectorXd::Ones(2), std::vector<char>(3, 1), VectorXd());
  BOOST_TEST(solver.info() == Status::InvalidInput);
  VectorXd h = VectorXd::Ones(2);
  h(1) = std::numeric_limits<double>::quiet_NaN();
  (void)solver.solve(MatrixXd::Identity(2, 2), h, {}, VectorXd());
  BOOST_TEST(solver.info() == Status::InvalidInput);
}
