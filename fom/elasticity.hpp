#pragma once
/// \file elasticity.hpp
/// \brief Linear elasticity on a Mesh: stiffness, H¹ Gram matrix (for error norms)
/// and element stresses. 2D: bilinear (Q1) quads, plane strain or plane stress;
/// 3D: linear tetrahedra (one quadrature point, constant strain) and trilinear
/// hexahedra (2x2x2 Gauss points), isotropic,
/// \f$ \sigma = \lambda\,\mathrm{tr}(\varepsilon) I + 2\mu\varepsilon \f$.
///
/// Dofs are numbered node-wise: dof d·i + c is component c of node i (d = mesh.dim).
/// Plane strain: \f$ \sigma = \mathbf{D}\varepsilon \f$ with
/// \f$ \mathbf{D} = \frac{E}{(1+\nu)(1-2\nu)} \begin{bmatrix}1-\nu&\nu&0\\ \nu&1-\nu&0\\0&0&\frac{1-2\nu}{2}\end{bmatrix} \f$,
/// integrated with 2x2 Gauss points.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <vector>

#include <contactrom/fom/mesh.hpp>

namespace contactrom::fom {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// \brief Isotropic material of one body.
struct Material {
  double young = 1.0;    ///< Young's modulus E (default 1)
  double poisson = 0.3;  ///< Poisson's ratio ν (default 0.3)
  /// Plane stress (unit thickness) instead of plane strain, default false:
  /// \f$ \mathbf{D} = \frac{E}{1-\nu^2} \begin{bmatrix}1&\nu&0\\ \nu&1&0\\0&0&\frac{1-\nu}{2}\end{bmatrix} \f$, σ_zz = 0.
  bool plane_stress = false;
};

/// \brief Assembles the stiffness (dn x dn, all dofs, no boundary conditions applied;
/// 2D: plane strain or stress per material). `materials[b]` is used for elements of body b.
/// \throws InputError if an element is inverted (non-positive Jacobian).
SparseMatrix assemble_stiffness(const Mesh& mesh, const std::vector<Material>& materials);

/// \brief Gram matrix of the vector H¹ inner product
/// \f$ (u,v)_{H^1} = \int u\cdot v + \nabla u : \nabla v \f$ (dn x dn).
SparseMatrix assemble_h1_gram(const Mesh& mesh);

/// \brief Stress at each element's centre, one row per element. 2D: columns
/// σ_xx, σ_yy, σ_xy, σ_zz (ν(σ_xx+σ_yy) in plane strain, 0 in plane stress), von Mises;
/// 3D: σ_xx, σ_yy, σ_zz, σ_xy, σ_yz, σ_xz, von Mises.
Eigen::MatrixXd element_stresses(const Mesh& mesh, const std::vector<Material>& materials,
                                 const Eigen::VectorXd& u);

}  // namespace contactrom::fom
