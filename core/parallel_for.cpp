#include <contactrom/core/parallel_for.hpp>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include <contactrom/core/errors.hpp>

namespace contactrom {

int resolve_threads(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

void check_threads(long long threads, const std::string& what) {
  if (threads < 0 || threads > kMaxThreads)
    throw InputError(what + " = " + std::to_string(threads) + " invalid; expected an integer in [0, " +
                     std::to_string(kMaxThreads) + "] (0: all cores)");
}

void parallel_for(int n, int threads, const std::function<void(int)>& task, const ProgressCallback& progress) {
  parallel_for_chains(n, 1, threads, task, progress);
}

void parallel_for_chains(int n, int chain, int threads, const std::function<void(int)>& task,
                         const ProgressCallback& progress) {
  if (n <= 0) return;
  chain = std::max(chain, 1);
  const int chains = (n + chain - 1) / chain;
  const int nt = std::min(resolve_threads(threads), chains);
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  std::condition_variable changed;
  int done = 0;
  std::exception_ptr error;

  auto worker = [&] {
    for (;;) {
      if (failed.load()) return;
      const int c = next.fetch_add(1);
      if (c >= chains) return;
      for (int i = c * chain; i < std::min(n, (c + 1) * chain); ++i) {
        if (failed.load()) return;
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
        try {
          progress(reported, n);
        } catch (...) {  // the caller stops the run (e.g. an interrupt): no new task starts
          lock.lock();
          if (!error) error = std::current_exception();
          failed = true;
          break;
        }
        lock.lock();
      }
    }
  }
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace contactrom
