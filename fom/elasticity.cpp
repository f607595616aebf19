#include <contactrom/fom/elasticity.hpp>

#include <cmath>
#include <string>

#include <contactrom/core/errors.hpp>

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

// --- 3D: linear tetrahedra and trilinear hexahedra ----------------------------

/// Isotropic 3D elasticity, Voigt order xx, yy, zz, xy, yz, xz (engineering shears).
Eigen::Matrix<double, 6, 6> constitutive_matrix_3d(const Material& m) {
  const double e = m.young, nu = m.poisson;
  const double lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = e / (2.0 * (1.0 + nu));
  Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
  d.topLeftCorner<3, 3>().setConstant(lambda);
  for (int i = 0; i < 3; ++i) d(i, i) += 2.0 * mu, d(3 + i, 3 + i) = mu;
  return d;
}

/// A quadrature point of a reference cell: shape functions, their reference
/// derivatives (rows ξ, η, ζ) and the weight.
struct CellPoint {
  Eigen::Matrix<double, 8, 1> n = Eigen::Matrix<double, 8, 1>::Zero();
  Eigen::Matrix<double, 3, 8> dn = Eigen::Matrix<double, 3, 8>::Zero();
  double weight = 0.0;
};

CellPoint hexa_point(double xi, double eta, double zeta, double weight) {
  static const double sx[8] = {-1, 1, 1, -1, -1, 1, 1, -1}, sy[8] = {-1, -1, 1, 1, -1, -1, 1, 1},
                      sz[8] = {-1, -1, -1, -1, 1, 1, 1, 1};
  CellPoint p;
  p.weight = weight;
  for (int a = 0; a < 8; ++a) {
    const double fx = 1 + sx[a] * xi, fy = 1 + sy[a] * eta, fz = 1 + sz[a] * zeta;
    p.n(a) = 0.125 * fx * fy * fz;
    p.dn(0, a) = 0.125 * sx[a] * fy * fz;
    p.dn(1, a) = 0.125 * sy[a] * fx * fz;
    p.dn(2, a) = 0.125 * sz[a] * fx * fy;
  }
  return p;
}

CellPoint tetra_point(double xi, double eta, double zeta, double weight) {
  CellPoint p;
  p.weight = weight;
  p.n.head<4>() << 1 - xi - eta - zeta, xi, eta, zeta;
  p.dn.leftCols<4>() << -1, 1, 0, 0, -1, 0, 1, 0, -1, 0, 0, 1;
  return p;
}

/// Quadrature of a cell with `nodes` nodes: the stiffness is exact with one point
/// for a tetrahedron (constant strain) and 2x2x2 Gauss points for a hexahedron; the
/// H¹ mass term of a tetrahedron uses the 4-point rule of degree 2.
const std::vector<CellPoint>& cell_quadrature(int nodes, bool mass) {
  static const std::vector<CellPoint> hexa = [] {
    std::vector<CellPoint> q;
    for (double z : {-kGauss, kGauss})
      for (double y : {-kGauss, kGauss})
        for (double x : {-kGauss, kGauss}) q.push_back(hexa_point(x, y, z, 1.0));
    return q;
  }();
  static const std::vector<CellPoint> tetra_one = {tetra_point(0.25, 0.25, 0.25, 1.0 / 6.0)};
  static const std::vector<CellPoint> tetra_four = [] {
    const double a = 0.5854101966249685, b = 0.1381966011250105;
    return std::vector<CellPoint>{tetra_point(b, b, b, 1.0 / 24), tetra_point(a, b, b, 1.0 / 24),
                                  tetra_point(b, a, b, 1.0 / 24), tetra_point(b, b, a, 1.0 / 24)};
  }();
  if (nodes == 8) return hexa;
  return mass ? tetra_four : tetra_one;
}

/// Physical gradients (3 x nodes) and Jacobian determinant of cell e at a point.
double cell_gradients(const Mesh& mesh, int e, const CellPoint& p, Eigen::Matrix<double, 3, 8>& grad) {
  const auto& c = mesh.cells[static_cast<size_t>(e)];
  const int n = Mesh::cell_size(c);
  Eigen::Matrix3d jac = Eigen::Matrix3d::Zero();  // rows: d/dξ, d/dη, d/dζ; cols: x, y, z
  for (int a = 0; a < n; ++a) jac += p.dn.col(a) * mesh.nodes.col(c[static_cast<size_t>(a)]).head<3>().transpose();
  const double det = jac.determinant();
  if (!(det > 0.0))
    throw InputError("mesh cell " + std::to_string(e) + " is inverted or degenerate (Jacobian " + std::to_string(det) +
                     "); expected positively oriented tetrahedra and hexahedra");
  grad.setZero();
  grad.leftCols(n) = jac.inverse() * p.dn.leftCols(n);
  return det;
}

Eigen::Matrix<double, 6, 24> strain_matrix_3d(const Eigen::Matrix<double, 3, 8>& grad, int n) {
  Eigen::Matrix<double, 6, 24> b = Eigen::Matrix<double, 6, 24>::Zero();
  for (int a = 0; a < n; ++a) {
    const double gx = grad(0, a), gy = grad(1, a), gz = grad(2, a);
    b(0, 3 * a) = gx;
    b(1, 3 * a + 1) = gy;
    b(2, 3 * a + 2) = gz;
    b(3, 3 * a) = gy, b(3, 3 * a + 1) = gx;
    b(4, 3 * a + 1) = gz, b(4, 3 * a + 2) = gy;
    b(5, 3 * a) = gz, b(5, 3 * a + 2) = gx;
  }
  return b;
}

template <class CellMatrix>
SparseMatrix assemble_3d(const Mesh& mesh, CellMatrix&& cell_matrix) {
  Triplets trip;
  std::size_t count = 0;
  for (const auto& c : mesh.cells) count += static_cast<std::size_t>(9 * Mesh::cell_size(c) * Mesh::cell_size(c));
  trip.reserve(count);
  for (int e = 0; e < mesh.num_cells(); ++e) {
    const auto& c = mesh.cells[static_cast<size_t>(e)];
    const int n = Mesh::cell_size(c);
    const Eigen::Matrix<double, 24, 24> ke = cell_matrix(e, n);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            trip.emplace_back(3 * c[static_cast<size_t>(a)] + i, 3 * c[static_cast<size_t>(b)] + j, ke(3 * a + i, 3 * b + j));
  }
  const int ndof = 3 * mesh.num_nodes();
  SparseMatrix k(ndof, ndof);
  k.setFromTriplets(trip.begin(), trip.end());
  return k;
}

const Material& material_of(const std::vector<Material>& materials, int body, int element) {
  if (body < 0 || body >= static_cast<int>(materials.size()))
    throw InputError("mesh element " + std::to_string(element) + " belongs to body " + std::to_string(body) +
                     " but only " + std::to_string(materials.size()) + " materials are defined");
  return materials[static_cast<size_t>(body)];
}

SparseMatrix assemble_stiffness_3d(const Mesh& mesh, const std::vector<Material>& materials) {
  return assemble_3d(mesh, [&](int e, int n) {
    const Eigen::Matrix<double, 6, 6> d = constitutive_matrix_3d(material_of(materials, mesh.cell_body[static_cast<size_t>(e)], e));
    Eigen::Matrix<double, 24, 24> ke = Eigen::Matrix<double, 24, 24>::Zero();
    Eigen::Matrix<double, 3, 8> grad;
    for (const CellPoint& p : cell_quadrature(n, false)) {
      const double det = cell_gradients(mesh, e, p, grad);
      const Eigen::Matrix<double, 6, 24> b = strain_matrix_3d(grad, n);
      ke.noalias() += (p.weight * det) * b.transpose() * d * b;
    }
    return ke;
  });
}

SparseMatrix assemble_h1_gram_3d(const Mesh& mesh) {
  return assemble_3d(mesh, [&](int e, int n) {
    Eigen::Matrix<double, 24, 24> ke = Eigen::Matrix<double, 24, 24>::Zero();
    Eigen::Matrix<double, 3, 8> grad;
    for (const CellPoint& p : cell_quadrature(n, true)) {
      const double det = cell_gradients(mesh, e, p, grad);
      const Eigen::Matrix<double, 8, 8> scalar = p.n * p.n.transpose() + grad.transpose() * grad;
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b)
          for (int i = 0; i < 3; ++i) ke(3 * a + i, 3 * b + i) += p.weight * det * scalar(a, b);
    }
    return ke;
  });
}

Eigen::MatrixXd element_stresses_3d(const Mesh& mesh, const std::vector<Material>& materials, const Eigen::VectorXd& u) {
  Eigen::MatrixXd out(mesh.num_cells(), 7);
  Eigen::Matrix<double, 3, 8> grad;
  for (int e = 0; e < mesh.num_cells(); ++e) {
    const auto& c = mesh.cells[static_cast<size_t>(e)];
    const int n = Mesh::cell_size(c);
    const CellPoint centre = n == 8 ? hexa_point(0, 0, 0, 8.0) : tetra_point(0.25, 0.25, 0.25, 1.0 / 6.0);
    cell_gradients(mesh, e, centre, grad);
    Eigen::Matrix<double, 24, 1> ue = Eigen::Matrix<double, 24, 1>::Zero();
    for (int a = 0; a < n; ++a) ue.segment<3>(3 * a) = u.segment<3>(3 * c[static_cast<size_t>(a)]);
    const Eigen::Matrix<double, 6, 1> s =
        constitutive_matrix_3d(material_of(materials, mesh.cell_body[static_cast<size_t>(e)], e)) *
        strain_matrix_3d(grad, n) * ue;
    const double vm = std::sqrt(0.5 * ((s(0) - s(1)) * (s(0) - s(1)) + (s(1) - s(2)) * (s(1) - s(2)) +
                                       (s(2) - s(0)) * (s(2) - s(0))) +
                                3.0 * (s(3) * s(3) + s(4) * s(4) + s(5) * s(5)));
    out.row(e) << s(0), s(1), s(2), s(3), s(4), s(5), vm;
  }
  return out;
}

}  // namespace

SparseMatrix assemble_stiffness(const Mesh& mesh, const std::vector<Material>& materials) {
  if (mesh.dim == 3) return assemble_stiffness_3d(mesh, materials);
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
  if (mesh.dim == 3) return assemble_h1_gram_3d(mesh);
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
  if (mesh.dim == 3) return element_stresses_3d(mesh, materials, u);
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
