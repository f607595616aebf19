// Python bindings of the reduced side: the offline stage and its snapshot
// database, the reduced model with its online method, and the evaluation of a
// reduced model against the FOM over a parameter set.
#include <Python.h>
#include <variant>

#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/parallel_for.hpp>
#include "python/bindings.hpp"
#include <contactrom/rom/adaptive_training.hpp>
#include <contactrom/rom/fallback.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_methods.hpp>

namespace contactrom::python {
namespace {

/// The offset kind named by `offset` (None: harmonic), or by its older spelling
/// `lifting` when given; both given must agree.
rom::OffsetKind offset_kind(const py::object& offset_arg, const py::object& lifting) {
  const bool alias = !lifting.is_none();
  const std::string offset = offset_arg.is_none() ? std::string("harmonic") : py::str(offset_arg).cast<std::string>();
  const std::string text = alias ? py::str(lifting).cast<std::string>() : offset;
  if (alias && !offset_arg.is_none() && offset != text)
    throw InputError("offset " + quoted(offset, 200) + " and lifting " + quoted(text, 200) +
                     " disagree; expected only offset (lifting is its older name)");
  if (text == "harmonic") return rom::OffsetKind::Harmonic;
  if (text == "dirichlet") return rom::OffsetKind::Dirichlet;
  throw InputError(std::string(alias ? "lifting " : "offset ") + quoted(text, 200) +
                   " unknown; expected harmonic or dirichlet");
}

std::unique_ptr<ReducedModel> build_reduced_model(const Database& database, double delta, const std::string& method,
                                                  const py::dict& options, const py::object& offset,
                                                  bool include_failed, const py::object& lifting) {
  rom::check_online_method(method);
  std::map<std::string, std::string> values;
  for (const auto& [key, value] : options) values[py::str(key)] = option_text(value);
  const rom::OnlineSolverOptions solver_options = rom::options_from_map(method, values);
  rom::ReducedModelOptions model_options;
  model_options.delta = delta;
  model_options.offset = offset_kind(offset, lifting);
  model_options.include_failed_snapshots = include_failed;
  auto r = std::make_unique<ReducedModel>();
  r->db = database.db;
  {
    py::gil_scoped_release release;
    r->rom = std::make_shared<rom::OnlineModel>(database.problem, *r->db, model_options, method, solver_options);
  }
  if (r->rom->model().primal_rank() == 0)
    runtime_warning("ReducedModel: delta " + format_number(delta) +
                    " keeps no POD mode; the reduced displacement is the offset alone");
  return r;
}

/// Reads the keyword settings of offline_adaptive (rom::adaptive_option_table()
/// keys; numbers as numbers, words as str) into `o`, each checked as the CLI checks it.
void read_adaptive_settings(const py::dict& settings, rom::AdaptiveOptions& o) {
  const rom::OptionTable<rom::AdaptiveOptions>& table = rom::adaptive_option_table();
  for (const auto& [key_object, value] : settings) {
    const std::string key = py::str(key_object);
    if (!table.find(key)) {
      std::vector<std::string> keys;
      for (const rom::OptionSpec& spec : table.specs()) keys.push_back(spec.key);
      throw InputError("offline_adaptive setting " + quoted(key, 200) + " unknown; expected one of: " + join(keys, ", ") +
                       ", threads, resume, path");
    }
    table.read(o, key, option_text(value), key);
  }
}

/// The docstring of offline_adaptive: its settings from the table.
std::string adaptive_doc() {
  std::string doc = R"doc(
Adaptive offline stage, as `contactrom offline --adaptive` (docs/rom.md, "Adaptive
training"): FOM snapshots at the candidates where the reduced model's error estimate
is largest, `batch` per round, until the largest estimate is below `tolerance` or the
database holds `max_snapshots`. `threads`: 0 (all cores) or 1 to 1024. `resume`: an
adaptive database to continue, whose settings the ones not given keep (candidates,
seed, indicator, method and delta must stay the same). `path`: the database is
written there after every round. Returns the database.

Settings (keywords; `tolerance` is required for a new run):
)doc";
  for (const rom::OptionSpec& spec : rom::adaptive_option_table().specs())
    doc += "  " + spec.key + ": " + spec.help + " (" + rom::describe_option_type(spec) + "; default " +
           spec.default_value + ")\n";
  return doc;
}

/// A reduced model with the FOM behind it (rom::FallbackSolver); keeps the model alive.
struct Fallback {
  std::shared_ptr<const rom::OnlineModel> rom;
  std::shared_ptr<rom::FallbackSolver> solver;
};

/// The answer as a dict; a FOM answer's solution warnings are listed under 'warnings'
/// and issued as RuntimeWarnings, as FullOrderSolver.solve does.
py::dict fallback_answer(const fom::Problem& problem, const rom::FallbackAnswer& a) {
  py::dict d;
  warn_solution(problem, a.result.mu, a.warnings);
  d["warnings"] = a.warnings;
  d["solution"] = a.result;
  d["source"] = a.from_fom ? "fom" : "rom";
  d["fallback_reason"] = a.reason;
  d["rom_status"] = std::string(to_string(a.rom_status));
  d["rom_primal_estimate"] = a.rom_primal_estimate;
  d["rom_dual_estimate"] = a.rom_dual_estimate;
  d["rom_time_s"] = a.rom_time_s;
  d["fom_time_s"] = a.fom_time_s;
  return d;
}

std::unique_ptr<ReducedModel> load_reduced_model(py::handle path_like) {
  const std::string path = path_arg(path_like);
  auto r = std::make_unique<ReducedModel>();
  py::gil_scoped_release release;
  r->rom = std::make_shared<rom::OnlineModel>(rom::OnlineModel::load(path));
  return r;
}

py::dict summary_dict(const rom::EvaluationSummary& s, const fom::Problem& problem) {
  const int num_params = problem.num_params();
  py::dict d;
  for (const auto& [key, value] : rom::summary_values(s))
    std::visit([&d, &k = key](const auto& v) { d[k.c_str()] = v; }, value);
  const py::ssize_t n = static_cast<py::ssize_t>(s.rows.size());
  std::vector<fom::Param> mus;
  py::array_t<double> primal(n), dual(n), time(n), penetration(n), separation(n), primal_estimate(n), dual_estimate(n);
  py::array_t<int> sparsity(n), iterations(n);
  py::array_t<bool> converged(n), absolute(n);
  py::list status, reference_status;
  for (py::ssize_t i = 0; i < n; ++i) {
    const rom::EvaluationRow& row = s.rows[i];
    reference_status.append(to_string(row.fom_status));
    mus.push_back(row.mu);
    primal.mutable_at(i) = row.primal_error;
    dual.mutable_at(i) = row.dual_error;
    time.mutable_at(i) = row.time_s;
    sparsity.mutable_at(i) = row.sparsity;
    iterations.mutable_at(i) = row.iterations;
    converged.mutable_at(i) = row.converged;
    absolute.mutable_at(i) = row.absolute_errors;
    penetration.mutable_at(i) = row.contact.penetration;
    separation.mutable_at(i) = row.contact.complementarity;
    primal_estimate.mutable_at(i) = row.primal_estimate;
    dual_estimate.mutable_at(i) = row.dual_estimate;
    status.append(to_string(row.status));
  }
  py::dict rows;
  rows["mu"] = params_array(mus, num_params);
  rows["primal_error"] = primal;
  rows["dual_error"] = dual;
  rows["sparsity"] = sparsity;
  rows["iterations"] = iterations;
  rows["time_s"] = time;
  rows["converged"] = converged;
  rows["status"] = status;
  rows["absolute_errors"] = absolute;
  rows["penetration"] = penetration;
  rows["separation"] = separation;
  rows["primal_estimate"] = primal_estimate;
  rows["dual_estimate"] = dual_estimate;
  rows["reference_status"] = reference_status;
  d["rows"] = rows;
  return d;
}

}  // namespace

void bind_rom(py::module_& m) {
  py::class_<Database>(m, "SnapshotDatabase", R"doc(
FOM snapshots at the training parameters with the problem they belong to. Arrays
are read-only views with one snapshot per row, as in the HDF5 file.)doc")
      .def_property_readonly("problem", [](const Database& d) { return std::const_pointer_cast<fom::Problem>(d.problem); })
      .def_property_readonly("problem_name", [](const Database& d) { return d.db->problem.name; })
      .def_property_readonly("num_snapshots", [](const Database& d) { return d.db->num_snapshots(); })
      .def_property_readonly("num_dofs", [](const Database& d) { return d.db->num_dofs(); })
      .def_property_readonly("num_constraints", [](const Database& d) { return d.db->num_constraints(); })
      .def_property_readonly("param_names", [](const Database& d) { return d.db->problem.param_names; })
      .def_property_readonly(
          "training_kind", [](const Database& d) { return d.explicit_params ? std::string("explicit") : d.db->training_kind; },
          "'train' or 'level' (a training set, `--train n` / `--level n`), 'list', 'adaptive', or 'explicit' (the "
          "parameters given to offline()).")
      .def_property_readonly("training_size", [](const Database& d) { return d.db->training_size; })
      .def_property_readonly(
          "parameters", [](py::object self) { return columns_as_rows(self.cast<const Database&>().db->parameters, self); },
          "(n_snap, n_params)")
      .def_property_readonly(
          "primal", [](py::object self) { return columns_as_rows(self.cast<const Database&>().db->primal, self); },
          "(n_snap, n_dofs): u - u_lift of each snapshot")
      .def_property_readonly(
          "dual", [](py::object self) { return columns_as_rows(self.cast<const Database&>().db->dual, self); },
          "(n_snap, n_c): contact pressure of each snapshot")
      .def_property_readonly("status",
                             [](const Database& d) {
                               std::vector<std::string> s;
                               for (Status st : d.db->status) s.push_back(to_string(st));
                               return s;
                             })
      .def_property_readonly("iterations", [](const Database& d) { return d.db->iterations; })
      .def_property_readonly("time_s", [](const Database& d) { return d.db->time_s; })
      .def_property_readonly("wall_time_s", [](const Database& d) { return d.db->wall_time_s; })
      .def_property_readonly("threads", [](const Database& d) { return d.db->threads; })
      .def_property_readonly(
          "adaptive",
          [](const Database& d) -> py::object {
            if (d.db->training_kind != "adaptive") return py::none();
            const rom::AdaptiveRecord& a = d.db->adaptive;
            py::dict r;
            for (const auto& [key, value] : a.settings)
              std::visit([&r, &k = key](const auto& v) { r[k.c_str()] = v; }, value);
            r["initial_snapshots"] = a.initial_snapshots;
            r["round_snapshots"] = py::array_t<int>(a.round_snapshots.size(), a.round_snapshots.data());
            r["round_added"] = py::array_t<int>(a.round_added.size(), a.round_added.data());
            r["round_max_indicator"] = py::array_t<double>(a.round_max_indicator.size(), a.round_max_indicator.data());
            r["round_mean_indicator"] = py::array_t<double>(a.round_mean_indicator.size(), a.round_mean_indicator.data());
            r["round_time_s"] = py::array_t<double>(a.round_time_s.size(), a.round_time_s.data());
            return std::move(r);
          },
          "How an adaptive run built the database (a dict of its settings and per-round arrays), None otherwise.")
      .def(
          "validation_set",
          [](const Database& d) {
            return params_array(rom::database_validation_set(*d.db, *d.problem), d.problem->num_params());
          },
          "The validation parameters of the database's training set (those `contactrom online` evaluates).")
      .def(
          "save",
          [](const Database& d, py::handle path_like) {
            const std::string path = path_arg(path_like);
            if (d.explicit_params)
              throw InputError("cannot write " + quoted(path, 200) + ": the database holds snapshots at the parameters "
                               "given to offline(), not a training set, and no reader accepts such a file; expected a "
                               "database of offline(problem, n) or offline_adaptive()");
            py::gil_scoped_release release;
            rom::write_database(path, *d.db);
          },
          py::arg("path"), "Writes the HDF5 file (atomically), readable by the CLI and load_database.")
      .def("__repr__", [](const Database& d) {
        return "<contactrom.SnapshotDatabase " + quoted(d.db->problem.name, 200) + ": " + std::to_string(d.db->num_snapshots()) +
               " snapshots>";
      });

  m.def(
      "load_database",
      [](py::handle path_like) {
        const std::string path = path_arg(path_like);
        py::gil_scoped_release release;
        auto db = std::make_shared<rom::SnapshotDatabase>(rom::read_database(path));
        Database d;
        d.problem = rom::problem_from_database(*db, path);
        d.db = std::move(db);
        return d;
      },
      py::arg("path"), "Reads a database written by `contactrom offline` or SnapshotDatabase.save; rebuilds its problem.");

  m.def(
      "offline",
      [](std::shared_ptr<fom::Problem> problem, py::handle params, int threads) {
        check_threads(threads, "threads");
        rom::OfflineOptions options;
        options.threads = threads;
        options.progress = interrupt_check();  // Ctrl-C stops it
        Database d;
        d.problem = problem;
        // An int n (numpy's integers too): the training set of size or level n.
        const bool is_int =
            !py::isinstance<py::bool_>(params) && !py::isinstance<py::array>(params) && PyIndex_Check(params.ptr());
        if (!is_int && (py::isinstance<py::float_>(params) || (py::hasattr(params, "dtype") && !py::isinstance<py::array>(params))))
          throw InputError("params " + std::string(py::str(py::repr(params))) +
                           " is a number but not an int; expected an int n (the training set of size or level n) or an"
                           " array of parameters of shape (n, " + std::to_string(problem->num_params()) + ")");
        if (is_int) {
          const int n = py::int_(params.attr("__index__")()).cast<int>();
          const fom::SamplingPlan& plan = problem->definition().training;
          if (plan.selector() == "list" && n != static_cast<int>(plan.points.size()))
            throw InputError("problem " + quoted(problem->name(), 200) + " trains on its " +
                             std::to_string(plan.points.size()) + " listed points; expected params " +
                             std::to_string(plan.points.size()) + " (or an array of parameters), not " + std::to_string(n));
          py::gil_scoped_release release;
          d.db = std::make_shared<rom::SnapshotDatabase>(rom::generate_snapshots(*problem, n, options));
        } else {
          const std::vector<fom::Param> ps = to_params(*problem, params);
          py::gil_scoped_release release;
          d.db = std::make_shared<rom::SnapshotDatabase>(
              rom::generate_snapshots(*problem, ps, "train", static_cast<int>(ps.size()), options));
          d.explicit_params = true;
        }
        return d;
      },
      py::arg("problem").none(false), py::arg("params"), py::arg("threads") = 0, R"doc(
FOM snapshots in parallel (GIL released). `params` is an int n (the training set
of size or level n, as `contactrom offline --train n` / `--level n`) or an array
of parameters (n, n_params); a database of other parameters than a training set
works in memory but is refused when read back from a file.)doc");

  m.def(
      "offline_adaptive",
      [](std::shared_ptr<fom::Problem> problem, py::object tolerance, int threads, py::object resume,
         py::object path_like, py::kwargs settings) {
        check_threads(threads, "threads");
        if (!resume.is_none() && !py::isinstance<Database>(resume))
          throw py::type_error("resume is a SnapshotDatabase (contactrom.load_database(path)), not " +
                               std::string(py::str(py::repr(resume))));
        const Database* previous = resume.is_none() ? nullptr : &resume.cast<const Database&>();
        rom::AdaptiveOptions o = previous ? rom::adaptive_options_of(*previous->db) : rom::AdaptiveOptions{};
        if (tolerance.is_none() && !previous)
          throw InputError("offline_adaptive needs tolerance (e.g. 0.05) for a new run");
        if (!tolerance.is_none()) settings["tolerance"] = tolerance;
        read_adaptive_settings(settings, o);
        o.offline.threads = threads;
        o.offline.progress = interrupt_check();  // Ctrl-C stops it
        const std::string path = path_like.is_none() ? std::string() : path_arg(path_like);
        if (!path.empty()) o.on_round = [path](const rom::AdaptiveRound&, const rom::SnapshotDatabase& db) {
          rom::write_database(path, db);
        };
        Database d;
        d.problem = problem;
        py::gil_scoped_release release;
        const rom::AdaptiveTrainer trainer(*problem, o);
        d.db = std::make_shared<rom::SnapshotDatabase>(previous ? trainer.resume(*previous->db, "the database to resume")
                                                                : trainer.run());
        return d;
      },
      py::arg("problem").none(false), py::arg("tolerance") = py::none(), py::arg("threads") = 0, py::arg("resume") = py::none(),
      py::arg("path") = py::none(), adaptive_doc().c_str());

  m.def(
      "adaptive_options", [] { return rom::adaptive_option_table().to_values(rom::AdaptiveOptions{}); },
      "The settings offline_adaptive takes, each with its default (a dict: numbers as int or float, words as str), "
      "as `contactrom offline --help` states them.");

  py::class_<rom::OnlineResult>(m, "RomSolution",
                                "One online query; arrays are read-only views owned by this object.")
      .def_property_readonly("mu", [](const rom::OnlineResult& r) { return r.mu; })
      .def_property_readonly("u_hat", [](py::object self) { return vector_view(self.cast<const rom::OnlineResult&>().u_hat, self); },
                             "Reduced coordinates (r).")
      .def_property_readonly("u", [](py::object self) { return vector_view(self.cast<const rom::OnlineResult&>().u, self); },
                             "Full displacement Phi u_hat + offset(mu) (n_dofs).")
      .def_property_readonly(
          "lam", [](py::object self) { return vector_view(self.cast<const rom::OnlineResult&>().lambda, self); },
          "Full contact pressure D[:, selected] @ coefficients (n_c).")
      .def_property_readonly(
          "selected",
          [](const rom::OnlineResult& r) {
            return py::array_t<int>(static_cast<py::ssize_t>(r.selected.size()), r.selected.data());
          },
          "Selected dictionary columns (int array: indices into ReducedModel.dictionary columns).")
      .def_readonly("contact_force", &rom::OnlineResult::contact_force,
                    "Total contact force sum_s w_s lam_s (per unit thickness in 2D), as FomSolution.contact_force.")
      .def_property_readonly(
          "coefficients", [](py::object self) { return vector_view(self.cast<const rom::OnlineResult&>().coefficients, self); },
          "Coefficients of the selected columns, in the same order.")
      .def_readonly("iterations", &rom::OnlineResult::iterations)
      .def_readonly("converged", &rom::OnlineResult::converged)
      .def_property_readonly("status", [](const rom::OnlineResult& r) { return std::string(to_string(r.status)); })
      .def_readonly("message", &rom::OnlineResult::message)
      .def_property_readonly(
          "penetration", [](const rom::OnlineResult& r) { return r.contact.penetration; },
          "Largest penetration of the answer at its own pairing, in units of the displacement scale U.")
      .def_property_readonly(
          "separation", [](const rom::OnlineResult& r) { return r.contact.complementarity; },
          "Separation under pressure (pressure-weighted mean |gap|) at its own pairing, in units of U.")
      .def_readonly("primal_estimate", &rom::OnlineResult::primal_estimate,
                    "Estimate of the relative H1 displacement error against the FOM, made without the FOM (NaN: none).")
      .def_readonly("dual_estimate", &rom::OnlineResult::dual_estimate,
                    "Estimate of the relative L2 pressure error against the FOM, made without the FOM (NaN: none).")
      .def_readonly("time_s", &rom::OnlineResult::time_s)
      .def("__repr__", [](const rom::OnlineResult& r) {
        return "<contactrom.RomSolution " + std::string(to_string(r.status)) + ", " + std::to_string(r.selected.size()) +
               " columns, " + std::to_string(r.iterations) + " iterations>";
      });

  py::class_<Fallback>(m, "FallbackModel", "A reduced model that lets the FOM answer where it cannot (ReducedModel.with_fallback).")
      .def(
          "solve",
          [](const Fallback& f, py::handle mu) {
            const fom::Param p = to_param(f.rom->problem(), mu);
            rom::FallbackAnswer a;
            {
              py::gil_scoped_release release;
              a = f.solver->solve(p);
            }
            return fallback_answer(f.rom->problem(), a);
          },
          py::arg("mu"), "One query: the ROM's answer if kept, else the FOM's (a dict; see ReducedModel.with_fallback).")
      .def("__repr__", [](const Fallback& f) {
        return "<contactrom.FallbackModel " + f.rom->method() + ", primal tolerance " +
               format_number(f.solver->options().primal_tolerance) + ", dual tolerance " +
               format_number(f.solver->options().dual_tolerance) + ">";
      });

  py::class_<ReducedModel>(m, "ReducedModel", R"doc(
POD basis, dual dictionary, reduced operators and an online method, built from a
snapshot database or loaded from a reduced-model file (`contactrom reduce`). The
object owns the problem (and the database) it needs.)doc")
      .def(py::init(&build_reduced_model), py::arg("db"), py::arg("delta") = 1e-8, py::arg("method") = "greedy",
           py::arg("options") = py::dict(), py::arg("offset") = py::none(),
           py::arg("include_failed_snapshots") = false, py::arg("lifting") = py::none(), R"doc(
Builds the reduced model of a SnapshotDatabase: the POD of its primal snapshots
truncated at `delta` (energy share dropped), the dual dictionary of its pressures,
the reduced operators, and the online `method` (contactrom.online_methods()) with its
`options` (a dict of the method's keys, numbers as numbers). `offset`: what the
reduced displacement is measured from, "harmonic" (default; the unconstrained FOM
response) or "dirichlet" (the problem's Dirichlet lifting); `lifting` is accepted as
its older name. `include_failed_snapshots`: also use snapshots whose FOM solve did
not succeed. ValueError names the argument for a bad value.)doc")
      .def_static("load", &load_reduced_model, py::arg("path"),
                  "Reads a reduced-model file (`contactrom reduce` or ReducedModel.save): no FOM, no meshing.")
      .def(
          "save",
          [](const ReducedModel& r, py::handle path_like) {
            const std::string path = path_arg(path_like);
            py::gil_scoped_release release;
            r.rom->save(path);
          },
          py::arg("path"), "Writes the reduced-model file (atomically), readable by `contactrom query` and load.")
      .def_property_readonly("problem",
                             [](const ReducedModel& r) { return std::const_pointer_cast<fom::Problem>(r.rom->shared_problem()); })
      .def_property_readonly(
          "database",
          [](const ReducedModel& r) -> py::object {
            if (!r.db) return py::none();
            return py::cast(Database{r.db, r.rom->shared_problem()});
          },
          "The snapshot database it was built from (None when loaded from a file).")
      .def_property_readonly("method", [](const ReducedModel& r) { return r.rom->method(); })
      .def_property_readonly(
          "options", [](const ReducedModel& r) { return rom::options_to_values(r.rom->method(), r.rom->options()); },
          "Every setting of the method (defaults filled in), as stored in the reduced-model file: numbers as "
          "int or float, flags as bool, choices as str.")
      .def_property_readonly("delta", [](const ReducedModel& r) { return r.rom->model().delta(); })
      .def_property_readonly("primal_rank", [](const ReducedModel& r) { return r.rom->model().primal_rank(); })
      .def_property_readonly("dictionary_size", [](const ReducedModel& r) { return r.rom->model().dictionary_size(); })
      .def_property_readonly("dual_basis_size", [](const ReducedModel& r) { return r.rom->solver().dual_basis_size(); })
      .def_property_readonly(
          "basis", [](const ReducedModel& r) -> const Eigen::MatrixXd& { return r.rom->model().basis(); },
          py::return_value_policy::reference_internal, "POD basis Phi (n_dofs, r), read-only view.")
      .def_property_readonly(
          "dictionary", [](const ReducedModel& r) -> const Eigen::MatrixXd& { return r.rom->model().dictionary(); },
          py::return_value_policy::reference_internal, "Dual dictionary D (n_c, m), read-only view.")
      .def_property_readonly(
          "singular_values",
          [](const ReducedModel& r) -> const Eigen::VectorXd& { return r.rom->model().singular_values(); },
          py::return_value_policy::reference_internal)
      .def_property_readonly("dictionary_snapshots",
                             [](const ReducedModel& r) { return r.rom->model().dictionary_snapshots(); },
                             "Database snapshot index of each dictionary column.")
      .def(
          "solve",
          [](const ReducedModel& r, py::handle mu) {
            const fom::Param p = to_param(r.rom->problem(), mu);
            py::gil_scoped_release release;
            return r.rom->solver().solve(p);
          },
          py::arg("mu"), "One online query (GIL released): a RomSolution.")
      .def(
          "with_fallback",
          [](const ReducedModel& r, double primal_tolerance, double dual_tolerance) {
            rom::FallbackOptions o;  // checked by FallbackSolver
            o.primal_tolerance = primal_tolerance;
            o.dual_tolerance = dual_tolerance;
            return Fallback{r.rom, std::make_shared<rom::FallbackSolver>(r.rom->solver(), o)};
          },
          py::arg("primal_tolerance") = rom::FallbackOptions().primal_tolerance,
          py::arg("dual_tolerance") = rom::FallbackOptions().dual_tolerance, R"doc(
The model with the FOM behind it (as `contactrom query --fallback fom`): its solve(mu)
returns a dict with 'solution' (a RomSolution: the ROM's answer, or the FOM's u, lam
and status), 'source' ('rom' or 'fom'), 'fallback_reason', 'rom_status',
'rom_primal_estimate', 'rom_dual_estimate', 'rom_time_s', 'fom_time_s' and 'warnings'
(a FOM answer's, as FomSolution.warnings, also issued as RuntimeWarnings). An answer
is kept from the ROM when its status is success and 3 x its estimates are within the
tolerances.)doc")
      .def(
          "solve_all",
          [](const ReducedModel& r, py::handle params) {
            const std::vector<fom::Param> ps = to_params(r.rom->problem(), params);
            std::vector<rom::OnlineResult> out;
            out.reserve(ps.size());
            py::gil_scoped_release release;
            const ProgressCallback check = interrupt_check();
            for (const fom::Param& p : ps) {
              out.push_back(r.rom->solver().solve(p));
              if (out.size() % 64 == 0) check(static_cast<int>(out.size()), static_cast<int>(ps.size()));
            }
            return out;
          },
          py::arg("params"), "Online queries at every row of params, in order (GIL released).")
      .def(
          "evaluate",
          [](const ReducedModel& r, py::object params, int threads, bool kkt) {
            check_threads(threads, "threads");
            const fom::Problem& problem = r.rom->problem();
            if (params.is_none() && !r.db)
              throw InputError("evaluate() of a reduced model loaded from a file needs params; it has no database "
                               "and so no validation set");
            const std::vector<fom::Param> ps =
                params.is_none() ? rom::database_validation_set(*r.db, problem) : to_params(problem, params);
            rom::EvaluationSummary s;
            std::string warning;
            {
              py::gil_scoped_release release;
              const fom::ActiveSetSolver fom_solver(problem);
              const std::vector<fom::FomSolution> refs = rom::compute_references(fom_solver, ps, threads, interrupt_check());
              warning = rom::references_warning(problem, ps, refs);
              rom::EvaluationOptions options;
              options.kkt = kkt;
              s = rom::evaluate_online(r.rom->solver(), ps, refs, options);
            }
            if (!warning.empty()) runtime_warning(warning);
            return summary_dict(s, problem);
          },
          py::arg("params") = py::none(), py::arg("threads") = 0, py::arg("kkt") = false, R"doc(
Errors against the FOM over `params` (default: the database's validation set, as
`contactrom online --validation`): the summary of `online --json` (same keys;
errors of rows whose FOM displacement is near zero are absolute, counted in
'absolute_error_rows' with their maxima 'max_absolute_primal_error' and
'max_absolute_dual_error', and left out of the relative means and maxima) plus
'rows', the per-parameter arrays (mu, primal_error, dual_error, sparsity,
iterations, time_s, converged, status, absolute_errors, penetration, separation,
primal_estimate, dual_estimate).)doc")
      .def("__repr__", [](const ReducedModel& r) {
        return "<contactrom.ReducedModel '" + r.rom->problem().name() + "' " + r.rom->method() + ": rank " +
               std::to_string(r.rom->model().primal_rank()) + ", dictionary " +
               std::to_string(r.rom->model().dictionary_size()) + ">";
      });

  m.def("online_methods", &rom::online_solver_names, "Names of the registered online methods.");
}

}  // namespace contactrom::python
