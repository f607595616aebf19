#pragma once
/// \file reduced_model.hpp
/// \brief The offline product shared by the dictionary ROMs: POD primal basis,
/// uncompressed dual dictionary and the parameter-affine reduced operators.
///
/// With \f$ u = u_{off}(\mu) + \Phi\hat u \f$, the offset
/// \f$ u_{off}(\mu) = \sum_k \phi_k(\mu) \tilde L_k \f$ carrying the Dirichlet data
/// (OffsetKind) and Φ zero on Dirichlet dofs, the reduced problem of paper eq. (5)
/// needs, for every parameter,
/// \f[ \hat K(\mu) = \Phi^T K(\mu) \Phi = \sum_q \theta_q(\mu)\,\Phi^T K_q \Phi, \qquad
///     \hat f(\mu) = \sum_k \phi_k(\mu) \Big( \Phi^T f_{ext,k}
///        - \sum_q \theta_q(\mu)\, \Phi^T K_q \tilde L_k \Big), \f]
/// which are assembled from the offline pieces \f$ \Phi^T K_q \Phi \f$ (r × r),
/// \f$ \Phi^T f_{ext,k} \f$ and \f$ \Phi^T K_q \tilde L_k \f$ (r each) at a cost
/// independent of the mesh. The nonlinear contact operators are rebuilt online
/// from the contact-surface rows only: \f$ \Phi_s = \Phi[\text{surface dofs}, :] \f$
/// and the surface offset \f$ u_{off,s}(\mu) = \sum_k \phi_k(\mu) \tilde L_{k,s} \f$.
///
/// The dual dictionary \f$ D_d \f$ (n_c × m) holds every pressure snapshot of the
/// database whose FOM status is Success, uncompressed, in database order.
#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <memory>
#include <mutex>
#include <vector>

#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/pod.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace contactrom::rom {

class ErrorIndicator;

/// \brief Which affine offset u_off(μ) = Σ_k φ_k(μ) L̃_k the reduced displacement is
/// measured from (u = u_off(μ) + Φû). Both carry the Dirichlet data exactly.
enum class OffsetKind {
  /// L̃_k = L_k, the problem's Dirichlet lifting (Dirichlet values, zero elsewhere): the POD is
  /// taken of the database snapshots u − u_lift as stored.
  Dirichlet,
  /// L̃_k = the unconstrained FOM response to load term k (Dirichlet values L_k and
  /// external load f_ext,k) at the reference parameter (centre of the range):
  /// \f$ \tilde L_k = L_k + K_{ff}^{-1}(f_{ext,k} - K L_k)_f \f$. For a
  /// parameter-independent K the reduced unconstrained solution is then exact
  /// (f̂ = 0) and Φ only has to represent the contact response.
  Harmonic
};

/// \brief Options of ReducedModel (documented defaults).
struct ReducedModelOptions {
  /// POD energy tolerance δ of the primal basis (paper: δ ∈ {1e-6, 1e-8, 1e-10}).
  /// Default 1e-8.
  double delta = 1e-8;
  /// Keep snapshots whose FOM status is not Success in the basis and dictionary.
  /// Default false (they are left out; the offline stage warns about them).
  bool include_failed_snapshots = false;
  /// With several contact pairs, each pressure snapshot enters the dictionary as one
  /// column per pair (its restriction to that pair's rows, where it is not zero), so
  /// that each pair's constraint has its own multiplier: a column spanning two pairs
  /// would let one pair's penetration be paid for by the other's lift-off. The
  /// columns of one snapshot share its parameter and primal snapshot
  /// (sibling_columns()). Default true; false: one column per snapshot.
  bool split_pairs = true;
  /// Offset u_off of the reduced displacement; see OffsetKind. Default Harmonic.
  OffsetKind offset = OffsetKind::Harmonic;
  /// Keep the primal snapshots of the dictionary columns (n × m), as the database
  /// stores them (u − u_lift), in the model. Only methods that combine whole training
  /// solutions need them (the convex hull); the others use their reduced coordinates
  /// Φᵀ(u − u_off) (r × m), which are always kept. Default true; OnlineModel keeps
  /// them only for a method that needs them.
  bool keep_primal_snapshots = true;
  /// How the POD is computed: algorithm, threads, block size, MPI ranks (rom/pod.hpp);
  /// its delta is replaced by `delta` above. Default PodOptions().
  PodOptions pod;
};

/// \brief Everything a ReducedModel holds besides its problem — the offline product
/// that a reduced-model file stores (rom/reduced_model_file.hpp). Sizes: n dofs,
/// r modes, m dictionary columns, n_c constraint rows, Q stiffness terms, T load terms.
struct ReducedModelData {
  ReducedModelOptions options;
  Eigen::MatrixXd basis;                   ///< Φ, n × r
  Eigen::VectorXd singular_values;         ///< of the primal snapshot matrix, decreasing
  std::vector<Eigen::VectorXd> offset_terms;    ///< L̃_k, T vectors of size n
  std::vector<Eigen::MatrixXd> stiffness_terms; ///< Φᵀ K_q Φ, Q matrices r × r
  Eigen::MatrixXd load_terms;                   ///< r × T, column k: Φᵀ f_ext,k
  std::vector<Eigen::MatrixXd> stiffness_offset_terms;  ///< per q, r × T, column k: Φᵀ K_q L̃_k
  Eigen::MatrixXd dictionary;              ///< D_d, n_c × m
  std::vector<int> dictionary_snapshots;   ///< database snapshot index of each column
  std::vector<fom::Param> dictionary_parameters;  ///< parameter of each column
  /// u − u_lift of each column (the training solution less the problem's Dirichlet
  /// lifting, as the database stores it), n × m; or empty (0 columns) when the model
  /// does not keep them (ReducedModelOptions::keep_primal_snapshots).
  Eigen::MatrixXd primal_snapshots;
  /// Φᵀ(u − u_off) of each column, r × m. May be left empty when primal_snapshots is
  /// given (then computed from them: Φᵀ(u − u_lift) + Φᵀ(u_lift − u_off)).
  Eigen::MatrixXd snapshot_coordinates;
};

/// \brief The database snapshots a reduced model keeps, in database order: those whose
/// FOM status is Success (all with ReducedModelOptions::include_failed_snapshots).
std::vector<int> reduced_model_columns(const SnapshotDatabase& db, const ReducedModelOptions& options);

/// \brief The offset terms L̃_k of `kind` (see OffsetKind).
std::vector<Eigen::VectorXd> reduced_model_offsets(const fom::Problem& problem, OffsetKind kind);

/// \brief The matrix a reduced model's POD is taken of: u − u_off(μ_c) of the kept
/// database snapshots (n_dofs × m), by blocks of rows, from the database in memory or
/// on disk (SnapshotDatabase::primal_file): the stored u − u_lift less
/// \f$ \sum_k \phi_k(\mu_c) (\tilde L_k - L_k) \f$. `db` and `problem` must outlive it.
class ReducedSnapshots : public SnapshotBlocks {
 public:
  ReducedSnapshots(const fom::Problem& problem, const SnapshotDatabase& db, std::vector<int> columns,
                   const std::vector<Eigen::VectorXd>& offset_terms);
  Eigen::Index rows() const override { return m_stored->rows(); }
  Eigen::Index cols() const override { return m_stored->cols(); }
  void read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const override;
  /// The stored snapshots u − u_lift, whole (n_dofs × m).
  Eigen::MatrixXd read_stored() const { return m_stored->read_all(); }
  /// Rows [first, first + block.rows()) of the stored snapshots, measured from the
  /// offset instead, in place: u − u_lift becomes u − u_off.
  void to_offset(Eigen::Index first, Eigen::MatrixXd& block) const;

 private:
  std::unique_ptr<SnapshotBlocks> m_stored;                 // u − u_lift, as stored
  std::vector<std::pair<int, Eigen::VectorXd>> m_shift;     // (k, L̃_k − L_k) for the nonzero ones
  Eigen::MatrixXd m_coefficients;                           // φ_k(μ_c), T × m
};

/// \brief The share of ReducedModel's construction that MPI ranks other than 0 take
/// in when `options.pod.reduction` spans several ranks: the collective POD of the
/// snapshots (rank 0 builds the model, with the same options).
void share_reduced_model_pod(const fom::Problem& problem, const SnapshotDatabase& db, const ReducedModelOptions& options);

/// \brief POD basis, dual dictionary and reduced operators; see the file comment.
/// Immutable after construction and safe to share between threads.
class ReducedModel {
 public:
  /// \brief Builds the model from a database that check_database() accepted for `problem`.
  /// The problem must outlive the model.
  /// \throws InputError if the database does not match the problem's sizes or
  ///   holds no usable snapshot.
  ReducedModel(const fom::Problem& problem, const SnapshotDatabase& db, const ReducedModelOptions& options = {});

  /// \brief Rebuilds a model from its stored offline product (no POD, no FOM): the
  /// contact-surface rows, the factor of Φᵀ K₀ Φ and the training grid are derived here.
  /// The problem must outlive the model.
  /// \throws InputError if a size of `data` does not match the problem or the others.
  ReducedModel(const fom::Problem& problem, ReducedModelData data);

  /// \brief A copy of the offline product (what save_reduced_model writes).
  ReducedModelData data() const;

  const fom::Problem& problem() const { return m_problem; }
  const ReducedModelOptions& options() const { return m_options; }
  double delta() const { return m_options.delta; }

  /// Number of primal modes r.
  int primal_rank() const { return static_cast<int>(m_phi.cols()); }
  /// Number of dictionary columns m.
  int dictionary_size() const { return static_cast<int>(m_dict.cols()); }
  /// POD basis Φ (n_dofs × r), orthonormal, zero rows on Dirichlet dofs.
  const Eigen::MatrixXd& basis() const { return m_phi; }
  /// Singular values of the primal snapshot matrix (decreasing).
  const Eigen::VectorXd& singular_values() const { return m_sigma; }
  /// Contact-surface rows of the basis, Φ_s (n_s × r), in surface_dofs() order.
  const Eigen::MatrixXd& surface_basis() const { return m_phi_s; }
  /// The same Φ_s stored row by row: the online methods combine a few of its rows
  /// per constraint row (C_s Φ_s touches 6 surface dofs per row).
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& surface_basis_rows() const {
    return m_phi_s_rows;
  }
  /// Dual dictionary D_d (n_c × m).
  const Eigen::MatrixXd& dictionary() const { return m_dict; }
  /// Database snapshot index of each dictionary column.
  const std::vector<int>& dictionary_snapshots() const { return m_dict_snapshots; }
  /// Parameter of each dictionary column.
  const std::vector<fom::Param>& dictionary_parameters() const { return m_dict_params; }
  /// The columns made from the same pressure snapshot as column p (p included, in
  /// column order): one per contact pair with ReducedModelOptions::split_pairs.
  const std::vector<int>& sibling_columns(int p) const {
    return m_siblings[static_cast<size_t>(m_dict_snapshots[static_cast<size_t>(p)])];
  }
  /// Primal snapshots of the dictionary columns as the database stores them,
  /// u − u_lift(μ) (n_dofs × m), for methods that combine whole training solutions
  /// (the convex hull's monolithic dictionary); n_dofs × 0 when the model does not
  /// keep them (has_primal_snapshots()).
  const Eigen::MatrixXd& primal_snapshots() const { return m_primal; }
  /// Whether primal_snapshots() holds one column per dictionary column.
  bool has_primal_snapshots() const { return m_primal.cols() == m_dict.cols() && m_dict.cols() > 0; }
  /// \brief Reduced coordinates of the dictionary columns' primal snapshots,
  /// \f$ \hat u_p = \Phi^T (u_p - u_{off}(\mu_p)) \f$ (r × m): the best reduced
  /// approximation of each training solution, used to warm-start the online methods.
  const Eigen::MatrixXd& snapshot_coordinates() const { return m_snapshot_coords; }
  /// \brief What the contact search of every row leaves at dictionary column p's
  /// reduced snapshot, \f$ u_s = \Phi_s \hat u_p + u_{off,s}(\mu_p) \f$ (fom::SearchMemory:
  /// closest segment, clearance and the displacements they were found at). An online
  /// query that starts near μ_p copies it into its own memory, so that its first
  /// search settles the rows that cannot have changed segment instead of searching
  /// the whole master chain — with the same pairing as a full search. Derived from
  /// the other data (not stored in a reduced-model file); empty memories when the
  /// contact model has no pairing.
  const fom::SearchMemory& snapshot_search_memory(int p) const { return m_snapshot_memory[static_cast<size_t>(p)]; }

  /// \brief One training parameter of an interpolation stencil and its weight.
  struct StencilPoint {
    int column;     ///< dictionary column (index into dictionary_parameters())
    double weight;  ///< interpolation weight (> 0; the weights of a stencil sum to 1)
  };
  /// \brief The training parameters around μ with multilinear interpolation weights:
  /// the two bracketing training parameters in 1D, the corners of the enclosing cell
  /// of a tensor grid in several dimensions (a coordinate outside the training range
  /// is clamped to it; corners of zero weight are left out, so a training parameter
  /// gets itself alone). When the training parameters do not form a tensor grid
  /// around μ, the nearest one (distance scaled by the parameter range) with weight 1.
  /// O(d · log m + 2^d); allocates only the returned vector.
  std::vector<StencilPoint> interpolation_stencil(const fom::Param& mu) const;
  /// \brief The column of the heaviest point of `stencil` (the first of equal
  /// weights): the training snapshot nearest to μ. −1 for an empty stencil.
  static int nearest_column(const std::vector<StencilPoint>& stencil);

  /// Reduced stiffness terms \f$ \Phi^T K_q \Phi \f$ (r × r each).
  const std::vector<Eigen::MatrixXd>& reduced_stiffness_terms() const { return m_k_hat; }
  /// \f$ \hat K(\mu) = \sum_q \theta_q(\mu) \Phi^T K_q \Phi \f$.
  Eigen::MatrixXd reduced_stiffness(const fom::Param& mu) const;
  /// \f$ \hat f(\mu) = \Phi^T f(\mu) \f$ from the affine pieces.
  Eigen::VectorXd reduced_rhs(const fom::Param& mu) const;
  /// Offset on the surface dofs, \f$ u_{off}(\mu) \f$ restricted to surface_dofs().
  Eigen::VectorXd surface_offset(const fom::Param& mu) const;
  /// Offset terms L̃_k of the reduced displacement (n_dofs each; see OffsetKind).
  const std::vector<Eigen::VectorXd>& offset_terms() const { return m_offset; }
  /// \f$ u_{off}(\mu) = \sum_k \phi_k(\mu) \tilde L_k \f$ (n_dofs).
  Eigen::VectorXd offset(const fom::Param& mu) const;
  /// \brief \f$ \Phi^T(u_{lift}(\mu) - u_{off}(\mu)) \f$ (r): the reduced coordinates of a
  /// field given as u − u_lift (a primal snapshot, a combination of them) are
  /// \f$ \Phi^T(u - u_{lift}) \f$ plus this. Zero for OffsetKind::Dirichlet.
  Eigen::VectorXd reduced_lifting(const fom::Param& mu) const;

  /// \brief Cholesky factor of \f$ \Phi^T K_0 \Phi \f$ when the problem has a single
  /// stiffness term (then \f$ \hat K(\mu) = \theta_0(\mu)\,\Phi^T K_0\Phi \f$: factorised
  /// once here, offline); nullptr otherwise (factorise per query).
  const Eigen::LLT<Eigen::MatrixXd>* single_term_factor() const { return m_single_ok ? &m_k_llt : nullptr; }
  /// \brief \f$ (\Phi^T K_0 \Phi)^{-1} \f$ from that factor (same condition), nullptr
  /// otherwise: the online solves need K̂⁻¹ times a few vectors of size r, where one
  /// small dense product costs less than two triangular solves.
  const Eigen::MatrixXd* single_term_inverse() const { return m_single_ok ? &m_k_inv : nullptr; }

  /// \brief Full displacement \f$ u = \Phi\hat u + u_{off}(\mu) \f$ (n_dofs).
  Eigen::VectorXd reconstruct_primal(const Eigen::VectorXd& u_hat, const fom::Param& mu) const;
  /// \brief Full pressure \f$ \lambda = D_d[:, I]\,\hat\lambda_I \f$ (n_c).
  Eigen::VectorXd reconstruct_dual(const std::vector<int>& columns, const Eigen::VectorXd& coefficients) const;

  /// \brief The error estimate of this model's answers (rom/error_indicator.hpp):
  /// built on the first call (one factorisation of K; thread-safe) and shared by
  /// every solver on the model and its copies.
  std::shared_ptr<const ErrorIndicator> error_indicator() const;

  /// Offline time spent building the model (POD + reduced operators), seconds.
  double setup_time() const { return m_setup_time; }
  /// Of which the POD (reading the snapshots included), seconds (0 for a loaded model).
  double pod_time() const { return m_pod_time; }

 private:
  const fom::Problem& m_problem;
  ReducedModelOptions m_options;
  Eigen::MatrixXd m_primal, m_phi, m_phi_s, m_dict, m_off_s;  // m_off_s: column k, L̃_k on the surface dofs
  Eigen::VectorXd m_sigma;
  std::vector<int> m_dict_snapshots;
  std::vector<fom::Param> m_dict_params;
  std::vector<std::vector<int>> m_siblings;  // per database snapshot: its columns (derived)
  Eigen::MatrixXd m_snapshot_coords;  // Φᵀ primal, r × m
  std::vector<fom::SearchMemory> m_snapshot_memory;  // contact search at each reduced snapshot
  // Training parameters as a tensor grid: sorted distinct values per dimension and
  // the dictionary column at each grid node (−1: none), first dimension fastest.
  std::vector<std::vector<double>> m_grid_values;
  std::vector<int> m_grid_columns;
  void build_parameter_grid();
  void take_dictionary(const SnapshotDatabase& db);  // D_d and the columns' parameters
  void compute_basis(const ReducedSnapshots& snapshots);  // Φ, σ, coordinates, primal snapshots
  void reduce_operators();  // Φᵀ K_q Φ, Φᵀ f_ext,k, Φᵀ K_q L̃_k
  void split_by_pair();  // ReducedModelOptions::split_pairs
  Eigen::MatrixXd coordinates_of(const Eigen::MatrixXd& stored) const;  // Φᵀ(u − u_off) of u − u_lift columns
  void derive();  // surface rows, snapshot coordinates and search memories, grid, factor of Φᵀ K₀ Φ
  std::vector<Eigen::VectorXd> m_offset;  // L̃_k
  std::vector<Eigen::MatrixXd> m_k_hat;   // Φᵀ K_q Φ
  Eigen::MatrixXd m_f_hat;                // column k: Φᵀ f_ext,k
  std::vector<Eigen::MatrixXd> m_kl_hat;  // per q, column k: Φᵀ K_q L̃_k
  Eigen::MatrixXd m_lift_hat;             // column k: Φᵀ(L_k − L̃_k) (derived)
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m_phi_s_rows;
  Eigen::LLT<Eigen::MatrixXd> m_k_llt;
  Eigen::MatrixXd m_k_inv;
  bool m_single_ok = false;
  double m_setup_time = 0.0, m_pod_time = 0.0;
  struct IndicatorSlot {
    std::once_flag once;
    std::shared_ptr<const ErrorIndicator> indicator;
  };
  std::shared_ptr<IndicatorSlot> m_indicator = std::make_shared<IndicatorSlot>();  // built by error_indicator()
};

/// \brief K̂(μ)⁻¹ for one online query: with a single stiffness term the offline
/// factor and inverse of K̂₀, scaled by 1/θ₀(μ); otherwise a Cholesky factorisation
/// of K̂(μ) made here. Shared by the greedy and the reduced active sets.
class ReducedStiffnessInverse {
 public:
  ReducedStiffnessInverse(const ReducedModel& model, const fom::Param& mu);
  ReducedStiffnessInverse(const ReducedStiffnessInverse&) = delete;
  ReducedStiffnessInverse& operator=(const ReducedStiffnessInverse&) = delete;

  /// False when K̂(μ) is not positive definite (factorisation failed) or θ₀(μ) is 0.
  bool ok() const { return m_ok; }
  /// K̂(μ)⁻¹ f through the Cholesky factor (once per query, e.g. the unconstrained û).
  Eigen::VectorXd solve(const Eigen::VectorXd& f) const { return m_inv_theta * m_factor->solve(f); }
  /// out = K̂(μ)⁻¹ rhs inside the online loops: one small dense product with the
  /// offline inverse when there is one, else the factor.
  template <class Rhs, class Out>
  void apply(const Rhs& rhs, Out&& out) const {
    if (m_inverse)
      out.noalias() = m_inv_theta * (*m_inverse) * rhs;
    else
      out = m_inv_theta * m_factor->solve(rhs);
  }

 private:
  Eigen::LLT<Eigen::MatrixXd> m_local;             // factor of K̂(μ) when there is no offline one
  const Eigen::LLT<Eigen::MatrixXd>* m_factor;     // the offline factor of K̂₀, or m_local
  const Eigen::MatrixXd* m_inverse = nullptr;      // K̂₀⁻¹ (offline), or none
  double m_inv_theta = 1.0;                        // 1/θ₀(μ) with the offline factor, else 1
  bool m_ok = true;
};

}  // namespace contactrom::rom
