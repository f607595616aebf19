// Tests of core/nnls.hpp: Lawson–Hanson NNLS in matrix form (Nnls) and Gram/QP form
// (NnlsQp), checked against the KKT conditions on seeded random problems of every
// shape, against closed-form answers, and on edge cases. The cross-check against
// SciPy's scipy.optimize.nnls runs through the CLI in test_sparse_cli.cpp.
#define BOOST_TEST_MODULE core_nnls
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "common/random_problems.hpp"
#include <contactrom/core/nnls.hpp>

using contactrom::Status;
using contactrom::Nnls;
using contactrom::NnlsOptions;
using contactrom::NnlsQp;
using contactrom::test::gaussian;
using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

double spectral_norm(const MatrixXd& a) {
  if (a.size() == 0) return 0.0;
  return Eigen::JacobiSVD<MatrixXd>(a).singularValues()(0);
}

/// Largest violation of the NNLS KKT conditions, relative to ||A||_2 ||b||:
/// x >= 0; g = A^T(Ax - b) >= 0 where x = 0; g = 0 where x > 0.
double kkt_violation(const MatrixXd& a, const VectorXd& b, const VectorXd& x) {
  const VectorXd g = a.transpose() * (a * x - b);
  const double scale = std::max(spectral_norm(a) * b.norm(), std::numeric_limits<double>::min());
  double violation = 0.0;
  for (Index j = 0; j < x.size(); ++j) {
    if (!(x(j) >= 0.0)) return std::numeric_limits<double>::infinity();  // negative or NaN
    violation = std::max(violation, x(j) > 0.0 ? std::abs(g(j)) / scale : -g(j) / scale);
  }
  return violation;
}

enum class Kind { Tall, Wide, RankDeficient, ExactNonNegative, AllNegativeUnconstrained, WithZeroAndDuplicate };

const char* name(Kind kind) {
  switch (kind) {
    case Kind::Tall: return "tall";
    case Kind::Wide: return "wide";
    case Kind::RankDeficient: return "rank-deficient";
    case Kind::ExactNonNegative: return "exact non-negative";
    case Kind::AllNegativeUnconstrained: return "all-negative unconstrained";
    case Kind::WithZeroAndDuplicate: return "zero and duplicated columns";
  }
  return "?";
}

struct RandomProblem {
  MatrixXd a;
  VectorXd b;
  VectorXd exact;  // a non-negative solution with zero residual, when known
};

RandomProblem make_problem(Kind kind, std::mt19937_64& gen) {
  std::uniform_int_distribution<Index> size(2, 40);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  RandomProblem p;
  Index m = size(gen);
  Index n = size(gen);
  switch (kind) {
    case Kind::Tall: n = std::max<Index>(1, m / 2); break;
    case Kind::Wide: m = std::max<Index>(1, n / 2); break;
    default: break;
  }
  if (kind == Kind::RankDeficient) {
    const Index rank = 1 + static_cast<Index>(uniform(gen) * static_cast<double>(std::min(m, n) - 1));
    p.a = gaussian(m, rank, gen) * gaussian(rank, n, gen);
  } else {
    p.a = gaussian(m, n, gen);
  }
  // Column scales over three orders of magnitude: the tolerance must be relative.
  for (Index j = 0; j < n; ++j) p.a.col(j) *= std::pow(10.0, 3.0 * uniform(gen) - 1.5);
  p.b = gaussian(m, 1, gen);
  if (kind == Kind::ExactNonNegative) {
    p.exact = VectorXd::Zero(n);
    for (Index j = 0; j < n; ++j) p.exact(j) = uniform(gen) < 0.3 ? uniform(gen) : 0.0;
    p.b = p.a * p.exact;
  } else if (kind == Kind::AllNegativeUnconstrained) {
    // b = -A y with y > 0: for a tall A the unconstrained solution is -y < 0.
    p.a = gaussian(n + m, n, gen);
    VectorXd y(n);
    for (Index j = 0; j < n; ++j) y(j) = 0.5 + uniform(gen);
    p.b = -p.a * y;
  } else if (kind == Kind::WithZeroAndDuplicate) {
    p.a.col(0).setZero();
    if (n > 2) p.a.col(n - 1) = p.a.col(1);
  }
  return p;
}

}  // namespace

BOOST_AUTO_TEST_CASE(kkt_conditions_hold_on_120_seeded_random_problems) {
  std::mt19937_64 gen(20240611);
  const Kind kinds[] = {Kind::Tall, Kind::Wide, Kind::RankDeficient, Kind::ExactNonNegative,
                        Kind::AllNegativeUnconstrained, Kind::WithZeroAndDuplicate};
  int solved = 0;
  int successes = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 120; ++trial) {
    const Kind kind = kinds[trial % 6];
    const RandomProblem p = make_problem(kind, gen);
    Nnls nnls;
    const VectorXd x = nnls.compute(p.a).solve(p.b);
    ++solved;
    if (nnls.info() == Status::Success) ++successes;
    BOOST_TEST_CONTEXT("trial " << trial << " (" << name(kind) << ", " << p.a.rows() << "x" << p.a.cols() << ")") {
      BOOST_TEST((nnls.info() == Status::Success));
      BOOST_TEST(x.size() == p.a.cols());
      const double violation = kkt_violation(p.a, p.b, x);
      worst = std::max(worst, violation);
      BOOST_TEST(violation <= 1e-10);
      if (kind == Kind::ExactNonNegative) BOOST_TEST((p.a * x - p.b).norm() <= 1e-10 * p.b.norm() + 1e-300);
      if (kind == Kind::WithZeroAndDuplicate) BOOST_TEST(x(0) == 0.0);  // zero column never freed
      BOOST_TEST(nnls.iterations() <= 3 * p.a.cols());
    }
  }
  BOOST_TEST_MESSAGE("NNLS random problems: " << successes << "/" << solved << " success, worst KKT " << worst);
  BOOST_TEST(solved == 120);
}

BOOST_AUTO_TEST_CASE(closed_form_identity_problem_clips_negative_entries) {
  // min ||x - b||, x >= 0 has the solution max(b, 0).
  const MatrixXd a = MatrixXd::Identity(4, 4);
  VectorXd b(4);
  b << 1.0, -2.0, 3.0, -0.5;
  Nnls nnls;
  const VectorXd x = nnls.compute(a).solve(b);
  BOOST_TEST((nnls.info() == Status::Success));
  VectorXd expected(4);
  expected << 1.0, 0.0, 3.0, 0.0;
  BOOST_TEST((x - expected).norm() == 0.0, boost::test_tools::tolerance(1e-15));
  BOOST_TEST(nnls.iterations() == 2);
}

BOOST_AUTO_TEST_CASE(closed_form_qp_problems) {
  // G = diag(2, 1), c = (2, -1): x = (1, 0).
  MatrixXd g = MatrixXd::Zero(2, 2);
  g(0, 0) = 2.0;
  g(1, 1) = 1.0;
  VectorXd c(2);
  c << 2.0, -1.0;
  NnlsQp qp;
  VectorXd x = qp.compute(g).solve(c);
  BOOST_TEST((qp.info() == Status::Success));
  BOOST_TEST(x(0) == 1.0, boost::test_tools::tolerance(1e-15));
  BOOST_TEST(x(1) == 0.0);
  // G = [[2,1],[1,2]], c = (1,1): interior solution (1/3, 1/3).
  g << 2.0, 1.0, 1.0, 2.0;
  c << 1.0, 1.0;
  x = qp.compute(g).solve(c);
  BOOST_TEST(x(0) == 1.0 / 3.0, boost::test_tools::tolerance(1e-14));
  BOOST_TEST(x(1) == 1.0 / 3.0, boost::test_tools::tolerance(1e-14));
  // Only the upper triangle is read.
  MatrixXd upper = g;
  upper(1, 0) = -100.0;
  BOOST_TEST((qp.compute(upper).solve(c) - x).norm() == 0.0, boost::test_tools::tolerance(1e-15));
}

BOOST_AUTO_TEST_CASE(gram_form_matches_matrix_form_and_qp_kkt) {
  std::mt19937_64 gen(7);
  for (int trial = 0; trial < 10; ++trial) {
    const MatrixXd a = gaussian(30, 20, gen);
    const VectorXd b = gaussian(30, 1, gen);
    Nnls nnls;
    const VectorXd x = nnls.compute(a).solve(b);
    const MatrixXd g = a.transpose() * a;
    const VectorXd c = a.transpose() * b;
    NnlsQp qp;
    const VectorXd y = qp.compute(g).solve(c);
    BOOST_TEST((qp.info() == Status::Success));
    BOOST_TEST((x - y).norm() <= 1e-10 * x.norm());
    // QP KKT: w = c - G y <= tol where y = 0, |w| <= tol where y > 0.
    const VectorXd w = c - g * y;
    const double scale = c.lpNorm<Eigen::Infinity>();
    for (Index j = 0; j < y.size(); ++j) {
      BOOST_TEST(y(j) >= 0.0);
      BOOST_TEST((y(j) > 0.0 ? std::abs(w(j)) : w(j)) <= 1e-10 * scale);
    }
    BOOST_TEST(qp.passive_set().size() == static_cast<std::size_t>((y.array() > 0.0).count()));
  }
}

BOOST_AUTO_TEST_CASE(one_factorisation_serves_many_right_hand_sides) {
  std::mt19937_64 gen(11);
  const MatrixXd a = gaussian(25, 15, gen);
  Nnls shared;
  shared.compute(a);
  for (int k = 0; k < 10; ++k) {
    const VectorXd b = gaussian(25, 1, gen);
    const VectorXd x = shared.solve(b);
    Nnls fresh;
    const VectorXd y = fresh.compute(a).solve(b);
    BOOST_TEST(kkt_violation(a, b, x) <= 1e-10);
    BOOST_TEST((x - y).norm() == 0.0);  // same arithmetic, same answer
  }
}

BOOST_AUTO_TEST_CASE(warm_start_from_the_solution_needs_no_active_set_change) {
  std::mt19937_64 gen(5);
  const MatrixXd a = gaussian(40, 25, gen);
  const VectorXd b = gaussian(40, 1, gen);
  Nnls nnls;
  nnls.compute(a);
  const VectorXd x = nnls.solve(b);
  const int cold_iterations = nnls.iterations();
  BOOST_TEST(cold_iterations > 2);
  const VectorXd warm = nnls.solve(b, x);
  BOOST_TEST((nnls.info() == Status::Success));
  BOOST_TEST(nnls.iterations() == 0);
  BOOST_TEST((warm - x).norm() <= 1e-12 * x.norm());
  // From an arbitrary positive start the same optimum is reached.
  const VectorXd start = VectorXd::Constant(25, 0.3);
  const VectorXd other = nnls.solve(b, start);
  BOOST_TEST(kkt_violation(a, b, other) <= 1e-10);
  BOOST_TEST((a * other - b).norm() == (a * x - b).norm(), boost::test_tools::tolerance(1e-10));
}

BOOST_AUTO_TEST_CASE(iteration_cap_gives_no_convergence_and_a_feasible_iterate) {
  std::mt19937_64 gen(3);
  const MatrixXd a = gaussian(30, 20, gen);
  const VectorXd b = gaussian(30, 1, gen);
  NnlsOptions options;
  options.max_iterations = 2;
  Nnls nnls(options);
  const VectorXd x = nnls.compute(a).solve(b);
  BOOST_TEST((nnls.info() == Status::NoConvergence));
  BOOST_TEST(nnls.iterations() == 2);
  BOOST_TEST(x.minCoeff() >= 0.0);
  BOOST_TEST(x.allFinite());
}

BOOST_AUTO_TEST_CASE(a_cap_stops_the_run_only_where_it_is_reached) {
  // Warm-started from a dense positive start, so both frees and binds happen. A cap
  // at or above the changes the run needs leaves it untouched; a lower cap stops it
  // at a feasible iterate before the change that would exceed the cap.
  std::mt19937_64 gen(17);
  const MatrixXd a = gaussian(30, 20, gen);
  const VectorXd b = gaussian(30, 1, gen);
  const VectorXd start = VectorXd::Constant(20, 0.3);
  Nnls uncapped;
  const VectorXd x = uncapped.compute(a).solve(b, start);
  BOOST_REQUIRE((uncapped.info() == Status::Success));
  const int needed = uncapped.iterations();
  BOOST_REQUIRE(needed > 3);
  for (int cap = 1; cap <= needed + 2; ++cap) {
    NnlsOptions options;
    options.max_iterations = cap;
    Nnls capped(options);
    const VectorXd y = capped.compute(a).solve(b, start);
    BOOST_TEST_CONTEXT("cap " << cap) {
      BOOST_TEST(y.minCoeff() >= 0.0);
      if (cap >= needed) {
        BOOST_TEST((capped.info() == Status::Success));
        BOOST_TEST(capped.iterations() == needed);
        BOOST_TEST((y - x).norm() == 0.0);
      } else {
        BOOST_TEST((capped.info() == Status::NoConvergence));
        BOOST_TEST(capped.iterations() <= cap + 1);  // a step may bind two variables at once
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(edge_case_empty_dictionary) {
  Nnls nnls;
  const VectorXd x = nnls.compute(MatrixXd(5, 0)).solve(VectorXd::Ones(5));
  BOOST_TEST((nnls.info() == Status::Success));
  BOOST_TEST(x.size() == 0);
  // No rows: every x >= 0 is optimal; the method returns 0.
  const VectorXd y = nnls.compute(MatrixXd(0, 3)).solve(VectorXd(0));
  BOOST_TEST((nnls.info() == Status::Success));
  BOOST_TEST(y.size() == 3);
  BOOST_TEST(y.norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(edge_case_zero_right_hand_side) {
  std::mt19937_64 gen(13);
  Nnls nnls;
  const VectorXd x = nnls.compute(gaussian(10, 6, gen)).solve(VectorXd::Zero(10));
  BOOST_TEST((nnls.info() == Status::Success));
  BOOST_TEST(x.norm() == 0.0);
  BOOST_TEST(nnls.iterations() == 0);
}

BOOST_AUTO_TEST_CASE(edge_case_duplicated_columns) {
  std::mt19937_64 gen(17);
  MatrixXd a(12, 3);
  a.col(0) = gaussian(12, 1, gen);
  a.col(1) = a.col(0);
  a.col(2) = gaussian(12, 1, gen);
  const VectorXd b = 2.0 * a.col(0) + 0.5 * a.col(2);
  Nnls nnls;
  const VectorXd x = nnls.compute(a).solve(b);
  BOOST_TEST((nnls.info() == Status::Success));
  BOOST_TEST(x.allFinite());
  BOOST_TEST(x(0) + x(1) == 2.0, boost::test_tools::tolerance(1e-12));
  BOOST_TEST(x(2) == 0.5, boost::test_tools::tolerance(1e-12));
  BOOST_TEST(kkt_violation(a, b, x) <= 1e-10);
  BOOST_TEST(((x(0) == 0.0) || (x(1) == 0.0)));  // only one copy is freed
}

BOOST_AUTO_TEST_CASE(edge_case_column_of_zeros) {
  std::mt19937_64 gen(19);
  MatrixXd a = gaussian(8, 4, gen);
  a.col(2).setZero();
  const VectorXd b = gaussian(8, 1, gen);
  Nnls nnls;
  const VectorXd x = nnls.compute(a).solve(b);
  BOOST_TEST((nnls.info() == Status::Success));
  BOOST_TEST(x(2) == 0.0);
  BOOST_TEST(kkt_violation(a, b, x) <= 1e-10);
}

BOOST_AUTO_TEST_CASE(invalid_input_is_a_status_not_an_exception) {
  std::mt19937_64 gen(23);
  MatrixXd a = gaussian(6, 4, gen);
  Nnls nnls;
  // solve before compute
  BOOST_TEST(nnls.solve(VectorXd::Ones(6)).size() == 0);
  BOOST_TEST((nnls.info() == Status::InvalidInput));
  // right-hand side of the wrong size
  VectorXd x = nnls.compute(a).solve(VectorXd::Ones(5));
  BOOST_TEST((nnls.info() == Status::InvalidInput));
  BOOST_TEST(x.size() == 4);
  BOOST_TEST(x.norm() == 0.0);
  // NaN in b, then NaN in A
  VectorXd b = VectorXd::Ones(6);
  b(2) = std::numeric_limits<double>::quiet_NaN();
  x = nnls.solve(b);
  BOOST_TEST((nnls.info() == Status::InvalidInput));
  BOOST_TEST(x.allFinite());
  a(1, 1) = std::numeric_limits<double>::quiet_NaN();
  nnls.compute(a);
  BOOST_TEST((nnls.info() == Status::InvalidInput));
  BOOST_TEST(nnls.solve(VectorXd::Ones(6)).allFinite());
  BOOST_TEST((nnls.info() == Status::InvalidInput));
  // Gram form: not square, negative diagonal, wrong c, warm start of the wrong size
  NnlsQp qp;
  qp.compute(MatrixXd::Ones(2, 3));
  BOOST_TEST((qp.info() == Status::InvalidInput));
  qp.compute(-MatrixXd::Identity(2, 2));
  BOOST_TEST((qp.info() == Status::InvalidInput));
  qp.compute(MatrixXd::Identity(2, 2));
  BOOST_TEST((qp.info() == Status::Success));
  qp.solve(VectorXd::Ones(3));
  BOOST_TEST((qp.info() == Status::InvalidInput));
  qp.solve(VectorXd::Ones(2), VectorXd::Ones(1));
  BOOST_TEST((qp.info() == Status::InvalidInput));
}

BOOST_AUTO_TEST_CASE(unbounded_qp_is_reported_as_numerical_issue) {
  // G = diag(1, 0), c = (1, 1): x_2 decreases the objective without bound.
  MatrixXd g = MatrixXd::Zero(2, 2);
  g(0, 0) = 1.0;
  NnlsQp qp;
  const VectorXd x = qp.compute(g).solve(VectorXd::Ones(2));
  BOOST_TEST((qp.info() == Status::NumericalIssue));
  BOOST_TEST(x.allFinite());
  BOOST_TEST(x.minCoeff() >= 0.0);
}
