// Python bindings of the full-order side: Problem (parameters, operators K(μ),
// C(u), g(u)), FullOrderSolver and its results, KKT residuals and verification.
#include <contactrom/baselines/kkt_verifier.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/parallel_for.hpp>
#include "python/bindings.hpp"
#include <contactrom/fom/contact_checks.hpp>
#include <contactrom/fom/rope.hpp>
#include <contactrom/rom/offline.hpp>

namespace contactrom::python {

namespace {

/// Pairing and constraint operator at u, with the columns in full dof numbering.
struct ConstraintAt {
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> c;  // n_c × n_dofs
  Eigen::VectorXd g;
};

/// u: one finite value per dof of `problem`.
void check_u(const fom::Problem& problem, const Eigen::VectorXd& u) {
  check_vector(u, "u", problem.num_dofs(), "the dofs of " + quoted(problem.name(), 200));
}

ConstraintAt constraint_at(const fom::Problem& problem, const Eigen::VectorXd& u) {
  check_u(problem, u);
  const fom::ContactModel& contact = problem.contact();
  const Eigen::VectorXd us = contact.restrict_to_surface(u);
  fom::ConstraintMatrix cs;
  ConstraintAt out;
  contact.assemble(contact.search(us), cs, out.g);
  const std::vector<int>& dofs = contact.surface_dofs();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(cs.nonZeros()));
  for (int r = 0; r < cs.outerSize(); ++r)
    for (fom::ConstraintMatrix::InnerIterator it(cs, r); it; ++it) entries.emplace_back(r, dofs[it.col()], it.value());
  out.c.resize(cs.rows(), problem.num_dofs());
  out.c.setFromTriplets(entries.begin(), entries.end());
  return out;
}

void check_sizes(const fom::Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& lambda) {
  check_u(problem, u);
  check_vector(lambda, "lam", problem.contact().num_constraints(), "the contact rows of " + quoted(problem.name(), 200));
}

FomResult finish(const fom::Problem& problem, fom::FomSolution solution) {
  // A failed solve may carry no field at all; its status and message say why.
  if (solution.u.size() != problem.num_dofs() || solution.lambda.size() != problem.contact().num_constraints())
    throw std::runtime_error("the FOM solver returned no solution for problem " + quoted(problem.name(), 200) + " (status " +
                             to_string(solution.status) +
                             (solution.message.empty() ? "" : ": " + solution.message) + ")");
  FomResult r;
  r.kkt = solution.kkt;  // the residuals its status was certified with
  r.contact_force = fom::contact_force(problem, solution.lambda);
  r.warnings = fom::solution_warnings(problem, solution.u);
  r.problem_name = problem.name();
  r.problem_fingerprint = problem.fingerprint();
  r.solution = std::move(solution);
  return r;
}

/// `errors`: the errors against the reference by the rule of `online` (relative, or
/// absolute where the reference displacement is near zero); null without a valid one.
py::dict report_dict(const baselines::VerificationReport& r, const fom::ReferenceErrors* errors) {
  py::dict d;
  d["status"] = to_string(r.status);
  d["message"] = r.message;
  d["kkt"] = kkt_dict(r.kkt);
  if (r.has_reference) {
    py::dict e;
    e["primal_error"] = errors ? errors->primal : r.errors.primal_h1;
    e["dual_error"] = errors ? errors->dual : r.errors.dual_l2;
    e["errors"] = errors && errors->absolute ? "absolute" : "relative";
    e["active_set_differences"] = r.errors.active_set_differences;
    d["errors"] = e;
  } else {
    d["errors"] = py::none();
  }
  return d;
}

/// Problem.from_file and contactrom.problem: meshing runs without the GIL and stops on
/// Ctrl-C; the reference-configuration contact warnings (as the CLI prints them) are
/// issued as RuntimeWarnings.
std::shared_ptr<fom::Problem> make(py::handle name_or_path, int refine) {
  const std::string name = path_arg(name_or_path);
  fom::ProblemOptions options;
  options.refine = refine;
  options.progress = interrupt_check();  // Ctrl-C kills gmsh
  std::shared_ptr<fom::Problem> problem;
  std::vector<std::string> warnings;
  {
    py::gil_scoped_release release;
    problem = fom::make_problem(name, options);
    warnings = fom::reference_contact_warnings(*problem);
  }
  for (const std::string& w : warnings) runtime_warning("problem " + quoted(problem->name(), 200) + ": " + w);
  return problem;
}

}  // namespace

void warn_solution(const fom::Problem& problem, const fom::Param& mu, const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings)
    runtime_warning("FOM solution of " + quoted(problem.name(), 200) + " at " + problem.parameters().text(mu) + ": " + w);
}

void bind_fom(py::module_& m) {
  py::class_<fom::Problem, std::shared_ptr<fom::Problem>> problem(m, "Problem", R"doc(
A parametrised linear-elastic contact problem (a shipped name, a problem file or
the built-in `rope`). K(mu), C(u) and g(u) are the operators of

    min_u0 1/2 u0^T K(mu) u0 - u0^T f(mu)   s.t.   C(u) u - g(u) <= 0

with u = u_lift(mu) + u0 on all dofs (Dirichlet dofs kept).)doc");
  problem
      .def_static("from_file", &make, py::arg("path"), py::arg("refine") = 0,
                  "Reads a problem file (.toml), meshes it (refined `refine` times) and builds the problem.")
      .def_property_readonly("name", &fom::Problem::name)
      .def_property_readonly("param_names", &fom::Problem::param_names)
      .def_property_readonly("num_params", &fom::Problem::num_params)
      .def_property_readonly("param_lower", &fom::Problem::param_lower, py::return_value_policy::copy)
      .def_property_readonly("param_upper", &fom::Problem::param_upper, py::return_value_policy::copy)
      .def_property_readonly(
          "param_ranges",
          [](const fom::Problem& p) {
            py::dict d;
            for (int i = 0; i < p.num_params(); ++i)
              d[py::str(p.param_names()[i])] = py::make_tuple(p.param_lower()(i), p.param_upper()(i));
            return d;
          },
          "{name: (lower, upper)}; range_text says which lower bounds are open.")
      .def_property_readonly("range_text", &fom::Problem::range_text)
      .def_property_readonly("num_dofs", &fom::Problem::num_dofs)
      .def_property_readonly("num_constraints", [](const fom::Problem& p) { return p.contact().num_constraints(); })
      .def_property_readonly("dofs_per_node", &fom::Problem::dofs_per_node)
      .def_property_readonly("free_dofs", &fom::Problem::free_dofs)
      .def_property_readonly("surface_dofs", [](const fom::Problem& p) { return p.contact().surface_dofs(); })
      .def_property_readonly(
          "contact_weights", [](const fom::Problem& p) { return p.contact().weights(); },
          "Tributary length of each contact row (the pressure lam is per unit length).")
      .def_property_readonly(
          "contact_points", [](const fom::Problem& p) { return Eigen::MatrixXd(p.contact().constraint_points().transpose()); },
          "Reference coordinates of the contact rows, shape (n_c, dim) (dim = 2 or 3).")
      .def_property_readonly(
          "node_coordinates",
          [](const fom::Problem& p) -> py::object {
            if (!p.mesh()) return py::cast(fom::rope_nodes(p));
            return py::cast(Eigen::MatrixXd(p.mesh()->nodes.transpose()));
          },
          "Node coordinates, shape (n_nodes, dim) (dim = 2 or 3; rope: the 1-D abscissae).")
      .def_property_readonly(
          "warnings",
          [](const fom::Problem& p) {
            py::gil_scoped_release release;
            return fom::reference_contact_warnings(p);
          },
          "Warnings about the contact pairs in the reference configuration (surfaces that overlap, slave nodes "
          "just beyond their master), as `contactrom fom` prints them; a list of str, empty when none.")
      .def_property_readonly("fingerprint", &fom::Problem::fingerprint)
      .def_property_readonly("displacement_scale", &fom::Problem::displacement_scale)
      .def("check_param", [](const fom::Problem& p, py::handle mu) { return to_param(p, mu); }, py::arg("mu"),
           "mu as an array, checked against the ranges (ValueError with the CLI's message otherwise).")
      .def(
          "training_set", [](const fom::Problem& p, int n) { return params_array(fom::training_set(p, n), p.num_params()); },
          py::arg("n"), "Training parameters of size or level n (the problem's [training] plan), shape (m, n_params).")
      .def(
          "validation_set",
          [](const fom::Problem& p, int n) {
            (void)fom::training_set(p, n);  // n checked as a training size or level
            return params_array(fom::validation_set(p, n), p.num_params());
          },
          py::arg("n"), "Validation parameters associated with training size or level n.")
      .def(
          "K", [](const fom::Problem& p, py::handle mu) { return p.stiffness(to_param(p, mu)); }, py::arg("mu"),
          "Stiffness K(mu) on all dofs as a scipy.sparse.csc_matrix.")
      .def(
          "rhs", [](const fom::Problem& p, py::handle mu) { return p.rhs(to_param(p, mu)); }, py::arg("mu"),
          "f(mu) = f_ext(mu) - K(mu) u_lift(mu), zero on Dirichlet rows.")
      .def(
          "lifting", [](const fom::Problem& p, py::handle mu) { return p.lifting(to_param(p, mu)); }, py::arg("mu"),
          "u_lift(mu): the Dirichlet values, zero elsewhere.")
      .def(
          "C", [](const fom::Problem& p, const Eigen::VectorXd& u) { return constraint_at(p, u).c; }, py::arg("u"),
          "Constraint operator C(u) (n_c x n_dofs, scipy.sparse.csr_matrix), pairing searched at u.")
      .def(
          "g", [](const fom::Problem& p, const Eigen::VectorXd& u) { return constraint_at(p, u).g; }, py::arg("u"),
          "Gap vector g(u) (n_c) of the same linearisation: C(u) u - g(u) <= 0.")
      .def(
          "normal_gaps",
          [](const fom::Problem& p, const Eigen::VectorXd& u) {
            check_u(p, u);
            return fom::normal_gaps(p, u);
          },
          py::arg("u"), "Gap of every contact row in length units (unpaired rows: inf).")
      .def(
          "contact_force",
          [](const fom::Problem& p, const Eigen::VectorXd& lam) {
            check_vector(lam, "lam", p.contact().num_constraints(), "the contact rows of " + quoted(p.name(), 200));
            return fom::contact_force(p, lam);
          },
          py::arg("lam"), "Total contact force sum_s w_s lam_s (per unit thickness).")
      .def(
          "kkt_residuals",
          [](const fom::Problem& p, py::handle mu, const Eigen::VectorXd& u, const Eigen::VectorXd& lam) {
            const fom::Param m = to_param(p, mu);
            check_sizes(p, u, lam);
            return kkt_dict(fom::kkt_residuals(p, m, u, lam));
          },
          py::arg("mu"), py::arg("u"), py::arg("lam"), "The four relative KKT residuals of (u, lam) at mu, as a dict.")
      .def("__repr__", [](const fom::Problem& p) {
        return "<contactrom.Problem " + quoted(p.name(), 200) + ": " + p.range_text() + ", " + std::to_string(p.num_dofs()) +
               " dofs, " + std::to_string(p.contact().num_constraints()) + " contact rows>";
      });
  m.def("problem", &make, py::arg("name"), py::arg("refine") = 0,
        "A shipped problem by name ('hertz', 'ironing', 'rope', ...) or a problem file path.");

  py::class_<FomResult>(m, "FomSolution", "One FOM solution; arrays are read-only views owned by this object.")
      .def_property_readonly("mu", [](const FomResult& r) { return r.solution.mu; })
      .def_property_readonly("u", [](py::object self) { return vector_view(self.cast<const FomResult&>().solution.u, self); },
                             "Full displacement (lifting included), n_dofs.")
      .def_property_readonly(
          "lam", [](py::object self) { return vector_view(self.cast<const FomResult&>().solution.lambda, self); },
          "Contact pressure per contact row (>= 0).")
      .def_property_readonly("status", [](const FomResult& r) { return std::string(to_string(r.solution.status)); })
      .def_property_readonly("converged", [](const FomResult& r) { return r.solution.status == Status::Success; })
      .def_property_readonly("message", [](const FomResult& r) { return r.solution.message; })
      .def_property_readonly("iterations", [](const FomResult& r) { return r.solution.iterations; })
      .def_property_readonly("pairing_iterations", [](const FomResult& r) { return r.solution.pairing_iterations; },
                             "Pairing fixed-point iterations (solves of every contact row).")
      .def_property_readonly("zone_iterations", [](const FomResult& r) { return r.solution.zone_iterations; },
                             "Solves of the contact zone alone within them (docs/theory.md, the pairing fixed point).")
      .def_property_readonly("active", [](const FomResult& r) { return r.solution.active; })
      .def_property_readonly("time_s", [](const FomResult& r) { return r.solution.time_s; })
      .def_property_readonly("contact_force", [](const FomResult& r) { return r.contact_force; })
      .def_readonly("warnings", &FomResult::warnings,
                    "Warnings about the solution (elements it turns inside out), as `contactrom fom` prints them; a "
                    "list of str, empty when none.")
      .def_property_readonly("kkt", [](const FomResult& r) { return kkt_dict(r.kkt); },
                             "Relative KKT residuals (stationarity, penetration, negative_pressure, complementarity, max).")
      .def("__repr__", [](const FomResult& r) {
        return "<contactrom.FomSolution " + std::string(to_string(r.solution.status)) + ", " +
               std::to_string(r.solution.active) + " active rows>";
      });

  py::class_<FullOrderSolver>(m, "FullOrderSolver", R"doc(
The FOM solver of a problem: the active-set solver (default; K factorised once
here when it does not depend on mu) or Ipopt (solver="ipopt").)doc")
      .def(py::init([](std::shared_ptr<fom::Problem> problem, const std::string& solver) {
             auto s = std::make_unique<FullOrderSolver>();
             s->problem = problem;
             s->kind = solver;
             py::gil_scoped_release release;
             s->solver = baselines::make_fom_solver(*problem, solver);
             return s;
           }),
           py::arg("problem").none(false), py::arg("solver") = "active-set", R"doc(
The FOM solver of `problem` (a contactrom.Problem): solver="active-set" (default:
contactrom's dual active set, K factorised here once when no Young's modulus depends
on mu) or "ipopt" (the interior-point reference). ValueError for another name.)doc")
      .def_property_readonly("problem", [](const FullOrderSolver& s) { return std::const_pointer_cast<fom::Problem>(s.problem); })
      .def_property_readonly("solver", [](const FullOrderSolver& s) { return s.kind; })
      .def_property_readonly("setup_time_s", [](const FullOrderSolver& s) {
        return s.solver->setup_time();
      })
      .def(
          "solve",
          [](const FullOrderSolver& s, py::handle mu) {
            const fom::Param p = to_param(*s.problem, mu);
            FomResult r;
            {
              py::gil_scoped_release release;
              r = finish(*s.problem, s.solve(p));
            }
            warn_solution(*s.problem, p, r.warnings);
            return r;
          },
          py::arg("mu"), "Solves at mu (GIL released). RuntimeError if the solver returns no solution at all.")
      .def(
          "solve_all",
          [](const FullOrderSolver& s, py::handle params, int threads) {
            check_threads(threads, "threads");
            const std::vector<fom::Param> ps = to_params(*s.problem, params);
            std::vector<FomResult> out(ps.size());
            {
              py::gil_scoped_release release;
              parallel_for(static_cast<int>(ps.size()), threads,
                           [&](int i) { out[i] = finish(*s.problem, s.solve(ps[i])); }, interrupt_check());
            }
            // One warning for the list: how many solutions carry warnings, and the first.
            std::vector<std::vector<std::string>> warnings;
            for (const FomResult& r : out) warnings.push_back(r.warnings);
            const std::string line = fom::solutions_warning(*s.problem, ps, warnings, "FOM solutions");
            if (!line.empty()) runtime_warning(line + " (FomSolution.warnings lists them)");
            return out;
          },
          py::arg("params"), py::arg("threads") = 0,
          "Solves at every row of params on `threads` threads (0: all cores; at most 1024); a list of FomSolution.");

  m.def(
      "verify",
      [](std::shared_ptr<fom::Problem> problem, py::handle mu, const Eigen::VectorXd& u, const Eigen::VectorXd& lam,
         const FomResult* reference, double degenerate_tol) {
        const fom::Param p = to_param(*problem, mu);
        check_sizes(*problem, u, lam);
        if (reference && reference->problem_fingerprint != problem->fingerprint())
          throw InputError("reference is a solution of problem " + quoted(reference->problem_name, 200) +
                           " (fingerprint " + reference->problem_fingerprint + "), not of " +
                           quoted(problem->name(), 200) + " (fingerprint " + problem->fingerprint() +
                           "); expected a FomSolution of the same problem file and mesh");
        baselines::VerificationReport r;
        fom::ReferenceErrors errors;
        {
          py::gil_scoped_release release;
          r = baselines::verify_solution(*problem, p, u, lam, reference ? &reference->solution : nullptr, degenerate_tol);
          if (r.status == Status::InvalidInput) throw InputError(r.message);
          if (r.has_reference && r.status == Status::Success)
            errors = fom::reference_errors(*problem, u, lam, reference->solution.u, reference->solution.lambda);
        }
        return report_dict(r, r.has_reference && r.status == Status::Success ? &errors : nullptr);
      },
      py::arg("problem").none(false), py::arg("mu"), py::arg("u"), py::arg("lam"), py::arg("reference") = nullptr,
      py::arg("degenerate_tol") = 1e-8, R"doc(
KKT verification of a candidate (u, lam) at mu: {'status', 'message', 'kkt': {...},
'errors': {'primal_error', 'dual_error', 'errors', 'active_set_differences'} or None}.
The errors are computed against `reference` (a FomSolution, e.g. of
FullOrderSolver(problem, solver="ipopt")) when one is given: relative H1 and L2
errors, or absolute ones where the reference displacement is near zero ('errors'
says which: 'relative' or 'absolute', as `contactrom online`).)doc");
}

}  // namespace contactrom::python
