#pragma once
/// \file reduced_active_set.hpp
/// \brief The standard (non-sparse) primal–dual active-set method on the reduced
/// saddle-point system with a fixed dual basis W — the online core shared by the
/// CPG baseline (W = cone-projected greedy basis, baselines/cpg.hpp) and the
/// full-dictionary baseline (W = D_d, baselines/full_dictionary.hpp).
///
/// Unknowns: reduced displacement û (u = Φû + u_off(μ), the offset of rom::ReducedModel) and reduced multipliers
/// λ̂ ≥ 0 on the columns of W (λ = Wλ̂). The reduced problem is
/// \f[ \min_{\hat u} \tfrac12 \hat u^T \hat K \hat u - \hat f^T \hat u \quad\text{s.t.}\quad
///     \hat C \hat u - \hat g \le \tau, \qquad
///     \hat C = W^T C(u) \Phi, \ \hat g = W^T (g(u) - C(u)\,u_{off}), \f]
/// whose KKT system, on the active set I (the columns whose constraint holds with
/// equality), is the saddle-point system
/// \f[ \begin{bmatrix} \hat K & \hat C_I^T \\ \hat C_I & 0 \end{bmatrix}
///     \begin{bmatrix} \hat u \\ \hat\lambda_I \end{bmatrix} =
///     \begin{bmatrix} \hat f \\ \hat g_I \end{bmatrix}. \f]
/// The loop is the greedy's default fixed point (rom::GreedySchedule::FixedPoint,
/// docs/rom.md), so the three methods are compared on the same outer iteration; only
/// the solve on frozen operators is this method's own. Starting from I = ∅ and the
/// unconstrained û = K̂⁻¹f̂ (or from a warm start, ReducedActiveSetOptions::init), x = û:
///  1. rebuild the contact operators at x from the surface rows only, exactly as
///     rom::GreedyActiveSet does (pairing = search(Φ_s x + u_off,s), C_s, g =
///     assemble(pairing)); when x is the û of the last solve (step 3), test û
///     physically at this, its own, pairing (rom::SupportRows::residuals: penetration
///     and separation under pressure within the contact tolerances): converged if it
///     passes, or if it failed already at the previous point (a fixed point of the
///     reduced problem; the full-order check then reports it);
///  2. û(x): the Hintermüller–Ito–Kunisch primal–dual active set (as in Benaceur, Ern,
///     Ehrlacher 2020) on these frozen operators — evaluate every column's violation
///     \f$ v = W^T (C_s u_s - g) \f$ at û, next active set = the columns of I whose
///     multiplier stays in the cone plus every column p ∉ I with v_p > τ (any number
///     of columns enters or leaves at once: the non-sparse counterpart of the greedy's
///     one change), solve the saddle-point system on I through its Schur complement
///     \f$ S = \hat C_I \hat K^{-1} \hat C_I^T \f$ — until the set is stable and every
///     column is within τ;
///  3. if Φ_s û moved by at most surface_step · U from Φ_s x, x = û (tested in step
///     1); else x = the Anderson extrapolation of x ↦ û(x), one history over the query.
/// At most max_iterations rebuilds and max_solves solves.
///
/// Inner solve (InnerSolve). `Equality` is the textbook PDAS: Sλ̂_I = Ĉ_I K̂⁻¹f̂ − ĝ_I
/// (minimum-norm when S is singular), then every negative λ̂_i leaves I. With a
/// non-negative, highly correlated dual basis (pressure snapshots), Ĉ_I has more rows
/// than rank as soon as a few columns are active; the multipliers are then not unique,
/// the minimum-norm ones have mixed signs and the plain iteration cycles or diverges
/// (measured in docs/baselines.md). `NonNegative` (default) solves the same system with
/// the sign condition imposed, \f$ \min_{\hat\lambda_I \ge 0} \tfrac12
/// \hat\lambda_I^T S \hat\lambda_I - (\hat C_I \hat K^{-1}\hat f - \hat g_I)^T
/// \hat\lambda_I \f$ (NnlsQp), i.e. "remove every negative" is done exactly inside
/// the solve; a column leaves I when its multiplier is zero and its constraint holds.
/// For a fixed pairing the working set then only gains violated columns or loses
/// inactive ones, so the iteration cannot cycle.
/// τ is applied exactly as in the greedy (absolute by default, τ = δ; or relative,
/// with the greedy's dictionary-wide scale), so both methods satisfy the same
/// reduced constraint.
///
/// OnlineResult::selected holds the active columns as indices into the model's
/// dictionary (W's columns are dictionary columns), so λ = D_d[:, I] λ̂_I as for the
/// greedy; `iterations` counts the saddle-point solves.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include <contactrom/core/nnls.hpp>
#include <contactrom/rom/greedy_active_set.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/support_rows.hpp>

namespace contactrom::baselines {

/// \brief How the saddle-point system on the active set is solved; see the file comment.
enum class InnerSolve {
  NonNegative,  ///< multipliers constrained to λ̂_I ≥ 0 (NNLS on the Schur complement); default
  Equality      ///< textbook PDAS: equality solve, negatives removed afterwards
};

/// \brief Settings of ReducedActiveSet (documented defaults). τ, its scaling, the cap
/// on the operator rebuilds (max_iterations) and the operator clock are the
/// rom::ActiveSetSettings of every active-set method; step_tolerance is accepted but
/// unused (the loop's step test is surface_step).
struct ReducedActiveSetOptions : rom::ActiveSetSettings {
  /// Reciprocal condition estimate of the Schur complement's LDLᵀ under which the
  /// system is solved in the least-squares, minimum-norm sense (dependent rows, e.g.
  /// more active columns than primal modes). Default 1e-13.
  double singular_tolerance = 1e-13;
  /// Inner solve of the saddle-point system. Default InnerSolve::NonNegative.
  InnerSolve inner_solve = InnerSolve::NonNegative;
  /// Settings of the NNLS inner solve (default: those of NnlsOptions).
  NnlsOptions nnls;
  /// Starting point: rom::WarmStart::Empty (default; û = K̂⁻¹f̂, as the paper ran the
  /// baselines); rom::WarmStart::Primal (û interpolated from the training snapshots
  /// around μ; the first active set is the set of columns violated there); or
  /// rom::WarmStart::Cell (the method's own solutions at the training parameters
  /// around μ, computed once in the constructor: their interpolated û and the union of
  /// their active sets). Nearest is refused.
  rom::WarmStart init = rom::WarmStart::Empty;
  /// How each rebuild searches the contact pairs, as for the greedy: Partial (default)
  /// keeps a memory of the previous searches (seeded, when warm-started, by the one
  /// made offline at the nearest training snapshot), Full searches every row in full.
  /// The operators are the same either way.
  rom::OperatorRebuild rebuild = rom::OperatorRebuild::Partial;
  /// Anderson depth of the rebuild point, one history over the query (as the greedy's
  /// GreedyOptions::anderson_depth). Default 5.
  int anderson_depth = 5;
  /// û is tested at its own pairing once the contact surface moved by at most this
  /// (units of U) from where the operators were built (GreedyOptions::surface_step).
  /// Default 1e-3.
  double surface_step = 1e-3;
  /// Cap on the saddle-point solves of a query, over all rebuilds. Default 1000.
  int max_solves = 1000;
};

/// \brief Binding table of ReducedActiveSetOptions: the options `cpg` and
/// `full-dictionary` share, declared once (rom/option_table.hpp).
const rom::OptionTable<ReducedActiveSetOptions>& reduced_active_set_option_table();

/// \brief `options` read through reduced_active_set_option_table()
/// (rom::read_options()); keys of `extra` it does not declare are left to the
/// method's other tables. \throws InputError on bad values.
/// \param method named in messages
ReducedActiveSetOptions reduced_active_set_options(const rom::OnlineSolverOptions& options,
                                                   const std::string& method = "full-dictionary");

/// \brief Primal–dual active-set online solver with dual basis W = D_d[:, columns];
/// see the file comment.
class ReducedActiveSet : public rom::OnlineSolver {
 public:
  using Options = ReducedActiveSetOptions;

  /// \param name registry name reported by name()
  /// \param model reduced model (must outlive the solver)
  /// \param dual_columns dictionary columns forming W (distinct, in range)
  /// \throws InputError if a column is out of range or repeated.
  ReducedActiveSet(std::string name, const rom::ReducedModel& model, std::vector<int> dual_columns,
                   const Options& options = {});

  std::string name() const override { return m_name; }
  const rom::ReducedModel& model() const override { return m_model; }

  /// Dictionary columns forming W, in the order of W's columns.
  const std::vector<int>& dual_columns() const { return m_columns; }
  int dual_basis_size() const override { return static_cast<int>(m_columns.size()); }
  /// W = D_d[:, dual_columns()] (n_c × |W|).
  const Eigen::MatrixXd& dual_basis() const { return m_w; }
  /// The threshold τ actually used (same units as \f$ W^T (Cu - g) \f$).
  double threshold() const { return m_threshold; }
  const Options& options() const { return m_options; }

 private:
  std::string m_name;
  const rom::ReducedModel& m_model;
  std::vector<int> m_columns;
  Eigen::MatrixXd m_w;
  rom::SupportRows m_support;  // contact rows where W is not zero, W on them
  Options m_options;
  double m_threshold = 0.0;
  /// Per dictionary column (training parameter): the cold solution's û and active
  /// set (positions in W), for init = cell; empty otherwise.
  struct Start {
    Eigen::VectorXd u_hat;
    std::vector<int> active;
  };
  std::vector<Start> m_starts;
  struct Query;
  /// The query at μ from the starting point `init` (the constructor's cold solves use
  /// WarmStart::Empty).
  void solve_from(const fom::Param& mu, rom::WarmStart init, rom::OnlineResult& res) const;
  void solve_reduced(const fom::Param& mu, rom::OnlineResult& res) const override;
};

/// \brief Reduced-level penetration \f$ \max_p D_d[:,p]^T (C(u)\,u - g(u)) \f$ over the
/// dictionary columns `columns`, with the pairing recomputed from the full displacement
/// `u` (as fom::kkt_residuals does). Returns −∞ for an empty column list.
double reduced_penetration(const rom::ReducedModel& model, const std::vector<int>& columns,
                           const Eigen::VectorXd& u);

}  // namespace contactrom::baselines
