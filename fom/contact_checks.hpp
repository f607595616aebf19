#pragma once
/// \file contact_checks.hpp
/// \brief The contact pairs of a problem in its reference configuration (no
/// load), in 2D and 3D: pairs whose surfaces already overlap, slave nodes that lie
/// beyond the ends of their master curve (the edges of their master surface) close
/// to it (they are never paired: no pressure can act there), and pairs with no slave
/// node facing the master at all.
#include <string>
#include <vector>

#include <contactrom/fom/problem.hpp>

namespace contactrom::fom {

/// \brief A reference-configuration overlap larger than this fraction of the
/// displacement scale U is warned about (surfaces should touch or be apart before
/// loading: an overlap is pushed apart by forces the load did not cause).
constexpr double kReferenceOverlapFraction = 0.1;

/// \brief One-line warnings about the contact pairs of `problem` in the reference
/// configuration: a pair whose paired slave nodes penetrate their master by more
/// than kReferenceOverlapFraction·U (naming the largest overlap), and slave nodes
/// that project beyond an end of their master curve (an edge of their master
/// surface) while lying within its mean segment (facet edge) length of it (never paired);
/// and, first, a default displacement scale U (no `displacement_scale` in the problem
/// file) at least 5 times some other nonzero prescribed displacement (a slide sets U,
/// not the indentation). Empty for the rope and for problems without those.
std::vector<std::string> reference_contact_warnings(const Problem& problem);

/// \brief One-line warnings about a solution `u` (all dofs) of `problem`, per body:
/// elements that `u` turns inside out (the deformed Jacobian determinant at a corner
/// of a quadrilateral or hexahedron, or the volume of a tetrahedron, changes sign).
/// Such a displacement is far beyond the small-strain model, and bodies may have
/// passed through each other where the contact search cannot see it (a slave node
/// carried past its master body faces no master at all), even though the solution
/// meets its KKT conditions. Empty when no element is inverted, and for the rope.
std::vector<std::string> solution_warnings(const Problem& problem, const Eigen::VectorXd& u);

/// \brief One line about a list of FOM solutions whose solution_warnings() are
/// `warnings` (one list per solution, at `params`): "K of the N <what> of '<problem>'
/// carry warnings; the first, at d = 0.2: <its first warning>", or "" when none does.
std::string solutions_warning(const Problem& problem, const std::vector<Param>& params,
                              const std::vector<std::vector<std::string>>& warnings, const std::string& what);

/// \brief Throws InputError naming the pair unless every contact pair has at least
/// one slave node facing its master curve or surface (paired) in the reference configuration:
/// a pair none of whose nodes is ever paired enforces nothing.
void check_contact_pairs_face(const Problem& problem);

}  // namespace contactrom::fom
