#pragma once
/// \file cpg.hpp
/// \brief The "active set with CPG" baseline of the paper's comparison table: a dual
/// reduced basis built by the Cone-Projected Greedy algorithm of A. Benaceur,
/// A. Ern, V. Ehrlacher, "A reduced basis method for parametrized variational
/// inequalities applied to contact mechanics", IJNME 121 (2020) 1170–1197, used by
/// the standard (non-sparse) primal–dual active-set method on the reduced
/// saddle-point system (baselines/reduced_active_set.hpp).
///
/// Offline, CPG compresses the pressure snapshots λ_1 … λ_m (the dictionary D_d)
/// into a basis W of selected snapshots, so W ≥ 0 and the reduced pressure
/// λ = Wλ̂, λ̂ ≥ 0, is non-negative by construction:
///  1. start with the snapshot of largest norm (the most loaded state; it is also the
///     snapshot worst approximated by the empty cone, whose relative error is 1 for
///     every non-zero snapshot, so this is the greedy choice with the tie broken by
///     the norm);
///  2. project every snapshot on the cone {Wx : x ≥ 0} (NNLS in Gram form,
///     NnlsQp) and compute its relative projection error
///     \f$ e_j = \|\lambda_j - W x_j\| / \|\lambda_j\| \f$;
///  3. stop when \f$ \max_j e_j \le \f$ tolerance, else add the worst approximated
///     snapshot and go to 2.
/// Norm: the \f$ L^2(\Gamma_c) \f$ norm \f$ \|\lambda\|^2 = \sum_s w_s \lambda_s^2 \f$
/// (tributary lengths w_s; the norm of the dual errors) — or the Euclidean norm when no
/// weights are given. A zero snapshot has error 0 and is never selected.
///
/// Exact command lines (see docs/baselines.md):
/// \code
///   contactrom offline --problem hertz --train 30 --out hertz30.h5
///   contactrom online  --db hertz30.h5 --method cpg --validation --json
///   contactrom verify  --db hertz30.h5 --method cpg --cpg-tolerance 1e-2 --json
/// \endcode
#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include <contactrom/baselines/reduced_active_set.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/nnls.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::baselines {

/// \brief Settings of cone_projected_greedy (documented defaults).
struct CpgOptions {
  /// Stop when the worst relative cone-projection error is at most this; < 0: the
  /// problem's default (default_cpg_tolerance; 1e-2 without a problem). Default −1.
  double tolerance = -1.0;
  /// Cap on the basis size; ≤ 0: no cap (at most every non-zero snapshot). Default 0.
  int max_size = 0;
  /// Settings of the NNLS cone projections (default: those of NnlsOptions).
  NnlsOptions nnls;
};

/// \brief The problem's CPG tolerance: its file's `[rom] cpg_tolerance`, else 1e-2.
/// The shipped files carry the paper's values (1e-2 for `hertz`, 5e-2 for `ironing`
/// and `ironing2`).
double default_cpg_tolerance(const fom::Problem& problem);

/// \brief Outcome of cone_projected_greedy.
struct CpgBasis {
  /// Selected snapshots (column indices of the input matrix), in selection order.
  std::vector<int> columns;
  /// history[k]: worst relative projection error over all snapshots once the basis
  /// holds k+1 vectors. On Success history.back() ≤ tolerance and, when more than one
  /// vector was selected, history[size−2] > tolerance.
  std::vector<double> history;
  /// Final relative projection error of every snapshot (0 for selected ones).
  Eigen::VectorXd errors;
  double tolerance = 0.0;  ///< the tolerance used
  /// Success; NoConvergence when max_size stopped the loop above the tolerance;
  /// NumericalIssue when an NNLS projection failed (the basis so far is returned).
  Status status = Status::Success;
  double time_s = 0.0;  ///< wall time of the construction (offline), seconds
  /// Worst final projection error (0 for an empty input).
  double worst_error() const { return errors.size() ? errors.maxCoeff() : 0.0; }
};

/// \brief Cone-projected greedy selection of columns of `snapshots` (n × m, the
/// pressure snapshots); see the file comment.
/// \param weights quadrature weights of the norm (size n, > 0), or empty for the
///   Euclidean norm
/// \param options tolerance < 0 is read as 1e-2
/// \throws InputError if weights have the wrong size or a non-positive entry, the
///   snapshots are not finite, or the tolerance is above 1.
CpgBasis cone_projected_greedy(const Eigen::MatrixXd& snapshots, const Eigen::VectorXd& weights,
                               const CpgOptions& options = {});

/// \brief Relative cone-projection error of every column of `snapshots` on the cone
/// spanned by the columns `basis` (same norm as cone_projected_greedy). Used by the
/// greedy loop and by tests.
/// \param status set to NumericalIssue if an NNLS projection failed (optional)
Eigen::VectorXd cone_projection_errors(const Eigen::MatrixXd& snapshots, const Eigen::VectorXd& weights,
                                       const std::vector<int>& basis, const NnlsOptions& nnls = {},
                                       Status* status = nullptr);

/// \brief The CPG online solver: ReducedActiveSet with W = the CPG basis built (in the
/// constructor, offline) from the model's dictionary with the L²(Γc) norm.
class CpgActiveSet final : public ReducedActiveSet {
 public:
  /// \param cpg CPG settings; tolerance < 0 selects default_cpg_tolerance(problem)
  CpgActiveSet(const rom::ReducedModel& model, const CpgOptions& cpg = {},
               const ReducedActiveSetOptions& options = {});

  /// The CPG basis (its columns are dictionary columns, equal to dual_columns()).
  const CpgBasis& basis() const { return m_basis; }

 private:
  CpgActiveSet(CpgBasis&& basis, const rom::ReducedModel& model, const ReducedActiveSetOptions& options);
  CpgBasis m_basis;
};

/// \brief Builds the CPG basis of a reduced model's dictionary (L²(Γc) norm).
CpgBasis build_cpg_basis(const rom::ReducedModel& model, const CpgOptions& options = {});

/// \brief Binding table of CpgOptions: the options of `cpg` beyond the reduced
/// active set's, declared once (rom/option_table.hpp).
const rom::OptionTable<CpgOptions>& cpg_option_table();

/// \brief `options` read through cpg_option_table() (rom::read_options()); other keys
/// of `extra` are left to the reduced active set. \throws InputError naming the key
/// and the value if one is malformed or out of range.
CpgOptions cpg_options(const rom::OnlineSolverOptions& options);

/// \brief Registry factory of "cpg".
std::unique_ptr<rom::OnlineSolver> make_cpg_solver(const rom::ReducedModel& model,
                                                   const rom::OnlineSolverOptions& options);

}  // namespace contactrom::baselines
