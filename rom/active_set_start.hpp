#pragma once
/// \file active_set_start.hpp
/// \brief The start every online active-set query makes at μ — the greedy
/// (rom/greedy_active_set.hpp) and the primal–dual baselines
/// (baselines/reduced_active_set.hpp): the reduced stiffness K̂(μ)⁻¹ (the answer of
/// a query where it cannot be factorised), the surface offset, the unconstrained
/// solution \f$ \hat u_{free} = \hat K^{-1}\hat f \f$, and the warm start (WarmStart,
/// docs/rom.md "Warm start").
#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/support_rows.hpp>

namespace contactrom::rom {

/// \brief Where an online active-set iteration starts (see docs/rom.md, "Warm start").
/// The stencil is ReducedModel::interpolation_stencil(μ): the training parameters
/// bracketing μ (1D) or the corners of its enclosing grid cell, with multilinear weights.
enum class WarmStart {
  /// Paper Alg. 1: no column selected, û = K̂⁻¹ f̂ (the unconstrained solution).
  Empty,
  /// The stencil's columns selected, û = Σ w_j û_j (interpolated reduced
  /// coordinates of their snapshots), operators first built there.
  Cell,
  /// The heaviest stencil point alone: its column selected, û = its û_j.
  Nearest,
  /// No column selected, û = Σ w_j û_j: a primal guess only (what a primal–dual
  /// active set such as CPG can use, its first set being the violated columns there).
  Primal
};

/// \brief The option words of `allowed` (for OptionTable::choice of a method's
/// `init`): "empty", "cell", "nearest", "primal", in the order given.
std::vector<std::pair<std::string, WarmStart>> warm_start_words(const std::vector<WarmStart>& allowed);

/// \brief The start of an active-set query at μ; see the file comment.
struct ActiveSetStart {
  /// \brief Factorises K̂(μ) (or takes the offline factor when K̂(μ) = θ₀(μ)K̂₀).
  ActiveSetStart(const ReducedModel& model, const fom::Param& mu) : k_inv(model, mu) {}

  ReducedStiffnessInverse k_inv;   ///< K̂(μ)⁻¹
  Eigen::VectorXd off_s;          ///< surface offset u_off,s(μ)
  Eigen::VectorXd u_free;          ///< unconstrained reduced solution K̂⁻¹ f̂
  Eigen::VectorXd u_start;         ///< starting û
  std::vector<int> start_columns;  ///< starting selection (dictionary columns; empty for Empty and Primal)
  int nearest = -1;                ///< training snapshot nearest to the start (−1: none, init Empty)

  /// \brief Computes off_s, u_free and the starting point of `init`.
  /// \returns false, with `res` the answer of a failed query (NumericalIssue, û = 0,
  ///   λ = 0), when K̂(μ) could not be factorised.
  bool begin(const ReducedModel& model, const fom::Param& mu, WarmStart init, OnlineResult& res);

  /// \brief Starts the first contact search of `ops` from the one made offline at
  /// the nearest training snapshot (same pairing as a full search, most rows settled
  /// at once); nothing without a nearest snapshot.
  void seed(const ReducedModel& model, SupportOperators& ops) const;
};

}  // namespace contactrom::rom
