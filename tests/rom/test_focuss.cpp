// Tests of rom/focuss.hpp: FOCUSS converges to planted sparse supports of
// under-determined Gaussian dictionaries; nnFOCUSS keeps every iterate
// non-negative (observed through the callback) and recovers planted non-negative
// solutions, from the NNLS start and from a dense start that needs relaxation.
#define BOOST_TEST_MODULE rom_focuss
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "common/random_problems.hpp"
#include <contactrom/rom/focuss.hpp>

using contactrom::Status;
using contactrom::rom::Focuss;
using contactrom::rom::FocussOptions;
using contactrom::rom::NnFocuss;
using contactrom::test::as_set;
using contactrom::test::gaussian;
using contactrom::test::planted;
using contactrom::test::scaled_dictionary;
using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

constexpr Index kRows = 60;
constexpr Index kCols = 200;
constexpr Index kSparsity = 5;

}  // namespace

BOOST_AUTO_TEST_CASE(focuss_converges_to_the_planted_support_in_at_least_90_of_100_trials) {
  std::mt19937_64 gen(20240611);
  int recovered = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const MatrixXd d = scaled_dictionary(kRows, kCols, gen);
    std::set<Index> support;
    const VectorXd a = planted(kCols, kSparsity, false, gen, support);
    Focuss focuss;
    const VectorXd alpha = focuss.compute(d).solve(d * a);
    BOOST_TEST_CONTEXT("trial " << trial) {
      BOOST_TEST((focuss.info() == Status::Success));
      BOOST_TEST(alpha.allFinite());
      BOOST_TEST((d * alpha - d * a).norm() <= 1e-8 * (d * a).norm());
      if (as_set(focuss.support()) == support) {
        ++recovered;
        BOOST_TEST((alpha - a).lpNorm<Eigen::Infinity>() <= 1e-10);
        BOOST_TEST((alpha.array() != 0.0).count() == kSparsity);  // pruned entries are exact zeros
      }
    }
  }
  BOOST_TEST_MESSAGE("FOCUSS planted support: " << recovered << "/100");
  BOOST_TEST(recovered >= 90);
}

BOOST_AUTO_TEST_CASE(nnfocuss_from_nnls_recovers_planted_non_negative_solutions) {
  std::mt19937_64 gen(424242);
  int recovered = 0;
  int negative_iterates = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const MatrixXd d = scaled_dictionary(kRows, kCols, gen);
    std::set<Index> support;
    const VectorXd a = planted(kCols, kSparsity, true, gen, support);
    NnFocuss nnfocuss;
    int calls = 0;
    nnfocuss.set_callback([&](int, const VectorXd& alpha) {
      ++calls;
      if (!(alpha.minCoeff() >= 0.0)) ++negative_iterates;
    });
    const VectorXd alpha = nnfocuss.compute(d).solve(d * a);
    BOOST_TEST_CONTEXT("trial " << trial) {
      BOOST_TEST((nnfocuss.info() == Status::Success));
      BOOST_TEST(calls == nnfocuss.iterations() + 1);
      BOOST_TEST(alpha.minCoeff() >= 0.0);
      if (as_set(nnfocuss.support()) == support) {
        ++recovered;
        BOOST_TEST((alpha - a).lpNorm<Eigen::Infinity>() <= 1e-10);
      }
    }
  }
  BOOST_TEST_MESSAGE("nnFOCUSS (NNLS start) planted support: " << recovered << "/100");
  BOOST_TEST(negative_iterates == 0);
  BOOST_TEST(recovered >= 90);
}

BOOST_AUTO_TEST_CASE(nnfocuss_relaxation_keeps_every_iterate_non_negative_from_a_dense_start) {
  // Convex-hull setting of the paper (appendix B): a row of ones appended to D,
  // planted coefficients on the simplex, dense uniform start 1/n. The plain FOCUSS
  // step from there has negative entries, so the relaxation is exercised.
  std::mt19937_64 gen(777);
  int recovered = 0;
  int relaxed_runs = 0;
  int negative_iterates = 0;
  for (int trial = 0; trial < 100; ++trial) {
    MatrixXd d(kRows + 1, kCols);
    d.topRows(kRows) = scaled_dictionary(kRows, kCols, gen);
    d.row(kRows).setOnes();
    std::set<Index> support;
    VectorXd a = planted(kCols, kSparsity, true, gen, support);
    a /= a.sum();
    NnFocuss nnfocuss;
    nnfocuss.set_callback([&](int, const VectorXd& alpha) {
      if (!(alpha.minCoeff() >= 0.0)) ++negative_iterates;
    });
    const VectorXd alpha =
        nnfocuss.compute(d).solve(d * a, VectorXd::Constant(kCols, 1.0 / static_cast<double>(kCols)));
    BOOST_TEST_CONTEXT("trial " << trial) {
      BOOST_TEST((nnfocuss.info() == Status::Success));
      BOOST_TEST(alpha.minCoeff() >= 0.0);
      if (nnfocuss.relaxations() > 0) ++relaxed_runs;
      if (as_set(nnfocuss.support()) == support) {
        ++recovered;
        BOOST_TEST((alpha - a).lpNorm<Eigen::Infinity>() <= 1e-10);
      }
    }
  }
  BOOST_TEST_MESSAGE("nnFOCUSS (dense start) planted support: " << recovered << "/100, relaxed in " << relaxed_runs);
  BOOST_TEST(negative_iterates == 0);
  BOOST_TEST(relaxed_runs >= 90);
  BOOST_TEST(recovered >= 90);
}

BOOST_AUTO_TEST_CASE(tall_dictionary_gives_the_least_squares_solution) {
  std::mt19937_64 gen(5);
  const MatrixXd d = gaussian(30, 8, gen);
  const VectorXd x = gaussian(30, 1, gen);
  Focuss focuss;
  const VectorXd alpha = focuss.compute(d).solve(x);
  BOOST_TEST((focuss.info() == Status::Success));
  BOOST_TEST(focuss.iterations() <= 2);
  const VectorXd least_squares = d.colPivHouseholderQr().solve(x);
  BOOST_TEST((alpha - least_squares).norm() <= 1e-12 * least_squares.norm());
}

BOOST_AUTO_TEST_CASE(iteration_cap_gives_no_convergence) {
  std::mt19937_64 gen(9);
  const MatrixXd d = gaussian(kRows, kCols, gen);
  std::set<Index> support;
  const VectorXd a = planted(kCols, kSparsity, false, gen, support);
  FocussOptions options;
  options.max_iterations = 1;
  Focuss focuss(options);
  int calls = 0;
  focuss.set_callback([&](int, const VectorXd&) { ++calls; });
  const VectorXd alpha = focuss.compute(d).solve(d * a);
  BOOST_TEST((focuss.info() == Status::NoConvergence));
  BOOST_TEST(focuss.iterations() == 1);
  BOOST_TEST(calls == 2);
  BOOST_TEST(alpha.allFinite());
}

BOOST_AUTO_TEST_CASE(pruning_is_relative_to_the_largest_coefficient) {
  // D = I: the start is x itself; entries at most prune_tolerance * max|x| vanish,
  // the rest is a fixed point.
  FocussOptions options;
  options.prune_tolerance = 0.5;
  Focuss focuss(options);
  VectorXd x(3);
  x << -2.0, 0.9, 1.1;
  const VectorXd alpha = focuss.compute(MatrixXd::Identity(3, 3)).solve(x);
  BOOST_TEST((focuss.info() == Status::Success));
  BOOST_TEST(alpha(0) == -2.0, boost::test_tools::tolerance(1e-15));
  BOOST_TEST(alpha(1) == 0.0);
  BOOST_TEST(alpha(2) == 1.1, boost::test_tools::tolerance(1e-15));
}

BOOST_AUTO_TEST_CASE(edge_case_empty_dictionary) {
  Focuss focuss;
  VectorXd alpha = focuss.compute(MatrixXd(4, 0)).solve(VectorXd::Ones(4));
  BOOST_TEST((focuss.info() == Status::Success));
  BOOST_TEST(alpha.size() == 0);
  NnFocuss nnfocuss;
  alpha = nnfocuss.compute(MatrixXd(4, 0)).solve(VectorXd::Ones(4));
  BOOST_TEST((nnfocuss.info() == Status::Success));
  BOOST_TEST(alpha.size() == 0);
  // No rows: x is empty, the minimum-norm answer is 0.
  alpha = focuss.compute(MatrixXd(0, 3)).solve(VectorXd(0));
  BOOST_TEST((focuss.info() == Status::Success));
  BOOST_TEST(alpha.size() == 3);
  BOOST_TEST(alpha.norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(edge_case_zero_signal) {
  std::mt19937_64 gen(13);
  const MatrixXd d = gaussian(10, 30, gen);
  Focuss focuss;
  VectorXd alpha = focuss.compute(d).solve(VectorXd::Zero(10));
  BOOST_TEST((focuss.info() == Status::Success));
  BOOST_TEST(alpha.norm() == 0.0);
  BOOST_TEST(focuss.iterations() == 0);
  NnFocuss nnfocuss;
  alpha = nnfocuss.compute(d).solve(VectorXd::Zero(10));
  BOOST_TEST((nnfocuss.info() == Status::Success));
  BOOST_TEST(alpha.norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(edge_case_duplicated_columns) {
  std::mt19937_64 gen(17);
  MatrixXd d = gaussian(6, 12, gen);
  d.col(5) = d.col(2);
  VectorXd a = VectorXd::Zero(12);
  a(2) = 1.5;
  a(7) = 0.5;
  const VectorXd x = d * a;
  Focuss focuss;
  const VectorXd alpha = focuss.compute(d).solve(x);
  BOOST_TEST(alpha.allFinite());
  BOOST_TEST((focuss.info() == Status::Success));
  BOOST_TEST((d * alpha - x).norm() <= 1e-10 * x.norm());
  NnFocuss nnfocuss;
  const VectorXd beta = nnfocuss.compute(d).solve(x, VectorXd::Constant(12, 0.1));
  BOOST_TEST(beta.allFinite());
  BOOST_TEST(beta.minCoeff() >= 0.0);
  BOOST_TEST((nnfocuss.info() == Status::Success));
  BOOST_TEST((d * beta - x).norm() <= 1e-10 * x.norm());
}

BOOST_AUTO_TEST_CASE(edge_case_column_of_zeros) {
  std::mt19937_64 gen(19);
  MatrixXd d = gaussian(8, 20, gen);
  d.col(4).setZero();
  std::set<Index> support;
  const VectorXd a = planted(20, 2, true, gen, support);
  Focuss focuss;
  const VectorXd alpha = focuss.compute(d).solve(d * a);
  BOOST_TEST(alpha.allFinite());
  BOOST_TEST(alpha(4) == 0.0);
  NnFocuss nnfocuss;
  const VectorXd beta = nnfocuss.compute(d).solve(d * a, VectorXd::Ones(20));
  BOOST_TEST(beta.allFinite());
  BOOST_TEST(beta(4) == 0.0);
}

BOOST_AUTO_TEST_CASE(invalid_input_is_a_status_not_an_exception) {
  std::mt19937_64 gen(23);
  MatrixXd d = gaussian(5, 9, gen);
  Focuss focuss;
  BOOST_TEST(focuss.solve(VectorXd::Ones(5)).size() == 0);  // before compute
  BOOST_TEST((focuss.info() == Status::InvalidInput));
  focuss.compute(d);
  BOOST_TEST(focuss.solve(VectorXd::Ones(4)).size() == 9);
  BOOST_TEST((focuss.info() == Status::InvalidInput));
  focuss.solve(VectorXd::Ones(5), VectorXd::Ones(8));
  BOOST_TEST((focuss.info() == Status::InvalidInput));
  NnFocuss nnfocuss;
  nnfocuss.compute(d);
  VectorXd start = VectorXd::Ones(9);
  start(3) = -1.0;
  BOOST_TEST(nnfocuss.solve(VectorXd::Ones(5), start).allFinite());
  BOOST_TEST((nnfocuss.info() == Status::InvalidInput));
  VectorXd x = VectorXd::Ones(5);
  x(1) = std::numeric_limits<double>::quiet_NaN();
  BOOST_TEST(nnfocuss.solve(x).allFinite());
  BOOST_TEST((nnfocuss.info() == Status::InvalidInput));
  d(2, 2) = std::numeric_limits<double>::infinity();
  focuss.compute(d);
  BOOST_TEST((focuss.info() == Status::InvalidInput));
  nnfocuss.compute(d);
  BOOST_TEST((nnfocuss.info() == Status::InvalidInput));
}
