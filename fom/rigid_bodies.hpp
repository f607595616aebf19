#pragma once
/// \file rigid_bodies.hpp
/// \brief Why a stiffness matrix is singular: the rigid motions of a mesh's bodies
/// that no Dirichlet condition stops. Such a motion costs no energy, so
/// \f$ K_{ff} \f$ is singular (or, in floating point, nearly so) and no solver can
/// give a unique displacement (contact alone cannot hold a body: the contact
/// constraints are inequalities).
#include <string>
#include <vector>

#include <contactrom/fom/problem.hpp>

namespace contactrom::fom {

/// \brief Names of the bodies of `problem`'s mesh with no Dirichlet dof, in body
/// order (empty for the 1D rope, or when every body is held).
std::vector<std::string> unheld_bodies(const Problem& problem);

/// \brief A rigid motion of one connected piece of the mesh that its Dirichlet
/// dofs do not stop.
struct FreeRigidMotion {
  std::string body;    ///< the piece's body name(s) ('a' or 'a'+'b' when glued)
  std::string motion;  ///< e.g. "translation in x", "rotation about (0.5, 1)"
};

/// \brief The free rigid motions of every connected piece of the mesh (nodes linked
/// by its elements): with the piece's Dirichlet dofs as the rows of \f$ A \f$ (the
/// component along the dof of each rigid motion: in 2D the translations \f$ t_x, t_y
/// \f$ and the rotation about the piece's centre, in 3D the three translations and
/// the three rotations about it, rotations scaled by the piece's size), a motion is
/// free when it lies in the (numerical) null space of \f$ A^T A \f$: an eigenvalue
/// below `relative_tolerance` times the largest. Free translations are reported
/// first ("free to translate in x"), then rotations ("free to rotate about (x, y)";
/// in 3D "about the axis parallel to z through (x, y, z)"). A piece with no
/// Dirichlet dof at all is reported once, as "held by no Dirichlet condition".
/// Empty for the 1D rope.
std::vector<FreeRigidMotion> free_rigid_motions(const Problem& problem, double relative_tolerance = 1e-10);

/// \brief Refuses a problem with a free rigid motion (the FOM solvers call it before
/// factorising; the reduced model before its lifting) (InputError naming the body
/// and the motion, e.g. "body 'top' is not held in every direction: free to
/// translate in x"); bodies held by nothing are named as in singular_stiffness_message().
void check_rigid_motions_held(const Problem& problem);

/// \brief One-line explanation of a failed factorisation of `problem`'s stiffness,
/// naming the unheld bodies when there are any, e.g. "the stiffness of problem
/// 'hertz' is singular: body 'top' is held by no Dirichlet condition (it can move
/// rigidly); expected every body to have clamped or prescribed boundary nodes".
std::string singular_stiffness_message(const Problem& problem);

}  // namespace contactrom::fom
