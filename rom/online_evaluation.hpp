#pragma once
/// \file online_evaluation.hpp
/// \brief The common interface of the online ROM solvers (greedy active set,
/// convex hull, CPG, full dictionary, ...), a name → factory registry, and the
/// evaluation of a ROM over a parameter set against the FOM: errors, sparsity,
/// iterations, time.
///
/// Exact command line (see docs/rom.md):
/// \code
///   contactrom online --db hertz30.h5 --method greedy --delta 1e-8 --validation --out hertz30.csv --json
/// \endcode
///
/// The registry itself, with every method's options, is in rom/online_methods.hpp.
/// Adding a method: implement OnlineSolver, then register it with
/// register_online_method() (declaring its options) or register_online_solver().
#include <Eigen/Dense>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "fom/active_set_solver.hpp"
#include "fom/kkt.hpp"
#include "fom/problem.hpp"
#include "rom/offline.hpp"
#include "rom/reduced_model.hpp"

namespace contactrom::rom {

/// \brief One online query of a ROM.
struct OnlineResult {
  fom::Param mu;                 ///< parameter of the query
  Eigen::VectorXd u_hat;         ///< reduced primal coordinates û (size r)
  Eigen::VectorXd u;             ///< full displacement Φû + u_lift(μ) (n_dofs)
  Eigen::VectorXd lambda;        ///< full contact pressure D_d[:, I] λ̂_I (n_c)
  std::vector<int> selected;     ///< selected dictionary columns I (indices into ReducedModel::dictionary())
  Eigen::VectorXd coefficients;  ///< λ̂_I, in the order of `selected`
  int iterations = 0;            ///< iterations of the method (one reduced solve each for greedy)
  bool converged = false;        ///< stopping criterion met before the iteration cap
  Status status = Status::Success;  ///< NoConvergence when !converged; NumericalIssue on a failed solve
  /// Wall time of the online core (seconds): everything from μ to (û, λ̂_I) and the
  /// full pressure, nonlinear contact operators included; the full-field
  /// reconstruction Φû + u_lift (a mesh-size operation needed only for output) is
  /// excluded and timed in `reconstruction_time_s`.
  double time_s = 0.0;
  double reconstruction_time_s = 0.0;  ///< wall time of u = Φû + u_lift (seconds)
  /// Part of `time_s` spent building the contact operators at the iterates (surface
  /// displacement Φ_s û, contact search, assembly of C_R and g_R, the rows Ĉ_I, ĝ_I
  /// of the reduced operators): the "construction of the non-linear operators" that
  /// the paper's timings leave out. Measured only when the solver was built with
  /// OnlineSolverOptions::time_operators (it costs two clock reads per phase);
  /// −1 otherwise, and for methods that do not measure it.
  double operator_time_s = -1.0;
  std::string message;                 ///< reason when status != Success
};

/// \brief An online ROM method. solve() is const and must be thread-safe.
class OnlineSolver {
 public:
  virtual ~OnlineSolver() = default;
  /// Registry name of the method ("greedy", ...).
  virtual std::string name() const = 0;
  /// The reduced model the solver works on.
  virtual const ReducedModel& model() const = 0;
  /// \brief Solves the reduced problem at μ (range-checked by the caller).
  virtual OnlineResult solve(const fom::Param& mu) const = 0;
  /// Number of dual columns the method draws from (the whole dictionary unless the
  /// method builds its own dual basis, e.g. CPG).
  virtual int dual_basis_size() const { return model().dictionary_size(); }
};

/// \brief Settings shared by the online methods (each documents which it reads).
struct OnlineSolverOptions {
  /// Penetration threshold τ of the greedy enrichment; < 0: τ = δ of the model (the
  /// paper's choice). Default −1.
  double tau = -1.0;
  /// How τ is applied: "absolute" (paper: on D_dᵀ(Cu − g) directly) or "relative"
  /// (τ times the scale U·max_p Σ_s w_s|D_d[s,p]|; see docs/rom.md). Default "absolute".
  std::string tau_scaling = "absolute";
  /// Iteration cap k_max. Default 50.
  int max_iterations = 50;
  /// Relative change of û under which the iteration may stop. Default 1e-5.
  double step_tolerance = 1e-5;
  /// Measure OnlineResult::operator_time_s (greedy, greedy-nested, cpg,
  /// full-dictionary). Off by default: the clock reads add about 1 % to a query.
  bool time_operators = false;
  /// Method-specific settings by name (for methods added later), as text.
  std::map<std::string, std::string> extra;
};

/// \brief Accumulates the wall time of the operator-construction phases of one
/// query into OnlineResult::operator_time_s; does nothing unless enabled.
class OperatorClock {
 public:
  explicit OperatorClock(bool enabled) : m_enabled(enabled) {}
  void start() {
    if (m_enabled) m_start = std::chrono::steady_clock::now();
  }
  void stop() {
    if (m_enabled) m_total += std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
  }
  /// Seconds accumulated, or −1 when disabled.
  double total() const { return m_enabled ? m_total : -1.0; }

 private:
  bool m_enabled;
  double m_total = 0.0;
  std::chrono::steady_clock::time_point m_start;
};

/// \brief Builds an online solver on a reduced model (which must outlive it).
using OnlineSolverFactory =
    std::function<std::unique_ptr<OnlineSolver>(const ReducedModel& model, const OnlineSolverOptions& options)>;

/// \brief Registers (or replaces) the factory of method `name`.
void register_online_solver(const std::string& name, OnlineSolverFactory factory);

/// \brief Registers a method at static-initialisation time. Beware: in a static
/// library the linker drops an object file that nothing references, together with
/// its registrar; a registrar in a program's own source file is safe.
struct OnlineSolverRegistrar {
  OnlineSolverRegistrar(const std::string& name, OnlineSolverFactory factory) {
    register_online_solver(name, std::move(factory));
  }
};

/// \brief Registered method names, sorted.
std::vector<std::string> online_solver_names();

/// \brief Refuses a method name that is not registered (before costly work).
/// \throws InputError "unknown online method 'x'; expected one of: ...".
void check_online_method(const std::string& name);

/// \brief Refuses method-specific settings (OnlineSolverOptions::extra) that `method`
/// does not know. \throws InputError "online method 'm' has no option 'k'; it knows: ...".
void check_extra_options(const OnlineSolverOptions& options, const std::string& method,
                         const std::vector<std::string>& known);

/// \brief Value of a method-specific setting (OnlineSolverOptions::extra) as a finite
/// number. \throws InputError "<method> option <key> = '<text>' is not a number".
double parse_option_number(const std::string& method, const std::string& key, const std::string& text);

/// \brief Value of a method-specific setting as an integer (the whole text).
/// \throws InputError "<method> option <key> = '<text>' is not an integer".
long long parse_option_integer(const std::string& method, const std::string& key, const std::string& text);

/// \brief Builds the solver registered as `name`, after checking `options` against
/// the method's declared options (validate_online_options in rom/online_methods.hpp).
/// \throws InputError "unknown online method 'x'; expected one of: ..." for an unknown
/// name, or naming the method, option, value and what was expected.
std::unique_ptr<OnlineSolver> make_online_solver(const std::string& name, const ReducedModel& model,
                                                 const OnlineSolverOptions& options = {});

/// \brief FOM reference solutions at `params` (one shared solver, in parallel on
/// `threads` threads, ≤ 0: hardware concurrency; no warm start).
std::vector<fom::FomSolution> compute_references(const fom::ActiveSetSolver& solver,
                                                 const std::vector<fom::Param>& params, int threads = 0,
                                                 const ProgressCallback& progress = {});

/// \brief One evaluated query.
struct EvaluationRow {
  fom::Param mu;
  double primal_error = 0.0;   ///< relative H¹ error against the FOM (absolute if `absolute_errors`)
  double dual_error = 0.0;     ///< relative L²(Γc) error against the FOM (absolute if `absolute_errors`)
  /// The FOM displacement is near zero (fom::kNearZeroReference): the two errors are
  /// absolute, since relative ones would divide by round-off.
  bool absolute_errors = false;
  int sparsity = 0;            ///< |I|, number of selected dictionary columns
  int iterations = 0;
  double time_s = 0.0;         ///< online core time (OnlineResult::time_s)
  bool converged = false;
  Status status = Status::Success;
  std::vector<int> selected;   ///< selected columns as database snapshot indices
  Status fom_status = Status::Success;
  double fom_time_s = 0.0;     ///< FOM reference time (measured in parallel: indicative only)
  fom::KktResiduals kkt;       ///< FOM KKT residuals of the ROM solution (if requested)
};

/// \brief Settings of evaluate_online.
struct EvaluationOptions {
  bool kkt = false;  ///< compute the FOM KKT residuals of every ROM solution. Default false.
};

/// \brief Means and maxima over the rows; the keys of `online --json`.
struct EvaluationSummary {
  std::string method;
  double delta = 0.0;
  int dictionary_size = 0;
  int dual_basis_size = 0;  ///< OnlineSolver::dual_basis_size()
  int primal_rank = 0;
  std::vector<EvaluationRow> rows;
  /// Means and maxima of the relative errors: rows with absolute errors are left out
  /// (counted in `absolute_error_rows`).
  double mean_primal_error = 0.0, max_primal_error = 0.0;
  double mean_dual_error = 0.0, max_dual_error = 0.0;
  int absolute_error_rows = 0;  ///< rows whose errors are absolute (near-zero FOM displacement)
  double mean_sparsity = 0.0;
  int max_sparsity = 0;
  double mean_iterations = 0.0;
  double mean_time_s = 0.0, median_time_s = 0.0;
  int nonconverged = 0;   ///< ROM queries that hit the iteration cap or failed
  int fom_failures = 0;   ///< reference FOM solves whose status != Success
  double max_kkt = 0.0;   ///< largest KKT residual over the rows (if computed)
};

/// \brief Solves `solver` at every parameter (sequentially, so the timings are not
/// disturbed) and compares with the references (same order as `params`).
EvaluationSummary evaluate_online(const OnlineSolver& solver, const std::vector<fom::Param>& params,
                                  const std::vector<fom::FomSolution>& references,
                                  const EvaluationOptions& options = {});

/// \brief Writes the rows as CSV (atomically): one column per parameter (named
/// after it), then primal_h1_error, dual_l2_error, sparsity, iterations, time_s,
/// converged (0/1), status, selected (space-separated database snapshot indices),
/// errors ("relative", or "absolute" where the FOM displacement is near zero).
void write_evaluation_csv(const std::string& path, const fom::Problem& problem, const EvaluationSummary& summary);

/// \brief Median online time per query.
struct OnlineTiming {
  double median_core_s = 0.0;   ///< median of OnlineResult::time_s (nonlinear operators included)
  double median_total_s = 0.0;  ///< median wall time of solve(), full-field reconstruction included
  /// Median of time_s − operator_time_s (the paper's timing convention: construction
  /// of the contact operators left out), when the solver measures operator_time_s
  /// (OnlineSolverOptions::time_operators); −1 otherwise.
  double median_without_operators_s = -1.0;
  int queries = 0;              ///< number of timed queries
};

/// \brief Per-query time samples of online passes, in seconds; `without` stays empty
/// unless the solver measures OnlineResult::operator_time_s.
struct OnlineSamples {
  std::vector<double> core, total, without;
  /// Medians of the samples so far.
  OnlineTiming timing() const;
};

/// \brief One timed pass of `solver` over `params` (no warm-up), appended to `out`.
void time_online_pass(const OnlineSolver& solver, const std::vector<fom::Param>& params, OnlineSamples& out);

/// \brief One timed pass of the FOM over `params` (no warm-up): per-query wall
/// times appended to `out`.
void time_fom_pass(const fom::ActiveSetSolver& solver, const std::vector<fom::Param>& params, std::vector<double>& out);

/// \brief Times `solver` over `params`, `repeats` times each (after one warm-up
/// pass), on the calling thread. For `contactrom bench` and docs/rom.md.
OnlineTiming time_online(const OnlineSolver& solver, const std::vector<fom::Param>& params, int repeats = 3);

/// \brief Median wall time per FOM query (factorisation reused: the solver is
/// built before timing), `repeats` passes over `params` after one warm-up query.
double time_fom(const fom::ActiveSetSolver& solver, const std::vector<fom::Param>& params, int repeats = 1);

/// \brief Medians of the FOM and of several online solvers timed in interleaved
/// rounds (see time_interleaved).
struct InterleavedTiming {
  double fom_median_s = 0.0;             ///< median FOM time per query over all rounds
  std::vector<double> fom_round_median_s;  ///< the FOM median of each round
  /// Per solver, in the order given; median_without_operators_s comes from its
  /// clocked twin (−1 without one).
  std::vector<OnlineTiming> online;
};

/// \brief Times the FOM (factorisation reused) and every solver in `solvers` over
/// `params`: one warm-up pass of each, then `rounds` rounds of one FOM pass followed
/// by one pass of every solver; medians over all rounds. A slow spell of the machine
/// then lands on all of them alike instead of on whichever was being timed, so
/// their ratios are reproducible. `clocked` is empty or holds, per solver, a twin
/// built with OnlineSolverOptions::time_operators (or null): it is timed in the same
/// rounds and gives that solver's median_without_operators_s, while the solver's own
/// times stay free of the clock reads. On the calling thread; `solvers` must not
/// hold null.
InterleavedTiming time_interleaved(const fom::ActiveSetSolver& fom, const std::vector<const OnlineSolver*>& solvers,
                                   const std::vector<fom::Param>& params, int rounds,
                                   const std::vector<const OnlineSolver*>& clocked = {});

/// \brief Median of a list of numbers (0 for an empty list).
double median(std::vector<double> values);

}  // namespace contactrom::rom
