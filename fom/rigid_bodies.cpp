#include "fom/rigid_bodies.hpp"

namespace contactrom::fom {

std::vector<std::string> unheld_bodies(const Problem& problem) {
  std::vector<std::string> out;
  const Mesh* mesh = problem.mesh();
  if (!mesh) return out;
  const int dpn = problem.dofs_per_node();
  std::vector<char> held(mesh->body_names.size(), 0);
  for (int e = 0; e < mesh->num_elements(); ++e)
    for (int node : mesh->element_nodes(e))
      for (int d = 0; d < dpn; ++d)
        if (problem.is_dirichlet()[static_cast<size_t>(dpn * node + d)]) held[static_cast<size_t>(mesh->element_body(e))] = 1;
  for (size_t b = 0; b < held.size(); ++b)
    if (!held[b]) out.push_back(mesh->body_names[b]);
  return out;
}

std::string singular_stiffness_message(const Problem& problem) {
  const std::vector<std::string> free = unheld_bodies(problem);
  std::string message = "the stiffness of problem '" + problem.name() + "' is singular";
  if (free.empty())
    return message + " (Cholesky factorisation failed); expected every body held by enough Dirichlet conditions to stop"
                     " its rigid motions";
  std::string names;
  for (size_t i = 0; i < free.size(); ++i) names += (i ? ", '" : "'") + free[i] + "'";
  return message + ": " + (free.size() == 1 ? "body " : "bodies ") + names +
         (free.size() == 1 ? " is" : " are") +
         " held by no Dirichlet condition (free to move rigidly); expected every body to have clamped or"
         " prescribed boundary nodes";
}

}  // namespace contactrom::fom
