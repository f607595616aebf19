#pragma once
/// \file bindings.hpp
/// \brief Shared pieces of the contactrom Python module (_contactrom): the objects
/// that own what the C++ classes only reference, parameter conversion and
/// read-only numpy views of Eigen storage.
///
/// Ownership: a fom::ActiveSetSolver keeps a reference to its Problem and a
/// rom::OnlineModel a shared pointer; the Python objects below hold shared pointers
/// to everything they reference, so a Python user may drop the problem or the
/// database and keep the solver or the reduced model.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <exception>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <contactrom/baselines/ipopt_qp.hpp>
#include <contactrom/core/parallel_for.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/reduced_model_file.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace contactrom::python {

namespace py = pybind11;

using ProblemPtr = std::shared_ptr<const fom::Problem>;

/// \brief Thrown by interrupt_check() when Python has an exception pending (Ctrl-C:
/// KeyboardInterrupt); the module's translator leaves that exception to Python.
struct PythonErrorPending : std::exception {
  const char* what() const noexcept override { return "a Python exception is pending (interrupted)"; }
};

/// \brief A progress callback for the long calls that release the GIL: takes the GIL,
/// runs Python's signal handlers (Ctrl-C), and stops the run by throwing
/// PythonErrorPending if one raised. Call only from the thread that released the GIL.
ProgressCallback interrupt_check();

/// \brief A snapshot database and the problem it was computed for (built by
/// `offline`, or rebuilt from the file by `load_database`).
struct Database {
  std::shared_ptr<const rom::SnapshotDatabase> db;
  ProblemPtr problem;
  /// Snapshots at parameters the caller gave (not a training set): usable in memory,
  /// never written (no reader accepts such a file).
  bool explicit_params = false;
};

/// \brief A FOM solution with its KKT residuals (computed once, after the solve).
struct FomResult {
  fom::FomSolution solution;
  fom::KktResiduals kkt;
  double contact_force = 0.0;
  std::vector<std::string> warnings;  ///< fom::solution_warnings (elements turned inside out), as `fom --json`
  std::string problem_name, problem_fingerprint;  ///< the problem it solves (verify refuses another's)
};

/// \brief The FOM solver of `FullOrderSolver`: the active-set solver or Ipopt.
struct FullOrderSolver {
  ProblemPtr problem;
  std::string kind;  // "active-set" or "ipopt"
  std::unique_ptr<fom::FullOrderSolver> solver;  // baselines::make_fom_solver(*problem, kind)
  /// Solves at μ (thread-safe; the caller releases the GIL).
  fom::FomSolution solve(const fom::Param& mu) const { return solver->solve(mu); }
};

/// \brief A reduced model with its online method (which owns its problem), and the
/// database it was built from (null for a model loaded from a reduced-model file).
struct ReducedModel {
  std::shared_ptr<const rom::OnlineModel> rom;
  std::shared_ptr<const rom::SnapshotDatabase> db;
};

/// \brief Issues the `warnings` of a FOM solution of `problem` at `mu` as
/// RuntimeWarnings, each naming the problem and mu (the caller holds the GIL).
void warn_solution(const fom::Problem& problem, const fom::Param& mu, const std::vector<std::string>& warnings);

/// \brief Issues `message` as a Python RuntimeWarning (the caller holds the GIL).
/// \throws py::error_already_set when a warnings filter turns it into an error.
void runtime_warning(const std::string& message);

/// \brief μ from a Python number or sequence, checked as the CLI checks `--param`
/// (same messages: the values are written back as the shortest text that reads as
/// the same double). \throws InputError for a wrong count, a non-finite value or a
/// value out of range.
fom::Param to_param(const fom::Problem& problem, py::handle value);

/// \brief A path argument: a str, bytes or any os.PathLike (os.fsdecode).
std::string path_arg(py::handle value);

/// \brief Throws InputError unless `v` has `size` entries, all finite, naming
/// `name` and what was expected (`what`, e.g. "the dofs of 'hertz'").
void check_vector(const Eigen::VectorXd& v, const char* name, Eigen::Index size, const std::string& what);

/// \brief A list of parameters (one per row of a 2-D array, or a 1-D array / list
/// of numbers for a one-parameter problem), each checked by to_param.
/// \throws InputError for a wrong shape, a bad value or no rows at all.
std::vector<fom::Param> to_params(const fom::Problem& problem, py::handle values);

/// \brief Parameters as an (n, n_params) numpy array.
py::array_t<double> params_array(const std::vector<fom::Param>& params, int num_params);

/// \brief Read-only numpy view of a vector owned by `owner` (no copy).
py::array vector_view(const Eigen::VectorXd& v, py::handle owner);

/// \brief Read-only numpy view of the columns of `m` as rows: shape (cols, rows),
/// one snapshot or mode per row (no copy; m is column-major).
py::array columns_as_rows(const Eigen::MatrixXd& m, py::handle owner);

/// \brief The KKT residuals as a dict (stationarity, penetration,
/// negative_pressure, complementarity, max).
py::dict kkt_dict(const fom::KktResiduals& k);

/// \brief Text form of a Python option value: bool → true/false, numbers as the
/// shortest text that reads back the same, strings as they are.
std::string option_text(py::handle value);

void bind_fom(py::module_& m);
void bind_rom(py::module_& m);
void bind_kernels(py::module_& m);

}  // namespace contactrom::python
