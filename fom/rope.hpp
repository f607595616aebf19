#pragma once
/// \file rope.hpp
/// \brief The 1D elastic rope above an obstacle (Kollepara et al., "Sparse
/// approximations for contact mechanics", appendix B), the one problem written in C++:
/// \f[ \min_u \tfrac12 \int_0^1 \nu (u')^2 + \int_0^1 f u \quad\text{s.t.}\quad
///     u \ge \psi(x) = -0.2(\sin \pi x - \sin 3\pi x) - 0.5, \quad u(0) = u(1) = 0, \f]
/// with \f$ \nu = \gamma \f$ for x < 0.5 and 30 otherwise, γ ∈ [10, 50] the parameter,
/// P1 elements on a uniform grid of [0, 1] (one dof per node, node i at x = i / elements),
/// and the obstacle constraint at every node (fom::ObstacleContact).
///
/// \code
///   contactrom offline --problem rope --out rope.h5
/// \endcode
#include <Eigen/Dense>
#include <memory>

#include <contactrom/fom/problem.hpp>

namespace contactrom::fom {

/// \brief Options of make_rope_problem (documented defaults).
struct RopeOptions {
  /// Number of P1 elements (2 to 1,000,000). Default 200 (`--problem rope`).
  int elements = 200;
  /// Uniform load f per unit length, pulling the rope onto the obstacle (a negative
  /// value pulls it away). Default 400.
  double load = 400.0;
};

/// \brief The rope problem; see the file comment. `make_problem("rope")` and the
/// databases built on it use the default options.
/// \throws InputError for a number of elements outside 2..1000000.
std::unique_ptr<Problem> make_rope_problem(const RopeOptions& options = {});

/// \brief The node abscissae of a rope problem (num_dofs() values, uniform on [0, 1]),
/// for output: the rope has no mesh (Problem::mesh() is nullptr).
Eigen::VectorXd rope_nodes(const Problem& rope);

}  // namespace contactrom::fom
