#pragma once
/// \file lawson_hanson.hpp
/// \brief The Lawson–Hanson active-set loop, written once for every problem of the
/// form "minimise a convex quadratic over \f$x \ge 0\f$ (plus, optionally, equality
/// constraints kept on the passive set)": NNLS in Gram form (NnlsQp, core/nnls.hpp)
/// and least squares on the probability simplex (rom::SimplexLeastSquares,
/// rom/chls.hpp). The loop is the same; what differs is the descent direction of a
/// bound variable and the least-squares solve on the passive (free) set, which each
/// problem supplies through LawsonHansonProblem.
///
/// Reference: C. L. Lawson and R. J. Hanson, *Solving Least Squares Problems*,
/// Prentice-Hall 1974 (SIAM 1995), chapter 23, algorithm NNLS; the loop is
/// described in docs/sparse_kernels.md.
#include <Eigen/Dense>
#include <vector>

#include <contactrom/core/errors.hpp>

namespace contactrom {

/// \brief What the Lawson–Hanson loop needs from one problem: its passive set and
/// the two computations that differ between problems. The passive set is ordered
/// by entry (the entering variable is always last).
class LawsonHansonProblem {
 public:
  virtual ~LawsonHansonProblem() = default;

  /// \brief The passive (free) variables, in the order they entered.
  virtual const std::vector<Eigen::Index>& passive() const = 0;

  /// \brief Descent of each variable at x: `w(j)` > threshold means that freeing the
  /// bound variable j lowers the objective (minus the gradient, shifted by the
  /// multiplier of an equality constraint if there is one).
  /// \returns the threshold (the scaled optimality tolerance).
  virtual double descent(const Eigen::VectorXd& x, Eigen::VectorXd& w) = 0;

  /// \brief Appends variable j to the passive set.
  /// \returns false, leaving the set unchanged, if j cannot be freed (numerically
  ///          dependent on the passive variables).
  virtual bool free(Eigen::Index j) = 0;

  /// \brief Removes the passive variable at `position` (0-based, in entry order).
  virtual void bind(Eigen::Index position) = 0;

  /// \brief Minimiser z of the objective over the passive variables alone (bound
  /// variables at 0, no sign constraint), ordered as passive().
  /// \returns false when the solve fails (non-finite z or an impossible passive set).
  virtual bool solve_passive(Eigen::VectorXd& z) = 0;

  /// \brief Status at convergence, given the last descent w and the variables the
  /// loop refused to free since the passive set last changed (`refused[j]` != 0).
  /// Default Status::Success.
  virtual Status converged(const Eigen::VectorXd& w, const std::vector<char>& refused) {
    (void)w;
    (void)refused;
    return Status::Success;
  }
};

/// \brief Settings of lawson_hanson().
struct LawsonHansonOptions {
  /// Cap on the number of active-set changes (each frees or binds one variable);
  /// a change is made only while fewer have been made. Must be > 0.
  int max_iterations = 1;
  /// A passive variable whose value falls to this or below after a step is bound
  /// together with the blocking one (absolute; 0 binds only exact zeros).
  double bind_tolerance = 0.0;
  /// Starts with the passive solve instead of the optimality test: for a warm start
  /// whose passive set was filled before the call.
  bool start_with_passive_solve = false;
};

/// \brief Outcome of lawson_hanson().
struct LawsonHansonResult {
  Status status = Status::Success;  ///< Success, NoConvergence, or NumericalIssue
  int iterations = 0;               ///< active-set changes made
};

/// \brief Runs the Lawson–Hanson loop on `problem` from the feasible point x
/// (x_j = 0 off the passive set, x_j > 0 on it), updating x in place:
///  1. optimality test: stop if no bound variable has descent above the threshold;
///  2. free the bound variable of largest descent;
///  3. solve on the passive set; if a passive value is not positive, step from x
///     towards the solution as far as x ≥ 0 allows, bind the blocking variables and
///     repeat 3; otherwise take the solution and go to 1.
/// An entering variable whose first passive value is not positive (only rounding
/// can do this) is refused until the passive set next changes.
LawsonHansonResult lawson_hanson(LawsonHansonProblem& problem, Eigen::VectorXd& x,
                                 const LawsonHansonOptions& options);

}  // namespace contactrom
