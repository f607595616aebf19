// contactrom verify --db DB.h5 --method M[,M2,...] [--delta D] [--tau T] [--tau-scaling S]
//                   [--cpg-tolerance E] [--inner-solve nonnegative|equality]
//                   [--reference ipopt|fom] [--threads T] [--limit N] [--bench] [--repeats R] [--out FILE.csv] [--progress] [--json]
// KKT verification of reduced solutions against the Ipopt reference (DESIGN §5):
// for every validation parameter of the database's training set and every method,
//  - the FOM KKT residuals of the reduced solution (baselines::verify_solution, i.e.
//    fom::kkt_residuals with the pairing recomputed from u: stationarity,
//    penetration, negative pressure, complementarity — full-order values, reported
//    as they are),
//  - its errors against the reference solution (primal H¹, dual L²(Γc), active-set
//    differences; fom::compare_solutions through verify_solution),
//  - the reduced-level penetration max_p W_pᵀ(C(u)u − g(u)) over the method's dual
//    columns (greedy and full-dictionary: every dictionary column; cpg: its basis),
//    against the method's threshold τ (acceptance: ≤ τ + 1e-10),
// and the same KKT residuals of the reference solution itself. The reference is
// baselines::IpoptQpSolver (default) or the custom FOM active-set solver
// (--reference fom, fast). Several methods share one set of reference solves.
// --bench adds the median online time per query (also without the construction of
// the contact operators, the paper's convention) and the FOM time with the
// factorisation reused, all timed in interleaved rounds (rom::time_interleaved).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "baselines/cpg.hpp"
#include "baselines/full_dictionary.hpp"
#include "baselines/ipopt_qp.hpp"
#include "baselines/kkt_verifier.hpp"
#include "baselines/reduced_active_set.hpp"
#include "fom/active_set_solver.hpp"
#include "fom/atomic_file.hpp"
#include "fom/errors.hpp"
#include "fom/kkt.hpp"
#include "rom/greedy_active_set.hpp"
#include "rom/offline.hpp"
#include "rom/online_evaluation.hpp"
#include "rom/online_methods.hpp"
#include "rom/reduced_model.hpp"
#include "rom/snapshot_database.hpp"
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {


/// Slack of the reduced-level acceptance test: max_p W_pᵀ(Cu − g) ≤ τ + this.
constexpr double kReducedPenetrationSlack = 1e-10;

struct VerifyArgs {
  std::string db, methods, reference = "ipopt", out, tau_scaling = "absolute", inner_solve, init;
  double delta = 1e-8, tau = -1.0, cpg_tolerance = -1.0;
  int threads = 0, max_iterations = 50, limit = 0, repeats = 3;
  bool json = false, progress = false, bench = false;
};

/// Per-parameter outcome of one method.
struct MethodRow {
  baselines::VerificationReport report;  // KKT residuals and errors against the reference
  double reduced_penetration = 0.0;
  Status status = Status::Success;
  bool converged = false;
  int iterations = 0, sparsity = 0;
  double time_s = 0.0;
};

struct MethodReport {
  std::string name;
  std::vector<int> dual_columns;  // dictionary columns of the reduced constraint
  bool reduced_constraint = false;  // whether the method imposes W^T(Cu - g) <= tau
  double tau = 0.0;
  std::vector<MethodRow> rows;
  // Summary.
  baselines::VerificationSummary summary;
  double max_reduced_penetration = -std::numeric_limits<double>::infinity();
  int reduced_violations = 0, nonconverged = 0;
  double mean_time_s = 0.0, mean_sparsity = 0.0, mean_iterations = 0.0;
  rom::OnlineTiming timing;
  double basis_time_s = 0.0;  // CPG offline construction
};

std::vector<std::string> split_methods(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  if (out.empty()) throw InputError("--method '" + text + "' names no method");
  for (size_t i = 0; i < out.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (out[i] == out[k]) throw InputError("--method names '" + out[i] + "' twice");
  return out;
}

std::string format_double(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  return buf;
}

/// Evenly spaced subset of `n` parameters (first and last kept), for quick checks.
std::vector<fom::Param> subsample(const std::vector<fom::Param>& params, int n) {
  if (n <= 0 || n >= static_cast<int>(params.size())) return params;
  std::vector<fom::Param> out;
  for (int i = 0; i < n; ++i) {
    const size_t k = n == 1 ? 0 : static_cast<size_t>(std::llround(double(i) * (params.size() - 1) / (n - 1)));
    out.push_back(params[k]);
  }
  return out;
}

/// The dual columns and threshold τ of the reduced constraint of a method.
void describe_constraint(const rom::OnlineSolver& solver, const rom::OnlineSolverOptions& options,
                         MethodReport& report) {
  const rom::ReducedModel& model = solver.model();
  if (const auto* ras = dynamic_cast<const baselines::ReducedActiveSet*>(&solver)) {
    report.dual_columns = ras->dual_columns();
    report.tau = ras->threshold();
    report.reduced_constraint = true;
    if (const auto* cpg = dynamic_cast<const baselines::CpgActiveSet*>(&solver)) report.basis_time_s = cpg->basis().time_s;
    return;
  }
  // The greedy (and any other dictionary method): D_dᵀ(Cu − g) ≤ τ over ALL columns.
  report.dual_columns.resize(static_cast<size_t>(model.dictionary_size()));
  for (int p = 0; p < model.dictionary_size(); ++p) report.dual_columns[p] = p;
  if (const auto* greedy = dynamic_cast<const rom::GreedyActiveSet*>(&solver)) {
    report.tau = greedy->threshold();
    report.reduced_constraint = true;
  } else {
    report.tau = rom::GreedyActiveSet(model, rom::greedy_options(options)).threshold();
    report.reduced_constraint = false;  // reported for information only
  }
}

nlohmann::json method_json(const MethodReport& r, const rom::ReducedModel& model, bool bench, double fom_time) {
  nlohmann::json j;
  j["method"] = r.name;
  j["primal_rank"] = model.primal_rank();
  j["dictionary_size"] = model.dictionary_size();
  j["dual_basis_size"] = r.dual_columns.size();
  j["tau"] = r.tau;
  j["reduced_constraint"] = r.reduced_constraint;
  j["max_kkt"] = kkt_json(r.summary.max_kkt);
  j["max_primal_error"] = r.summary.max_primal_h1;
  j["mean_primal_error"] = r.summary.mean_primal_h1;
  j["max_dual_error"] = r.summary.max_dual_l2;
  j["mean_dual_error"] = r.summary.mean_dual_l2;
  j["max_active_set_differences"] = r.summary.max_active_set_differences;
  j["invalid"] = r.summary.invalid;
  j["max_reduced_penetration"] = r.max_reduced_penetration;
  j["reduced_penetration_violations"] = r.reduced_violations;
  j["reduced_penetration_ok"] = r.reduced_violations == 0;
  j["nonconverged"] = r.nonconverged;
  j["mean_iterations"] = r.mean_iterations;
  j["mean_sparsity"] = r.mean_sparsity;
  j["mean_time_s"] = r.mean_time_s;
  if (r.name == "cpg") j["basis_time_s"] = r.basis_time_s;
  if (bench) {
    j["median_time_s"] = r.timing.median_core_s;
    j["median_total_time_s"] = r.timing.median_total_s;
    j["speedup_vs_fom"] = r.timing.median_core_s > 0.0 ? fom_time / r.timing.median_core_s : 0.0;
    // −1 for methods that do not clock their operator construction (convex-hull).
    j["median_time_without_operators_s"] = r.timing.median_without_operators_s;
  }
  return j;
}

void write_csv(const std::string& path, const fom::Problem& problem, const std::vector<fom::Param>& params,
               const std::vector<fom::FomSolution>& refs, const std::vector<baselines::VerificationReport>& ref_reports,
               const std::string& ref_name, const std::vector<MethodReport>& reports) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "method,";
    for (const std::string& name : problem.param_names()) out << name << ',';
    out << "primal_h1_error,dual_l2_error,active_set_differences,stationarity,penetration,negative_pressure,"
           "complementarity,reduced_penetration,tau,converged,status,iterations,sparsity,time_s\n";
    auto params_text = [&](size_t i) {
      std::string s;
      for (int k = 0; k < params[i].size(); ++k) s += format_double(params[i](k)) + ",";
      return s;
    };
    for (size_t i = 0; i < params.size(); ++i) {
      const fom::KktResiduals& k = ref_reports[i].kkt;
      out << ref_name << ',' << params_text(i) << "0,0,0," << format_double(k.stationarity) << ','
          << format_double(k.penetration) << ',' << format_double(k.negative_pressure) << ','
          << format_double(k.complementarity) << ",,," << (refs[i].status == Status::Success ? 1 : 0) << ','
          << to_string(refs[i].status) << ',' << refs[i].iterations << ',' << refs[i].active << ','
          << format_double(refs[i].time_s) << '\n';
    }
    for (const MethodReport& r : reports)
      for (size_t i = 0; i < params.size(); ++i) {
        const MethodRow& row = r.rows[i];
        const fom::SolutionErrors& e = row.report.errors;
        const fom::KktResiduals& k = row.report.kkt;
        out << r.name << ',' << params_text(i) << format_double(e.primal_h1) << ',' << format_double(e.dual_l2)
            << ',' << e.active_set_differences << ',' << format_double(k.stationarity) << ','
            << format_double(k.penetration) << ',' << format_double(k.negative_pressure) << ','
            << format_double(k.complementarity) << ','
            << format_double(row.reduced_penetration) << ',' << format_double(r.tau) << ',' << (row.converged ? 1 : 0)
            << ',' << to_string(row.status) << ',' << row.iterations << ',' << row.sparsity << ','
            << format_double(row.time_s) << '\n';
      }
  });
}

void run_verify(const VerifyArgs& a) {
  if (!a.out.empty()) check_output_path(a.out);
  const std::vector<std::string> methods = split_methods(a.methods);
  const std::vector<std::string> names = rom::online_solver_names();
  for (const std::string& m : methods)
    if (std::find(names.begin(), names.end(), m) == names.end()) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      throw InputError("unknown online method '" + m + "'; expected one of: " + known);
    }
  if (a.reference != "ipopt" && a.reference != "fom")
    throw InputError("--reference '" + a.reference + "' unknown; expected ipopt or fom");

  const rom::SnapshotDatabase db = rom::read_database(a.db);
  auto problem = rom::problem_from_database(db, a.db);
  rom::ReducedModelOptions model_options;
  model_options.delta = a.delta;
  const rom::ReducedModel model(*problem, db, model_options);
  warn_if_no_primal_modes(model);
  rom::OnlineSolverOptions options;
  options.tau = a.tau;
  options.tau_scaling = a.tau_scaling;
  options.max_iterations = a.max_iterations;
  // --cpg-tolerance concerns cpg, --inner-solve the reduced active sets (cpg,
  // full-dictionary); each method gets only the settings it knows.
  std::vector<std::unique_ptr<rom::OnlineSolver>> solvers;
  std::vector<rom::OnlineSolverOptions> solver_options;
  for (const std::string& m : methods) {
    rom::OnlineSolverOptions o = options;
    if (m == "cpg" && a.cpg_tolerance >= 0.0) o.extra["cpg_tolerance"] = format_double(a.cpg_tolerance);
    if ((m == "cpg" || m == "full-dictionary") && !a.inner_solve.empty()) o.extra["inner_solve"] = a.inner_solve;
    // --init concerns the methods with a warm start; each checks the value itself.
    if ((m == "greedy" || m == "greedy-nested" || m == "cpg" || m == "full-dictionary") && !a.init.empty())
      o.extra["init"] = a.init;
    solvers.push_back(rom::make_online_solver(m, model, o));
    solver_options.push_back(o);
  }

  const std::vector<fom::Param> params = subsample(rom::database_validation_set(db, *problem), a.limit);
  const int n = static_cast<int>(params.size());
  const bool show = a.progress || ::isatty(STDERR_FILENO);

  // Reference solutions. IpoptQpSolver::solve is thread-safe; its Ipopt calls are
  // serialised by a process-wide mutex, so threads overlap only the pairing loop,
  // assembly and residual work around them.
  std::vector<fom::FomSolution> refs(params.size());
  std::vector<baselines::VerificationReport> ref_reports(params.size());
  const auto t_ref = std::chrono::steady_clock::now();
  {
    rom::ProgressBar bar(std::cerr, "verify: " + a.reference + " references", show);
    auto progress = [&bar](int done, int total) { bar.update(done, total); };
    if (a.reference == "ipopt") {
      const baselines::IpoptQpSolver ipopt(*problem);
      rom::parallel_for(
          n, a.threads,
          [&](int i) {
            refs[i] = ipopt.solve(params[i]);
            ref_reports[i] = baselines::verify_solution(*problem, refs[i]);
          },
          progress);
    } else {
      const fom::ActiveSetSolver fom_solver(*problem);
      rom::parallel_for(
          n, a.threads,
          [&](int i) {
            refs[i] = fom_solver.solve(params[i]);
            ref_reports[i] = baselines::verify_solution(*problem, refs[i]);
          },
          progress);
    }
    bar.finish();
  }
  const double ref_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_ref).count();
  const baselines::VerificationSummary ref_summary = baselines::summarize(ref_reports);
  const fom::KktResiduals& ref_max = ref_summary.max_kkt;
  int ref_failures = 0;
  for (int i = 0; i < n; ++i)
    if (refs[i].status != Status::Success) ++ref_failures;

  // Reduced solutions, sequentially per method (timings undisturbed); the residual
  // work after each solve does not enter the reported times.
  std::vector<MethodReport> reports;
  for (size_t s = 0; s < solvers.size(); ++s) {
    const rom::OnlineSolver& solver = *solvers[s];
    MethodReport r;
    r.name = solver.name();
    describe_constraint(solver, options, r);
    r.rows.resize(params.size());
    rom::ProgressBar bar(std::cerr, "verify: " + r.name, show);
    for (int i = 0; i < n; ++i) {
      const rom::OnlineResult res = solver.solve(params[i]);
      MethodRow& row = r.rows[i];
      row.report = baselines::verify_solution(*problem, params[i], res.u, res.lambda, &refs[i]);
      r.summary.add(row.report);
      row.reduced_penetration = baselines::reduced_penetration(model, r.dual_columns, res.u);
      row.status = res.status;
      row.converged = res.converged;
      row.iterations = res.iterations;
      row.sparsity = static_cast<int>(res.selected.size());
      row.time_s = res.time_s;
      r.max_reduced_penetration = std::max(r.max_reduced_penetration, row.reduced_penetration);
      if (row.reduced_penetration > r.tau + kReducedPenetrationSlack) ++r.reduced_violations;
      if (!row.converged || row.status != Status::Success) ++r.nonconverged;
      r.mean_time_s += row.time_s / n;
      r.mean_sparsity += double(row.sparsity) / n;
      r.mean_iterations += double(row.iterations) / n;
      bar.update(i + 1, n);
    }
    bar.finish();
    reports.push_back(std::move(r));
  }
  // --bench: the FOM and every method, plain and clocking its contact-operator
  // construction (the paper's convention), in interleaved rounds (as `bench`).
  double fom_time = 0.0;
  if (a.bench) {
    std::vector<std::unique_ptr<rom::OnlineSolver>> owned;
    std::vector<const rom::OnlineSolver*> plain, clocked;
    for (size_t s = 0; s < solvers.size(); ++s) {
      rom::OnlineSolverOptions o = solver_options[s];
      o.time_operators = true;
      owned.push_back(rom::make_online_solver(methods[s], model, o));
      plain.push_back(solvers[s].get());
      clocked.push_back(owned.back().get());
    }
    const fom::ActiveSetSolver fom_solver(*problem);
    const rom::InterleavedTiming t = rom::time_interleaved(fom_solver, plain, params, a.repeats, clocked);
    fom_time = t.fom_median_s;
    for (size_t s = 0; s < reports.size(); ++s) reports[s].timing = t.online[s];
  }
  if (!a.out.empty()) write_csv(a.out, *problem, params, refs, ref_reports, a.reference, reports);

  if (a.json) {
    nlohmann::json j;
    j["problem"] = problem->name();
    j[db.training_kind] = db.training_size;
    j["delta"] = model.delta();
    j["validation_size"] = n;
    j["reference"] = {{"solver", a.reference},
                      {"failures", ref_failures},
                      {"max_kkt", kkt_json(ref_max)},
                      {"wall_time_s", ref_wall}};
    j["reduced_penetration_slack"] = kReducedPenetrationSlack;
    j["methods"] = nlohmann::json::object();
    for (const MethodReport& r : reports) j["methods"][r.name] = method_json(r, model, a.bench, fom_time);
    if (a.bench) j["fom_median_time_s"] = fom_time;
    std::cout << j.dump() << std::endl;
    return;
  }

  std::cout << "verify " << problem->name() << " (" << db.training_kind << " " << db.training_size << "): " << n
            << " validation parameters, primal rank " << model.primal_rank() << " (delta " << model.delta()
            << "), dictionary " << model.dictionary_size() << "\n"
            << "reference " << a.reference << ": " << ref_failures << " failures, " << std::setprecision(3) << ref_wall
            << " s\n"
            << "maximum over the validation set (KKT residuals are full-order and relative, see fom/kkt.hpp):\n";
  auto cell = [](const std::string& s, int w) {
    std::ostringstream o;
    o << std::left << std::setw(w) << s;
    return o.str();
  };
  std::cout << cell("", 18) << cell("dual", 6) << cell("stationar.", 11) << cell("penetr.", 10) << cell("neg.press.", 11)
            << cell("complem.", 10) << cell("primal err", 11) << cell("dual err", 10) << cell("red. pen.", 11)
            << cell("tau", 10) << "not conv.\n";
  std::cout << cell(a.reference + " reference", 18) << cell("-", 6) << cell(sci(ref_max.stationarity), 11)
            << cell(sci(ref_max.penetration), 10) << cell(sci(ref_max.negative_pressure), 11)
            << cell(sci(ref_max.complementarity), 10) << cell("-", 11) << cell("-", 10) << cell("-", 11)
            << cell("-", 10) << ref_failures << "\n";
  for (const MethodReport& r : reports)
    std::cout << cell(r.name, 18) << cell(std::to_string(r.dual_columns.size()), 6)
              << cell(sci(r.summary.max_kkt.stationarity), 11) << cell(sci(r.summary.max_kkt.penetration), 10)
              << cell(sci(r.summary.max_kkt.negative_pressure), 11) << cell(sci(r.summary.max_kkt.complementarity), 10)
              << cell(sci(r.summary.max_primal_h1), 11) << cell(sci(r.summary.max_dual_l2), 10) << cell(sci(r.max_reduced_penetration), 11)
              << cell(sci(r.tau), 10) << r.nonconverged << "\n";
  for (const MethodReport& r : reports) {
    std::cout << r.name << ": mean primal error " << sci(r.summary.mean_primal_h1) << ", mean dual error "
              << sci(r.summary.mean_dual_l2)
              << ", mean |I| " << std::setprecision(3) << r.mean_sparsity << ", mean iterations " << r.mean_iterations
              << ", mean time " << r.mean_time_s * 1e6 << " us";
    if (r.reduced_constraint)
      std::cout << "; reduced penetration <= tau + " << kReducedPenetrationSlack << ": "
                << (r.reduced_violations ? "VIOLATED at " + std::to_string(r.reduced_violations) + " parameters"
                                         : std::string("yes"));
    if (a.bench)
      std::cout << "; median " << r.timing.median_core_s * 1e6 << " us, "
                << (r.timing.median_core_s > 0.0 ? fom_time / r.timing.median_core_s : 0.0) << "x faster than the FOM";
    if (a.bench && r.timing.median_without_operators_s >= 0.0)
      std::cout << " (" << r.timing.median_without_operators_s * 1e6 << " us without building the contact operators)";
    std::cout << "\n";
  }
  if (a.bench) std::cout << "FOM (factorisation reused): median " << fom_time * 1e3 << " ms per query\n";
  if (!a.out.empty()) std::cout << "per-parameter results written to " << a.out << "\n";
}

CommandRegistrar reg("verify", [](CLI::App& app) {
  auto args = std::make_shared<VerifyArgs>();
  auto* sub = app.add_subcommand("verify", "KKT verification of reduced solutions against the Ipopt reference");
  sub->add_option("--db", args->db, "snapshot database written by contactrom offline")
      ->check(non_empty_path())->required();
  sub->add_option("--method", args->methods, "online method(s), comma-separated (e.g. greedy,cpg,full-dictionary)")
      ->required();
  add_number(sub, "--delta", args->delta, "POD energy tolerance of the primal basis (default 1e-8)", Interval::closed(0, 1));
  add_number(sub, "--tau", args->tau, "penetration threshold of the reduced constraint (default: tau = delta)", Interval::at_least(0));
  sub->add_option("--tau-scaling", args->tau_scaling, "absolute (default, paper) | relative")
      ->check(CLI::IsMember({"absolute", "relative"}));
  add_integer(sub, "--max-iterations", args->max_iterations, "iteration cap k_max (default 50)", 1, 100000);
  add_number(sub, "--cpg-tolerance", args->cpg_tolerance, "CPG cone-projection tolerance (default: 1e-2 hertz, 5e-2 ironing/ironing2, 1e-2 otherwise)", Interval::closed(0, 1));
  sub->add_option("--inner-solve", args->inner_solve,
                  "cpg/full-dictionary saddle-point solve: nonnegative (default) | equality (textbook PDAS)")
      ->check(CLI::IsMember({"nonnegative", "equality"}));
  sub->add_option("--init", args->init,
                  "starting point of greedy/greedy-nested (empty|cell|nearest|primal; default cell) and of "
                  "cpg/full-dictionary (empty|primal|cell; default empty)");
  sub->add_option("--reference", args->reference, "reference solver: ipopt (default) | fom (custom active set)");
  add_integer(sub, "--threads", args->threads, "threads for the reference solves (default: hardware concurrency)", 1, 1024);
  add_integer(sub, "--limit", args->limit, "use N evenly spaced validation parameters (default: all)", 1, 1000000);
  sub->add_flag("--bench", args->bench, "also time each method and the FOM, in interleaved rounds (rom::time_interleaved)");
  add_integer(sub, "--repeats", args->repeats, "timing passes over the parameters with --bench (default 3)", 1, 1000);
  sub->add_option("--out", args->out, "CSV file with one row per method and parameter")
      ->check(non_empty_path());
  sub->add_flag("--progress", args->progress, "draw progress bars even when stderr is not a terminal");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(rom::describe_online_methods());
  sub->callback([args] { run_verify(*args); });
});

}  // namespace
}  // namespace contactrom::cli
