// Tests of rom/omp.hpp: batch OMP recovers planted sparse supports of Gaussian
// dictionaries, returns coefficients of the unnormalised columns, honours each stop
// criterion, and handles empty, zero and duplicated columns without NaN.
#define BOOST_TEST_MODULE rom_omp
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "common/random_problems.hpp"
#include <contactrom/rom/omp.hpp>

using contactrom::Status;
using contactrom::rom::Omp;
using contactrom::rom::OmpOptions;
using contactrom::rom::OmpStop;
using contactrom::test::as_set;
using contactrom::test::gaussian;
using contactrom::test::planted;
using contactrom::test::scaled_dictionary;
using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

}  // namespace

BOOST_AUTO_TEST_CASE(recovers_planted_5_sparse_supports_in_at_least_95_of_100_trials) {
  std::mt19937_64 gen(20240611);
  int exact_support = 0;
  double worst_coefficient_error = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    const MatrixXd d = scaled_dictionary(100, 400, gen);
    std::set<Index> support;
    const VectorXd a = planted(400, 5, false, gen, support);
    Omp omp;
    const VectorXd alpha = omp.compute(d).solve(d * a);
    BOOST_TEST_CONTEXT("trial " << trial) {
      BOOST_TEST((omp.info() == Status::Success));
      BOOST_TEST(alpha.allFinite());
      if (as_set(omp.support()) == support) {
        ++exact_support;
        const double error = (alpha - a).lpNorm<Eigen::Infinity>();
        worst_coefficient_error = std::max(worst_coefficient_error, error);
        BOOST_TEST(error <= 1e-10);
        BOOST_TEST(omp.iterations() == 5);
        BOOST_TEST((omp.stop_reason() == OmpStop::ResidualTolerance));
      }
    }
  }
  BOOST_TEST_MESSAGE("OMP exact support: " << exact_support << "/100, worst coefficient error "
                                           << worst_coefficient_error);
  BOOST_TEST(exact_support >= 95);
}

BOOST_AUTO_TEST_CASE(residual_tolerance_stops_at_the_first_sufficient_atom_count) {
  std::mt19937_64 gen(31);
  const MatrixXd d = scaled_dictionary(60, 150, gen);
  std::set<Index> support;
  VectorXd a = planted(150, 12, false, gen, support);
  // Geometrically decaying magnitudes: each further atom removes about half of the
  // remaining residual, so the tolerance 0.05 is met after a handful of atoms.
  double magnitude = 1.0;
  for (const Index j : support) {
    a(j) = a(j) > 0.0 ? magnitude : -magnitude;
    magnitude *= 0.5;
  }
  VectorXd x = d * a;
  const VectorXd noise = gaussian(60, 1, gen);
  x += 1e-3 * x.norm() / noise.norm() * noise;
  OmpOptions options;
  options.tolerance = 0.05;
  Omp omp(options);
  const VectorXd alpha = omp.compute(d).solve(x);
  BOOST_TEST((omp.info() == Status::Success));
  BOOST_TEST((omp.stop_reason() == OmpStop::ResidualTolerance));
  const double residual = (d * alpha - x).norm();
  BOOST_TEST(residual <= 0.05 * x.norm());
  BOOST_TEST(omp.residual_norm() == residual, boost::test_tools::tolerance(1e-10));
  const int k = omp.iterations();
  BOOST_TEST(k >= 2);
  BOOST_TEST(k < 12);
  // One atom fewer does not meet the tolerance: OMP did not overshoot.
  options.max_atoms = k - 1;
  Omp shorter(options);
  const VectorXd beta = shorter.compute(d).solve(x);
  BOOST_TEST((shorter.stop_reason() == OmpStop::AtomLimit));
  BOOST_TEST((d * beta - x).norm() > 0.05 * x.norm());
}

BOOST_AUTO_TEST_CASE(atom_cap_stops_the_selection) {
  std::mt19937_64 gen(37);
  const MatrixXd d = scaled_dictionary(100, 400, gen);
  std::set<Index> support;
  const VectorXd a = planted(400, 5, false, gen, support);
  OmpOptions options;
  options.max_atoms = 3;
  Omp omp(options);
  const VectorXd alpha = omp.compute(d).solve(d * a);
  BOOST_TEST((omp.info() == Status::Success));
  BOOST_TEST((omp.stop_reason() == OmpStop::AtomLimit));
  BOOST_TEST(omp.iterations() == 3);
  BOOST_TEST((alpha.array() != 0.0).count() == 3);
  BOOST_TEST(omp.residual_norm() > 1e-3 * (d * a).norm());
}

BOOST_AUTO_TEST_CASE(coefficients_are_least_squares_on_the_selected_atoms) {
  // Tall dictionary, signal outside its range: all atoms get selected and the
  // result is the least-squares solution; the residual is orthogonal to D.
  std::mt19937_64 gen(41);
  const MatrixXd d = scaled_dictionary(30, 8, gen);
  const VectorXd x = gaussian(30, 1, gen);
  Omp omp;
  const VectorXd alpha = omp.compute(d).solve(x);
  BOOST_TEST((omp.info() == Status::NoConvergence));  // tolerance 1e-8 unreachable
  BOOST_TEST((omp.stop_reason() == OmpStop::NoProgress));
  BOOST_TEST(omp.iterations() == 8);
  const VectorXd least_squares = d.colPivHouseholderQr().solve(x);
  BOOST_TEST((alpha - least_squares).norm() <= 1e-12 * least_squares.norm());
  BOOST_TEST((d.transpose() * (x - d * alpha)).norm() <= 1e-12 * d.norm() * x.norm());
}

BOOST_AUTO_TEST_CASE(edge_case_empty_dictionary) {
  Omp omp;
  VectorXd alpha = omp.compute(MatrixXd(6, 0)).solve(VectorXd::Ones(6));
  BOOST_TEST(alpha.size() == 0);
  BOOST_TEST((omp.info() == Status::NoConvergence));
  BOOST_TEST((omp.stop_reason() == OmpStop::NoProgress));
  BOOST_TEST(omp.residual_norm() == std::sqrt(6.0), boost::test_tools::tolerance(1e-15));
  alpha = omp.solve(VectorXd::Zero(6));
  BOOST_TEST((omp.info() == Status::Success));
}

BOOST_AUTO_TEST_CASE(edge_case_zero_signal) {
  std::mt19937_64 gen(43);
  Omp omp;
  const VectorXd alpha = omp.compute(gaussian(10, 20, gen)).solve(VectorXd::Zero(10));
  BOOST_TEST((omp.info() == Status::Success));
  BOOST_TEST(omp.iterations() == 0);
  BOOST_TEST(alpha.norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(edge_case_duplicated_columns_select_one_copy) {
  std::mt19937_64 gen(47);
  MatrixXd d(20, 3);
  d.col(0) = gaussian(20, 1, gen);
  d.col(1) = 3.0 * d.col(0);  // same direction, other scale
  d.col(2) = gaussian(20, 1, gen);
  const VectorXd x = d.col(0) + d.col(2);
  Omp omp;
  const VectorXd alpha = omp.compute(d).solve(x);
  BOOST_TEST((omp.info() == Status::Success));
  BOOST_TEST(alpha.allFinite());
  BOOST_TEST(omp.iterations() == 2);
  BOOST_TEST(((alpha(0) == 0.0) != (alpha(1) == 0.0)));
  BOOST_TEST((d * alpha - x).norm() <= 1e-12 * x.norm());
}

BOOST_AUTO_TEST_CASE(edge_case_dependent_atom_stops_without_nan) {
  // x has a part orthogonal to both (identical) atoms: after one atom the only
  // candidate is the duplicate, which is linearly dependent -> stop, no NaN.
  std::mt19937_64 gen(53);
  MatrixXd d(15, 2);
  d.col(0) = gaussian(15, 1, gen);
  d.col(1) = d.col(0);
  VectorXd x = d.col(0) + gaussian(15, 1, gen);
  Omp omp;
  const VectorXd alpha = omp.compute(d).solve(x);
  BOOST_TEST(alpha.allFinite());
  BOOST_TEST(omp.iterations() == 1);
  BOOST_TEST((omp.info() == Status::NoConvergence));
  BOOST_TEST((omp.stop_reason() == OmpStop::NoProgress));
  // The one coefficient is the projection of x on the atom.
  const double projection = d.col(0).dot(x) / d.col(0).squaredNorm();
  BOOST_TEST(alpha.sum() == projection, boost::test_tools::tolerance(1e-12));
}

BOOST_AUTO_TEST_CASE(edge_case_column_of_zeros_is_never_selected) {
  std::mt19937_64 gen(59);
  MatrixXd d = gaussian(12, 5, gen);
  d.col(3).setZero();
  const VectorXd x = gaussian(12, 1, gen);
  Omp omp;
  const VectorXd alpha = omp.compute(d).solve(x);
  BOOST_TEST(alpha.allFinite());
  BOOST_TEST(alpha(3) == 0.0);
  BOOST_TEST(omp.iterations() == 4);
  // An all-zero dictionary selects nothing.
  const VectorXd none = omp.compute(MatrixXd::Zero(12, 4)).solve(x);
  BOOST_TEST(none.norm() == 0.0);
  BOOST_TEST((omp.info() == Status::NoConvergence));
}

BOOST_AUTO_TEST_CASE(invalid_input_is_a_status_not_an_exception) {
  std::mt19937_64 gen(61);
  MatrixXd d = gaussian(8, 5, gen);
  Omp omp;
  BOOST_TEST(omp.solve(VectorXd::Ones(8)).size() == 0);  // before compute
  BOOST_TEST((omp.info() == Status::InvalidInput));
  omp.compute(d);
  const VectorXd wrong = omp.solve(VectorXd::Ones(7));
  BOOST_TEST((omp.info() == Status::InvalidInput));
  BOOST_TEST(wrong.size() == 5);
  VectorXd x = VectorXd::Ones(8);
  x(0) = std::numeric_limits<double>::infinity();
  BOOST_TEST(omp.solve(x).allFinite());
  BOOST_TEST((omp.info() == Status::InvalidInput));
  d(0, 0) = std::numeric_limits<double>::quiet_NaN();
  omp.compute(d);
  BOOST_TEST((omp.info() == Status::InvalidInput));
  BOOST_TEST(omp.solve(VectorXd::Ones(8)).allFinite());
  BOOST_TEST((omp.info() == Status::InvalidInput));
}
