#pragma once
/// \file parallel_for.hpp
/// \brief A minimal thread pool: `task(i)` for i = 0..n-1 on worker threads, with
/// progress reported from the calling thread.
#include <functional>
#include <string>

namespace contactrom {

/// \brief Called after each completed task with (completed, total); calls are
/// serialised (never concurrent) and come from the thread that called the
/// parallel function.
using ProgressCallback = std::function<void(int done, int total)>;

/// \brief Runs `task(i)` for i = 0..n-1 on `threads` worker threads (≤ 0: the
/// hardware concurrency; never more threads than tasks). Tasks are handed out in
/// increasing order from a shared counter. The first exception thrown by a task, or
/// by `progress` (a way to stop the run), is rethrown after all workers have
/// stopped (the remaining tasks are skipped; the running ones finish).
void parallel_for(int n, int threads, const std::function<void(int)>& task, const ProgressCallback& progress = {});

/// \brief As parallel_for(), but the items come in chains of `chain` consecutive ones
/// (items c·chain … (c+1)·chain − 1; the last chain may be shorter), each run by
/// one worker in increasing order, so that an item may start from its predecessor's
/// result; the chains are handed out in increasing order. `progress` still counts
/// items, and a failure or a throwing `progress` stops every chain before its next
/// item. chain ≤ 1: parallel_for().
void parallel_for_chains(int n, int chain, int threads, const std::function<void(int)>& task,
                         const ProgressCallback& progress = {});

/// \brief Number of worker threads `requested` resolves to (≤ 0: hardware concurrency, at least 1).
int resolve_threads(int requested);

/// \brief Largest thread count a user may ask for (CLI `--threads`, Python `threads=`).
inline constexpr int kMaxThreads = 1024;

/// \brief Checks a thread count a user gave: 0 (all cores) or 1..kMaxThreads.
/// \param what how the value is named in the message (`--threads`, `threads`)
/// \throws InputError "<what> = <threads> invalid; expected an integer in [0, 1024] (0: all cores)".
void check_threads(long long threads, const std::string& what);


}  // namespace contactrom
