#pragma once
/// \file parallel_for.hpp
/// \brief A minimal thread pool: `task(i)` for i = 0..n-1 on worker threads, with
/// progress reported from the calling thread.
#include <functional>

namespace contactrom {

/// \brief Called after each completed task with (completed, total); calls are
/// serialised (never concurrent) and come from the thread that called the
/// parallel function.
using ProgressCallback = std::function<void(int done, int total)>;

/// \brief Runs `task(i)` for i = 0..n-1 on `threads` worker threads (≤ 0: the
/// hardware concurrency; never more threads than tasks). Tasks are handed out in
/// increasing order from a shared counter. The first exception thrown by a task is
/// rethrown after all workers have stopped (the remaining tasks are skipped).
void parallel_for(int n, int threads, const std::function<void(int)>& task, const ProgressCallback& progress = {});

/// \brief Number of worker threads `requested` resolves to (≤ 0: hardware concurrency, at least 1).
int resolve_threads(int requested);


}  // namespace contactrom
