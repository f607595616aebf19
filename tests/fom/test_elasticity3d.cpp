// 3D linear elasticity (fom/elasticity, mesh.dim == 3): tetrahedra and trilinear
// hexahedra against the closed-form uniaxial solution of a block, the linear patch
// test on distorted cells, rigid motions in the stiffness's null space, and the
// element stresses.
#define BOOST_TEST_MODULE fom_elasticity3d
#include <Eigen/SparseCholesky>
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <functional>
#include <random>

#include "common/box_mesh.hpp"
#include <contactrom/fom/elasticity.hpp>

using namespace contactrom::fom;
using Eigen::Vector3d;

namespace {

/// The box [0,1]x[0,1]x[0,h] in n^3 hexahedra or tetrahedra, interior nodes jittered.
Mesh box(int n, double jitter, bool tets, unsigned seed = 7, Vector3d size = Vector3d(1.0, 1.0, 1.0)) {
  contactrom::test::BoxSpec b;
  b.cells = {n, n, n};
  b.size = size;
  b.tets = tets;
  b.jitter = jitter;
  b.seed = seed;
  return contactrom::test::box_mesh(b);
}

/// Solves K u = 0 with u = `value(x)` on the dofs `fixed(node, component)` selects.
Eigen::VectorXd solve_with_dirichlet(const Mesh& m, const SparseMatrix& k,
                                     const std::function<bool(const Vector3d&, int)>& fixed,
                                     const std::function<double(const Vector3d&, int)>& value) {
  const int n = 3 * m.num_nodes();
  std::vector<int> index(n, -1);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  int nf = 0;
  for (int i = 0; i < m.num_nodes(); ++i)
    for (int c = 0; c < 3; ++c) {
      const Vector3d x = m.nodes.col(i);
      if (fixed(x, c)) u(3 * i + c) = value(x, c);
      else index[3 * i + c] = nf++;
    }
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd rhs = -(k * u);
  Eigen::VectorXd f(nf);
  for (int i = 0; i < n; ++i)
    if (index[i] >= 0) f(index[i]) = rhs(i);
  for (int col = 0; col < k.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(k, col); it; ++it)
      if (index[it.row()] >= 0 && index[col] >= 0) t.emplace_back(index[it.row()], index[col], it.value());
  SparseMatrix kff(nf, nf);
  kff.setFromTriplets(t.begin(), t.end());
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(kff);
  BOOST_REQUIRE(ldlt.info() == Eigen::Success);
  const Eigen::VectorXd uf = ldlt.solve(f);
  for (int i = 0; i < n; ++i)
    if (index[i] >= 0) u(i) = uf(index[i]);
  return u;
}

}  // namespace

// A block [0,1]x[0,1]x[0,2] on rollers (u_x = 0 on x = 0, u_y = 0 on y = 0,
// u_z = 0 on z = 0) stretched by u_z = δ on its top: the closed form is uniform
// uniaxial stress, u = (−νεx, −νεy, εz) with ε = δ/2, σ_zz = Eε, the others zero,
// and the top's reaction force Eε (unit area). Both elements hold linear fields,
// so they reproduce it to rounding, also on distorted cells.
BOOST_AUTO_TEST_CASE(uniaxial_block_matches_the_closed_form_for_tetrahedra_and_hexahedra) {
  const double e = 3.0, nu = 0.27, delta = 0.02, height = 2.0, strain = delta / height;
  for (bool tets : {false, true}) {
    const Mesh m = box(4, 0.3, tets, 11, Vector3d(1.0, 1.0, height));
    const SparseMatrix k = assemble_stiffness(m, {Material{e, nu}});
    auto on = [](double a, double b) { return std::abs(a - b) < 1e-12; };
    const Eigen::VectorXd u = solve_with_dirichlet(
        m, k,
        [&](const Vector3d& x, int c) { return on(x(c), 0.0) || (c == 2 && on(x(2), height)); },
        [&](const Vector3d& x, int c) { return c == 2 && on(x(2), height) ? delta : 0.0; });
    double err = 0.0;
    for (int i = 0; i < m.num_nodes(); ++i) {
      const Vector3d x = m.nodes.col(i);
      const Vector3d exact(-nu * strain * x(0), -nu * strain * x(1), strain * x(2));
      err = std::max(err, (u.segment<3>(3 * i) - exact).cwiseAbs().maxCoeff());
    }
    BOOST_TEST(err <= 1e-12 * delta * 1e3, (tets ? "tetrahedra" : "hexahedra") << " max error " << err);
    const Eigen::MatrixXd s = element_stresses(m, {Material{e, nu}}, u);
    BOOST_TEST(s.cols() == 7);
    for (int c = 0; c < m.num_cells(); ++c) {
      BOOST_TEST(std::abs(s(c, 2) - e * strain) <= 1e-10);
      for (int j : {0, 1, 3, 4, 5}) BOOST_TEST(std::abs(s(c, j)) <= 1e-10);
      BOOST_TEST(std::abs(s(c, 6) - e * strain) <= 1e-10);  // von Mises of uniaxial stress
    }
    // Reaction on the top: the sum of (K u)_z over its nodes is the force E ε · area.
    const Eigen::VectorXd r = k * u;
    double force = 0.0;
    for (int i = 0; i < m.num_nodes(); ++i)
      if (on(m.nodes(2, i), height)) force += r(3 * i + 2);
    BOOST_TEST(std::abs(force - e * strain) <= 1e-10 * e * strain * 1e3, "force " << force);
  }
}

// Rigid translations and rotations cost no energy; a shear does.
BOOST_AUTO_TEST_CASE(rigid_motions_are_the_null_space) {
  for (bool tets : {false, true}) {
    const Mesh m = box(3, 0.3, tets);
    const SparseMatrix k = assemble_stiffness(m, {Material{1.0, 0.3}});
    BOOST_TEST(k.rows() == 3 * m.num_nodes());
    BOOST_TEST((SparseMatrix(k.transpose()) - k).norm() <= 1e-12 * k.norm());
    for (int mode = 0; mode < 6; ++mode) {
      Eigen::VectorXd r(3 * m.num_nodes());
      for (int i = 0; i < m.num_nodes(); ++i) {
        const Vector3d x = m.nodes.col(i);
        Vector3d v = Vector3d::Zero();
        if (mode < 3) v(mode) = 1.0;
        else v = Vector3d::Unit(mode - 3).cross(x);
        r.segment<3>(3 * i) = v;
      }
      BOOST_TEST((k * r).norm() <= 1e-12 * k.norm() * r.norm(), "mode " << mode);
    }
    Eigen::VectorXd shear(3 * m.num_nodes());
    for (int i = 0; i < m.num_nodes(); ++i) shear.segment<3>(3 * i) = Vector3d(m.nodes(1, i), 0.0, 0.0);
    BOOST_TEST(shear.dot(k * shear) > 0.1);
  }
}

// The H¹ Gram matrix integrates |u|² + |∇u|² exactly for a linear field: for
// u = (x, 0, 0) on the unit cube, ∫x² + 1 = 4/3.
BOOST_AUTO_TEST_CASE(h1_gram_integrates_a_linear_field) {
  for (bool tets : {false, true}) {
    const Mesh m = box(3, 0.0, tets);  // undistorted: det J is constant, the rules exact
    const SparseMatrix g = assemble_h1_gram(m);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * m.num_nodes());
    for (int i = 0; i < m.num_nodes(); ++i) u(3 * i) = m.nodes(0, i);
    BOOST_TEST(std::abs(u.dot(g * u) - 4.0 / 3.0) <= 1e-12, (tets ? "tetrahedra" : "hexahedra"));
  }
}
