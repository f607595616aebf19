#pragma once
/// \file pairing_fixed_point.hpp
/// \brief The contact pairing fixed point shared by the FOM solvers
/// (fom::ActiveSetSolver, baselines::IpoptQpSolver) and the convex-hull ROM
/// (rom::ConvexHullSolver): the constraint operator
/// \f$ C(u), g(u) \f$ of node-to-segment contact depends on the deformed
/// configuration, so the QP "minimise the energy subject to \f$ C u_s \le g \f$" is
/// solved at a fixed pairing and the pairing is recomputed from its solution until
/// it no longer changes the problem.
///
/// Algorithm, on the surface displacement \f$ x \f$ (n_s):
///  1. pair at \f$ x \f$ (ContactModel::search_rows, seeded by the previous
///     pairing, with a SearchMemory of the loop's searches) and assemble \f$ C, g \f$;
///  2. solve at that pairing (the caller's exact QP solve) →
///     \f$ \lambda \f$ and the surface displacement \f$ F(x) \f$ of the solution;
///  3. re-pair at \f$ F(x) \f$ → \f$ C', g' \f$ and stop when the KKT system of the
///     solution is unchanged (pairing_change() ≤ `tolerance`);
///  4. otherwise, when the caller supplies a zone step (the FOM:
///     fom/contact_zone.hpp) and the change is at most `zone_start`: the next pairing
///     is the one the step proposes, for as long as each proposal reduces the change;
///     after one that does not, Anderson steps until the change is below `zone_retry`
///     times its value there, then zone steps again;
///  5. otherwise \f$ x \leftarrow \f$ Anderson mixing of \f$ x, F(x) \f$
///     (AndersonMixer, Walker & Ni 2011, type II, depth `anderson_depth`) and go to 1;
///     a solve that reports PairedSolution::map_changed (a reduced solver changed
///     the columns it solves on, so F itself changed) drops the history first.
///
/// The QP is always solved exactly: the extrapolated \f$ x \f$ only chooses the
/// pairing, so a converged result is a KKT point of its own pairing whatever the
/// acceleration did (for the convex-hull ROM: an exact projected solve, α on the
/// simplex). Models without pairing (obstacles) take one solve.
///
/// Stopping test (pairing_change()): with \f$ v = (C u_s - g)/w \f$ and
/// \f$ v' = (C' u_s - g')/w \f$ the gaps per tributary length w under the old and new
/// pairing, U the problem's displacement scale,
/// \f[ r = \max\Big( \frac{\|C'^T\lambda - C^T\lambda\|}{\|C^T\lambda\|},\;
///     \max_{s \in A} \frac{|v'_s - v_s|}{U},\; \max_s \frac{\max(v'_s, 0)}{U} \Big), \f]
/// A the paired rows that carry pressure (\f$ \lambda_s > 0 \f$) or are within
/// tolerance·U of contact (a row without a pair is no contact, whatever gap the new
/// pairing gives it): the contact forces, the gaps that matter and the
/// penetration must each be unchanged to `tolerance` (relative).
///
/// The penetration term asks more than an unchanged pairing: that the solution be
/// feasible under the new pairing, which an exact QP solution is (to rounding) once
/// its pairing has settled. A reduced solution is not: a convex combination of
/// snapshots computed with other pairings penetrates slightly (hertz: up to 4e-5 U)
/// whatever its pairing, so with the term the test could never pass. Such callers
/// set PairingFixedPointOptions::penetration = false: the test then measures only
/// what re-pairing changes — forces and gaps — with the same meaning of `tolerance`.
#include <Eigen/Dense>
#include <limits>
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>

#include <contactrom/core/anderson.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/contact_model.hpp>

namespace contactrom::fom {

/// \brief Options of solve_pairing_fixed_point() (documented defaults).
struct PairingFixedPointOptions {
  int max_iterations = 300;   ///< cap on the solves (pairing iterations). Default 300.
  double tolerance = 1e-12;   ///< stop when pairing_change() ≤ this (relative). Default 1e-12.
  int anderson_depth = 10;    ///< Anderson depth (0: plain fixed-point iteration). Default 10.
  /// Clear the Anderson history whenever the change |F(x) − x| grows. Default true.
  bool anderson_restart = true;
  /// Whether the penetration under the new pairing is part of pairing_change() (see
  /// the file comment): true for exact solves, false for reduced solutions, which
  /// penetrate slightly whatever their pairing. Default true.
  bool penetration = true;
  /// Zone steps (when the caller supplies them) once pairing_change() is at most
  /// this; 0: never. Default 0.3 (from farther away the rows in contact and their
  /// segments still change; the Anderson iterates get there in a few steps).
  double zone_start = 0.3;
  /// After a zone step whose proposal did not reduce the change, zone steps resume
  /// once Anderson steps bring the change below this fraction of its value there; 0:
  /// Anderson for the rest of the solve. Default 0.5.
  double zone_retry = 0.5;
};

/// \brief What the solve at a fixed pairing returns to the fixed point.
struct PairedSolution {
  Status status = Status::Success;         ///< anything but Success stops the fixed point
  Eigen::VectorXd surface_displacement;    ///< \f$ F(x) \f$: u on the surface dofs at the solution (n_s)
  Eigen::VectorXd lambda;                  ///< pressure per constraint row (n_c); > 0 marks the rows that carry force
  /// The solve's map x ↦ F(x) changed since the previous solve (a reduced solver
  /// changed the columns it solves on): the Anderson history is dropped, and the
  /// next iterate is F(x) itself. Exact solvers leave it false.
  bool map_changed = false;
};

/// \brief Outcome of solve_pairing_fixed_point().
struct PairingFixedPointResult {
  /// Success when pairing_change() ≤ tolerance, NoConvergence at the cap, else the
  /// status of the failing solve (solution.status then says which solve failed:
  /// it is Success when the cap was reached).
  Status status = Status::Success;
  int iterations = 0;  ///< solves done
  /// pairing_change() of the last iterate (0 without pairing, ∞ if a solve failed first).
  double residual = std::numeric_limits<double>::infinity();
  /// The pairing the last solution was computed with; c, g, solution and residual
  /// all belong to it (also at the cap).
  Pairing pairing;
  ConstraintMatrix c;        ///< its constraint operator
  Eigen::VectorXd g;         ///< its gap offsets
  PairedSolution solution;   ///< the last solve's result
};

/// \brief The stopping test of the pairing fixed point (see the file comment):
/// how much re-pairing at `u_s` (constraint operator `c_next`, `g_next`) changes the
/// KKT system of the solution `u_s`, `lambda` computed with `c`, `g`; relative.
/// \param weights tributary length per row (ContactModel::weights())
/// \param u_scale displacement scale U of the problem
/// \param tolerance rows within tolerance·U of contact count as touching
/// \param penetration include the term \f$ \max_s \max(v'_s, 0)/U \f$ (PairingFixedPointOptions::penetration)
double pairing_change(const ConstraintMatrix& c, const Eigen::VectorXd& g, const ConstraintMatrix& c_next,
                      const Eigen::VectorXd& g_next, const Eigen::VectorXd& u_s, const Eigen::VectorXd& lambda,
                      const Eigen::VectorXd& weights, double u_scale, double tolerance, bool penetration = true);

/// \brief Runs the pairing fixed point (see the file comment) from the surface
/// displacement `x` and its pairing `pairing`.
/// \param solve_at `PairedSolution(const Pairing&, const ConstraintMatrix& c, const
///   Eigen::VectorXd& g, const Eigen::VectorXd& x)`: the exact solve at the pairing
///   whose operator is c, g; x is the iterate the pairing was computed from.
/// \param zone_step optional `bool(const PairedSolution& solution, const Pairing& next,
///   const SearchMemory& memory, Pairing& out)`: the pairing proposed from the last
///   solution, whose re-pairing is `next`, the searches starting from the loop's
///   `memory` (false: no proposal this time); nullptr: Anderson steps only.
/// \param memory the searches' memory to start from (a caller that searched near x
///   already: the first re-pairing is then settled from it, not searched in full);
///   default empty. The pairings found are the same either way.
template <class SolveAtPairing, class ZoneStep = std::nullptr_t>
PairingFixedPointResult solve_pairing_fixed_point(const ContactModel& contact, double u_scale, Eigen::VectorXd x,
                                                  Pairing pairing, const PairingFixedPointOptions& options,
                                                  SolveAtPairing&& solve_at, ZoneStep&& zone_step = nullptr,
                                                  SearchMemory memory = {}) {
  PairingFixedPointResult out;
  AndersonMixer mixer(options.anderson_depth, options.anderson_restart);
  ConstraintMatrix c_next;
  Eigen::VectorXd g_next;
  Pairing next;
  // The iterates move less and less: the memory settles most rows of the two
  // searches per iteration without searching the whole master chain, with the
  // full search's result.
  bool assembled = false;  // out.c, out.g already hold the operator of `pairing`
  const bool zone_on = options.zone_start > 0.0;
  // Change when the last proposal was taken; after one that did not reduce it, the
  // change below which zone steps resume (`waiting`).
  double zone_change = std::numeric_limits<double>::infinity();
  bool waiting = false;
  Pairing proposal;
  out.status = Status::NoConvergence;
  for (int it = 0; it < options.max_iterations; ++it) {
    ++out.iterations;
    if (!assembled) contact.assemble(pairing, out.c, out.g);
    out.solution = solve_at(pairing, out.c, out.g, x);
    out.pairing = pairing;
    if (out.solution.status != Status::Success) {
      out.status = out.solution.status;
      return out;
    }
    if (!contact.has_pairing()) {
      out.residual = 0.0;
      out.status = Status::Success;
      return out;
    }
    const Eigen::VectorXd& f = out.solution.surface_displacement;
    contact.search_rows(f, nullptr, &pairing, memory, next);
    contact.assemble(next, c_next, g_next);
    out.residual = pairing_change(out.c, out.g, c_next, g_next, f, out.solution.lambda, contact.weights(), u_scale,
                                  options.tolerance, options.penetration);
    if (out.residual <= options.tolerance) {
      out.status = Status::Success;
      return out;
    }
    // At the cap, out keeps the last solve's pairing, operator and solution: the
    // next pairing is not built into it.
    if (it + 1 == options.max_iterations) break;
    if constexpr (!std::is_same_v<std::decay_t<ZoneStep>, std::nullptr_t>) {
      if (zone_on && out.residual <= options.zone_start) {
        bool step = out.residual < zone_change;
        // The last proposal did not reduce the change: Anderson until it falls below
        // zone_retry times its value here (never, with zone_retry 0).
        if (!step && !waiting) zone_change = options.zone_retry * out.residual;
        waiting = !step;
        if (step && zone_step(out.solution, next, memory, proposal)) {
          zone_change = out.residual;
          x = f;
          std::swap(pairing, proposal);
          assembled = false;
          mixer.clear();
          continue;
        }
      }
    }
    if (out.solution.map_changed) mixer.clear();
    x = mixer.next(x, f);
    assembled = x == f;
    if (assembled) {  // a plain step (no history yet): the pairing and operator at f are built
      std::swap(pairing, next);
      std::swap(out.c, c_next);
      std::swap(out.g, g_next);
    } else {
      contact.search_rows(x, nullptr, &next, memory, pairing);
    }
  }
  return out;
}

/// \brief The message of a fixed point that reached its cap: "contact pairing did
/// not settle in N fixed-point iterations (last change r > tolerance t)".
std::string pairing_no_convergence_message(const PairingFixedPointResult& result,
                                           const PairingFixedPointOptions& options);

}  // namespace contactrom::fom
