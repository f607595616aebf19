// Tests of fom/contact_model.hpp: node-to-segment pairing, normals and gaps in closed
// form on a flat master line and on a master arc (chords of the unit circle), the
// linearised constraint C(u)u − g(u) under rigid motions and penetration, unpaired
// rows, several pairs, the searches with a hint, a row subset or a memory (same
// result as the full search), assemble_rows (a row selection of assemble, the
// closed-form row in ascending columns whatever the node order), the scalar obstacle of the rope, and
// the refusal of malformed pairs.
#define BOOST_TEST_MODULE fom_contact_model
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "common/contact_geometry.hpp"
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/contact_model.hpp>

using namespace contactrom;
using contactrom::test::circular_master;
using contactrom::test::ContactGeometry;
using contactrom::test::flat_master;
using contactrom::test::surface_motion;
using Eigen::MatrixXd;
using Eigen::Vector2d;
using Eigen::VectorXd;

namespace {

/// C(u)u − g(u) at the pairing searched at u.
VectorXd constraint_value(const fom::ContactModel& model, const VectorXd& u_s) {
  fom::ConstraintMatrix c;
  VectorXd g;
  model.assemble(model.search(u_s), c, g);
  return c * u_s - g;
}

/// Same rows paired with the same segments, positions and normals, bit for bit.
bool identical(const fom::Pairing& a, const fom::Pairing& b) {
  return a.segment == b.segment && a.xi == b.xi && a.normal.cols() == b.normal.cols() && a.normal == b.normal;
}

Eigen::Matrix2d rotation(double a) {
  Eigen::Matrix2d r;
  r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return r;
}

}  // namespace

BOOST_AUTO_TEST_CASE(flat_master_pairing_gap_and_rows) {
  // Master nodes at x = 3, 2, 1, 0 (segment j spans [2 − j, 3 − j]); slaves at height 0.2.
  const ContactGeometry geo = flat_master({0.3, 1.1, 1.7, 2.5}, 0.2, 3);
  const fom::NodeToSegmentContact model(geo.nodes, {geo.chains});
  BOOST_TEST(model.num_constraints() == 4);
  BOOST_TEST(model.has_pairing());
  // Tributary lengths: half of each adjacent slave segment (0.8, 0.6, 0.8 long).
  const VectorXd w = (VectorXd(4) << 0.4, 0.7, 0.7, 0.4).finished();
  BOOST_TEST((model.weights() - w).norm() <= 1e-15);
  // Surface dofs: the slave nodes, then the master nodes (ids 4 … 7): every dof here.
  std::vector<int> all(16);
  for (int i = 0; i < 16; ++i) all[static_cast<size_t>(i)] = i;
  BOOST_TEST(model.surface_dofs() == all);

  const fom::Pairing p = model.search(VectorXd::Zero(16));
  BOOST_TEST(p.segment == (std::vector<int>{2, 1, 1, 0}));
  const std::vector<double> xi = {0.7, 0.9, 0.3, 0.5};
  for (int k = 0; k < 4; ++k) {
    BOOST_TEST(std::abs(p.xi[static_cast<size_t>(k)] - xi[static_cast<size_t>(k)]) <= 1e-15, "row " << k);
    BOOST_TEST((p.normal.col(k) - Vector2d(0.0, 1.0)).norm() <= 1e-15, "row " << k);
  }
  fom::ConstraintMatrix c;
  VectorXd g;
  model.assemble(p, c, g);
  BOOST_TEST((g - 0.2 * w).norm() <= 1e-15);
  // Row k: −w n on the slave, w(1 − ξ) n and w ξ n on the segment's ends a, b.
  MatrixXd expected = MatrixXd::Zero(4, 16);
  for (int k = 0; k < 4; ++k) {
    const int j = p.segment[static_cast<size_t>(k)], a = 4 + j, b = 5 + j;
    const double wk = w(k), x = xi[static_cast<size_t>(k)];
    expected(k, 2 * k + 1) = -wk;
    expected(k, 2 * a + 1) = wk * (1.0 - x);
    expected(k, 2 * b + 1) = wk * x;
  }
  BOOST_TEST((MatrixXd(c) - expected).norm() <= 1e-15);

  // Slaves pushed down by 0.3 (through the line by 0.1): C u − g = w (0.3 − 0.2).
  Eigen::Matrix2Xd move = Eigen::Matrix2Xd::Zero(2, 8);
  for (int k = 0; k < 4; ++k) move(1, k) = -0.3;
  const VectorXd value = constraint_value(model, surface_motion(model, move));
  BOOST_TEST((value - 0.1 * w).norm() <= 1e-15);
}

BOOST_AUTO_TEST_CASE(slave_beyond_the_chain_end_is_unpaired) {
  const ContactGeometry geo = flat_master({-0.5, 1.5, 3.5}, 0.2, 3);
  const fom::NodeToSegmentContact model(geo.nodes, {geo.chains});
  const fom::Pairing p = model.search(VectorXd::Zero(static_cast<Eigen::Index>(model.surface_dofs().size())));
  BOOST_TEST(p.segment == (std::vector<int>{-1, 1, -1}));
  fom::ConstraintMatrix c;
  VectorXd g;
  model.assemble(p, c, g);
  for (int k : {0, 2}) {
    BOOST_TEST(MatrixXd(c).row(k).norm() == 0.0);
    BOOST_TEST(g(k) == 0.0);
  }
}

BOOST_AUTO_TEST_CASE(arc_master_normals_and_gaps_in_closed_form) {
  // Six chords of the unit circle over [0, π] (Δ = π/6), slaves at radius 1.2 above
  // every chord midpoint and every inner vertex. Above a vertex: chain position
  // segment + ξ = vertex index, normal radial (the nodal normal of a regular polygon
  // averages two chord normals), gap = 1.2 − 1. Above a midpoint: ξ = ½ and the
  // chord lies at cos(Δ/2) from the centre; inside the arc the normal is radial and
  // the gap 1.2 − cos(Δ/2). On the two end chords the end node's normal is the
  // chord's own (at angle Δ/2 from the far node's), so the normal at the midpoint
  // points Δ/4 off radial, towards the inner node, and the gap is (1.2 − cos(Δ/2))·cos(Δ/4).
  const int n = 6;
  const double delta = M_PI / n, rho = 1.2;
  std::vector<double> angles;
  for (int j = 0; j < n; ++j) {
    angles.push_back((j + 0.5) * delta);
    if (j + 1 < n) angles.push_back((j + 1) * delta);
  }
  const ContactGeometry geo = circular_master(angles, rho, n);
  const fom::NodeToSegmentContact model(geo.nodes, {geo.chains});
  const int ns = static_cast<int>(angles.size());
  const VectorXd zero = VectorXd::Zero(static_cast<Eigen::Index>(model.surface_dofs().size()));
  const fom::Pairing p = model.search(zero);
  fom::ConstraintMatrix c;
  VectorXd g;
  model.assemble(p, c, g);
  const auto end_chord = [&](int k) { return k == 0 || k == ns - 1; };
  for (int k = 0; k < ns; ++k) {
    const double a = angles[static_cast<size_t>(k)], position = a / delta;
    const bool mid = k % 2 == 0;
    const double tilt = end_chord(k) ? (k == 0 ? delta / 4 : -delta / 4) : 0.0;
    BOOST_TEST_CONTEXT("slave at angle " << a) {
      BOOST_TEST(std::abs(p.segment[static_cast<size_t>(k)] + p.xi[static_cast<size_t>(k)] - position) <= 1e-12);
      BOOST_TEST((p.normal.col(k) - Vector2d(std::cos(a + tilt), std::sin(a + tilt))).norm() <= 1e-12);
      const double gap = mid ? (rho - std::cos(delta / 2)) * std::cos(tilt) : rho - 1.0;
      BOOST_TEST(std::abs(g(k) - model.weights()(k) * gap) <= 1e-12);
    }
  }

  // A rigid rotation by 0.3 rad keeps every pairing (rotated normals) and every
  // deformed gap, so C(u)u − g(u) = −w·gap = −g(0).
  Eigen::Matrix2Xd move(2, geo.nodes.cols());
  for (Eigen::Index i = 0; i < geo.nodes.cols(); ++i) move.col(i) = rotation(0.3) * geo.nodes.col(i) - geo.nodes.col(i);
  const VectorXd u_rot = surface_motion(model, move);
  const fom::Pairing pr = model.search(u_rot);
  for (int k = 0; k < ns; ++k) {
    BOOST_TEST(std::abs(pr.segment[static_cast<size_t>(k)] + pr.xi[static_cast<size_t>(k)] - angles[static_cast<size_t>(k)] / delta) <= 1e-12);
    BOOST_TEST((pr.normal.col(k) - rotation(0.3) * p.normal.col(k)).norm() <= 1e-12);
  }
  BOOST_TEST((constraint_value(model, u_rot) + g).norm() <= 1e-12);

  // Midpoint slaves pushed radially inwards by 0.3 (through the chord by
  // 0.3 − gap): C u − g = w (0.3 − gap) on those rows, times cos(Δ/4) on the end chords.
  Eigen::Matrix2Xd push = Eigen::Matrix2Xd::Zero(2, geo.nodes.cols());
  for (int k = 0; k < ns; k += 2) push.col(k) = -0.3 * Vector2d(std::cos(angles[static_cast<size_t>(k)]), std::sin(angles[static_cast<size_t>(k)]));
  const VectorXd value = constraint_value(model, surface_motion(model, push));
  for (int k = 0; k < ns; k += 2)
    BOOST_TEST(std::abs(value(k) - model.weights()(k) * (0.3 - (rho - std::cos(delta / 2))) *
                                       (end_chord(k) ? std::cos(delta / 4) : 1.0)) <= 1e-12);
}

BOOST_AUTO_TEST_CASE(a_slave_pairs_only_with_its_own_pairs_master) {
  // Pair 0: slaves 0, 1 over the master line x ∈ [0, 3] (nodes 4 … 7); pair 1: slaves
  // 2, 3 at the same places but with the master line 10 below (nodes 8, 9).
  Eigen::Matrix2Xd nodes(2, 10);
  nodes.col(0) = Vector2d(0.5, 0.2), nodes.col(1) = Vector2d(2.5, 0.2);
  nodes.col(2) = Vector2d(0.6, 0.3), nodes.col(3) = Vector2d(2.4, 0.3);
  for (int j = 0; j < 4; ++j) nodes.col(4 + j) = Vector2d(3.0 - j, 0.0);
  nodes.col(8) = Vector2d(3.0, -10.0), nodes.col(9) = Vector2d(0.0, -10.0);
  const fom::NodeToSegmentContact model(nodes, {{{0, 1}, {4, 5, 6, 7}}, {{2, 3}, {8, 9}}});
  BOOST_TEST(model.num_pairs() == 2);
  BOOST_TEST(model.pair_of_row(1) == 0);
  BOOST_TEST(model.pair_of_row(2) == 1);
  BOOST_TEST(model.slave_nodes() == (std::vector<int>{0, 1, 2, 3}));
  const fom::Pairing p = model.search(VectorXd::Zero(static_cast<Eigen::Index>(model.surface_dofs().size())));
  BOOST_TEST(p.segment == (std::vector<int>{2, 0, 0, 0}));
  fom::ConstraintMatrix c;
  VectorXd g;
  model.assemble(p, c, g);
  // Gaps 0.2 for pair 0 and 10.3 for pair 1, times the weights (one slave segment
  // per pair: w = half its length).
  BOOST_TEST(std::abs(g(0) - 0.2 * 1.0) <= 1e-14);
  BOOST_TEST(std::abs(g(2) - 10.3 * 0.9) <= 1e-12);
}

BOOST_AUTO_TEST_CASE(hint_rows_and_memory_do_not_change_the_search) {
  // A random walk of the arc geometry (40 chords, 25 slaves): the search with a wrong
  // hint, with a memory of the previous searches, and of a row subset give the full
  // search's pairing (the subset on its rows, unpaired elsewhere).
  std::vector<double> angles;
  for (int k = 0; k < 25; ++k) angles.push_back(0.2 + 2.7 * k / 24.0);
  const ContactGeometry geo = circular_master(angles, 1.05, 40);
  const fom::NodeToSegmentContact model(geo.nodes, {geo.chains});
  const Eigen::Index n = static_cast<Eigen::Index>(model.surface_dofs().size());
  std::mt19937_64 gen(21);
  std::normal_distribution<double> normal;
  VectorXd u = VectorXd::Zero(n);
  fom::SearchMemory memory, subset_memory;
  fom::Pairing with_memory, subset_out;
  const std::vector<int> rows = {1, 4, 5, 17, 24};
  fom::Pairing wrong;
  wrong.segment.assign(25, 0);
  for (int step = 0; step < 60; ++step) {
    const double size = step % 10 == 9 ? 0.3 : 0.001;  // now and then a large jump
    for (Eigen::Index i = 0; i < n; ++i) u(i) += size * normal(gen);
    const fom::Pairing full = model.search(u);
    BOOST_TEST_CONTEXT("step " << step) {
      BOOST_TEST(identical(model.search_rows(u, nullptr, &wrong), full));
      model.search_rows(u, nullptr, nullptr, memory, with_memory);
      BOOST_TEST(identical(with_memory, full));
      model.search_rows(u, &rows, nullptr, subset_memory, subset_out);
      for (int k = 0; k < 25; ++k) {
        const bool listed = std::find(rows.begin(), rows.end(), k) != rows.end();
        const int expected = listed ? full.segment[static_cast<size_t>(k)] : -1;
        BOOST_TEST(subset_out.segment[static_cast<size_t>(k)] == expected, "row " << k);
        if (listed && expected >= 0) {
          BOOST_TEST(subset_out.xi[static_cast<size_t>(k)] == full.xi[static_cast<size_t>(k)]);
          BOOST_TEST((subset_out.normal.col(k) - full.normal.col(k)).norm() == 0.0);
        }
      }
    }
  }
  BOOST_TEST(memory.certified > 0);  // the memory did settle rows without a full search
}

BOOST_AUTO_TEST_CASE(assemble_rows_is_a_row_selection_of_assemble) {
  std::vector<double> angles;
  for (int k = 0; k < 9; ++k) angles.push_back(0.3 + 0.3 * k);
  const ContactGeometry geo = circular_master(angles, 1.1, 12);
  const fom::NodeToSegmentContact model(geo.nodes, {geo.chains});
  const fom::Pairing p = model.search(VectorXd::Zero(static_cast<Eigen::Index>(model.surface_dofs().size())));
  fom::ConstraintMatrix full, part;
  VectorXd g_full, g_part;
  model.assemble(p, full, g_full);
  const std::vector<int> rows = {0, 3, 4, 8};
  model.assemble_rows(p, rows, part, g_part);
  BOOST_REQUIRE(part.rows() == 4);
  for (size_t i = 0; i < rows.size(); ++i) {
    BOOST_TEST((MatrixXd(part).row(static_cast<Eigen::Index>(i)) - MatrixXd(full).row(rows[i])).norm() == 0.0);
    BOOST_TEST(g_part(static_cast<Eigen::Index>(i)) == g_full(rows[i]));
  }
  // The generic implementation (used by models without their own) agrees.
  const fom::ContactModel& base = model;
  fom::ConstraintMatrix generic;
  VectorXd g_generic;
  base.fom::ContactModel::assemble_rows(p, rows, generic, g_generic);
  BOOST_TEST((MatrixXd(generic) - MatrixXd(part)).norm() == 0.0);
  BOOST_TEST((g_generic - g_part).norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(assembled_rows_are_the_formula_in_ascending_columns_whatever_the_node_order) {
  // Two pairs whose surface node numbers put a row's slave node before, after and
  // between its master segment's nodes. Pair 0: slaves 0 … 4 on y = 0 over the master
  // nodes 8, 9, 10 on y = −0.3 (surface nodes 8 …). Pair 1: slaves 5, 6, 7 on y = 0.4
  // over a master chain made of node 11 and pair 0's slave nodes 4 … 0, so its
  // segment 11 → 4 has surface nodes 8+ > k > 4 and the others both below k. At 40
  // random displacements and row subsets, every row of assemble_rows must be the
  // linearised gap of its pairing: −w n on slave node k, w(1 − ξ) n on a, w ξ n on b,
  // g = w n·(X_k − X_m(ξ)) in the reference coordinates, with ascending columns.
  Eigen::Matrix2Xd nodes(2, 12);
  for (int k = 0; k < 5; ++k) nodes.col(k) = Vector2d(k, 0.0);
  nodes.col(5) = Vector2d(0.5, 0.4), nodes.col(6) = Vector2d(2.2, 0.4), nodes.col(7) = Vector2d(4.6, 0.4);
  nodes.col(8) = Vector2d(4.5, -0.3), nodes.col(9) = Vector2d(2.0, -0.3), nodes.col(10) = Vector2d(-0.5, -0.3);
  nodes.col(11) = Vector2d(5.0, 0.1);
  const std::vector<fom::ContactPairChains> chains = {{{0, 1, 2, 3, 4}, {8, 9, 10}}, {{5, 6, 7}, {11, 4, 3, 2, 1, 0}}};
  const fom::NodeToSegmentContact model(nodes, chains);
  const Eigen::Index n = static_cast<Eigen::Index>(model.surface_dofs().size());
  BOOST_REQUIRE(n == 2 * 12);
  std::vector<int> surface_node(12);  // mesh node → surface node
  for (Eigen::Index i = 0; i < n; i += 2) surface_node[static_cast<size_t>(model.surface_dofs()[static_cast<size_t>(i)] / 2)] = static_cast<int>(i / 2);
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  std::bernoulli_distribution keep(0.6);
  int slave_first = 0, slave_between = 0, slave_last = 0;
  for (int step = 0; step < 40; ++step) {
    VectorXd u(n);
    for (Eigen::Index i = 0; i < n; ++i) u(i) = jitter(gen);
    const fom::Pairing p = model.search(u);
    std::vector<int> rows;
    for (int k = 0; k < 8; ++k)
      if (step == 0 || keep(gen)) rows.push_back(k);
    fom::ConstraintMatrix c;
    VectorXd g;
    model.assemble_rows(p, rows, c, g);
    BOOST_REQUIRE(c.rows() == static_cast<Eigen::Index>(rows.size()));
    for (size_t i = 0; i < rows.size(); ++i) {
      const int k = rows[i], j = p.segment[static_cast<size_t>(k)];
      const auto row = static_cast<Eigen::Index>(i);
      BOOST_TEST_CONTEXT("step " << step << " row " << k) {
        BOOST_REQUIRE(j >= 0);  // every slave lies over its master chain
        const std::vector<int>& master = chains[static_cast<size_t>(model.pair_of_row(k))].master;
        const int a = master[static_cast<size_t>(j)], b = master[static_cast<size_t>(j + 1)];
        const double w = model.weights()(k), xi = p.xi[static_cast<size_t>(k)];
        const Vector2d normal = p.normal.col(k);
        VectorXd expected = VectorXd::Zero(n);
        expected.segment<2>(2 * surface_node[static_cast<size_t>(k)]) = -w * normal;
        expected.segment<2>(2 * surface_node[static_cast<size_t>(a)]) = w * (1.0 - xi) * normal;
        expected.segment<2>(2 * surface_node[static_cast<size_t>(b)]) = w * xi * normal;
        int previous = -1, at = 0, slave_at = -1;
        for (fom::ConstraintMatrix::InnerIterator it(c, row); it; ++it, ++at) {
          BOOST_TEST(it.col() > previous);
          previous = static_cast<int>(it.col());
          BOOST_TEST(std::abs(it.value() - expected(it.col())) <= 1e-15);
          if (it.col() == 2 * surface_node[static_cast<size_t>(k)]) slave_at = at / 2;
        }
        BOOST_TEST(at == 6);
        (slave_at == 0 ? slave_first : slave_at == 1 ? slave_between : slave_last) += 1;
        const Vector2d x_m = (1.0 - xi) * nodes.col(a) + xi * nodes.col(b);
        BOOST_TEST(std::abs(g(row) - w * normal.dot(nodes.col(k) - x_m)) <= 1e-15);
      }
    }
  }
  BOOST_TEST(slave_first > 0);
  BOOST_TEST(slave_between > 0);
  BOOST_TEST(slave_last > 0);
}

BOOST_AUTO_TEST_CASE(restrict_to_surface_gathers_the_surface_dofs) {
  // The flat geometry's five nodes placed at ids 6, 2 (slaves) and 7, 0, 3 (master)
  // of an 8-node mesh: surface dofs are the slaves' then the master's, node by node.
  const ContactGeometry geo = flat_master({0.5, 1.5}, 0.1, 2);
  const std::vector<int> id = {6, 2, 7, 0, 3};
  Eigen::Matrix2Xd nodes = Eigen::Matrix2Xd::Zero(2, 8);
  for (int i = 0; i < 5; ++i) nodes.col(id[static_cast<size_t>(i)]) = geo.nodes.col(i);
  const fom::NodeToSegmentContact model(nodes, {{{6, 2}, {7, 0, 3}}});
  const std::vector<int> expected = {12, 13, 4, 5, 14, 15, 0, 1, 6, 7};
  BOOST_TEST(model.surface_dofs() == expected);
  const VectorXd u_full = VectorXd::LinSpaced(16, 0.0, 15.0);
  const VectorXd u_s = model.restrict_to_surface(u_full);
  BOOST_REQUIRE(u_s.size() == 10);
  for (Eigen::Index i = 0; i < 10; ++i) BOOST_TEST(u_s(i) == static_cast<double>(expected[static_cast<size_t>(i)]));
}

BOOST_AUTO_TEST_CASE(obstacle_rows_are_minus_w_and_minus_w_psi) {
  const VectorXd x = (VectorXd(3) << 0.0, 0.5, 1.0).finished();
  const VectorXd psi = (VectorXd(3) << 1.0, 2.0, 3.0).finished();
  const VectorXd w = (VectorXd(3) << 0.25, 0.5, 0.25).finished();
  const fom::ObstacleContact model(x, psi, w);
  BOOST_TEST(!model.has_pairing());
  BOOST_TEST(model.num_constraints() == 3);
  BOOST_TEST(model.surface_dofs() == (std::vector<int>{0, 1, 2}));
  BOOST_TEST((model.constraint_points().row(0).transpose() - x).norm() == 0.0);
  const fom::Pairing p = model.search(VectorXd::Zero(3));
  BOOST_TEST(p.segment.empty());
  fom::ConstraintMatrix c;
  VectorXd g;
  model.assemble(p, c, g);
  BOOST_TEST((MatrixXd(c) - MatrixXd(-w.asDiagonal().toDenseMatrix())).norm() == 0.0);
  BOOST_TEST((g + w.cwiseProduct(psi)).norm() == 0.0);
  // u below ψ by 0.1 at the middle node: C u − g = w (ψ − u) = 0.05 there.
  const VectorXd u = psi - 0.1 * VectorXd::Unit(3, 1);
  BOOST_TEST(std::abs((c * u - g)(1) - 0.05) <= 1e-15);
}

BOOST_AUTO_TEST_CASE(pairing_comparison_is_continuous_across_segment_ends) {
  fom::Pairing a, b;
  a.segment = {1}, a.xi = {1.0}, a.normal = Eigen::Matrix2Xd::Zero(2, 1);
  a.normal(1, 0) = 1.0;
  b = a;
  b.segment = {2}, b.xi = {0.0};  // the same point: end of segment 1 = start of segment 2
  BOOST_TEST(a.same_as(b, 1e-14));
  b.xi = {0.1};
  BOOST_TEST(!a.same_as(b, 1e-3));
  b.segment = {-1};
  BOOST_TEST(!a.same_as(b, 1.0));
}

BOOST_AUTO_TEST_CASE(malformed_pairs_are_input_errors) {
  const ContactGeometry geo = flat_master({0.5, 1.5}, 0.1, 2);
  // A slave node in two pairs.
  BOOST_CHECK_THROW(fom::NodeToSegmentContact(geo.nodes, {geo.chains, geo.chains}), InputError);
  // A master chain of a single node (no segment).
  BOOST_CHECK_THROW(fom::NodeToSegmentContact(geo.nodes, {{{0, 1}, {2}}}), InputError);
  // A master curve through the pair's own slave node.
  BOOST_CHECK_THROW(fom::NodeToSegmentContact(geo.nodes, {{{0, 1}, {2, 3, 1}}}), InputError);
  // No slave node.
  BOOST_CHECK_THROW(fom::NodeToSegmentContact(geo.nodes, {{{}, {2, 3, 4}}}), InputError);
}
