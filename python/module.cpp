// The _contactrom extension module: error translation, the shared conversions of
// bindings.hpp, and the registration of the fom, rom and sparse-kernel bindings.
// The pure-Python package `contactrom` (python/contactrom/) re-exports it.
#include <cmath>

#include <contactrom/core/blas_threads.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/version.hpp>
#include <contactrom/fom/input_values.hpp>
#include "python/bindings.hpp"

namespace contactrom::python {

namespace {
// One text, checked by the CLI's parser, so that a refusal reads exactly as the
// CLI's for the same numbers.
fom::Param checked_param(const fom::Problem& problem, const double* values, py::ssize_t n) {
  std::string text;
  for (py::ssize_t i = 0; i < n; ++i) text += (i ? "," : "") + format_number(values[i]);
  return parse_problem_param(problem, text);
}
}  // namespace

fom::Param to_param(const fom::Problem& problem, py::handle value) {
  const auto refuse = [&] {
    return InputError("a parameter of " + quoted(problem.name(), 200) + " is a number or a sequence of " +
                      std::to_string(problem.num_params()) + " numbers (" + problem.range_text() + "), not " +
                      quoted(py::str(py::repr(value)).cast<std::string>(), 80));
  };
  // None, bools and text are not numbers (numpy would turn them into nan or 1, or
  // read the text), alone or in a sequence.
  if (value.is_none() || py::isinstance<py::bool_>(value) || py::isinstance<py::str>(value) ||
      py::isinstance<py::bytes>(value))
    throw refuse();
  if (!py::isinstance<py::float_>(value) && !py::isinstance<py::int_>(value)) {
    py::object kind;
    try {
      kind = py::module_::import("numpy").attr("asarray")(value).attr("dtype").attr("kind");
    } catch (const py::error_already_set&) {
      throw refuse();
    }
    const std::string k = py::str(kind);
    if (k != "i" && k != "u" && k != "f") throw refuse();
  }
  if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)) {
    const double v = PyFloat_AsDouble(value.ptr());  // an int beyond the doubles: OverflowError
    if (v == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      throw InputError("parameter value " + quoted(py::str(value).cast<std::string>(), 80) +
                       " is not a finite number; expected " + problem.range_text());
    }
    return checked_param(problem, &v, 1);
  }
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a) PyErr_Clear();
  if (a && a.ndim() == 0) return checked_param(problem, a.data(), 1);  // numpy scalars
  if (!a || a.ndim() != 1) throw refuse();
  return checked_param(problem, a.data(), a.size());
}

std::vector<fom::Param> to_params(const fom::Problem& problem, py::handle values) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  const bool one = problem.num_params() == 1;
  if (!a || a.ndim() < 1 || a.ndim() > 2 || (a.ndim() == 1 && !one))
    throw InputError("parameters of " + quoted(problem.name(), 200) + " are an array of shape (n, " +
                     std::to_string(problem.num_params()) + ")" + (one ? " or (n,)" : "") + " (" +
                     problem.range_text() + ")");
  const py::ssize_t width = a.ndim() == 1 ? 1 : a.shape(1);
  // As the CLI refuses an empty parameter file: no rows would give an empty database,
  // no solutions or error statistics of nothing.
  if (a.shape(0) == 0)
    throw InputError("params of " + quoted(problem.name(), 200) + " has no rows (shape (0" +
                     (a.ndim() == 2 ? ", " + std::to_string(width) : std::string(",")) +
                     ")); expected at least one parameter, an array of shape (n, " + std::to_string(problem.num_params()) +
                     ") with n >= 1");
  std::vector<fom::Param> out;
  for (py::ssize_t i = 0; i < a.shape(0); ++i) out.push_back(checked_param(problem, a.data() + i * width, width));
  return out;
}

std::string path_arg(py::handle value) {
  return py::module_::import("os").attr("fsdecode")(value).cast<std::string>();
}

void check_vector(const Eigen::VectorXd& v, const char* name, Eigen::Index size, const std::string& what) {
  if (v.size() != size)
    throw InputError(std::string(name) + " has " + std::to_string(v.size()) + " entries; expected " +
                     std::to_string(size) + " (" + what + ")");
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v(i)))
      throw InputError(std::string(name) + "[" + std::to_string(i) + "] is " + format_number(v(i)) +
                       "; expected finite numbers");
}

py::array_t<double> params_array(const std::vector<fom::Param>& params, int num_params) {
  py::array_t<double> out({static_cast<py::ssize_t>(params.size()), static_cast<py::ssize_t>(num_params)});
  auto w = out.mutable_unchecked<2>();
  for (size_t i = 0; i < params.size(); ++i)
    for (int k = 0; k < num_params; ++k) w(i, k) = params[i](k);
  return out;
}

namespace {
py::array readonly(py::array a) {
  a.attr("setflags")(py::arg("write") = false);
  return a;
}
}  // namespace

py::array vector_view(const Eigen::VectorXd& v, py::handle owner) {
  return readonly(py::array(py::dtype::of<double>(), {v.size()}, {static_cast<py::ssize_t>(sizeof(double))},
                            v.data(), owner));
}

py::array columns_as_rows(const Eigen::MatrixXd& m, py::handle owner) {
  const auto d = static_cast<py::ssize_t>(sizeof(double));
  return readonly(py::array(py::dtype::of<double>(), {m.cols(), m.rows()}, {m.rows() * d, d}, m.data(), owner));
}

py::dict kkt_dict(const fom::KktResiduals& k) {
  py::dict d;
  d["stationarity"] = k.stationarity;
  d["penetration"] = k.penetration;
  d["negative_pressure"] = k.negative_pressure;
  d["complementarity"] = k.complementarity;
  d["max"] = k.max();
  return d;
}

ProgressCallback interrupt_check() {
  return [](int, int) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw PythonErrorPending();
  };
}

void runtime_warning(const std::string& message) {
  if (PyErr_WarnEx(PyExc_RuntimeWarning, message.c_str(), 1) != 0) throw py::error_already_set();
}

std::string option_text(py::handle value) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  // numpy scalars (np.int64(3), np.float32(1e-6), np.bool_(True)): by their kind.
  if (!py::isinstance<py::str>(value) && py::hasattr(value, "dtype") && py::hasattr(value.attr("dtype"), "kind") &&
      py::len(py::getattr(value, "shape", py::tuple())) == 0) {
    const std::string kind = py::str(value.attr("dtype").attr("kind"));
    if (kind == "b") return value.attr("item")().cast<bool>() ? "true" : "false";
    if (kind == "i" || kind == "u") return py::str(value.attr("item")());
    if (kind == "f") return format_number(value.attr("item")().cast<double>());
  }
  if (py::isinstance<py::int_>(value)) return py::str(value);
  if (py::isinstance<py::float_>(value)) return format_number(value.cast<double>());
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  throw InputError("option value " + std::string(py::str(py::repr(value))) +
                   " is not a number, a string or a bool");
}

}  // namespace contactrom::python

PYBIND11_MODULE(_contactrom, m) {
  namespace py = pybind11;
  using namespace contactrom;
  m.doc() = "contactrom: reduced-order models of contact problems (C++ core)";
  m.attr("__version__") = version();
  // As the CLI: one BLAS thread under each of our threads, and the CLI's bits
  // (OPENBLAS_NUM_THREADS, set before Python starts, overrides it; docs/python.md).
  use_one_blas_thread_by_default();

  // Bad input → ValueError with the CLI's one-line message; anything else the C++
  // side throws (std::bad_alloc aside) is a RuntimeError, as pybind11 does by default.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const python::PythonErrorPending&) {
      if (!PyErr_Occurred()) PyErr_SetString(PyExc_KeyboardInterrupt, "interrupted");  // the pending one, else this
    }
  });

  python::bind_fom(m);
  python::bind_rom(m);
  python::bind_kernels(m);
}
