// Tests of fom/sparse_cholesky: the block of the inverse on the trailing set and
// the solves agree with a dense factorisation; failures are statuses; solves are
// safe to run concurrently.
#define BOOST_TEST_MODULE fom_sparse_cholesky
#include <boost/test/unit_test.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <random>
#include <thread>
#include <vector>

#include <contactrom/fom/sparse_cholesky.hpp>

using contactrom::Status;
using contactrom::fom::SparseCholesky;

namespace {

/// SPD matrix with `components` disconnected blocks, each the 5-point Laplacian of
/// an m x m grid plus a random symmetric positive diagonal shift (seeded).
Eigen::SparseMatrix<double> grid_matrix(int m, int components, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> shift(0.1, 1.0);
  const int per = m * m, n = per * components;
  std::vector<Eigen::Triplet<double>> t;
  for (int c = 0; c < components; ++c)
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        const int k = c * per + i * m + j;
        t.emplace_back(k, k, 4.0 + shift(rng));
        if (i + 1 < m) t.emplace_back(k, k + m, -1.0), t.emplace_back(k + m, k, -1.0);
        if (j + 1 < m) t.emplace_back(k, k + 1, -1.0), t.emplace_back(k + 1, k, -1.0);
      }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

/// Boundary nodes of each grid component, components interleaved and shuffled, so
/// the trailing set is neither sorted nor grouped.
std::vector<int> boundary_set(int m, int components, unsigned seed) {
  std::vector<int> set;
  for (int c = 0; c < components; ++c)
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        if (i == 0 || j == 0 || i == m - 1 || j == m - 1) set.push_back(c * m * m + i * m + j);
  std::shuffle(set.begin(), set.end(), std::mt19937(seed));
  return set;
}

double rel_diff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

}  // namespace

BOOST_AUTO_TEST_CASE(inverse_block_matches_the_dense_inverse) {
  for (int components : {1, 2, 3}) {
    const Eigen::SparseMatrix<double> a = grid_matrix(12, components, 7u + components);
    const std::vector<int> last = boundary_set(12, components, 11u);
    SparseCholesky llt;
    BOOST_REQUIRE(llt.compute(a, last).info() == Status::Success);
    BOOST_TEST(llt.trailing_size() == static_cast<int>(last.size()));
    const Eigen::MatrixXd inv = Eigen::MatrixXd(a).inverse();
    Eigen::MatrixXd expected(last.size(), last.size());
    for (size_t i = 0; i < last.size(); ++i)
      for (size_t j = 0; j < last.size(); ++j) expected(i, j) = inv(last[i], last[j]);
    const Eigen::MatrixXd block = llt.inverse_block();
    BOOST_TEST_CONTEXT(components << " components") {
      BOOST_TEST(rel_diff(block, expected) <= 1e-12);
      BOOST_TEST((block - block.transpose()).norm() == 0.0);
    }
  }
}

BOOST_AUTO_TEST_CASE(solves_match_the_dense_solution) {
  const Eigen::SparseMatrix<double> a = grid_matrix(10, 2, 3u);
  const std::vector<int> last = boundary_set(10, 2, 5u);
  SparseCholesky llt;
  BOOST_REQUIRE(llt.compute(a, last).info() == Status::Success);
  const Eigen::LLT<Eigen::MatrixXd> dense{Eigen::MatrixXd(a)};
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd b(a.rows(), 3), f(last.size(), 2);
  for (Eigen::Index i = 0; i < b.size(); ++i) b.data()[i] = normal(rng);
  for (Eigen::Index i = 0; i < f.size(); ++i) f.data()[i] = normal(rng);
  BOOST_TEST(rel_diff(llt.solve(b), dense.solve(b)) <= 1e-12);
  // solve_trailing(f) = A⁻¹ E f with E injecting f into the trailing set.
  Eigen::MatrixXd ef = Eigen::MatrixXd::Zero(a.rows(), 2);
  for (size_t i = 0; i < last.size(); ++i) ef.row(last[i]) = f.row(i);
  BOOST_TEST(rel_diff(llt.solve_trailing(f), dense.solve(ef)) <= 1e-12);
}

BOOST_AUTO_TEST_CASE(empty_trailing_set_factorises_and_solves) {
  const Eigen::SparseMatrix<double> a = grid_matrix(6, 1, 2u);
  SparseCholesky llt;
  BOOST_REQUIRE(llt.compute(a, {}).info() == Status::Success);
  BOOST_TEST(llt.inverse_block().size() == 0);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(a.rows());
  BOOST_TEST((Eigen::MatrixXd(a) * llt.solve(b) - b).norm() <= 1e-12 * b.norm());
}

BOOST_AUTO_TEST_CASE(indefinite_matrix_is_a_numerical_issue) {
  Eigen::SparseMatrix<double> a = grid_matrix(6, 1, 2u);
  a.coeffRef(17, 17) = -10.0;
  SparseCholesky llt;
  BOOST_TEST(llt.compute(a, {1, 2, 3}).info() == Status::NumericalIssue);
  BOOST_TEST(llt.solve(Eigen::VectorXd::Ones(a.rows())).size() == 0);
  BOOST_TEST(llt.inverse_block().size() == 0);
}

BOOST_AUTO_TEST_CASE(bad_trailing_sets_are_invalid_input) {
  const Eigen::SparseMatrix<double> a = grid_matrix(5, 1, 2u);
  SparseCholesky llt;
  BOOST_TEST(llt.compute(a, {3, 3}).info() == Status::InvalidInput);
  BOOST_TEST(llt.compute(a, {-1}).info() == Status::InvalidInput);
  BOOST_TEST(llt.compute(a, {25}).info() == Status::InvalidInput);
  BOOST_TEST(llt.compute(Eigen::SparseMatrix<double>(3, 4), {}).info() == Status::InvalidInput);
}

BOOST_AUTO_TEST_CASE(concurrent_solves_agree_with_a_serial_solve) {
  const Eigen::SparseMatrix<double> a = grid_matrix(20, 2, 9u);
  const std::vector<int> last = boundary_set(20, 2, 4u);
  SparseCholesky llt;
  BOOST_REQUIRE(llt.compute(a, last).info() == Status::Success);
  const int threads = 4;
  std::vector<Eigen::MatrixXd> rhs, expected, got(threads);
  for (int t = 0; t < threads; ++t) {
    rhs.push_back(Eigen::MatrixXd::Constant(last.size(), 1, 1.0 + t));
    expected.push_back(llt.solve_trailing(rhs.back()));
  }
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (int r = 0; r < 20; ++r) got[t] = llt.solve_trailing(rhs[t]);
    });
  for (auto& th : pool) th.join();
  for (int t = 0; t < threads; ++t) BOOST_TEST((got[t] - expected[t]).norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(a_reused_order_gives_the_same_factor_for_another_matrix) {
  // The order of one matrix reused for another of the same pattern gives exactly
  // the factor a fresh compute() with that order gives, and the right inverse block.
  const Eigen::SparseMatrix<double> a = grid_matrix(9, 2, 21u), b = grid_matrix(9, 2, 22u);
  const std::vector<int> last = boundary_set(9, 2, 6u);
  SparseCholesky first;
  BOOST_REQUIRE(first.compute(a, last).info() == Status::Success);
  const std::vector<int>& order = first.permutation();
  BOOST_REQUIRE(order.size() == static_cast<size_t>(a.rows()));
  BOOST_TEST(std::equal(last.begin(), last.end(), order.end() - last.size()));
  SparseCholesky reused;
  BOOST_REQUIRE(reused.compute(b, last, order).info() == Status::Success);
  const Eigen::MatrixXd inv = Eigen::MatrixXd(b).inverse();
  Eigen::MatrixXd expected(last.size(), last.size());
  for (size_t i = 0; i < last.size(); ++i)
    for (size_t j = 0; j < last.size(); ++j) expected(i, j) = inv(last[i], last[j]);
  BOOST_TEST(rel_diff(reused.inverse_block(), expected) <= 1e-12);
  // An order that does not end with `last`, or is not a permutation, is refused.
  std::vector<int> shuffled = order;
  std::swap(shuffled.front(), shuffled.back());
  BOOST_TEST(SparseCholesky().compute(b, last, shuffled).info() == Status::InvalidInput);
  std::vector<int> repeated = order;
  repeated[0] = repeated[1];
  BOOST_TEST(SparseCholesky().compute(b, last, repeated).info() == Status::InvalidInput);
}
