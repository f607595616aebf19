// Patch test of the Q1 plane-strain element: a linear displacement field (uniform
// strain and stress) imposed on the boundary of a distorted quad mesh must be
// reproduced exactly in the interior, and the element stresses must be uniform.
#define BOOST_TEST_MODULE fom_elasticity
#include <Eigen/SparseCholesky>
#include <boost/test/unit_test.hpp>
#include <random>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/elasticity.hpp>

using namespace contactrom;
using namespace contactrom::fom;

namespace {
Mesh distorted_mesh(int n, unsigned seed) {
  Mesh m;
  m.nodes.resize(2, (n + 1) * (n + 1));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3 / n, 0.3 / n);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const bool boundary = i == 0 || j == 0 || i == n || j == n;
      m.nodes.col(j * (n + 1) + i) << double(i) / n + (boundary ? 0.0 : jitter(rng)),
          double(j) / n + (boundary ? 0.0 : jitter(rng));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      m.quads.push_back({a, a + 1, a + n + 2, a + n + 1});
      m.quad_body.push_back(0);
    }
  m.body_names = {"block"};
  return m;
}
}  // namespace

BOOST_AUTO_TEST_CASE(linear_field_is_reproduced_on_distorted_mesh) {
  const int n = 5;
  const Mesh mesh = distorted_mesh(n, 42);
  const std::vector<Material> mat = {{2.5, 0.3}};
  const SparseMatrix k = assemble_stiffness(mesh, mat);
  const Eigen::Matrix2d grad = (Eigen::Matrix2d() << 1e-2, 3e-3, -2e-3, 5e-3).finished();
  const Eigen::Vector2d shift(0.1, -0.2);
  const int nn = mesh.num_nodes();
  Eigen::VectorXd exact(2 * nn);
  for (int i = 0; i < nn; ++i) exact.segment<2>(2 * i) = grad * mesh.nodes.col(i) + shift;
  std::vector<int> free, fixed;
  for (int i = 0; i < nn; ++i) {
    const Eigen::Vector2d x = mesh.nodes.col(i);
    const bool boundary = x.minCoeff() < 1e-12 || x.maxCoeff() > 1 - 1e-12;
    for (int d = 0; d < 2; ++d) (boundary ? fixed : free).push_back(2 * i + d);
  }
  BOOST_REQUIRE(!free.empty());
  Eigen::MatrixXd kd = Eigen::MatrixXd(k);
  Eigen::MatrixXd kff(free.size(), free.size()), kfd(free.size(), fixed.size());
  Eigen::VectorXd ud(fixed.size());
  for (size_t a = 0; a < free.size(); ++a) {
    for (size_t b = 0; b < free.size(); ++b) kff(a, b) = kd(free[a], free[b]);
    for (size_t b = 0; b < fixed.size(); ++b) kfd(a, b) = kd(free[a], fixed[b]);
  }
  for (size_t b = 0; b < fixed.size(); ++b) ud(b) = exact(fixed[b]);
  const Eigen::VectorXd uf = kff.llt().solve(-kfd * ud);
  double err = 0.0;
  for (size_t a = 0; a < free.size(); ++a) err = std::max(err, std::abs(uf(a) - exact(free[a])));
  BOOST_TEST(err <= 1e-10 * exact.cwiseAbs().maxCoeff());

  const Eigen::MatrixXd stress = element_stresses(mesh, mat, exact);
  for (int c = 0; c < 4; ++c)
    BOOST_TEST((stress.col(c).array() - stress(0, c)).abs().maxCoeff() <= 1e-10 * stress.cwiseAbs().maxCoeff());
}

BOOST_AUTO_TEST_CASE(rigid_motions_are_in_the_kernel) {
  const Mesh mesh = distorted_mesh(4, 7);
  const SparseMatrix k = assemble_stiffness(mesh, {{1.0, 0.3}});
  Eigen::VectorXd tx(2 * mesh.num_nodes()), rot(2 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    tx.segment<2>(2 * i) << 1.0, 0.0;
    rot.segment<2>(2 * i) << -mesh.nodes(1, i), mesh.nodes(0, i);
  }
  BOOST_TEST((k * tx).norm() <= 1e-12);
  BOOST_TEST((k * rot).norm() <= 1e-12);
}

BOOST_AUTO_TEST_CASE(inverted_quad_is_rejected) {
  Mesh mesh = distorted_mesh(2, 1);
  std::swap(mesh.quads[0][1], mesh.quads[0][3]);  // clockwise
  BOOST_CHECK_THROW(assemble_stiffness(mesh, {{1.0, 0.3}}), InputError);
}
