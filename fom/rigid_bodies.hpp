#pragma once
/// \file rigid_bodies.hpp
/// \brief Why a stiffness matrix is singular: the bodies of a mesh that no
/// Dirichlet condition holds. Such a body can move rigidly at no energy, so
/// \f$ K_{ff} \f$ is singular and no solver can give a unique displacement
/// (contact alone cannot hold it: the contact constraints are inequalities).
#include <string>
#include <vector>

#include "fom/problem.hpp"

namespace contactrom::fom {

/// \brief Names of the bodies of `problem`'s mesh with no Dirichlet dof, in body
/// order (empty for the 1D rope, or when every body is held).
std::vector<std::string> unheld_bodies(const Problem& problem);

/// \brief One-line explanation of a failed factorisation of `problem`'s stiffness,
/// naming the unheld bodies when there are any, e.g. "the stiffness of problem
/// 'hertz' is singular: body 'top' is held by no Dirichlet condition (it can move
/// rigidly); expected every body to have clamped or prescribed boundary nodes".
std::string singular_stiffness_message(const Problem& problem);

}  // namespace contactrom::fom
