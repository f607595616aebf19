#include "fom/elasticity.hpp"

#include <cmath>
#include <string>

#include "core/errors.hpp"

namespace contactrom::fom {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

Eigen::Matrix3d constitutive_matrix(const Material& m) {
  const double e = m.young, nu = m.poisson;
  if (m.plane_stress) {
    Eigen::Matrix3d d;
    d << 1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu);
    return (e / (1.0 - nu * nu)) * d;
  }
  const double c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
  Eigen::Matrix3d d;
  d << 1.0 - nu, nu, 0.0, nu, 1.0 - nu, 0.0, 0.0, 0.0, 0.5 * (1.0 - 2.0 * nu);
  return c * d;
}

/// Shape functions and their reference derivatives at (xi, eta) in [-1,1]^2.
struct ShapeAt {
  Eigen::Vector4d n;
  Eigen::Matrix<double, 2, 4> dn;  // d/dxi, d/deta
};

ShapeAt shape(double xi, double eta) {
  static const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  ShapeAt s;
  for (int a = 0; a < 4; ++a) {
    s.n(a) = 0.25 * (1 + sx[a] * xi) * (1 + sy[a] * eta);
    s.dn(0, a) = 0.25 * sx[a] * (1 + sy[a] * eta);
    s.dn(1, a) = 0.25 * sy[a] * (1 + sx[a] * xi);
  }
  return s;
}

/// Physical gradients (2x4) and Jacobian determinant of quad q at (xi, eta).
double physical_gradients(const Mesh& mesh, int q, const ShapeAt& s, Eigen::Matrix<double, 2, 4>& grad) {
  Eigen::Matrix<double, 2, 4> x;
  for (int a = 0; a < 4; ++a) x.col(a) = mesh.nodes.col(mesh.quads[q][a]);
  const Eigen::Matrix2d jac = s.dn * x.transpose();  // rows: d/dxi, d/deta; cols: x, y
  const double det = jac.determinant();
  if (!(det > 0.0)) {
    throw InputError("mesh quad " + std::to_string(q) + " is inverted or degenerate (Jacobian " +
                     std::to_string(det) + "); expected counter-clockwise convex quads");
  }
  grad = jac.inverse() * s.dn;
  return det;
}

Eigen::Matrix<double, 3, 8> strain_matrix(const Eigen::Matrix<double, 2, 4>& grad) {
  Eigen::Matrix<double, 3, 8> b = Eigen::Matrix<double, 3, 8>::Zero();
  for (int a = 0; a < 4; ++a) {
    b(0, 2 * a) = grad(0, a);
    b(1, 2 * a + 1) = grad(1, a);
    b(2, 2 * a) = grad(1, a);
    b(2, 2 * a + 1) = grad(0, a);
  }
  return b;
}

const double kGauss = 1.0 / std::sqrt(3.0);

template <class ElementMatrix>
SparseMatrix assemble(const Mesh& mesh, ElementMatrix&& element_matrix) {
  Triplets trip;
  trip.reserve(static_cast<size_t>(mesh.num_quads()) * 64);
  for (int q = 0; q < mesh.num_quads(); ++q) {
    const Eigen::Matrix<double, 8, 8> ke = element_matrix(q);
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 2; ++i)
        for (int b = 0; b < 4; ++b)
          for (int j = 0; j < 2; ++j)
            trip.emplace_back(2 * mesh.quads[q][a] + i, 2 * mesh.quads[q][b] + j, ke(2 * a + i, 2 * b + j));
  }
  const int n = 2 * mesh.num_nodes();
  SparseMatrix k(n, n);
  k.setFromTriplets(trip.begin(), trip.end());
  return k;
}

}  // namespace

SparseMatrix assemble_stiffness(const Mesh& mesh, const std::vector<Material>& materials) {
  return assemble(mesh, [&](int q) {
    const int body = mesh.quad_body[q];
    if (body < 0 || body >= static_cast<int>(materials.size()))
      throw InputError("mesh quad " + std::to_string(q) + " belongs to body " + std::to_string(body) +
                       " but only " + std::to_string(materials.size()) + " materials are defined");
    const Eigen::Matrix3d d = constitutive_matrix(materials[body]);
    Eigen::Matrix<double, 8, 8> ke = Eigen::Matrix<double, 8, 8>::Zero();
    for (double xi : {-kGauss, kGauss})
      for (double eta : {-kGauss, kGauss}) {
        Eigen::Matrix<double, 2, 4> grad;
        const double det = physical_gradients(mesh, q, shape(xi, eta), grad);
        const Eigen::Matrix<double, 3, 8> b = strain_matrix(grad);
        ke += det * b.transpose() * d * b;
      }
    return ke;
  });
}

SparseMatrix assemble_h1_gram(const Mesh& mesh) {
  return assemble(mesh, [&](int q) {
    Eigen::Matrix<double, 8, 8> ke = Eigen::Matrix<double, 8, 8>::Zero();
    for (double xi : {-kGauss, kGauss})
      for (double eta : {-kGauss, kGauss}) {
        const ShapeAt s = shape(xi, eta);
        Eigen::Matrix<double, 2, 4> grad;
        const double det = physical_gradients(mesh, q, s, grad);
        const Eigen::Matrix4d scalar = s.n * s.n.transpose() + grad.transpose() * grad;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b)
            for (int i = 0; i < 2; ++i) ke(2 * a + i, 2 * b + i) += det * scalar(a, b);
      }
    return ke;
  });
}

Eigen::MatrixXd element_stresses(const Mesh& mesh, const std::vector<Material>& materials,
                                 const Eigen::VectorXd& u) {
  Eigen::MatrixXd out(mesh.num_quads(), 5);
  for (int q = 0; q < mesh.num_quads(); ++q) {
    const Material& m = materials[mesh.quad_body[q]];
    Eigen::Matrix<double, 2, 4> grad;
    physical_gradients(mesh, q, shape(0.0, 0.0), grad);
    Eigen::Matrix<double, 8, 1> ue;
    for (int a = 0; a < 4; ++a) ue.segment<2>(2 * a) = u.segment<2>(2 * mesh.quads[q][a]);
    const Eigen::Vector3d s = constitutive_matrix(m) * strain_matrix(grad) * ue;
    const double szz = m.plane_stress ? 0.0 : m.poisson * (s(0) + s(1));
    const double vm = std::sqrt(0.5 * ((s(0) - s(1)) * (s(0) - s(1)) + (s(1) - szz) * (s(1) - szz) +
                                       (szz - s(0)) * (szz - s(0))) +
                                3.0 * s(2) * s(2));
    out.row(q) << s(0), s(1), s(2), szz, vm;
  }
  return out;
}

}  // namespace contactrom::fom
