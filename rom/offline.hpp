#pragma once
/// \file offline.hpp
/// \brief Offline stage: FOM snapshots at the training parameters, computed in
/// parallel, collected into a SnapshotDatabase.
///
/// Exact command line of the stage (see docs/rom.md):
/// \code
///   contactrom offline --problem hertz --train 30 --out hertz30.h5 --threads 2
///   contactrom offline --problem ironing --level 5 --out ironing5.h5
/// \endcode
///
/// Determinism: one fom::ActiveSetSolver (factorisation done once) is shared by
/// all worker threads; every parameter is solved from scratch (no warm start from
/// a neighbouring parameter) and its snapshot is written into the column
/// preassigned to it, so the arrays are bit-identical whatever the thread count
/// and scheduling. Only the timing fields differ between runs.
#include <chrono>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "fom/active_set_solver.hpp"
#include "fom/problem.hpp"
#include "rom/snapshot_database.hpp"

namespace contactrom::rom {

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

/// \brief Options of generate_snapshots (documented defaults).
struct OfflineOptions {
  int threads = 0;  ///< worker threads; ≤ 0: std::thread::hardware_concurrency(). Default 0.
  /// Label written as the `created_by` attribute. Default "contactrom 0.1.0".
  std::string created_by = "contactrom 0.1.0";
  ProgressCallback progress;  ///< called after every snapshot (optional)
};

/// \brief Computes the FOM snapshots of `problem` at `params` (in parallel; see the
/// file comment) and returns them as a database. Snapshots whose status is not
/// Success are kept (with their status) — the caller reports them, and the reduced
/// model leaves them out.
/// \param training_kind "train" or "level", \param training_size n, recorded in the
///   database so that `online` can rebuild the validation set.
SnapshotDatabase generate_snapshots(const fom::Problem& problem, const std::vector<fom::Param>& params,
                                    const std::string& training_kind, int training_size,
                                    const OfflineOptions& options = {});

/// \brief Same, with the training set selected by `n` as the problem expects
/// (fom::training_set(problem, n): `--train n` or `--level n` as its training plan says).
SnapshotDatabase generate_snapshots(const fom::Problem& problem, int n, const OfflineOptions& options = {});

/// \brief A one-line progress bar "label [#####.....] 17/30  42.1/s  ETA 0.3 s"
/// redrawn in place with a carriage return. It draws only when enabled (the CLI enables it
/// when stderr is a terminal or with --progress); finish() ends the line.
class ProgressBar {
 public:
  ProgressBar(std::ostream& out, std::string label, bool enabled);
  /// Redraws with `done` of `total` completed (throttled to ~20 redraws/s, and
  /// always drawn for the last one).
  void update(int done, int total);
  /// Ends the line (prints '\n') if anything was drawn.
  void finish();

 private:
  std::ostream& m_out;
  std::string m_label;
  bool m_enabled;
  bool m_drawn = false;
  std::chrono::steady_clock::time_point m_start, m_last;
};

}  // namespace contactrom::rom
