#include <contactrom/rom/offline.hpp>

#include <algorithm>
#include <memory>

namespace contactrom::rom {

SnapshotDatabase generate_snapshots(const fom::Problem& problem, const std::vector<fom::Param>& params,
                                    const std::string& training_kind, int training_size,
                                    const OfflineOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  check_training_kind(training_kind);
  for (const fom::Param& mu : params) problem.check_param(mu);
  const int n = static_cast<int>(params.size());
  const int nd = problem.num_dofs(), nc = problem.contact().num_constraints();

  SnapshotDatabase db;
  db.problem = record_problem(problem);
  db.created_by = options.created_by;
  db.training_kind = training_kind;
  db.training_size = training_size;
  db.parameters.resize(problem.num_params(), n);
  for (int j = 0; j < n; ++j) db.parameters.col(j) = params[j];
  const bool streamed = !options.stream_to.empty();
  db.primal = Eigen::MatrixXd::Zero(nd, streamed ? 0 : n);
  std::unique_ptr<DatabaseWriter> writer;
  if (streamed) writer = std::make_unique<DatabaseWriter>(options.stream_to, nd, n, options.stream_label);
  db.dual = Eigen::MatrixXd::Zero(nc, n);
  db.status.assign(n, Status::Success);
  db.iterations.assign(n, 0);
  db.pairing_iterations.assign(n, 0);
  db.time_s.assign(n, 0.0);

  // One solver (one factorisation) shared by every worker: it is const and
  // thread-safe. Each chain writes only its own columns j.
  const fom::ActiveSetSolver solver(problem);
  db.setup_time_s = solver.setup_time();
  const std::vector<char>& dirichlet = problem.is_dirichlet();
  const int chain = std::max(options.chain, 1);
  db.threads = std::min(resolve_threads(options.threads), std::max((n + chain - 1) / chain, 1));
  fom::solve_in_chains(
      solver, params, chain, options.threads,
      [&](int j, fom::FomSolution&& sol) {
        db.status[j] = sol.status;
        db.iterations[j] = sol.iterations;
        db.pairing_iterations[j] = sol.pairing_iterations;
        db.time_s[j] = sol.time_s;
        // Primal snapshot u − u_lift(μ), exactly zero on Dirichlet dofs (the lifting
        // carries the Dirichlet values; rounding differences between the solver's and
        // the problem's lifting sums are removed here).
        Eigen::VectorXd col = Eigen::VectorXd::Zero(nd);
        if (sol.u.size() == nd) {
          col = sol.u - problem.lifting(params[j]);
          for (int i = 0; i < nd; ++i)
            if (dirichlet[i]) col(i) = 0.0;
        }
        if (writer)
          writer->write_primal(j, col);
        else
          db.primal.col(j) = col;
        if (sol.lambda.size() == nc) db.dual.col(j) = sol.lambda;
      },
      options.progress);
  db.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (writer) {
    writer->finish(db);
    db.primal_files = {options.stream_to};
    for (int j = 0; j < n; ++j) db.primal_refs.push_back({0, j});
  }
  return db;
}

SnapshotDatabase generate_snapshots(const fom::Problem& problem, int n, const OfflineOptions& options) {
  return generate_snapshots(problem, fom::training_set(problem, n), problem.definition().training.selector(), n, options);
}

}  // namespace contactrom::rom
