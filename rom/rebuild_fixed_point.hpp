#pragma once
/// \file rebuild_fixed_point.hpp
/// \brief The outer loop of the online active-set methods: the fixed point
/// x ↦ û(x), û(x) the reduced solution on the contact operators built at x
/// (docs/rom.md, "The fixed-point schedule"). The greedy's default schedule
/// (rom::GreedyActiveSet) and the baselines' primal–dual active set
/// (baselines::ReducedActiveSet: CPG and the full dictionary) run this one loop and
/// differ only in the solve on the frozen operators, so they are compared on the
/// same iteration.
///
/// Algorithm, from a starting point x:
///  1. build the contact operators at x (surface rows only); where x is the û of the
///     last solve, test û at this, its own, pairing (penetration and separation under
///     pressure within the contact tolerances): converged if it passes, or if it
///     failed already at the previous point — a fixed point of the reduced problem
///     that iterating cannot improve (the full-order check then reports it);
///  2. û(x): the method's exact solve on the frozen operators;
///  3. if the contact surface moved by at most `surface_step` (units of U) from x,
///     x = û (tested in step 1); else x = the method's extrapolation of x ↦ û(x)
///     (Anderson, one history over the query).
/// At most `max_rebuilds` rebuilds and `max_solves` solves.
#include <Eigen/Dense>
#include <ostream>

namespace contactrom::rom {

/// \brief How far the contact surface moved: \f$ \|u_s' - u_s\|_\infty / U \f$, U the
/// problem's displacement scale (the loop's step test).
inline double surface_step(const Eigen::VectorXd& moved, const Eigen::VectorXd& from, double scale) {
  return (moved.size() > 0 ? (moved - from).lpNorm<Eigen::Infinity>() : 0.0) / scale;
}

/// \brief The caps and the step test of run_rebuild_fixed_point().
struct RebuildLimits {
  int max_rebuilds = 0;       ///< cap on the operator rebuilds
  int max_solves = 0;         ///< cap on the solves on frozen operators, over all rebuilds
  double surface_step = 0.0;  ///< x = û once the surface moved by at most this (units of U)
};

/// \brief How run_rebuild_fixed_point() ended.
enum class RebuildOutcome {
  Converged,  ///< û passed the test at its own pairing, or failed it twice in a row
  AtCap,      ///< a cap of RebuildLimits was reached first
  NonFinite   ///< a solve on frozen operators produced a non-finite value
};

/// \brief Runs the loop of the file comment on `loop`, which provides
///  - `void rebuild(bool at_u_hat)`: the operators at x (at_u_hat: x is the last û);
///  - `bool physically_converged()`: the test of û at the operators just built;
///  - `int solves() const`: the solves on frozen operators so far;
///  - `bool solve_frozen(int rebuild)`: û(x) on the frozen operators (false: non-finite);
///  - `double step()`: how far û moves the contact surface from x (surface_step());
///  - `void accept()`: x = û; `void extrapolate()`: x = the extrapolation of x ↦ û(x).
/// \param trace when set, one line per rebuild: "<name> rebuild=k surface step=s U"
template <class Loop>
RebuildOutcome run_rebuild_fixed_point(Loop& loop, const RebuildLimits& limits, std::ostream* trace = nullptr,
                                       const char* name = "") {
  bool pending = false;      // x is the last û: to be tested at its own pairing
  bool failed_test = false;  // the previous û failed that test
  for (int rebuild = 0;; ++rebuild) {
    // 1. Operators at x; where x = û, the test at û's own pairing.
    loop.rebuild(pending);
    if (pending) {
      if (loop.physically_converged() || failed_test) return RebuildOutcome::Converged;
      failed_test = true;
    } else {
      failed_test = false;
    }
    if (rebuild >= limits.max_rebuilds || loop.solves() >= limits.max_solves) return RebuildOutcome::AtCap;
    // 2. û(x) on the frozen operators.
    if (!loop.solve_frozen(rebuild)) return RebuildOutcome::NonFinite;
    // 3. The next point: û once the step is within the basis' resolution, else the extrapolation.
    const double step = loop.step();
    if (trace) *trace << name << " rebuild=" << rebuild << " surface step=" << step << " U\n";
    pending = step <= limits.surface_step;
    if (pending)
      loop.accept();
    else
      loop.extrapolate();
  }
}

}  // namespace contactrom::rom
