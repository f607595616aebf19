// Python bindings of the sparse kernels (core/nnls.hpp, rom/omp.hpp,
// rom/focuss.hpp) on numpy arrays. Shapes and finiteness are checked here, so a
// wrong input is a ValueError naming it rather than a zero vector with status
// invalid_input.
#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/exact_scaling.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/nnls.hpp>
#include "python/bindings.hpp"
#include <contactrom/rom/focuss.hpp>
#include <contactrom/rom/omp.hpp>

namespace contactrom::python {
namespace {

/// Result of a sparse kernel: x and how the solve ended (the keys of `contactrom sparse --json`).
struct SparseResult {
  Eigen::VectorXd x;
  Status status = Status::Success;
  int iterations = 0;
  std::vector<Eigen::Index> support;
  double residual = 0.0;           ///< ||A x - b||_2 (the kernel's matrix and right-hand side)
  double relative_residual = 0.0;  ///< residual / ||b|| (the residual itself when b = 0)
  std::optional<std::string> stop_reason;  ///< OMP's (rom::to_string(OmpStop)); none for the other kernels
};

void check_system(const char* kernel, const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const char* a_name,
                  const char* b_name) {
  if (b.size() != a.rows())
    throw InputError(std::string(kernel) + ": " + b_name + " has " + std::to_string(b.size()) + " entries; expected " +
                     std::to_string(a.rows()) + " (the rows of " + a_name + ")");
  if (!a.allFinite()) throw InputError(std::string(kernel) + ": " + a_name + " has a non-finite entry");
  if (!b.allFinite()) throw InputError(std::string(kernel) + ": " + b_name + " has a non-finite entry");
}

/// A tolerance must be a finite number >= 0 (as `contactrom sparse --tol`).
void check_tolerance(const char* kernel, const char* name, double value) {
  if (!(std::isfinite(value) && value >= 0.0))
    throw InputError(std::string(kernel) + ": " + name + " = " + format_number(value) + "; expected a finite number >= 0");
}

/// Runs `solve` on D and x scaled by exact_scaling() without the GIL, and packs the
/// solver's outcome (coefficients of the given D and x).
template <class Solver>
SparseResult run(Solver& solver, const Eigen::MatrixXd& d, const Eigen::VectorXd& x,
                 const std::function<Eigen::VectorXd(const Eigen::MatrixXd&, const Eigen::VectorXd&)>& solve) {
  SparseResult r;
  {
    py::gil_scoped_release release;
    r.x = solve_exactly_scaled(d, x, solve, [](Eigen::VectorXd& c) -> Eigen::VectorXd& { return c; });
  }
  r.status = solver.info();
  r.iterations = solver.iterations();
  const ResidualNorms norms = residual_norms(d, r.x, x);  // as `contactrom sparse`
  r.residual = norms.residual;
  r.relative_residual = norms.relative;
  for (Eigen::Index i = 0; i < r.x.size(); ++i)
    if (r.x(i) != 0.0) r.support.push_back(i);
  return r;
}

/// Binds FOCUSS or nnFOCUSS (same options, same call) as `name`.
template <class Solver>
void bind_focuss(py::module_& m, const char* name, const char* doc) {
  m.def(
      name,
      [name](const Eigen::MatrixXd& d, const Eigen::VectorXd& x, int max_iterations, double tolerance,
             double prune_tolerance) {
        check_system(name, d, x, "D", "x");
        check_tolerance(name, "tolerance", tolerance);
        check_tolerance(name, "prune_tolerance", prune_tolerance);
        if (max_iterations < 1)
          throw InputError(std::string(name) + ": max_iterations = " + std::to_string(max_iterations) +
                           "; expected an iteration cap >= 1");
        rom::FocussOptions o;
        o.max_iterations = max_iterations;
        o.tolerance = tolerance;
        o.prune_tolerance = prune_tolerance;
        Solver solver(o);
        return run(solver, d, x, [&](const Eigen::MatrixXd& ds, const Eigen::VectorXd& xs) { return solver.compute(ds).solve(xs); });
      },
      py::arg("D"), py::arg("x"), py::arg("max_iterations") = 100, py::arg("tolerance") = 1e-10,
      py::arg("prune_tolerance") = 1e-8, doc);
}

}  // namespace

void bind_kernels(py::module_& m) {
  py::class_<SparseResult>(m, "SparseResult",
                           "Solution of a sparse kernel: x, status, iterations, support, residual, relative_residual "
                           "and (OMP) stop_reason, as `contactrom sparse --json`.")
      .def_property_readonly("x", [](py::object self) { return vector_view(self.cast<const SparseResult&>().x, self); })
      .def_property_readonly("status", [](const SparseResult& r) { return std::string(to_string(r.status)); })
      .def_readonly("iterations", &SparseResult::iterations)
      .def_readonly("support", &SparseResult::support, "Indices of the non-zero entries of x, ascending.")
      .def_readonly("residual", &SparseResult::residual,
                    "||A x - b||_2 for nnls(A, b), ||D x - signal||_2 for omp/focuss/nnfocuss(D, signal), at the "
                    "returned x.")
      .def_readonly("relative_residual", &SparseResult::relative_residual,
                    "residual / ||b|| (or / ||signal||); the residual itself when that norm is 0.")
      .def_readonly("stop_reason", &SparseResult::stop_reason,
                    "OMP: why it stopped, 'residual_tolerance', 'atom_limit' (success) or 'no_progress' "
                    "(no_convergence); None for nnls, focuss and nnfocuss.")
      .def("__repr__", [](const SparseResult& r) {
        return "<contactrom.SparseResult " + std::string(to_string(r.status)) + ", " +
               std::to_string(r.support.size()) + " non-zeros>";
      });

  m.def(
      "nnls",
      [](const Eigen::MatrixXd& a, const Eigen::VectorXd& b, int max_iterations, double tolerance) {
        check_system("nnls", a, b, "A", "b");
        check_tolerance("nnls", "tolerance", tolerance);
        NnlsOptions o;
        o.max_iterations = max_iterations;
        o.tolerance = tolerance;
        Nnls solver(o);
        return run(solver, a, b, [&](const Eigen::MatrixXd& as, const Eigen::VectorXd& bs) { return solver.compute(as).solve(bs); });
      },
      py::arg("A"), py::arg("b"), py::arg("max_iterations") = 0, py::arg("tolerance") = 1e-12,
      "min ||A x - b|| s.t. x >= 0 (Lawson-Hanson); max_iterations <= 0: 3n.");
  m.def(
      "omp",
      [](const Eigen::MatrixXd& d, const Eigen::VectorXd& x, int max_atoms, double tolerance) {
        check_system("omp", d, x, "D", "x");
        check_tolerance("omp", "tolerance", tolerance);
        if (max_atoms < -1)
          throw InputError("omp: max_atoms = " + std::to_string(max_atoms) + "; expected a number of atoms >= 0, or -1 (no limit)");
        rom::OmpOptions o;
        o.max_atoms = max_atoms;
        o.tolerance = tolerance;
        rom::Omp solver(o);
        SparseResult r =
            run(solver, d, x, [&](const Eigen::MatrixXd& ds, const Eigen::VectorXd& xs) { return solver.compute(ds).solve(xs); });
        r.stop_reason = rom::to_string(solver.stop_reason());
        return r;
      },
      py::arg("D"), py::arg("x"), py::arg("max_atoms") = -1, py::arg("tolerance") = 1e-8,
      "Orthogonal matching pursuit: sparse alpha with D alpha ~ x (||x - D alpha|| <= tolerance ||x||).");
  bind_focuss<rom::Focuss>(m, "focuss", "FOCUSS (re-weighted minimum norm) from the minimum-norm solution.");
  bind_focuss<rom::NnFocuss>(m, "nnfocuss", "nnFOCUSS (non-negative FOCUSS started from NNLS).");
}

}  // namespace contactrom::python
