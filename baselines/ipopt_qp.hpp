#pragma once
/// \file ipopt_qp.hpp
/// \brief Reference FOM solver: the same QP as fom::ActiveSetSolver (sparse
/// Hessian K on the free dofs, linear constraints C u ≤ g, same lifting) solved
/// by Ipopt (interior point, Wächter & Biegler 2006) inside the same contact
/// pairing fixed-point loop. Used to cross-validate the custom active-set solver.
#include <memory>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/problem.hpp>

namespace contactrom::baselines {

/// \brief Options of IpoptQpSolver (documented defaults).
struct IpoptOptions {
  double tol = 1e-12;               ///< Ipopt `tol` (default 1e-12, tight for cross-validation)
  /// Ipopt `acceptable_tol`; also the NLP error up to which a stop at a tiny step
  /// (Search_Direction_Becomes_Too_Small: the round-off floor lies above `tol`, e.g. rope
  /// at large γ where \f$ \epsilon\,\|K\|\,\|u\| \approx 10^{-12} \f$) counts as success (default 1e-9).
  double acceptable_tol = 1e-9;
  /// Largest FOM stationarity, penetration and negative-pressure residual
  /// (fom/kkt.hpp, relative) of a solution reported as success. Ipopt's tolerances
  /// are absolute in its scaled problem: for a load near zero (hertz d = 1e-300) it
  /// reports success with a stationarity residual of 1e278 relative to the load; such
  /// a solution is reported as no_convergence with its residuals. Normal queries stay
  /// below 1e-12 (default 1e-6).
  double kkt_tolerance = 1e-6;
  /// Ipopt `mu_min`, the smallest barrier parameter. Ipopt's 1e-11 leaves multipliers
  /// ≈ 1e-11 / slack on inactive rows, enough to flip the active set of nodes that barely
  /// separate; 1e-16 drives them to round-off (default 1e-16).
  double mu_min = 1e-16;
  int max_iterations = 3000;        ///< Ipopt `max_iter` per QP solve (default 3000)
  int print_level = 0;              ///< Ipopt `print_level`; 0 with `sb = yes` silences Ipopt (default 0)
  int max_pairing_iterations = 300;  ///< cap of the pairing fixed point (default 300)
  /// Stopping tolerance of the pairing fixed point, as in fom::ActiveSetSolver
  /// (fom::pairing_change(), on the rows whose pressure exceeds active_tolerance times
  /// the largest) (default 1e-12).
  double pairing_tolerance = 1e-12;
  /// Anderson acceleration depth of the pairing fixed point, as in fom::ActiveSetSolver
  /// (0: plain iteration, whose rate is ≈ 0.8 on `hertz` d = 0.3) (default 5).
  int anderson_depth = 5;
  /// Warm-start each QP of the pairing loop (and the first one, when `warm` is given) from
  /// the previous primal–dual point; cuts Ipopt's iterations per pairing step from ≈12 to 1–3 (default true).
  bool warm_start = true;
  /// Ipopt `warm_start_bound_push`, `warm_start_mult_bound_push`, `warm_start_slack_bound_push`
  /// and `mu_init` of a warm start (default 1e-9).
  double warm_start_push = 1e-9;
  /// A row counts as active (FomSolution::active) when \f$ \lambda_s > \f$ active_tolerance
  /// \f$ \cdot \max_s \lambda_s \f$ and its gap is at most active_tolerance times the
  /// problem's displacement scale: an interior-point method leaves tiny positive
  /// multipliers (≈ barrier parameter / slack) on inactive rows (default 1e-8).
  double active_tolerance = 1e-8;
};

/// \brief Ipopt solver of the FOM contact QP. Ipopt's status maps to
/// contactrom::Status (Solve_Succeeded/Solved_To_Acceptable_Level → Success,
/// Maximum_Iterations_Exceeded → NoConvergence, others → NumericalIssue) and its
/// constraint multipliers are returned as pressures. Maximum_CpuTime_Exceeded also
/// maps to NoConvergence. On failure the message names Ipopt's status and the KKT
/// residuals (fom/kkt.hpp) of the returned last iterate.
///
/// Each QP solve creates its own IpoptApplication. solve() is const and may be called
/// from several threads, but the Ipopt calls are serialised by a process-wide mutex
/// (Ipopt 3.11 with sequential MUMPS is not known to be re-entrant).
///
/// Variables are the free dofs of \f$ u_0 \f$ (\f$ u = u_{lift}(\mu) + u_0 \f$); the objective
/// \f$ \tfrac12 u_0^T K_{ff} u_0 - f_f^T u_0 \f$ has the constant Hessian \f$ K_{ff} \f$ (lower
/// triangle), the constraints are \f$ C_{\cdot f}\, u_{0,f} \le g - C u_{lift} \f$ for paired
/// rows touching a free dof; other rows are dropped and get \f$ \lambda_s = 0 \f$. The pairing
/// fixed point is the active-set solver's (fom/pairing_fixed_point.hpp: Anderson-accelerated,
/// one stopping test); it starts from the unconstrained solution (or from `warm`).
class IpoptQpSolver final : public fom::FullOrderSolver {
 public:
  explicit IpoptQpSolver(const fom::Problem& problem, IpoptOptions options = {});
  ~IpoptQpSolver() override;
  /// \brief Solves at `mu` (range-checked). Never throws on numerical failure:
  /// the status and message of the returned solution say what happened.
  fom::FomSolution solve(const fom::Param& mu, const fom::FomSolution* warm = nullptr) const override;
  /// Time spent in the constructor extracting the constant \f$ K_{ff} \f$ (0 for rope's μ-dependent K).
  double setup_time() const override;
  const IpoptOptions& options() const;

 private:
  struct Impl;
  class Query;  // one solve: the starting point, the Ipopt solve per pairing, the wrap-up
  std::unique_ptr<Impl> m_impl;
};

/// \brief The full-order solver `name` of `problem`: "active-set" (fom::ActiveSetSolver,
/// contactrom's own) or "ipopt" (IpoptQpSolver, the reference).
/// \throws InputError "solver '<name>' unknown; expected active-set or ipopt" otherwise.
std::unique_ptr<fom::FullOrderSolver> make_fom_solver(const fom::Problem& problem, const std::string& name);

}  // namespace contactrom::baselines
