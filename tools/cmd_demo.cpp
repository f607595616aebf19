// contactrom demo [--dir DIR] [--train N] [--delta D] [--threads T]
// The whole pipeline on `hertz` in a few seconds:
//   1. FOM table for d = 0.05 … 0.3 (contact force, half-width and peak pressure
//      next to two-cylinder Hertz theory, active nodes, iterations, time);
//   2. offline: N = 30 snapshots in parallel into DIR/hertz<N>.h5 (default DIR: a
//      temporary folder, removed at the end);
//   3. online: greedy active set (δ = 1e-8), warm-started (default) and from the
//      empty set (`--option init=empty`, the start of the paper's Alg. 1), on
//      the 119 validation parameters against the FOM: errors, sparsity, iterations,
//      median time per query of ROM and FOM (factorisation reused), speedup.
// Equivalent commands: contactrom offline --problem hertz --train 30 --out hertz30.h5
//                      contactrom online --db hertz30.h5 --method greedy --delta 1e-8 --validation
//                      contactrom online --db hertz30.h5 --method greedy --option init=empty --delta 1e-8 --validation
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/stopwatch.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/greedy_active_set.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/online_timing.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/snapshot_database.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct DemoArgs {
  std::string dir;
  int train = 30, threads = 0;
  double delta = 1e-8;
};

/// Contact half-width: midway between the outermost active node and the next
/// node, averaged over both sides of the symmetric contact.
double half_width(const fom::Problem& problem, const Eigen::VectorXd& lambda) {
  const Eigen::MatrixXd& x = problem.contact().constraint_points();
  double half = 0.0;
  for (int side : {-1, 1}) {
    double last_active = 0.0, first_free = 1e300;
    for (int k = 0; k < lambda.size(); ++k)
      if (side * x(0, k) >= -1e-12 && lambda(k) > 0.0) last_active = std::max(last_active, side * x(0, k));
    for (int k = 0; k < lambda.size(); ++k)
      if (side * x(0, k) > last_active + 1e-12) first_free = std::min(first_free, side * x(0, k));
    half += 0.25 * (last_active + (first_free < 1e300 ? first_free : last_active));
  }
  return half;
}

/// Where the largest primal error of the validation set lies with respect to the
/// training parameters (one parameter, d).
void worst_error_line(const rom::EvaluationSummary& s, const rom::SnapshotDatabase& db) {
  const rom::EvaluationRow* worst = nullptr;
  for (const rom::EvaluationRow& row : s.rows)
    if (!worst || row.primal_error > worst->primal_error) worst = &row;
  if (!worst || db.num_snapshots() == 0) return;
  const double d = worst->mu(0), lowest = db.parameters.row(0).minCoeff(), highest = db.parameters.row(0).maxCoeff();
  double below = lowest, above = highest;
  for (Eigen::Index k = 0; k < db.parameters.cols(); ++k) {
    const double t = db.parameters(0, k);
    if (t <= d) below = std::max(below, t);
    if (t >= d) above = std::min(above, t);
  }
  if (d < lowest || d > highest)
    std::printf("   largest primal error %.2e at d = %g: outside the training range [%g, %g], an extrapolation\n"
                "   (no snapshot beyond it: its contact zone is %s than every column's).\n",
                worst->primal_error, d, lowest, highest, d < lowest ? "narrower" : "wider");
  else
    std::printf("   largest primal error %.2e at d = %g, between the training points %g and %g.\n",
                worst->primal_error, d, below, above);
}

void fom_table(const fom::Problem& problem, const fom::ActiveSetSolver& solver) {
  // Plane-strain two-cylinder Hertz theory for the FOM's force P:
  // a = sqrt(4PR/(πE*)), p0 = 2P/(πa), R = 0.5, 1/E* = 2(1 − ν²)/E.
  const double r = 0.5, e_star = 1.0 / (2.0 * (1.0 - 0.3 * 0.3));
  std::printf("1. FOM hertz (active-set solver, factorisation %.0f ms, reused)\n", solver.setup_time() * 1e3);
  std::printf("   %6s %10s %11s %9s %10s %9s %7s %6s %9s\n", "d", "force", "half-width", "Hertz a", "peak p",
              "Hertz p0", "active", "iter", "time ms");
  for (double d : {0.05, 0.1, 0.15, 0.2, 0.25, 0.3}) {
    const fom::Param mu = Eigen::VectorXd::Constant(1, d);
    const fom::FomSolution sol = solver.solve(mu);
    const double force = fom::contact_force(problem, sol.lambda);
    const double a = std::sqrt(4.0 * force * r / (M_PI * e_star)), p0 = 2.0 * force / (M_PI * a);
    std::printf("   %6.2f %10.5f %11.4f %9.4f %10.4f %9.4f %7d %6d %9.2f%s\n", d, force, half_width(problem, sol.lambda),
                a, sol.lambda.maxCoeff(), p0, sol.active, sol.iterations, sol.time_s * 1e3,
                sol.status == Status::Success ? "" : "  (not converged)");
  }
}

void run_demo(const DemoArgs& a) {
  const auto t_start = std::chrono::steady_clock::now();
  namespace fs = std::filesystem;
  std::string dir = a.dir;
  const bool temporary = dir.empty();
  if (temporary) {
    std::error_code ec;
    const fs::path base = fs::temp_directory_path(ec);  // $TMPDIR, else /tmp
    std::string name = ((ec ? fs::path("/tmp") : base) / "contactrom-demo-XXXXXX").string();
    if (!::mkdtemp(name.data()))
      throw InputError("cannot create a temporary folder under " + quoted(fs::path(name).parent_path().string(), 200) +
                       ": " + std::strerror(errno) + "; expected a writable TMPDIR, or give --dir");
    dir = name;
    register_created_folder(dir);  // removed, with the database, if a signal ends the run
  } else {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) throw InputError("cannot create folder " + quoted(dir, 200));
  }
  struct Remove {
    std::string dir, file;
    bool active;
    ~Remove() {
      if (!active) return;
      if (!file.empty()) forget_scratch_file(file);
      forget_created_folder(dir);
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } remove{dir, {}, temporary};

  auto problem = fom::make_problem("hertz");
  const fom::ActiveSetSolver solver(*problem);
  std::cout << "contactrom demo: hertz, two half-disks pressed by d (" << problem->num_dofs() << " dofs, "
            << problem->contact().num_constraints() << " contact nodes)\n\n";
  fom_table(*problem, solver);

  // 2. Offline.
  const std::string db_path = dir + "/hertz" + std::to_string(a.train) + ".h5";
  rom::OfflineOptions offline;
  offline.threads = a.threads;
  ProgressBar bar(std::cerr, "   offline", ::isatty(STDERR_FILENO));
  offline.progress = [&bar](int done, int total) { bar.update(done, total); };
  const rom::SnapshotDatabase db = rom::generate_snapshots(*problem, a.train, offline);
  bar.finish();
  if (temporary) remove.file = db_path, register_scratch_file(db_path);
  rom::write_database(db_path, db);
  int failed = 0;
  for (Status s : db.status) failed += s != Status::Success;
  std::printf("\n2. Offline: %d snapshots (d = 0.3 i/%d) on %d threads in %.2f s, %d not converged\n   database %s%s\n",
              db.num_snapshots(), a.train, db.threads, db.wall_time_s, failed, db_path.c_str(),
              temporary ? " (temporary)" : "");

  // 3. Online.
  rom::ReducedModelOptions model_options;
  model_options.delta = a.delta;
  const rom::ReducedModel model(*problem, rom::read_database(db_path), model_options);
  // The default greedy (warm start) and the same from the empty set (the paper's start).
  rom::GreedyOptions paper_options;
  paper_options.init = rom::WarmStart::Empty;
  const rom::GreedyActiveSet greedy(model), paper(model, paper_options);
  const std::vector<fom::Param> params = rom::database_validation_set(db, *problem);
  // FOM references for the errors; the times come from interleaved rounds of the FOM
  // and both starts (as `bench`), so that a slow spell of the machine does not
  // land on one of them only.
  std::vector<fom::FomSolution> refs;
  for (const fom::Param& mu : params) refs.push_back(solver.solve(mu));
  const rom::EvaluationSummary s = rom::evaluate_online(greedy, params, refs);
  const rom::EvaluationSummary sn = rom::evaluate_online(paper, params, refs);
  const rom::InterleavedTiming timing = rom::time_interleaved(solver, {&greedy, &paper}, params, 3);
  const rom::OnlineTiming &t = timing.online[0], &tn = timing.online[1];
  const double fom_median = timing.fom_median_s;
  std::printf("\n3. Online greedy active set on %zu validation parameters (delta = %g: primal rank %d, %d dictionary "
              "columns)\n",
              params.size(), a.delta, s.primal_rank, s.dictionary_size);
  std::printf("   %-36s %21s   %21s\n", "", "greedy (warm start)", "greedy (empty start)");
  std::printf("   %-36s %10s %10s   %10s %10s\n", "", "mean", "max", "mean", "max");
  std::printf("   %-36s %10.2e %10.2e   %10.2e %10.2e\n", "primal error (relative H1)", s.mean_primal_error,
              s.max_primal_error, sn.mean_primal_error, sn.max_primal_error);
  std::printf("   %-36s %10.2e %10.2e   %10.2e %10.2e\n", "dual error (relative L2 on contact)", s.mean_dual_error,
              s.max_dual_error, sn.mean_dual_error, sn.max_dual_error);
  std::printf("   %-36s %10.2f %10d   %10.2f %10d\n", "sparsity |I| (selected snapshots)", s.mean_sparsity,
              s.max_sparsity, sn.mean_sparsity, sn.max_sparsity);
  std::printf("   %-36s %10.2f %10s   %10.2f\n", "iterations (reduced solves)", s.mean_iterations, "",
              sn.mean_iterations);
  std::printf("   %-36s %10d %10s   %10d\n", "not converged", s.nonconverged, "", sn.nonconverged);
  std::printf("   %-36s %10d %10s   %10d\n", "inaccurate (contact check)", s.inaccurate, "", sn.inaccurate);
  std::printf("   %-36s %10.1f %10s   %10.1f     (us; full field +%.1f us)\n", "ROM time per query (median)",
              t.median_core_s * 1e6, "", tn.median_core_s * 1e6, (t.median_total_s - t.median_core_s) * 1e6);
  std::printf("   %-36s %10.1f us\n", "FOM time per query (median)", fom_median * 1e6);
  std::printf("   %-36s %10.1f x %8s   %10.1f x\n", "speedup", t.median_core_s > 0 ? fom_median / t.median_core_s : 0.0,
              "", tn.median_core_s > 0 ? fom_median / tn.median_core_s : 0.0);
  std::printf("\n   delta: the share of the snapshots' energy the POD may drop; primal rank: the number of POD\n"
              "   modes kept for the displacement; dictionary columns: the training snapshots' contact pressures,\n"
              "   from which each answer selects a few (|I|) and combines them with non-negative weights.\n");
  worst_error_line(s, db);
  std::printf("   ROM time includes the contact search and the reduced constraint operators of every iteration.\n"
              "   warm start: from the columns and coordinates of the bracketing snapshots (docs/rom.md).\n"
              "   demo finished in %.1f s\n",
              seconds_since(t_start));
}

CommandRegistrar reg("demo", [](CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  auto* sub = app.add_subcommand("demo", "Full pipeline on hertz: FOM table, offline, online greedy with errors and speedup");
  sub->add_option("--dir", args->dir, "keep the database in this folder (default: temporary, removed)")
      ->check(non_empty_path());
  add_integer(sub, "--train", args->train, "training size (default 30)", 2, 1000);
  add_number(sub, "--delta", args->delta, "POD energy tolerance (default 1e-8)", Interval::closed(0, 1));
  add_threads(sub, args->threads, "offline threads");
  sub->callback([args] { run_demo(*args); });
});

}  // namespace
}  // namespace contactrom::cli
