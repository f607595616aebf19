// Tests of rom/support_rows.hpp: the support rows of a dual basis, and the reduced
// quantities computed from the compact operators C_R, g_R — violation Wᵀ(Cu − g),
// gap operator A = C_R Φ_s, b = C_R u_off − g_R, and the reduced row
// (ĉ_p, ĝ_p) — against the same quantities formed densely from the full C, on seeded
// random data with node-to-segment rows (six entries) and shorter rows. Then
// SupportOperators: its rebuilt C_R, g_R are the support rows of the full assembly,
// with and without the search memory.
#define BOOST_TEST_MODULE rom_support_rows
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <random>
#include <vector>

#include "common/contact_geometry.hpp"
#include "common/random_problems.hpp"
#include <contactrom/fom/contact_model.hpp>
#include <contactrom/rom/support_rows.hpp>

using namespace contactrom;
using contactrom::test::gaussian;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// Random constraint matrix (rows × cols): rows with six entries (node-to-segment),
/// two entries, or none (unpaired), compressed row-major.
fom::ConstraintMatrix random_constraints(int rows, int cols, std::mt19937_64& gen) {
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> column(0, cols - 1);
  std::vector<Eigen::Triplet<double>> trip;
  for (int i = 0; i < rows; ++i) {
    const int nnz = i % 3 == 0 ? 6 : (i % 3 == 1 ? 2 : 0);
    std::vector<int> used;
    while (static_cast<int>(used.size()) < nnz) {
      const int c = column(gen);
      if (std::find(used.begin(), used.end(), c) == used.end()) used.push_back(c);
    }
    for (int c : used) trip.emplace_back(i, c, normal(gen));
  }
  fom::ConstraintMatrix c(rows, cols);
  c.setFromTriplets(trip.begin(), trip.end());
  c.makeCompressed();
  return c;
}

/// n_c × m dual basis with some all-zero rows and sparse columns.
MatrixXd random_basis(int nc, int m, std::mt19937_64& gen) {
  MatrixXd w = gaussian(nc, m, gen).cwiseAbs();
  std::bernoulli_distribution keep(0.5);
  for (int s = 0; s < nc; ++s)
    for (int p = 0; p < m; ++p)
      if (s % 4 == 1 || !keep(gen)) w(s, p) = 0.0;
  return w;
}

/// Rows `rows` of a sparse matrix, densely.
MatrixXd dense_rows(const fom::ConstraintMatrix& c, const std::vector<int>& rows) {
  const MatrixXd full(c);
  MatrixXd out(static_cast<Eigen::Index>(rows.size()), full.cols());
  for (size_t i = 0; i < rows.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = full.row(rows[i]);
  return out;
}

}  // namespace

BOOST_AUTO_TEST_CASE(support_rows_are_the_nonzero_rows) {
  MatrixXd w = MatrixXd::Zero(5, 3);
  w(1, 0) = 2.0, w(3, 0) = 1.0, w(3, 2) = -1.0;
  const rom::SupportRows s(w);
  BOOST_TEST(s.rows == (std::vector<int>{1, 3}));
  BOOST_TEST((s.basis - (MatrixXd(2, 3) << 2, 0, 0, 1, 0, -1).finished()).norm() == 0.0);
  BOOST_REQUIRE(s.column_support.size() == 3u);
  BOOST_TEST(s.column_support[0] == (std::vector<int>{0, 1}));
  BOOST_TEST(s.column_support[1].empty());
  BOOST_TEST(s.column_support[2] == (std::vector<int>{1}));
  const rom::SupportRows none(MatrixXd::Zero(4, 2));
  BOOST_TEST(none.rows.empty());
  BOOST_TEST(none.basis.rows() == 0);
}

BOOST_AUTO_TEST_CASE(compact_operators_match_the_dense_formulas) {
  std::mt19937_64 gen(31);
  for (int trial = 0; trial < 20; ++trial) {
    const int nc = 12, ns = 20, r = 1 + trial % 7, m = 5;
    const MatrixXd w = random_basis(nc, m, gen);
    const rom::SupportRows support(w);
    const fom::ConstraintMatrix c_full = random_constraints(nc, ns, gen);
    const VectorXd g_full = gaussian(nc, 1, gen);
    // The compact operators, as assemble_rows would give them.
    const MatrixXd c_rows = dense_rows(c_full, support.rows);
    fom::ConstraintMatrix c_r = c_rows.sparseView();
    c_r.makeCompressed();
    VectorXd g_r(static_cast<Eigen::Index>(support.rows.size()));
    for (size_t i = 0; i < support.rows.size(); ++i) g_r(static_cast<Eigen::Index>(i)) = g_full(support.rows[i]);
    const rom::RowMajorMatrix phi_s = gaussian(ns, r, gen);
    const VectorXd off_s = gaussian(ns, 1, gen), u_s = gaussian(ns, 1, gen);
    const MatrixXd c_dense(c_full);
    const double scale = 1.0 + c_dense.norm() * (1.0 + phi_s.norm() + off_s.norm() + u_s.norm()) * w.norm();

    BOOST_TEST_CONTEXT("trial " << trial << ", r = " << r) {
      // Violation Wᵀ(C u_s − g) over every column: rows outside R do not contribute.
      VectorXd gap, violation;
      support.violation(c_r, g_r, u_s, gap, violation);
      BOOST_TEST((violation - w.transpose() * (c_dense * u_s - g_full)).norm() <= 1e-13 * scale);

      // A = C_R Φ_s, b = C_R u_off − g_R; A û + b is the gap at û on R.
      rom::RowMajorMatrix a;
      VectorXd b;
      support.gap_operator(c_r, g_r, phi_s, off_s, a, b);
      BOOST_TEST((a - c_rows * phi_s).norm() <= 1e-13 * scale);
      BOOST_TEST((b - (c_rows * off_s - g_r)).norm() <= 1e-13 * scale);

      // ĉ_p = w_pᵀ C Φ_s, ĝ_p = w_pᵀ (g − C u_off): the rows of the reduced operators.
      Eigen::RowVectorXd c_hat(r);
      for (int p = 0; p < m; ++p) {
        const double g_hat = support.reduced_row(p, c_r, g_r, phi_s, off_s, c_hat);
        BOOST_TEST((c_hat - w.col(p).transpose() * c_dense * phi_s).norm() <= 1e-13 * scale, "column " << p);
        BOOST_TEST(std::abs(g_hat - w.col(p).dot(g_full - c_dense * off_s)) <= 1e-13 * scale, "column " << p);
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(support_operators_are_the_support_rows_of_the_full_assembly) {
  // An arc master (30 chords) with 20 slaves and a dual basis living on 7 of them;
  // a random walk of displacements, rebuilt with and without the search memory.
  std::vector<double> angles;
  for (int k = 0; k < 20; ++k) angles.push_back(0.15 + 2.8 * k / 19.0);
  const test::ContactGeometry geo = test::circular_master(angles, 1.03, 30);
  const fom::NodeToSegmentContact contact(geo.nodes, {geo.chains});
  MatrixXd w = MatrixXd::Zero(20, 3);
  for (int s : {2, 3, 4, 9, 10, 16, 19}) w(s, s % 3) = 1.0 + s;
  const rom::SupportRows support(w);
  BOOST_REQUIRE(support.rows.size() == 7u);
  rom::SupportOperators partial(true), full(false);
  std::mt19937_64 gen(32);
  std::normal_distribution<double> normal;
  const Eigen::Index n = static_cast<Eigen::Index>(contact.surface_dofs().size());
  VectorXd u = VectorXd::Zero(n);
  for (int step = 0; step < 30; ++step) {
    for (Eigen::Index i = 0; i < n; ++i) u(i) += (step % 7 == 6 ? 0.2 : 0.005) * normal(gen);
    partial.rebuild(contact, support, u);
    full.rebuild(contact, support, u);
    fom::ConstraintMatrix c;
    VectorXd g;
    contact.assemble(contact.search(u), c, g);
    BOOST_TEST_CONTEXT("step " << step) {
      for (const rom::SupportOperators* ops : {&partial, &full}) {
        BOOST_TEST((MatrixXd(ops->c) - dense_rows(c, support.rows)).norm() == 0.0);
        for (size_t i = 0; i < support.rows.size(); ++i) BOOST_TEST(ops->g(static_cast<Eigen::Index>(i)) == g(support.rows[i]));
      }
    }
  }
  BOOST_TEST(partial.certified_rows() > 0);
  BOOST_TEST(full.certified_rows() == 0);
}
