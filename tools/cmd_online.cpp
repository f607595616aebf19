// contactrom online --db DB.h5 --method greedy [--delta D] [--tau T] [--validation [--params FILE.csv]] [--param V]
//                   [--out FILE.csv|DIR] [--json] [--threads T] [--kkt] [--offset harmonic|dirichlet]
//                   [--tau-scaling absolute|relative] [--max-iterations K] [--option KEY=VALUE]...
// Builds the reduced model (POD basis with tolerance δ, dual dictionary) from a
// snapshot database and evaluates an online method:
//  - --validation (default without --param): at every validation parameter of the
//    problem (validation_set(n), n = the database's training size/level), against
//    the FOM; --out FILE.csv gets one row per parameter; prints a summary (or the
//    JSON object with --json, keys in docs/rom.md). --params FILE.csv replaces the
//    validation set by the parameters listed in FILE (one per line, --param order).
//  - --param V: one query, compared with the FOM; --out DIR writes
//    DIR/<problem>_<method>.vtu and DIR/<problem>_<method>_surface.csv.
#include <unistd.h>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include <contactrom/core/format.hpp>
#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/field_output.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/reduced_model_file.hpp>
#include <contactrom/rom/snapshot_database.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct OnlineArgs : MethodArgs {
  std::string db, param, params, out;
  int threads = 0;
  bool validation = false, json = false, kkt = false, progress = false;
};

nlohmann::json selected_json(const std::vector<int>& selected) { return selected; }

void run_single(const OnlineArgs& a, const fom::Problem& problem, const rom::ReducedModel& model,
                const rom::OnlineSolver& solver) {
  const fom::Param mu = parse_problem_param(problem, a.param);
  const rom::OnlineResult res = solver.solve(mu);
  const fom::ActiveSetSolver fom_solver(problem);
  const fom::FomSolution ref = fom_solver.solve(mu);
  const fom::ReferenceErrors errors = fom::reference_errors(problem, res.u, res.lambda, ref.u, ref.lambda);
  const double primal = errors.primal, dual = errors.dual;
  const fom::KktResiduals kkt = fom::kkt_residuals(problem, mu, res.u, res.lambda);
  std::vector<int> snapshots;
  for (int c : res.selected) snapshots.push_back(model.dictionary_snapshots()[c]);
  if (!a.out.empty()) {
    fom::write_fields(a.out, problem.name() + "_" + solver.name(), problem, mu, res.u, res.lambda);
  }
  nlohmann::json j;
  j["problem"] = problem.name();
  j["method"] = solver.name();
  j["param"] = param_json(mu);
  j["delta"] = model.delta();
  j["dictionary_size"] = model.dictionary_size();
  j["dual_basis_size"] = solver.dual_basis_size();
  j["primal_rank"] = model.primal_rank();
  j["status"] = to_string(res.status);
  j["converged"] = res.converged;
  j["penetration"] = res.contact.penetration;
  j["separation"] = res.contact.complementarity;
  j["primal_estimate"] = res.primal_estimate;
  j["dual_estimate"] = res.dual_estimate;
  if (!res.message.empty()) j["message"] = res.message;
  j["iterations"] = res.iterations;
  j["sparsity"] = res.selected.size();
  j["selected"] = selected_json(snapshots);
  j["coefficients"] = std::vector<double>(res.coefficients.data(), res.coefficients.data() + res.coefficients.size());
  j["time_s"] = res.time_s;
  j["primal_error"] = primal;
  j["dual_error"] = dual;
  j["errors"] = errors.absolute ? "absolute" : "relative";
  j["contact_force"] = res.contact_force;
  j["fom_contact_force"] = fom::contact_force(problem, ref.lambda);
  j["fom_time_s"] = ref.time_s;
  j["kkt"] = kkt_json(kkt);
  if (a.json) {
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "online " << solver.name() << " on " << problem.name() << " at " << j["param"].dump() << ": "
            << to_string(res.status) << (res.message.empty() ? "" : " (" + res.message + ")") << ", "
            << res.iterations << " iterations\n"
            << "dictionary " << model.dictionary_size() << " columns, primal rank " << model.primal_rank()
            << " (delta " << model.delta() << ")\n"
            << "selected snapshots " << j["selected"].dump() << " coefficients " << j["coefficients"].dump() << "\n"
            << std::setprecision(3) << "primal H1 error " << primal << ", dual L2 error " << dual
            << (errors.absolute ? " (absolute: the FOM displacement is near zero)" : "") << "\n"
            << "time " << res.time_s * 1e6 << " us (FOM " << ref.time_s * 1e3 << " ms)\n"
            << "KKT (relative): stationarity " << kkt.stationarity << ", penetration " << kkt.penetration
            << ", negative pressure " << kkt.negative_pressure << ", complementarity " << kkt.complementarity << "\n";
  if (!a.out.empty()) std::cout << "fields written to " << a.out << "/\n";
}

void run_validation(const OnlineArgs& a, const fom::Problem& problem, const rom::SnapshotDatabase& db,
                    const rom::OnlineSolver& solver) {
  const std::vector<fom::Param> params =
      a.params.empty() ? rom::database_validation_set(db, problem) : rom::read_parameter_csv(a.params, problem);
  const fom::ActiveSetSolver fom_solver(problem);
  // Two stages on stderr: the FOM references (in parallel), then the reduced queries.
  const bool show = a.progress || ::isatty(STDERR_FILENO);
  std::vector<fom::FomSolution> refs;
  {
    ProgressBar bar(std::cerr, "online: FOM references", show);
    refs = rom::compute_references(fom_solver, params, a.threads, [&bar](int done, int total) { bar.update(done, total); });
    bar.finish();
  }
  if (const std::string w = rom::references_warning(problem, params, refs); !w.empty())
    std::cerr << "contactrom: warning: " << w << "\n";
  rom::EvaluationOptions options;
  options.kkt = a.kkt;
  ProgressBar bar(std::cerr, "online: reduced queries", show);
  options.progress = [&bar](int done, int total) { bar.update(done, total); };
  const rom::EvaluationSummary s = rom::evaluate_online(solver, params, refs, options);
  bar.finish();
  if (!a.out.empty()) rom::write_evaluation_csv(a.out, problem, s);

  nlohmann::json j;
  append_summary_json(j, rom::summary_values(s));
  if (a.json) {
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "online " << s.method << " on " << problem.name() << " (" << db.training_kind << " "
            << db.training_size << "): " << s.rows.size()
            << (a.params.empty() ? " validation parameters\n" : " parameters of " + a.params + "\n")
            << "dictionary " << s.dictionary_size << " columns (dual basis " << s.dual_basis_size
            << "), primal rank " << s.primal_rank << " (delta "
            << s.delta << ")\n"
            << std::setprecision(3) << std::left << std::setw(22) << "" << std::setw(12) << "mean" << "max\n"
            << std::setw(22) << "primal H1 error" << std::setw(12) << s.mean_primal_error << s.max_primal_error << "\n"
            << std::setw(22) << "dual L2 error" << std::setw(12) << s.mean_dual_error << s.max_dual_error << "\n"
            << std::setw(22) << "sparsity |I|" << std::setw(12) << s.mean_sparsity << s.max_sparsity << "\n"
            << std::setw(22) << "iterations" << std::setw(12) << s.mean_iterations << "\n"
            << std::setw(22) << "time per query (us)" << std::setw(12) << s.mean_time_s * 1e6 << "(median "
            << s.median_time_s * 1e6 << ")\n"
            << "not converged: " << s.nonconverged << " of " << s.rows.size()
            << "; inaccurate (contact residuals above tolerance): " << s.inaccurate;
  if (s.absolute_error_rows)
    std::cout << "; " << s.absolute_error_rows << " rows with a near-zero FOM displacement left out of the errors "
              << "(absolute errors: max primal " << s.max_absolute_primal_error << ", max dual "
              << s.max_absolute_dual_error << "; per row in the CSV)";
  if (s.fom_failures) std::cout << "; FOM reference failures: " << s.fom_failures;
  if (a.kkt) std::cout << "; max KKT residual " << s.max_kkt;
  std::cout << "\n";
  if (!a.out.empty()) std::cout << "per-parameter results written to " << a.out << "\n";
}

void run_online(const OnlineArgs& a) {
  declare_input_files({a.db, a.params});
  if (!a.out.empty() && a.param.empty()) check_output_path(a.out);
  if (!a.param.empty() && a.validation)
    throw InputError("--param and --validation exclude each other; give one");
  if (!a.param.empty() && !a.params.empty())
    throw InputError("--param and --params exclude each other; give one (--params FILE.csv evaluates a parameter list)");
  if (!a.param.empty() && a.out.size() >= 4 && a.out.compare(a.out.size() - 4, 4, ".csv") == 0)
    throw InputError("--out " + quoted(a.out, 200) + " with --param names the folder of the VTU/CSV fields, not a CSV file; "
                     "expected a folder name (a CSV of results comes from --validation or contactrom query --out)");
  const rom::SnapshotDatabase db = rom::read_database(a.db);
  auto problem = rom::problem_from_database(db, a.db);
  declare_problem_inputs(*problem, {a.param.empty() ? a.out : std::string()});
  const rom::OnlineSolverOptions options = a.solver_options();
  // Validate the method name before the (more expensive) model construction.
  rom::check_online_method(a.method);
  const rom::ReducedModelOptions model_options = a.model_options();
  const rom::ReducedModel model(*problem, db, model_options);
  const auto solver = rom::make_online_solver(a.method, model, options);
  warn_if_no_primal_modes(model);  // after a method's refusal, which stays one line
  if (!a.param.empty())
    run_single(a, *problem, model, *solver);
  else
    run_validation(a, *problem, db, *solver);
}

CommandRegistrar reg("online", [](CLI::App& app) {
  auto args = std::make_shared<OnlineArgs>();
  auto* sub = app.add_subcommand("online", "Evaluate a reduced model built from a snapshot database");
  sub->add_option("--db", args->db, "snapshot database written by contactrom offline")
      ->check(non_empty_path())->required();
  add_method_options(sub, *args);
  sub->add_flag("--validation", args->validation, "evaluate on the validation set (default without --param)");
  sub->add_option("--param", args->param, "one query V or V1,V2");
  sub->add_option("--params", args->params,
                  "validation on the parameters of a CSV file (one per line, the --param order) instead of the "
                  "database's validation set")
      ->check(non_empty_path());
  sub->add_option("--out", args->out, "CSV file (validation) or folder for VTU/CSV fields (--param)")
      ->check(non_empty_path());
  add_threads(sub, args->threads, "threads for the FOM references");
  sub->add_flag("--kkt", args->kkt, "also compute the FOM KKT residuals of every ROM solution");
  sub->add_flag("--progress", args->progress,
                "validation: draw the progress bars (FOM references, reduced queries) even when stderr is not a terminal");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_online(*args); });
});

}  // namespace
}  // namespace contactrom::cli
