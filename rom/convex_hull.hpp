#pragma once
/// \file convex_hull.hpp
/// \brief The non-penetrating convex-hull ROM with a monolithic dictionary
/// (Kollepara et al., "Sparse approximations for contact mechanics", appendix B;
/// docs/theory.md §3.3). Math and choices: docs/convex_hull.md.
///
/// Offline (MonolithicDictionary): the columns of the monolithic dictionary are
/// the training solutions, each displacement snapshot \f$ d_{p,j} = u_j - u_{lift}(\mu_j) \f$
/// (as stored in the database and kept by the ReducedModel, ReducedModel::primal_snapshots();
/// the Dirichlet lifting, whatever offset the model's POD uses) stacked over its pressure snapshot
/// \f$ d_{d,j} = \lambda_j \f$. A projection
/// basis B of the residual test space is built in the primal space (free dofs
/// only: B is zero on Dirichlet dofs), either
///  - "svd": the truncated SVD of \f$ D_p \f$ at energy tolerance δ (rom/pod.hpp), or
///  - "random": \f$ B = \mathrm{orth}(D_p R) \f$, \f$ R \in U_{[0,1]}^{m\times L} \f$
///    drawn from a seeded std::mt19937_64 (paper eq. sparse_res_randomized),
/// and every parameter-independent piece of the projected residual is precomputed:
/// \f$ B^T K_q D_p \f$ per stiffness term, \f$ B^T f_{ext,k} \f$,
/// \f$ B^T K_q L_k \f$, the surface rows \f$ B_s, D_{p,s} \f$ and, for contact
/// models without pairing (rope), the constant contact block \f$ (C B)^T D_d \f$.
///
/// Online (ConvexHullSolver), for a parameter μ, with
/// \f$ u = u_{lift}(\mu) + D_p\alpha \f$, \f$ \lambda = D_d\alpha \f$:
/// \f[ \min \|\alpha\|_p \quad\text{s.t.}\quad \|B^T r(\alpha)\| < \varepsilon,\;
///     \mathbf 1^T\alpha = 1,\; \alpha \ge 0, \qquad
///     r(\alpha) = K(\mu) D_p \alpha + C^T(\mu, u) D_d\alpha - f(\mu), \f]
/// solved by nnFOCUSS (rom/focuss.hpp) started from NNLS on
/// \f[ D = \begin{bmatrix} B^T K_{mono} \\ \omega\,\mathbf 1^T \end{bmatrix},\quad
///     x = \begin{bmatrix} B^T f(\mu) \\ \omega \end{bmatrix},\quad
///     K_{mono} = K(\mu) D_p + C^T D_d, \f]
/// the convexity row weighted by \f$ \omega = \omega_0 \max_j \|B^T K_{mono}[:,j]\| \f$
/// (ω₀ = `sum_weight`, default 0.1), then "polished": the equality-constrained least squares
/// \f$ \min \|B^T r(\alpha)\| \f$ s.t. \f$ \alpha \ge 0, \mathbf 1^T\alpha = 1 \f$
/// is solved exactly (SimplexLeastSquares, rom/chls.hpp) on the support nnFOCUSS
/// selected, so that \f$ |\mathbf 1^T\alpha - 1| \sim 10^{-16} \f$ (see
/// docs/convex_hull.md for why and for the effect of ω₀).
/// For contact with pairing (hertz) C depends on u: the pairing is iterated with
/// the fixed point the FOM uses (fom::solve_pairing_fixed_point) on the surface
/// displacement \f$ x = u_s \f$ — pairing from x (first the centroid of the hull),
/// rebuild \f$ B_s^T C^T D_d \f$, exact projected solve →
/// \f$ F(x) = u_{lift,s} + D_{p,s}\alpha \f$, \f$ \lambda = D_d\alpha \f$ — until
/// re-pairing at F(x) changes the contact forces and gaps by at most
/// `pairing_tolerance` (fom::pairing_change() without its penetration term),
/// capped at `max_pairing_iterations`, Anderson-accelerated on x
/// (`anderson_depth`; α is never extrapolated). The support is selected by full
/// solves in the first `selection_iterations` solves only (until it repeats), then
/// frozen (a column dropped stays out), so that near-tied supports cannot alternate
/// for ever; once the pairing settles on a frozen support, one full solve at that
/// pairing re-selects, and a different support continues the fixed point.
///
/// Applicability: the hull of non-penetrating snapshots is non-penetrating only
/// when the feasible set is convex and parameter-independent
/// (rope). A problem file declares it with `[rom] convex_hull = true`: hertz does
/// (its pairing changes little over the range, so the hull is nearly feasible);
/// problems with large sliding (ironing, ironing2) do not and are refused.
///
/// Exact command lines (docs/convex_hull.md):
/// \code
///   contactrom offline --problem rope --out rope.h5
///   contactrom online --db rope.h5 --method convex-hull --delta 1e-7 --validation
///   contactrom hull-report --db rope.h5 --set validation --delta 1e-7 --out rope_val.csv --json
/// \endcode
#include <Eigen/Dense>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <contactrom/fom/contact_model.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/chls.hpp>
#include <contactrom/rom/focuss.hpp>
#include <contactrom/core/nnls.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::rom {

/// \brief How the projection basis B of the residual is built.
enum class ProjectionBasis {
  Svd,    ///< truncated SVD of D_p at energy tolerance δ
  Random  ///< orth(D_p R), R ∈ U[0,1]^{m×L}, seeded
};

/// \brief Settings of MonolithicDictionary and ConvexHullSolver (documented defaults).
struct ConvexHullOptions {
  /// Projection basis kind. Default Svd (the paper's rope example).
  ProjectionBasis basis = ProjectionBasis::Svd;
  /// Energy tolerance δ of the SVD basis (dimensionless); < 0: δ of the reduced
  /// model (the CLI's --delta). Default −1.
  double basis_delta = -1.0;
  /// Number L of random combinations for the "random" basis; ≤ 0: the rank of the
  /// SVD basis at basis_delta. Default 0.
  int rank_l = 0;
  /// Seed of the std::mt19937_64 that draws R. Default 42.
  std::uint64_t seed = 42;
  /// ω₀, weight of the convexity row relative to the largest column norm of
  /// \f$ B^T K_{mono} \f$ (dimensionless). Default 0.1: small enough for the Gram-form
  /// NNLS start to resolve the residual rows, the exact polish enforcing 1ᵀα = 1;
  /// without polish use ≥ 1e2 (docs/convex_hull.md).
  double sum_weight = 0.1;
  /// Re-solve the exact simplex-constrained least squares on the nnFOCUSS support.
  /// Default true.
  bool polish = true;
  /// Cap of the pairing fixed point (problems with pairing only). Default 20.
  int max_pairing_iterations = 20;
  /// Pairing loop, selection phase: at most this many full solves (nnFOCUSS over
  /// all columns); the support is frozen as soon as it repeats or this cap is
  /// reached, and the remaining iterations only update α on it. The re-selection at
  /// the settled pairing is one more full solve within this cap. Default 3.
  int selection_iterations = 3;
  /// Depth of the Anderson acceleration of the pairing fixed point, on the surface
  /// displacement (0: plain iteration); the history is dropped whenever the support
  /// changes. Default 3.
  int anderson_depth = 3;
  /// Tolerance of the pairing fixed point's stopping test, the FOM's
  /// (fom::pairing_change()) without its penetration term, which a convex
  /// combination cannot meet: stop when re-pairing at the solution's
  /// \f$ u_s \f$ changes the contact force \f$ C^T\lambda \f$ by at most this
  /// relative to its norm and the gaps of the rows in contact by at most this times
  /// the displacement scale U (dimensionless). Default 1e-8.
  double pairing_tolerance = 1e-8;
  /// Largest relative projected residual \f$ \|B^T r(\alpha)\| / \|B^T f(\mu)\| \f$ of
  /// a solve reported as success. A query outside the convex hull of the training
  /// snapshots (e.g. below the training range) has no convex combination that
  /// balances its load: its residual is of order 1, and it is reported as
  /// no_convergence with the residual in the message, never as success. Inside
  /// the hull it is at the level of the dictionary's approximation error (about
  /// 1e-6 on hertz, 1e-3 to 1e-2 on rope); hertz queries below the training range
  /// give 0.14 (d = 0.00875) to 1.7 (d → 0). Default 0.1.
  double residual_tolerance = 0.1;
  /// nnFOCUSS settings (rom/focuss.hpp); defaults: 100 iterations, tolerance 1e-10,
  /// pruning 1e-8.
  FocussOptions focuss;
  /// NNLS settings of the nnFOCUSS start (core/nnls.hpp).
  NnlsOptions nnls;
  /// Settings of the exact polishing solve (rom/chls.hpp).
  SimplexLeastSquaresOptions simplex;
};

/// \brief Throws InputError unless the convex-hull ROM applies to `problem` (see
/// the file comment), e.g. "convex-hull needs a convex, parameter-independent
/// feasible set; 'ironing' has large sliding contact whose pairing changes with the
/// parameter".
void check_convex_hull_applicable(const fom::Problem& problem);

/// \brief Offline part: the monolithic dictionary, the projection basis and the
/// parameter-independent projected operators; see the file comment.
/// Immutable after construction, safe to share between threads.
class MonolithicDictionary {
 public:
  /// \param model reduced model whose primal snapshots and dual dictionary form the
  ///   columns (must outlive this object)
  /// \throws InputError for invalid options (δ < 0, L > 100000) or a failed basis.
  MonolithicDictionary(const ReducedModel& model, const ConvexHullOptions& options = {});

  const ReducedModel& model() const { return m_model; }
  const ConvexHullOptions& options() const { return m_options; }

  /// Number of columns m.
  int size() const { return static_cast<int>(m_mono.cols()); }
  /// The monolithic dictionary \f$ [D_p; D_d] \f$ ((n_dofs + n_c) × m).
  const Eigen::MatrixXd& monolithic() const { return m_mono; }
  /// The primal block \f$ D_p \f$ (n_dofs × m).
  auto primal() const { return m_mono.topRows(m_num_dofs); }
  /// The dual block \f$ D_d \f$ (n_c × m).
  auto dual() const { return m_mono.bottomRows(m_mono.rows() - m_num_dofs); }
  /// Projection basis B (n_dofs × r_B), orthonormal, zero on Dirichlet dofs.
  const Eigen::MatrixXd& projection_basis() const { return m_b; }
  /// r_B, the number of columns of B.
  int projection_rank() const { return static_cast<int>(m_b.cols()); }
  /// Surface rows of D_p (n_s × m), in surface_dofs() order.
  const Eigen::MatrixXd& surface_primal() const { return m_dp_s; }

  /// \brief \f$ B^T K(\mu) D_p \f$ (r_B × m) from the affine pieces.
  Eigen::MatrixXd projected_stiffness(const fom::Param& mu) const;
  /// \brief \f$ B^T f(\mu) \f$ (r_B) from the affine pieces.
  Eigen::VectorXd projected_rhs(const fom::Param& mu) const;
  /// \brief Contact block \f$ B^T C^T D_d = (C B_s)^T D_d \f$ (r_B × m) for a
  /// constraint operator on the surface dofs.
  Eigen::MatrixXd projected_contact(const fom::ConstraintMatrix& c) const;
  /// \brief The constant contact block (contact without pairing), else nullptr.
  const Eigen::MatrixXd* constant_contact() const { return m_has_constant_contact ? &m_bc_const : nullptr; }
  /// \brief \f$ \Phi^T D_p \f$ (r × m): with ReducedModel::reduced_lifting(μ), the reduced
  /// coordinates \f$ \hat u = \Phi^T D_p\alpha + \Phi^T(u_{lift} - u_{off}) \f$ of an answer
  /// (OnlineResult::u_hat, in the model's convention u ≈ u_off + Φû).
  const Eigen::MatrixXd& reduced_coordinates() const { return m_phi_dp; }
  /// \brief Dirichlet lifting \f$ u_{lift}(\mu) \f$ on the surface dofs.
  Eigen::VectorXd surface_lifting(const fom::Param& mu) const;

  /// Offline time (basis + projected operators), seconds.
  double setup_time() const { return m_setup_time; }

 private:
  const ReducedModel& m_model;
  ConvexHullOptions m_options;
  int m_num_dofs = 0;
  Eigen::MatrixXd m_mono, m_dd, m_b, m_b_s, m_dp_s, m_lift_s, m_phi_dp, m_bc_const;
  std::vector<Eigen::MatrixXd> m_bkd;     // Bᵀ K_q D_p
  Eigen::MatrixXd m_bf;                   // column k: Bᵀ f_ext,k
  std::vector<Eigen::MatrixXd> m_bkl;     // per q, column k: Bᵀ K_q L_k
  bool m_has_constant_contact = false;
  double m_setup_time = 0.0;
};

/// \brief One convex-hull query with the method-specific statistics.
struct ConvexHullResult {
  OnlineResult online;               ///< u, λ, selected = support of α, coefficients = α_selected, ...
  Eigen::VectorXd alpha;             ///< α over all m columns
  double sum_violation = 0.0;        ///< \f$ |\mathbf 1^T\alpha - 1| \f$
  double projected_residual = 0.0;   ///< \f$ \|B^T r(\alpha)\| / \|B^T f(\mu)\| \f$ (absolute if Bᵀf = 0)
  int focuss_iterations = 0;         ///< nnFOCUSS iterations, summed over the pairing loop
  int nnls_iterations = 0;           ///< NNLS active-set changes, summed
  int pairing_iterations = 0;        ///< solves in the pairing fixed point (1 without pairing)
  fom::Pairing pairing;              ///< the pairing of the last solve (empty without pairing)
  /// fom::pairing_change() of the result, the pairing fixed point's stopping test
  /// (0 without pairing; ∞ if the first solve failed).
  double pairing_change = 0.0;
};

/// \brief The convex-hull online solver (registry name "convex-hull"); see the file comment.
class ConvexHullSolver final : public OnlineSolver {
 public:
  using Options = ConvexHullOptions;

  /// \param model reduced model (must outlive the solver)
  /// \throws InputError if the problem is not suited (check_convex_hull_applicable)
  ///   or the options are invalid.
  explicit ConvexHullSolver(const ReducedModel& model, const Options& options = {});

  std::string name() const override { return "convex-hull"; }
  const ReducedModel& model() const override { return m_dictionary.model(); }
  /// \brief Solves at μ and returns the method-specific statistics too (`online`
  /// with the contact check of solve()).
  ConvexHullResult solve_detailed(const fom::Param& mu) const;

  const MonolithicDictionary& dictionary() const { return m_dictionary; }
  const Options& options() const { return m_dictionary.options(); }

 private:
  void solve_reduced(const fom::Param& mu, OnlineResult& res) const override;
  Eigen::VectorXd reconstruct_primal(const OnlineResult& res) const override;
  bool answer_combines_snapshots() const override { return true; }
  /// The step of solve_detailed(): the answer `on` and the statistics `res`.
  void solve_hull(const fom::Param& mu, ConvexHullResult& res, OnlineResult& on) const;
  MonolithicDictionary m_dictionary;
};

/// \brief Binding table of ConvexHullOptions: every option of the method
/// `convex-hull`, declared once (rom/option_table.hpp).
const OptionTable<ConvexHullOptions>& convex_hull_option_table();

/// \brief `options` read through convex_hull_option_table() (read_options()); the
/// active-set settings (tau, max_iterations, ...) are not the convex hull's and are
/// ignored. \throws InputError for an unknown key or a value outside its declaration.
ConvexHullOptions convex_hull_options(const OnlineSolverOptions& options);

/// \brief Factory of the registry entry "convex-hull": ConvexHullSolver with
/// convex_hull_options(options). \throws InputError as ConvexHullSolver.
std::unique_ptr<OnlineSolver> make_convex_hull_solver(const ReducedModel& model, const OnlineSolverOptions& options);

}  // namespace contactrom::rom
