#include "rom/offline.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <mutex>
#include <ostream>
#include <thread>

namespace contactrom::rom {

int resolve_threads(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

void parallel_for(int n, int threads, const std::function<void(int)>& task, const ProgressCallback& progress) {
  if (n <= 0) return;
  const int nt = std::min(resolve_threads(threads), n);
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  std::condition_variable changed;
  int done = 0;
  std::exception_ptr error;

  auto worker = [&] {
    for (;;) {
      if (failed.load()) return;
      const int i = next.fetch_add(1);
      if (i >= n) return;
      try {
        task(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
      {
        std::lock_guard<std::mutex> lock(mutex);
        ++done;
      }
      changed.notify_one();
    }
  };

  std::vector<std::thread> pool;
  pool.reserve(nt);
  for (int t = 0; t < nt; ++t) pool.emplace_back(worker);
  // The calling thread only reports progress, so the callback never runs
  // concurrently and may write to a stream without locking.
  {
    std::unique_lock<std::mutex> lock(mutex);
    int reported = 0;
    while (reported < n && !failed) {
      changed.wait(lock, [&] { return done > reported || failed; });
      reported = done;
      if (progress && !failed) {
        lock.unlock();
        progress(reported, n);
        lock.lock();
      }
    }
  }
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

SnapshotDatabase generate_snapshots(const fom::Problem& problem, const std::vector<fom::Param>& params,
                                    const std::string& training_kind, int training_size,
                                    const OfflineOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  for (const fom::Param& mu : params) problem.check_param(mu);
  const int n = static_cast<int>(params.size());
  const int nd = problem.num_dofs(), nc = problem.contact().num_constraints();

  SnapshotDatabase db;
  describe_problem(problem, db);
  db.created_by = options.created_by;
  db.training_kind = training_kind;
  db.training_size = training_size;
  db.parameters.resize(problem.num_params(), n);
  for (int j = 0; j < n; ++j) db.parameters.col(j) = params[j];
  db.primal = Eigen::MatrixXd::Zero(nd, n);
  db.dual = Eigen::MatrixXd::Zero(nc, n);
  db.status.assign(n, Status::Success);
  db.iterations.assign(n, 0);
  db.pairing_iterations.assign(n, 0);
  db.time_s.assign(n, 0.0);
  db.threads = std::min(resolve_threads(options.threads), std::max(n, 1));

  // One solver (one factorisation) shared by every worker: solve() is const and
  // thread-safe. Each task writes only its own column j.
  const fom::ActiveSetSolver solver(problem);
  db.setup_time_s = solver.setup_time();
  const std::vector<char>& dirichlet = problem.is_dirichlet();
  parallel_for(
      n, options.threads,
      [&](int j) {
        const fom::FomSolution sol = solver.solve(params[j]);
        db.status[j] = sol.status;
        db.iterations[j] = sol.iterations;
        db.pairing_iterations[j] = sol.pairing_iterations;
        db.time_s[j] = sol.time_s;
        if (sol.u.size() == nd) {
          // Primal snapshot u − u_lift(μ), exactly zero on Dirichlet dofs (the
          // lifting carries the Dirichlet values; rounding differences between the
          // solver's and the problem's lifting sums are removed here).
          auto col = db.primal.col(j);
          col = sol.u - problem.lifting(params[j]);
          for (int i = 0; i < nd; ++i)
            if (dirichlet[i]) col(i) = 0.0;
        }
        if (sol.lambda.size() == nc) db.dual.col(j) = sol.lambda;
      },
      options.progress);
  db.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return db;
}

SnapshotDatabase generate_snapshots(const fom::Problem& problem, int n, const OfflineOptions& options) {
  return generate_snapshots(problem, fom::training_set(problem, n), problem.definition().training.selector(), n, options);
}

ProgressBar::ProgressBar(std::ostream& out, std::string label, bool enabled)
    : m_out(out), m_label(std::move(label)), m_enabled(enabled), m_start(std::chrono::steady_clock::now()),
      m_last(m_start) {}

void ProgressBar::update(int done, int total) {
  if (!m_enabled || total <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (done < total && m_drawn && now - m_last < std::chrono::milliseconds(50)) return;
  m_last = now;
  const double elapsed = std::chrono::duration<double>(now - m_start).count();
  const double rate = elapsed > 0.0 ? done / elapsed : 0.0;
  const double eta = rate > 0.0 ? (total - done) / rate : 0.0;
  constexpr int width = 30;
  const int filled = static_cast<int>(static_cast<long long>(width) * done / total);
  std::string bar(filled, '#');
  bar += std::string(width - filled, '.');
  char text[160];
  if (done < total)
    std::snprintf(text, sizeof text, " [%s] %d/%d  %.1f/s  ETA %.1f s", bar.c_str(), done, total, rate, eta);
  else
    std::snprintf(text, sizeof text, " [%s] %d/%d  %.1f/s  %.1f s", bar.c_str(), done, total, rate, elapsed);
  // Trailing blanks erase a longer previous line; the line never wraps.
  m_out << '\r' << m_label << text << "   " << std::flush;
  m_drawn = true;
}

void ProgressBar::finish() {
  if (m_drawn) m_out << '\n' << std::flush;
  m_drawn = false;
}

}  // namespace contactrom::rom
