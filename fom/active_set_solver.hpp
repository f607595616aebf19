#pragma once
/// \file active_set_solver.hpp
/// \brief The production FOM solver: contact pairing fixed point around a
/// condensed primal–dual active-set QP solve.
///
/// Algorithm (docs/theory.md §2):
///  1. Offline per stiffness: factorise K_ff once (CHOLMOD, SparseCholesky) with the
///     contact-surface dofs eliminated last, and condense onto the contact surface:
///     \f$ S = E_s^T K^{-1} E_s \f$ is read from the factor's trailing block (no
///     dense dofs x surface matrix is formed), plus the unconstrained solutions of
///     the affine load terms. Setup time and memory grow like the factorisation and
///     \f$ n_s^2 \f$. For `hertz`/`ironing` this happens once in the constructor
///     and is reused for every parameter.
///  2. Per query: \f$ u_0(\mu) \f$ unconstrained; loop { pairing from u (deformed
///     configuration) → \f$ C, g \f$ → Delassus \f$ G = C S C^T \f$,
///     \f$ h = C u_{0,s} - g \f$ → dual QP (DualQpSolver) →
///     \f$ u_s = u_{0,s} - S C^T\lambda \f$ } until re-pairing no longer changes the KKT system;
///     then \f$ u = u_0 - K^{-1} E_s C^T \lambda \f$ (one solve with the factor).
///     The dual QP runs on a working set W of rows (active, or within
///     working_set_margin·U of contact at the current iterate): G_W = C_W S C_Wᵀ,
///     then rows outside W that penetrate join W and the QP is solved again, so λ
///     is the QP solution of all rows at a cost set by |W|. The pairing fixed point
///     (fom/pairing_fixed_point.hpp) is Anderson-accelerated; each search is seeded
///     by the previous pairing.
/// solve() is const and thread-safe (no factorisation state is touched per query
/// when the stiffness is parameter-independent).
#include <Eigen/Dense>
#include <functional>
#include <memory>
#include <vector>

#include <contactrom/core/parallel_for.hpp>
#include <contactrom/fom/contact_model.hpp>
#include <contactrom/fom/dual_qp.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/pairing_fixed_point.hpp>
#include <contactrom/fom/contact_zone.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/fom/sparse_cholesky.hpp>

namespace contactrom::fom {

/// \brief Solution of one FOM query.
struct FomSolution {
  Param mu;                 ///< parameter
  Eigen::VectorXd u;        ///< full displacement, lifting included
  Eigen::VectorXd lambda;   ///< contact pressure per constraint row (≥ 0)
  Pairing pairing;          ///< pairing of the final constraint operator
  Status status = Status::Success;
  int iterations = 0;          ///< active-set iterations, summed over the pairing loop
  int pairing_iterations = 0;  ///< pairing fixed-point iterations (solves of every row)
  /// solves of the contact zone alone within them (fom/contact_zone.hpp), summed
  int zone_iterations = 0;
  int active = 0;              ///< number of rows with λ > 0
  double time_s = 0.0;         ///< wall time of the query (factorisation reused)
  std::string message;         ///< reason when status != Success
  /// KKT residuals of (u, λ) (fom::kkt_residuals(), pairing recomputed from u), as
  /// certify_fom_solution() left them; all zero if no solution was computed.
  KktResiduals kkt;
};

/// \brief Largest relative KKT residual (fom/kkt.hpp) of a FOM solution reported as
/// success: stationarity, penetration, negative pressure and (active-set solver)
/// complementarity. Converged solves stay below 1e-10.
constexpr double kFomKktTolerance = 1e-6;

/// \brief The FOM's promise on its status: computes `sol.kkt` with
/// fom::kkt_residuals(), which re-pairs at `sol.u` as a user checking the answer
/// would, and turns a Success whose stationarity, penetration or negative-pressure
/// residual (and complementarity, when `complementarity`) is above `tolerance` or not
/// a number into NoConvergence, with a message naming the residual. A solution
/// without fields (failed solve) is left as it is.
void certify_fom_solution(const Problem& problem, FomSolution& sol, double tolerance = kFomKktTolerance,
                          bool complementarity = true);

/// \brief A full-order solver of a problem: contactrom's active set (ActiveSetSolver)
/// or the Ipopt reference (baselines::IpoptQpSolver; baselines::make_fom_solver builds
/// either by name). solve() is const and thread-safe.
class FullOrderSolver {
 public:
  virtual ~FullOrderSolver() = default;
  /// \brief Solves the contact problem at `mu` (checked against the range); never
  /// throws on a numerical failure: the status and message say what happened.
  /// \param warm optional previous solution that may seed the iteration
  virtual FomSolution solve(const Param& mu, const FomSolution* warm = nullptr) const = 0;
  /// Time spent in the constructor (factorisation, condensation, extraction of K).
  virtual double setup_time() const = 0;
};

/// \brief Options of ActiveSetSolver (documented defaults).
struct ActiveSetOptions {
  int max_pairing_iterations = 300;  ///< cap of the pairing fixed point, default 300
  /// The pairing loop stops when re-pairing at the current solution changes the
  /// contact forces Cᵀλ (relative to |Cᵀλ|), the gaps of active rows and the
  /// penetration (relative to the displacement scale) by at most this
  /// (fom::pairing_change()); default 1e-12.
  double pairing_tolerance = 1e-12;
  /// The dual QP is solved on a working set: rows active or with a gap above
  /// −margin·U at the current iterate (U: displacement scale), grown until no
  /// other row penetrates; the result is the QP solution on all rows. < 0: all
  /// rows. Default 0.05.
  double working_set_margin = 0.05;
  int anderson_depth = 10;          ///< Anderson acceleration depth of the pairing fixed point (0: plain), default 10
  /// Clear the Anderson history when the pairing change grows. Default false: the
  /// early iterates of a sliding contact jump (ironing: 16.2 → 14.1 mean pairing
  /// iterations with the history kept; hertz never grows and is unchanged).
  bool anderson_restart = false;
  /// Steps on the contact zone alone (fom/contact_zone.hpp; 2D node-to-segment
  /// contact) once the pairing change is at most this; 0: Anderson steps only.
  /// Default 0.3.
  double zone_start = 0.3;
  /// After a zone step whose proposal did not reduce the pairing change, zone steps
  /// resume once Anderson steps bring it below this fraction of its value there; 0:
  /// Anderson for the rest of the solve. Default 0.5.
  double zone_retry = 0.5;
  ContactZoneOptions zone;  ///< options of the zone's steps (Anderson or Newton, tolerance)
  /// Largest relative KKT residual of a solution reported as success
  /// (certify_fom_solution()); default kFomKktTolerance = 1e-6.
  double kkt_tolerance = kFomKktTolerance;
  DualQpOptions qp;                 ///< options of the dual QP solve
};

/// \brief Condensed operators of one stiffness matrix (see file comment).
struct Condensation {
  std::unique_ptr<SparseCholesky> factor;  ///< K_ff, the free surface dofs eliminated last
  std::vector<int> free_dofs;              ///< the problem's free dofs (rows of the factor)
  std::vector<int> surface_position;       ///< per surface dof: its index in the factor's trailing set (−1: Dirichlet)
  Eigen::MatrixXd s;       ///< E_sᵀ K⁻¹ E_s, n_s x n_s (zero rows/columns for Dirichlet surface dofs)
  Eigen::MatrixXd z_load;  ///< unconstrained solution of each load term (lifting included), n x n_terms

  /// \brief \f$ K^{-1} E_s f_s \f$ on all n dofs (zero on Dirichlet dofs): the
  /// displacement of the surface forces `surface_force` (n_s), by one solve.
  Eigen::VectorXd surface_response(const Eigen::VectorXd& surface_force) const;
};

/// \brief Factorises K(μ) (CHOLMOD) and builds the condensation for `problem`.
/// \param order elimination order of the free dofs to reuse (SparseCholesky::
///   permutation() of an earlier condensation of the same problem), or nullptr to
///   compute a fill-reducing one.
/// Returns false (and leaves `out` untouched) if the factorisation fails.
bool condense(const Problem& problem, const Param& mu, Condensation& out, const std::vector<int>* order = nullptr);

/// \brief The unconstrained solution of each load term at `mu`, lifting included
/// (Condensation::z_load, n x n_terms): column k is
/// \f$ L_k + K_{ff}^{-1}(f_{ext,k} - K L_k)_f \f$, the harmonic lifting of the
/// reduced model. \throws InputError if K(μ) is singular on the free dofs.
Eigen::MatrixXd unconstrained_load_responses(const Problem& problem, const Param& mu);

/// \brief The FOM's dual QP of one pairing, as solve() runs it inside its pairing
/// loop (working set, warm start, rows outside the working set checked at the
/// solution): the exact condensed problem at the fixed pairing whose operator is
/// `c`, `g`, from the iterate `x_s` (surface displacement choosing the working set)
/// and the multipliers `lambda_start`. Mesh-size free: it touches S and the surface
/// only. Used by the reduced models' error estimate (rom/error_indicator.hpp).
/// \param u0_s unconstrained displacement on the surface dofs
/// \param iterations incremented by the QP's active-set iterations
PairedSolution solve_at_pairing(const Problem& problem, const Condensation& cond, const ActiveSetOptions& options,
                                const Eigen::VectorXd& u0_s, const Pairing& pairing, const ConstraintMatrix& c,
                                const Eigen::VectorXd& g, const Eigen::VectorXd& x_s,
                                const Eigen::VectorXd& lambda_start, int& iterations);

/// \brief The pairing fixed point options of the FOM's ActiveSetOptions (cap,
/// tolerance, Anderson depth and restart, zone start and retry).
PairingFixedPointOptions pairing_options(const ActiveSetOptions& options);

/// \brief The FOM's pairing loop, as solve() runs it: the pairing fixed point
/// (fom/pairing_fixed_point.hpp, Anderson steps and the contact zone's steps,
/// fom/contact_zone.hpp) around
/// the working-set dual QP of each pairing, from the surface displacement `x_s`
/// paired at `pairing` and the multipliers `lambda_start`, capped by
/// `fixed_point.max_iterations`. Mesh-size free (S and the surface only). Used by
/// solve() and by the reduced models' error estimate (rom/error_indicator.hpp),
/// which starts it from a reduced answer.
/// \param u0_s unconstrained displacement on the surface dofs
/// \param iterations incremented by the QPs' active-set iterations
/// \param memory memory of a search made near x_s (the one that found `pairing`), or
///   nullptr: the loop's searches start from it (same pairings, less searching)
/// \param zone_iterations incremented by the solves of the contact zone's steps, or nullptr
PairingFixedPointResult solve_pairing_loop(const Problem& problem, const Condensation& cond,
                                           const ActiveSetOptions& options,
                                           const PairingFixedPointOptions& fixed_point, const Eigen::VectorXd& u0_s,
                                           const Eigen::VectorXd& x_s, Pairing pairing,
                                           const Eigen::VectorXd& lambda_start, int& iterations,
                                           const SearchMemory* memory = nullptr, int* zone_iterations = nullptr);

/// \brief What ActiveSetSolver::solve_contact() leaves for ActiveSetSolver::finish():
/// a query's answer on the contact surface, before its displacement.
struct ContactAnswer {
  FomSolution solution;  ///< λ, pairing, status and counts; u, active and kkt are finish()'s
  /// u_s − u0_s on the surface dofs (u0: the unconstrained solution at its parameter):
  /// the contact response a neighbouring parameter's solve starts from
  Eigen::VectorXd response_s;
  ConstraintMatrix c;  ///< the constraint operator of its pairing
};

/// Length of the continuation chains of solve_in_chains() (the offline stage's
/// default, rom::OfflineOptions::chain).
constexpr int kDefaultChain = 8;

/// \brief Custom active-set FOM solver; see the file comment.
class ActiveSetSolver final : public FullOrderSolver {
 public:
  explicit ActiveSetSolver(const Problem& problem, ActiveSetOptions options = {});

  /// \brief Solves the contact problem at `mu` (checked against the range).
  /// \param warm optional previous solution, at this or another parameter (a
  ///   neighbour): the iteration starts from its multipliers and from its contact
  ///   response u − u0 (u0: the unconstrained solution at its parameter) added to
  ///   this parameter's u0. The answer is the same fixed point, to the pairing
  ///   tolerance: the start changes the path, so not the last bits.
  FomSolution solve(const Param& mu, const FomSolution* warm = nullptr) const override;

  /// \brief solve() in two steps, so that the displacements of several queries take
  /// one back-substitution with several right-hand sides, cheaper per query than one
  /// each (hertz refine 2: 1.3 against 5.3 ms with 8): solve_contact() answers on the
  /// contact surface, from scratch or from a neighbour's answer `previous` (as solve()'s
  /// warm start does), and finish() computes the displacements and certificates of
  /// `answers` together. A parameter-dependent stiffness has a factorisation per query:
  /// there solve_contact() finishes the query itself.
  ContactAnswer solve_contact(const Param& mu, const ContactAnswer* previous = nullptr) const;
  /// \brief The solutions of `answers` (see solve_contact()), in their order.
  std::vector<FomSolution> finish(std::vector<ContactAnswer> answers) const;

  /// \brief The query at a known pairing: the unconstrained solution, one assembly of
  /// C, one dual QP on its working set (chosen at the surface displacement `x_s`),
  /// one back-substitution and the certificate, without the pairing fixed point. With
  /// a solution's own pairing and surface displacement it reproduces that solution;
  /// its time is the limit a query's pairing loop is measured against (`contactrom
  /// bench`, key `fom_limit`). Needs a parameter-independent stiffness (else
  /// InvalidInput).
  FomSolution solve_at(const Param& mu, const Pairing& pairing, const Eigen::VectorXd& x_s) const;

  /// Time spent in the constructor: factorising and condensing when K is constant,
  /// ordering the dofs for the per-query factorisations otherwise (rope).
  double setup_time() const override { return m_setup_time; }
  const Problem& problem() const { return m_problem; }

 private:
  /// The pairing loop at `mu` with `cond`, from the unconstrained solution plus a
  /// neighbour's contact response `response_s` on the surface dofs (nullptr: none) and
  /// the multipliers `lambda` (nullptr: zero).
  ContactAnswer contact_answer(const Condensation& cond, const Param& mu, const Eigen::VectorXd* response_s,
                               const Eigen::VectorXd* lambda) const;
  /// u = u0 − K⁻¹ E_s Cᵀλ of every answer (one back-substitution for all), certified
  /// (certify_fom_solution()); adds the time to each answer's time_s.
  std::vector<FomSolution> finish(const Condensation& cond, std::vector<ContactAnswer> answers) const;

  const Problem& m_problem;
  ActiveSetOptions m_options;
  std::unique_ptr<Condensation> m_constant;  // set when K does not depend on μ
  std::vector<int> m_order;  // otherwise: elimination order reused by every query's factorisation
  double m_setup_time = 0.0;
};

/// \brief Solves `params` in continuation chains of `chain` consecutive ones on
/// `threads` worker threads (core/parallel_for.hpp's parallel_for_chains): each chain's
/// first parameter from scratch, each next one from its predecessor's answer
/// (ActiveSetSolver::solve_contact), and the chain's displacements by one
/// back-substitution (ActiveSetSolver::finish). `store(i, solution)` receives every
/// solution, from the worker thread that finished its chain (each i once; calls for
/// distinct i may run concurrently). The solutions are the same for any `threads`.
/// \param progress counts the parameters whose contact answer is done (parallel_for's
///   contract: from the calling thread; a throw stops the run)
void solve_in_chains(const ActiveSetSolver& solver, const std::vector<Param>& params, int chain, int threads,
                     const std::function<void(int, FomSolution&&)>& store, const ProgressCallback& progress = {});

}  // namespace contactrom::fom
