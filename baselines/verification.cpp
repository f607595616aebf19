#include <contactrom/baselines/verification.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <ostream>

#include <contactrom/baselines/cpg.hpp>
#include <contactrom/baselines/ipopt_qp.hpp>
#include <contactrom/baselines/reduced_active_set.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/atomic_file.hpp>
#include <contactrom/fom/parameter_space.hpp>
#include <contactrom/rom/greedy_active_set.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_methods.hpp>

namespace contactrom::baselines {
namespace {

void report_progress(const VerifyOptions& o, const std::string& stage, int done, int total) {
  if (o.progress) o.progress(stage, done, total);
}

/// The dual columns and threshold τ of the reduced constraint of a method.
void describe_constraint(const rom::OnlineSolver& solver, const rom::OnlineSolverOptions& options,
                         MethodVerification& report) {
  const rom::ReducedModel& model = solver.model();
  if (const auto* ras = dynamic_cast<const ReducedActiveSet*>(&solver)) {
    report.dual_columns = ras->dual_columns();
    report.tau = ras->threshold();
    report.reduced_constraint = true;
    if (const auto* cpg = dynamic_cast<const CpgActiveSet*>(&solver)) report.basis_time_s = cpg->basis().time_s;
    return;
  }
  // The greedy (and any other dictionary method): D_dᵀ(Cu − g) ≤ τ over ALL columns.
  report.dual_columns.resize(static_cast<size_t>(model.dictionary_size()));
  for (int p = 0; p < model.dictionary_size(); ++p) report.dual_columns[p] = p;
  if (const auto* greedy = dynamic_cast<const rom::GreedyActiveSet*>(&solver)) {
    report.tau = greedy->threshold();
    report.reduced_constraint = true;
  } else {
    // Reported for information only: τ as the greedy would use it (its own settings).
    rom::OnlineSolverOptions shared = options;
    shared.extra.clear();
    report.tau = rom::GreedyActiveSet(model, rom::greedy_options(shared)).threshold();
    report.reduced_constraint = false;
  }
}

/// Reference solutions and their KKT residuals, in parallel.
void solve_references(const fom::FullOrderSolver& solver, const fom::Problem& problem, const VerifyOptions& o,
                      VerifyReport& r) {
  const int n = static_cast<int>(r.params.size());
  parallel_for(
      n, o.threads,
      [&](int i) {
        r.references[i] = solver.solve(r.params[i]);
        r.reference_reports[i] = verify_solution(problem, r.references[i]);
      },
      [&](int done, int total) { report_progress(o, r.reference + " references", done, total); });
}

/// Errors by the rule of `online` (relative, or absolute against a near-zero
/// reference); +infinity when verify_solution found the sizes inconsistent.
fom::ReferenceErrors errors_against_reference(const fom::Problem& problem, const rom::OnlineResult& res,
                                              const fom::FomSolution& ref, const VerificationReport& report) {
  if (report.status != Status::Success || !report.has_reference) {
    const double inf = std::numeric_limits<double>::infinity();
    return {inf, inf, false};
  }
  return fom::reference_errors(problem, res.u, res.lambda, ref.u, ref.lambda);
}

MethodVerification verify_method(const rom::OnlineSolver& solver, const rom::OnlineSolverOptions& options,
                                 const VerifyOptions& o, const VerifyReport& r) {
  const fom::Problem& problem = solver.model().problem();
  const int n = static_cast<int>(r.params.size());
  MethodVerification m;
  m.name = solver.name();
  describe_constraint(solver, options, m);
  m.rows.resize(r.params.size());
  for (int i = 0; i < n; ++i) {
    const rom::OnlineResult res = solver.solve(r.params[i]);
    VerifyRow& row = m.rows[i];
    row.report = verify_solution(problem, r.params[i], res.u, res.lambda, &r.references[i]);
    m.summary.add(row.report);
    row.errors = errors_against_reference(problem, res, r.references[i], row.report);
    m.errors.add_errors(row.errors);
    row.reduced_penetration = reduced_penetration(solver.model(), m.dual_columns, res.u);
    row.status = res.status;
    row.converged = res.converged;
    row.iterations = res.iterations;
    row.sparsity = static_cast<int>(res.selected.size());
    row.time_s = res.time_s;
    m.max_reduced_penetration = std::max(m.max_reduced_penetration, row.reduced_penetration);
    if (row.reduced_penetration > m.tau + r.reduced_penetration_slack) ++m.reduced_violations;
    if (row.status == Status::Inaccurate)
      ++m.inaccurate;
    else if (!row.converged || row.status != Status::Success)
      ++m.nonconverged;
    m.mean_time_s += row.time_s / n;
    m.mean_sparsity += double(row.sparsity) / n;
    m.mean_iterations += double(row.iterations) / n;
    report_progress(o, m.name, i + 1, n);
  }
  return m;
}

/// Every method's solver, refusing an unknown reference or method, a method named
/// twice and settings a method refuses.
std::vector<std::unique_ptr<rom::OnlineSolver>> build_solvers(const rom::ReducedModel& model, const VerifyOptions& o) {
  if (o.reference != "ipopt" && o.reference != "fom")
    throw InputError("reference solver " + quoted(o.reference, 200) + " unknown; expected ipopt or fom");
  if (o.methods.empty()) throw InputError("verify: no online method given; expected at least one");
  std::vector<std::unique_ptr<rom::OnlineSolver>> solvers;
  for (size_t s = 0; s < o.methods.size(); ++s) {
    for (size_t k = 0; k < s; ++k)
      if (o.methods[s].name == o.methods[k].name)
        throw InputError("online method '" + o.methods[s].name + "' named twice; expected each once");
    solvers.push_back(rom::make_online_solver(o.methods[s].name, model, o.methods[s].options));
  }
  return solvers;
}

/// The report with the reference solutions, their KKT residuals and wall time.
VerifyReport reference_report(const fom::Problem& problem, const std::vector<fom::Param>& params,
                              const VerifyOptions& o) {
  VerifyReport r;
  r.params = params;
  r.reference = o.reference;
  r.references.resize(params.size());
  r.reference_reports.resize(params.size());
  // IpoptQpSolver::solve is thread-safe; its Ipopt calls are serialised by a
  // process-wide mutex, so threads overlap only the pairing loop, assembly and
  // residual work around them.
  const auto t_ref = std::chrono::steady_clock::now();
  solve_references(*make_fom_solver(problem, o.reference == "ipopt" ? "ipopt" : "active-set"), problem, o, r);
  r.reference_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_ref).count();
  r.reference_summary = summarize(r.reference_reports);
  for (const fom::FomSolution& ref : r.references)
    if (ref.status != Status::Success) ++r.reference_failures;
  return r;
}

/// Times the FOM and every method, plain and clocking its contact-operator
/// construction (the paper's convention), in interleaved rounds.
void time_methods(const rom::ReducedModel& model, const std::vector<std::unique_ptr<rom::OnlineSolver>>& solvers,
                  const VerifyOptions& o, VerifyReport& r) {
  std::vector<std::unique_ptr<rom::OnlineSolver>> owned;
  std::vector<const rom::OnlineSolver*> plain, clocked;
  for (size_t s = 0; s < solvers.size(); ++s) {
    rom::OnlineSolverOptions clocked_options = o.methods[s].options;
    clocked_options.time_operators = true;
    owned.push_back(rom::make_online_solver(o.methods[s].name, model, clocked_options));
    plain.push_back(solvers[s].get());
    clocked.push_back(owned.back().get());
  }
  const fom::ActiveSetSolver fom_solver(model.problem());
  const rom::InterleavedTiming t = rom::time_interleaved(fom_solver, plain, r.params, o.repeats, clocked);
  r.fom_median_time_s = t.fom_median_s;
  for (size_t s = 0; s < r.methods.size(); ++s) r.methods[s].timing = t.online[s];
}

}  // namespace

std::vector<fom::Param> subsample(const std::vector<fom::Param>& params, int n) {
  if (n <= 0 || n >= static_cast<int>(params.size())) return params;
  std::vector<fom::Param> out;
  for (int i = 0; i < n; ++i) {
    const size_t k = n == 1 ? 0 : static_cast<size_t>(std::llround(double(i) * (params.size() - 1) / (n - 1)));
    out.push_back(params[k]);
  }
  return out;
}

VerifyReport verify(const rom::ReducedModel& model, const std::vector<fom::Param>& params, const VerifyOptions& o) {
  const auto solvers = build_solvers(model, o);  // settings checked before the reference solves
  for (const fom::Param& mu : params) model.problem().check_param(mu);
  VerifyReport r = reference_report(model.problem(), params, o);
  // Reduced solutions, sequentially per method (timings undisturbed); the residual
  // work after each solve does not enter the reported times.
  for (size_t s = 0; s < solvers.size(); ++s) r.methods.push_back(verify_method(*solvers[s], o.methods[s].options, o, r));
  if (o.bench) time_methods(model, solvers, o, r);
  return r;
}

void write_verify_csv(const std::string& path, const fom::Problem& problem, const VerifyReport& r) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "method,";
    for (const std::string& name : problem.param_names()) out << name << ',';
    out << "primal_error,dual_error,errors,active_set_differences,stationarity,penetration,negative_pressure,"
           "complementarity,reduced_penetration,tau,converged,status,iterations,sparsity,time_s\n";
    auto params_text = [&](size_t i) {
      std::string s;
      for (int k = 0; k < r.params[i].size(); ++k) s += format_number(r.params[i](k)) + ",";
      return s;
    };
    auto kkt_text = [](const fom::KktResiduals& k) {
      return format_number(k.stationarity) + ',' + format_number(k.penetration) + ',' +
             format_number(k.negative_pressure) + ',' + format_number(k.complementarity);
    };
    for (size_t i = 0; i < r.params.size(); ++i) {
      const fom::FomSolution& ref = r.references[i];
      out << r.reference << ',' << params_text(i) << "0,0,relative,0," << kkt_text(r.reference_reports[i].kkt) << ",,,"
          << (ref.status == Status::Success ? 1 : 0) << ',' << to_string(ref.status) << ',' << ref.iterations << ','
          << ref.active << ',' << format_number(ref.time_s) << '\n';
    }
    for (const MethodVerification& m : r.methods)
      for (size_t i = 0; i < r.params.size(); ++i) {
        const VerifyRow& row = m.rows[i];
        const fom::ReferenceErrors& e = row.errors;
        out << m.name << ',' << params_text(i) << format_number(e.primal) << ',' << format_number(e.dual)
            << ',' << (e.absolute ? "absolute" : "relative") << ',' << row.report.errors.active_set_differences << ','
            << kkt_text(row.report.kkt) << ','
            << format_number(row.reduced_penetration) << ',' << format_number(m.tau) << ','
            << (row.converged ? 1 : 0) << ',' << to_string(row.status) << ',' << row.iterations << ','
            << row.sparsity << ',' << format_number(row.time_s) << '\n';
      }
  });
}

}  // namespace contactrom::baselines
