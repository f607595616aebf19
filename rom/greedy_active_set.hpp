#pragma once
/// \file greedy_active_set.hpp
/// \brief Greedy active-set online solver (Kollepara et al., "Sparse
/// approximations for contact mechanics", Algorithm 1; docs/theory.md §3.2).
///
/// Unknowns: reduced displacement û (u = Φû + u_off(μ), the offset of rom::ReducedModel) and sparse dictionary
/// coefficients λ̂_I (λ = D_d[:, I] λ̂_I). Starting from I = ∅ and the
/// unconstrained û = K̂⁻¹ f̂ (GreedyOptions::init = WarmStart::Empty, the paper's
/// Alg. 1) — or, by default, from the columns of the training parameters around μ
/// and their interpolated reduced coordinates (WarmStart) — each iteration k:
///  1. rebuilds the contact operators at the previous iterate from the surface
///     rows only: \f$ u_s = \Phi_s \hat u^{k-1} + u_{off,s} \f$, pairing =
///     search(u_s), (C_s, g) = assemble(pairing),
///     \f$ \hat C = D_d^T C_s \Phi_s \f$, \f$ \hat g = D_d^T (g - C_s u_{off,s}) \f$;
///  2. solves the saddle-point system
///     \f[ \begin{bmatrix} \hat K & \hat C_I^T \\ \hat C_I & 0 \end{bmatrix}
///         \begin{bmatrix} \hat u \\ \hat\lambda_I \end{bmatrix} =
///         \begin{bmatrix} \hat f \\ \hat g_I \end{bmatrix} \f]
///     by its Schur complement \f$ S = \hat C_I \hat K^{-1} \hat C_I^T \f$ with the
///     Cholesky factor of K̂ (built once offline when K does not depend on μ);
///  3. makes ONE change: if \f$ \hat\lambda_I \ge 0 \f$ it adds
///     \f$ p_{add} = \arg\max_{p \notin I} (\hat C \hat u - \hat g)^{+,\tau}_p \f$
///     (entries ≤ τ count as zero; nothing is added if all are), else it removes the
///     most negative \f$ \hat\lambda_p \f$;
///  4. stops when nothing was added or removed and
///     \f$ \|\hat u^k - \hat u^{k-1}\| \le \epsilon\,\|\hat u^k\| \f$ (ε = 1e-5) and,
///     beyond Alg. 1, the operators rebuilt at û^k itself confirm that no column
///     (selected ones included) is violated by more than τ — otherwise iterating
///     goes on with those operators, so a converged result meets the reduced
///     constraint \f$ D_d^T (C(u) u - g(u)) \le \tau \f$ at its own pairing;
///     or after k_max = 50 iterations (converged = false; by default the best iterate
///     with λ̂ ≥ 0 is then returned, see GreedyOptions::best_iterate_on_failure).
/// Beyond Alg. 1 (both on by default, off with anderson_depth = 0 and
/// on_cycle = continue): while a step changes nothing, the point where the next
/// operators are built is Anderson-accelerated (the pairing's fixed point may
/// oscillate, like the FOM's); and when a step brings back a selection met before in
/// the query, the query goes on with the nested schedule below.
/// Each rebuild searches the contact pairs with a memory of the previous searches
/// (GreedyOptions::rebuild, fom::SearchMemory): rows that cannot have changed master
/// segment skip the search of the whole chain, with the same operators as a full search.
/// With a warm start, the first search starts from the memory of the one made offline
/// at the nearest training snapshot (ReducedModel::snapshot_search_memory).
/// Only Ĉ_I (|I| rows) is formed, from the rows of C_R Φ_s on the union of the selected
/// columns' supports (SupportRows::reduced_rows); the violation of all m columns is evaluated as
/// \f$ D_d^T (C_s u_s - g) \f$, which equals \f$ \hat C\hat u - \hat g \f$. Every
/// operation costs O(n_s r + n_c (r |I| + m) + r²|I|): nothing scales with the mesh
/// beyond the contact surface. The returned (û, λ̂_I) solve the saddle-point system
/// of the last iteration (with the I used there). The contact search runs only for
/// the rows where some dictionary column is non-zero (SupportRows of D_d):
/// the other rows of C never enter Ĉ or the violation.
///
/// Nested schedule (GreedySchedule::Nested, method "greedy-nested"): the same
/// one-change steps 2–3 are repeated on FROZEN operators until they change nothing
/// (or revisit a selection: a cycle), and only then are the operators rebuilt at the
/// new iterate (step 1), Anderson-accelerated while the selection is unchanged. With
/// the operators frozen, \f$ A = C_R \Phi_s \f$ is formed once per rebuild, and each
/// selected column p keeps \f$ \hat C_p \f$, \f$ \hat K^{-1} \hat C_p^T \f$ and its effect on
/// every column's violation, so a one-change step costs O(|I|(r + m) + |I|³) and
/// needs no contact search. Stopping test and confirmation are those of step 4;
/// k_max counts the rebuilds, GreedyOptions::max_solves the one-change steps.
#include <iosfwd>

#include <contactrom/core/anderson.hpp>
#include <contactrom/rom/active_set_start.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/support_rows.hpp>

namespace contactrom::rom {

/// \brief When the reduced contact operators are rebuilt (see docs/rom.md).
enum class GreedySchedule {
  /// Default: the fixed point x ↦ û(x), û(x) the reduced problem on the contact
  /// operators built at x, solved exactly (Lawson–Hanson with a ratio test on its
  /// dual: the multipliers never go negative); x Anderson-accelerated with one
  /// history over the query; stopped by a physical test at û's own pairing (see the
  /// file comment). k_max counts the rebuilds.
  FixedPoint,
  /// Paper Alg. 1: operators rebuilt at the previous iterate before every
  /// one-change iteration.
  Interleaved,
  /// Operators rebuilt only once the one-change iterations have settled on the
  /// current (frozen) operators, or cycle on them; the rebuild point is
  /// Anderson-accelerated while the selection stays the same. Same selection
  /// rules, threshold and convergence test; k_max counts the rebuilds.
  Nested
};

/// \brief How the contact operators are rebuilt at a new iterate (see docs/rom.md).
enum class OperatorRebuild {
  /// Rows whose nodes moved too little since an earlier search to change master
  /// segment skip the search of the whole master chain (SupportOperators with a
  /// fom::SearchMemory). Same operators, hence the same iterates, as Full.
  Partial,
  /// Every support row searched along the whole master chain at every rebuild.
  Full
};

/// \brief Settings of GreedyActiveSet (documented defaults); τ, its scaling, the
/// iteration cap k_max, the step tolerance and the operator clock are the
/// ActiveSetSettings of every active-set method.
struct GreedyOptions : ActiveSetSettings {
  /// Relative pivot under which the Schur complement S is treated as singular
  /// (reciprocal condition estimate of its LDLᵀ); the system is then solved in the
  /// least-squares, minimum-norm sense. Default 1e-13.
  double singular_tolerance = 1e-13;
  /// When the iteration cap is reached (add/remove cycles, paper §4.1), return the
  /// iterate with non-negative multipliers and the smallest largest violation seen,
  /// instead of the last one (which may carry negative multipliers). The result is
  /// still flagged converged = false. Default true.
  bool best_iterate_on_failure = true;
  /// Starting point of the iteration. Default WarmStart::Cell (measured best, see
  /// docs/rom.md); WarmStart::Empty is the paper's Alg. 1.
  WarmStart init = WarmStart::Cell;
  /// Operator-rebuild schedule. Default FixedPoint; Interleaved is the paper's Alg. 1.
  GreedySchedule schedule = GreedySchedule::FixedPoint;
  /// How each rebuild searches the contact pairs. Default Partial.
  OperatorRebuild rebuild = OperatorRebuild::Partial;
  /// Anderson depth of the rebuild point while the selection stays the same (0:
  /// plain substitution, as in the paper's Alg. 1). Default 5.
  int anderson_depth = 5;
  /// Interleaved schedule: when a one-change step brings back a selection already
  /// met in the query, go on with the nested schedule (from the current û and
  /// selection, with the rebuilds left). false: the paper's Alg. 1, which may cycle
  /// to the cap. Default true.
  bool nested_on_cycle = true;
  /// Fixed-point schedule: û is tested at its own pairing once the contact surface
  /// moved by at most this, in units of the displacement scale U, between the point
  /// where the operators were built and û (max over the surface dofs of
  /// \f$ |\Phi_s(\hat u - x)| \f$). Default 1e-3 (a fiftieth of the default
  /// penetration tolerance). The other schedules use step_tolerance.
  double surface_step = 1e-3;
  /// Nested schedule: cap on the one-change solves of a query, over all rebuilds.
  /// Default 1000.
  int max_solves = 1000;
  /// If set, one line per iteration (|I|, action, largest violation, step) is
  /// written here; for diagnosis only (not thread-safe). Default nullptr.
  std::ostream* trace = nullptr;
};

/// \brief Greedy active-set online solver; see the file comment.
class GreedyActiveSet final : public OnlineSolver {
 public:
  using Options = GreedyOptions;

  /// \param model reduced model (must outlive the solver)
  explicit GreedyActiveSet(const ReducedModel& model, const Options& options = {});

  std::string name() const override { return m_options.schedule == GreedySchedule::Nested ? "greedy-nested" : "greedy"; }

  const ReducedModel& model() const override { return m_model; }
  /// The threshold τ actually used, after defaulting and scaling (same units as
  /// \f$ D_d^T (Cu - g) \f$).
  double threshold() const { return m_threshold; }
  const Options& options() const { return m_options; }

 private:
  const ReducedModel& m_model;
  Options m_options;
  double m_threshold = 0.0;
  SupportRows m_support;  // contact rows R where D_d is not zero, D_d restricted to R

  void solve_reduced(const fom::Param& mu, OnlineResult& res) const override;

  struct Query;        // the per-query quantities both schedules share
  struct Interleaved;  // the interleaved schedule's state between its steps
  struct Nested;       // the nested schedule's state between its steps
  void solve_interleaved(Query& q, OnlineResult& res) const;
  /// \param max_rebuilds cap on the operator rebuilds (k_max, or what the
  /// interleaved schedule left of it when it hands over on a cycle)
  void solve_nested(Query& q, OnlineResult& res, int max_rebuilds) const;
  void solve_fixed_point(Query& q, OnlineResult& res) const;
};

/// \brief The threshold τ that GreedyActiveSet applies with `options` (defaulted to δ
/// and scaled per TauScaling), in the units of \f$ D_d^T (Cu - g) \f$.
double greedy_threshold(const ReducedModel& model, const GreedyOptions& options);

/// \brief Multipliers of the reduced saddle-point system from its Schur complement
/// S (|I| × |I|): S⁻¹ rhs by LDLᵀ, or — when S is numerically singular (LDLᵀ failure
/// or reciprocal condition ≤ `singular_tolerance`, e.g. dependent rows) — the
/// least-squares, minimum-norm solution. The factorisation lives in per-thread
/// storage of fixed size while |I| ≤ 16, so the online steps do not allocate it
/// (the minimum-norm fallback does).
/// \param lambda the multipliers (size |I|)
void schur_multipliers(const Eigen::Ref<const Eigen::MatrixXd>& schur, const Eigen::Ref<const Eigen::VectorXd>& rhs,
                       double singular_tolerance, Eigen::Ref<Eigen::VectorXd> lambda);
/// \returns the multipliers, as schur_multipliers(schur, rhs, singular_tolerance, lambda).
Eigen::VectorXd schur_multipliers(const Eigen::Ref<const Eigen::MatrixXd>& schur,
                                  const Eigen::Ref<const Eigen::VectorXd>& rhs, double singular_tolerance);

/// \brief Binding table of GreedyOptions: every option of the methods `greedy` and
/// (without schedule, surface_step and on_cycle) `greedy-nested`, declared once.
const OptionTable<GreedyOptions>& greedy_option_table();

/// \brief `options` read through greedy_option_table() (read_options()).
/// \throws InputError for an unknown key or a value outside its declaration.
GreedyOptions greedy_options(const OnlineSolverOptions& options);

}  // namespace contactrom::rom
