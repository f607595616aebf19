#pragma once
/// \file elasticity.hpp
/// \brief Bilinear (Q1) plane-strain linear elasticity on a Mesh: stiffness,
/// H¹ Gram matrix (for error norms) and element stresses.
///
/// Dofs are numbered node-wise: dof 2i is u_x of node i, 2i+1 is u_y.
/// Plane strain: \f$ \sigma = \mathbf{D}\varepsilon \f$ with
/// \f$ \mathbf{D} = \frac{E}{(1+\nu)(1-2\nu)} \begin{bmatrix}1-\nu&\nu&0\\ \nu&1-\nu&0\\0&0&\frac{1-2\nu}{2}\end{bmatrix} \f$,
/// integrated with 2x2 Gauss points.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <vector>

#include "fom/mesh.hpp"

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

/// \brief Assembles the Q1 stiffness (plane strain or stress per material) (2n x 2n, all dofs, no
/// boundary conditions applied). `materials[b]` is used for quads of body b.
/// \throws InputError if a quad is inverted (non-positive Jacobian).
SparseMatrix assemble_stiffness(const Mesh& mesh, const std::vector<Material>& materials);

/// \brief Gram matrix of the vector H¹ inner product
/// \f$ (u,v)_{H^1} = \int u\cdot v + \nabla u : \nabla v \f$ (2n x 2n).
SparseMatrix assemble_h1_gram(const Mesh& mesh);

/// \brief Stress at each quad's centre: one row per quad, columns
/// σ_xx, σ_yy, σ_xy, σ_zz (ν(σ_xx+σ_yy) in plane strain, 0 in plane stress), von Mises.
Eigen::MatrixXd element_stresses(const Mesh& mesh, const std::vector<Material>& materials,
                                 const Eigen::VectorXd& u);

}  // namespace contactrom::fom
