#include <contactrom/rom/problem_record.hpp>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/problem_file.hpp>
#include <contactrom/fom/rope.hpp>

namespace contactrom::rom {

ProblemRecord record_problem(const fom::Problem& problem) {
  ProblemRecord r;
  r.name = problem.name();
  r.fingerprint = problem.fingerprint();
  r.param_names = problem.param_names();
  r.text = problem.definition().builtin.empty() ? problem.definition().text : "";
  r.mesh = problem.mesh() ? std::make_shared<const fom::Mesh>(*problem.mesh()) : nullptr;
  r.contact_points = problem.contact().constraint_points();
  r.contact_weights = problem.contact().weights();
  r.lifting_terms.resize(problem.num_dofs(), problem.num_load_terms());
  for (int k = 0; k < problem.num_load_terms(); ++k) r.lifting_terms.col(k) = problem.lifting_terms()[k];
  return r;
}

std::unique_ptr<fom::Problem> rebuild_problem(const ProblemRecord& r, const std::string& label) {
  std::unique_ptr<fom::Problem> problem;
  if (r.text.empty()) {
    if (r.name != "rope")
      throw InputError(label + " stores no problem file for problem '" + r.name +
                       "'; expected a file written by contactrom");
    problem = fom::make_rope_problem();
  } else {
    if (!r.mesh) throw InputError(label + " stores a problem file but no mesh (dataset /mesh)");
    // Messages about the stored problem file name the file it is stored in.
    fom::ProblemDefinition def = fom::parse_problem_text(r.text, label + ":/problem_file");
    problem = fom::build_problem(std::move(def), *r.mesh);
  }
  if (problem->name() != r.name)
    throw InputError(label + " names problem " + quoted(r.name, 200) + " but its problem file defines " + quoted(problem->name(), 200));
  if (problem->fingerprint() != r.fingerprint)
    throw InputError(label + " was built for mesh fingerprint " + r.fingerprint + " but the stored problem gives " +
                     problem->fingerprint() + "; rebuild it with this contactrom");
  if (problem->contact().num_constraints() != r.contact_weights.size() || problem->num_dofs() != r.lifting_terms.rows() ||
      problem->num_params() != static_cast<int>(r.param_names.size()))
    throw InputError(label + " stores " + std::to_string(r.lifting_terms.rows()) + " dofs, " +
                     std::to_string(r.contact_weights.size()) + " contact rows and " +
                     std::to_string(r.param_names.size()) + " parameters, but its problem has " +
                     std::to_string(problem->num_dofs()) + ", " + std::to_string(problem->contact().num_constraints()) +
                     " and " + std::to_string(problem->num_params()));
  return problem;
}

}  // namespace contactrom::rom
