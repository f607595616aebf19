#pragma once
/// \file online_timing.hpp
/// \brief Timing of the online methods and of the FOM: per-query samples, medians,
/// and interleaved rounds whose ratios are reproducible on a loaded machine. For
/// `contactrom bench`, `verify --bench` and `hull-report --time`.
#include <vector>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/online_solver.hpp>

namespace contactrom::rom {

/// \brief Median online time per query.
struct OnlineTiming {
  double median_core_s = 0.0;   ///< median of OnlineResult::time_s (nonlinear operators included)
  double median_total_s = 0.0;  ///< median wall time of solve(), full-field reconstruction included
  /// Median of time_s − operator_time_s (the paper's timing convention: construction
  /// of the contact operators left out), when the solver measures operator_time_s
  /// (OnlineSolverOptions::time_operators); −1 otherwise.
  double median_without_operators_s = -1.0;
  int queries = 0;              ///< number of timed queries
};

/// \brief Per-query time samples of online passes, in seconds; `without` stays empty
/// unless the solver measures OnlineResult::operator_time_s.
struct OnlineSamples {
  std::vector<double> core, total, without;
  /// Medians of the samples so far.
  OnlineTiming timing() const;
};

/// \brief One timed pass of `solver` over `params` (no warm-up), appended to `out`.
void time_online_pass(const OnlineSolver& solver, const std::vector<fom::Param>& params, OnlineSamples& out);

/// \brief One timed pass of the FOM over `params` (no warm-up): per-query wall
/// times appended to `out`.
void time_fom_pass(const fom::ActiveSetSolver& solver, const std::vector<fom::Param>& params, std::vector<double>& out);

/// \brief Times `solver` over `params`, `repeats` times each (after one warm-up
/// pass), on the calling thread. For `contactrom bench` and docs/rom.md.
OnlineTiming time_online(const OnlineSolver& solver, const std::vector<fom::Param>& params, int repeats = 3);

/// \brief Median wall time per FOM query (factorisation reused: the solver is
/// built before timing), `repeats` passes over `params` after one warm-up query.
double time_fom(const fom::ActiveSetSolver& solver, const std::vector<fom::Param>& params, int repeats = 1);

/// \brief Medians of the FOM and of several online solvers timed in interleaved
/// rounds (see time_interleaved).
struct InterleavedTiming {
  double fom_median_s = 0.0;             ///< median FOM time per query over all rounds
  std::vector<double> fom_round_median_s;  ///< the FOM median of each round
  /// Per solver, in the order given; median_without_operators_s comes from its
  /// clocked twin (−1 without one).
  std::vector<OnlineTiming> online;
};

/// \brief Times the FOM (factorisation reused) and every solver in `solvers` over
/// `params`: one warm-up pass of each, then `rounds` rounds of one FOM pass followed
/// by one pass of every solver; medians over all rounds. A slow spell of the machine
/// then lands on all of them alike instead of on whichever was being timed, so
/// their ratios are reproducible. `clocked` is empty or holds, per solver, a twin
/// built with OnlineSolverOptions::time_operators (or null): it is timed in the same
/// rounds and gives that solver's median_without_operators_s, while the solver's own
/// times stay free of the clock reads. On the calling thread; `solvers` must not
/// hold null.
InterleavedTiming time_interleaved(const fom::ActiveSetSolver& fom, const std::vector<const OnlineSolver*>& solvers,
                                   const std::vector<fom::Param>& params, int rounds,
                                   const std::vector<const OnlineSolver*>& clocked = {});

/// \brief Median of a list of numbers (0 for an empty list).
double median(std::vector<double> values);

}  // namespace contactrom::rom
