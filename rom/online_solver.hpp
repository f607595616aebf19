#pragma once
/// \file online_solver.hpp
/// \brief The common interface of the online ROM methods (greedy active set,
/// convex hull, CPG, full dictionary, ...): one query's result, the solver
/// interface, the settings given to a method by name (OnlineSolverOptions) and
/// their reading into a method's options struct through its binding table
/// (read_options(), rom/option_table.hpp), and the clock of the contact-operator
/// construction.
///
/// Methods are built by name through the registry (rom/online_methods.hpp) and
/// evaluated against the FOM by rom/online_evaluation.hpp.
/// Exact command line (see docs/rom.md):
/// \code
///   contactrom online --db hertz30.h5 --method greedy --param 0.1275 --json
/// \endcode
#include <Eigen/Dense>
#include <chrono>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/contact_residuals.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/option_table.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::rom {

class ErrorIndicator;

/// \brief One online query of a ROM.
struct OnlineResult {
  fom::Param mu;                 ///< parameter of the query
  Eigen::VectorXd u_hat;         ///< reduced primal coordinates û (size r)
  Eigen::VectorXd u;             ///< full displacement Φû + u_off(μ) (n_dofs; the convex hull: u_lift(μ) + D_p α)
  Eigen::VectorXd lambda;        ///< full contact pressure D_d[:, I] λ̂_I (n_c)
  std::vector<int> selected;     ///< selected dictionary columns I (indices into ReducedModel::dictionary())
  Eigen::VectorXd coefficients;  ///< λ̂_I, in the order of `selected`
  /// Total contact force Σ_s w_s λ_s (fom::contact_force; per unit thickness in 2D),
  /// set with the full-order check; NaN when the answer has no pressure field.
  double contact_force = std::numeric_limits<double>::quiet_NaN();
  int iterations = 0;            ///< iterations of the method (one reduced solve each for greedy)
  bool converged = false;        ///< stopping criterion met before the iteration cap
  /// NoConvergence when !converged; NumericalIssue on a failed solve; Inaccurate when
  /// the method converged but the answer's full-order contact residuals (`contact`)
  /// exceed the solver's tolerances (OnlineSolver::contact_tolerances()).
  Status status = Status::Success;
  /// Row-by-row full-order contact residuals of (u, λ) at their own pairing
  /// (fom/contact_residuals.hpp), evaluated after every query on the contact surface.
  fom::ContactResiduals contact;
  /// A posteriori estimates of the relative H¹ error of u and the relative L²(Γc)
  /// error of λ against the FOM (the quantities of primal_error and dual_error),
  /// made without the FOM solve (rom/error_indicator.hpp); NaN when not estimated
  /// (OnlineSolverOptions::estimate off, a parameter-dependent stiffness, a failed
  /// correction).
  double primal_estimate = std::numeric_limits<double>::quiet_NaN();
  double dual_estimate = std::numeric_limits<double>::quiet_NaN();  ///< see primal_estimate
  /// The estimates are absolute (the corrected displacement is near zero), as
  /// EvaluationRow::absolute_errors.
  bool absolute_estimates = false;
  /// Wall time of the error estimate, included in `time_s`.
  double estimate_time_s = 0.0;
  /// Wall time of the online core (seconds): everything from μ to (û, λ̂_I) and the
  /// full pressure, nonlinear contact operators included; the full-field
  /// reconstruction of u (a mesh-size operation needed only for output) is
  /// excluded and timed in `reconstruction_time_s`. The full-order contact check
  /// (`check_time_s`) is included: a status is part of the answer.
  double time_s = 0.0;
  /// Wall time of the full-order contact check that sets `contact` (one contact
  /// search and assembly on the surface), included in `time_s`.
  double check_time_s = 0.0;
  double reconstruction_time_s = 0.0;  ///< wall time of the reconstruction of u (seconds)
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
///
/// solve() is one query, the same for every method: it checks μ against the
/// problem's range, runs the method's step (solve_reduced()) on the clock, marks an
/// answer that did not converge, reconstructs the full displacement (timed apart),
/// and then judges the answer at the full order on the contact surface: a query the
/// method reports converged whose row-by-row contact residuals (penetration,
/// separation under pressure, negative pressure, at the answer's own pairing) exceed
/// contact_tolerances() gets Status::Inaccurate, with the worst residual and its row
/// in the message; with an error indicator set, the errors are estimated.
class OnlineSolver {
 public:
  virtual ~OnlineSolver() = default;
  /// Registry name of the method ("greedy", ...).
  virtual std::string name() const = 0;
  /// The reduced model the solver works on.
  virtual const ReducedModel& model() const = 0;
  /// \brief One query at μ; see the class comment.
  /// \throws InputError for μ of the wrong size or outside the problem's range.
  OnlineResult solve(const fom::Param& mu) const {
    return run_query(mu, [&](OnlineResult& res) { solve_reduced(mu, res); });
  }
  /// Number of dual columns the method draws from (the whole dictionary unless the
  /// method builds its own dual basis, e.g. CPG).
  virtual int dual_basis_size() const { return model().dictionary_size(); }
  /// Tolerances of the contact check (default: the problem's, fom::default_contact_tolerances).
  fom::ContactTolerances contact_tolerances() const;
  /// Estimates the errors of every answer with `indicator` (nullptr: none), its
  /// correction capped at `pairings` pairings (≤ 0: the indicator's
  /// ErrorIndicatorOptions::pairing_iterations).
  void set_error_indicator(std::shared_ptr<const ErrorIndicator> indicator, int pairings = 0) {
    m_indicator = std::move(indicator), m_estimate_pairings = pairings;
  }
  /// Whether an error indicator is set (the `estimate` option on).
  bool estimates_errors() const { return m_indicator != nullptr; }
  /// Sets the tolerances of the contact check.
  void set_contact_tolerances(const fom::ContactTolerances& tolerances) { m_tolerances = tolerances, m_tolerances_set = true; }

 protected:
  /// \brief The method's step, from μ (already checked; `res.mu` set) to its answer:
  /// û (`u_hat`), the selection and its multipliers, the pressure `lambda`,
  /// `iterations`, `converged`, `operator_time_s` when measured; on a failure
  /// `status` and `message`, and when it did not converge the reason in `message`.
  virtual void solve_reduced(const fom::Param& mu, OnlineResult& res) const = 0;
  /// \brief The full displacement of an answer (timed as reconstruction); default
  /// Φû + u_off(μ) (ReducedModel::reconstruct_primal).
  virtual Eigen::VectorXd reconstruct_primal(const OnlineResult& res) const;
  /// \brief Whether an answer's displacement is the combination of the model's primal
  /// snapshots given by `selected` and `coefficients` (the convex hull) rather than
  /// Φû + u_off(μ): its primal error is then estimated on that combination.
  virtual bool answer_combines_snapshots() const { return false; }
  /// \brief solve() with another step than solve_reduced(), for a method that
  /// reports more than OnlineResult (`step(res)` fills `res` as solve_reduced()).
  template <class Step>
  OnlineResult run_query(const fom::Param& mu, Step&& step) const {
    OnlineResult res = start_query(mu);
    const auto t0 = std::chrono::steady_clock::now();
    step(res);
    finish_query(t0, res);
    return res;
  }

 private:
  /// Checks μ; the result with `mu` set.
  OnlineResult start_query(const fom::Param& mu) const;
  /// Marks a non-converged answer, times the step (from t0), reconstructs u, checks
  /// the contact residuals and estimates the errors.
  void finish_query(std::chrono::steady_clock::time_point t0, OnlineResult& res) const;

  fom::ContactTolerances m_tolerances;
  bool m_tolerances_set = false;
  std::shared_ptr<const ErrorIndicator> m_indicator;
  int m_estimate_pairings = 0;
};

/// \brief The pairing check_contact() searched at an answer, with the memory of that
/// search (fom::SearchMemory), from which the error estimate's re-pairings start.
struct AnswerSearch {
  fom::Pairing pairing;
  fom::SearchMemory memory;
};

/// \brief The full-order contact check of an online answer: sets `res.contact` and
/// `res.check_time_s`, and turns a Success whose residuals exceed `tolerances` into
/// Status::Inaccurate (message: the residuals above tolerance and their rows). The
/// penetration and separation tolerances are relative to U, or to the answer's own
/// largest surface displacement when that is smaller (fom::tolerances_on_own_scale()).
/// \returns the search at the answer (storage of the calling thread, valid until its
///   next check), or nullptr when the answer has no fields.
const AnswerSearch* check_contact(const ReducedModel& model, const fom::ContactTolerances& tolerances,
                                  OnlineResult& res);

/// \brief The error estimate of an answer (OnlineResult::primal_estimate, dual_estimate,
/// absolute_estimates, estimate_time_s, added to time_s), from the search that
/// check_contact() made at it.
/// \param combination the answer combines the model's primal snapshots
///   (OnlineSolver::answer_combines_snapshots())
void estimate_errors(const ErrorIndicator& indicator, const AnswerSearch& search, OnlineResult& res,
                     int pairings = 0, bool combination = false);

/// \brief How the threshold τ is applied to the dictionary violations.
enum class TauScaling {
  Absolute,  ///< paper: entries of \f$ D_d^T (Cu - g) \f$ compared with τ directly
  Relative   ///< compared with τ·U·max_p Σ_s w_s|D_d[s,p]| (U: displacement scale)
};

/// \brief Settings of every active-set method (the greedy, `cpg`, `full-dictionary`).
struct ActiveSetSettings {
  /// Penetration threshold τ of the reduced constraint; < 0: τ = δ of the model (the
  /// paper's choice). Default −1.
  double tau = -1.0;
  /// How τ is applied: Absolute (paper: on D_dᵀ(Cu − g) directly) or Relative (τ
  /// times the scale U·max_p Σ_s w_s|D_d[s,p]|; see docs/rom.md). Default Absolute.
  TauScaling tau_scaling = TauScaling::Absolute;
  /// Iteration cap k_max (paper: 50; the fixed-point loops: operator rebuilds). Default 50.
  int max_iterations = 50;
  /// Relative change of û under which the iteration may stop (paper: 1e-5; the
  /// fixed-point loops test surface_step instead). Default 1e-5.
  double step_tolerance = 1e-5;
  /// Measure OnlineResult::operator_time_s. Off by default: the clock reads add
  /// about 1 % to a query.
  bool time_operators = false;
};

/// \brief Binding table of ActiveSetSettings (rom/option_table.hpp).
const OptionTable<ActiveSetSettings>& active_set_settings_table();

/// \brief Settings of the check every online method makes of its answers.
struct ContactCheckOptions {
  /// Tolerances of the full-order contact check of every answer (OnlineSolver);
  /// each < 0: the problem's (`[rom]` of its file, else fom::ContactTolerances).
  /// Default −1.
  double penetration_tolerance = -1.0;
  double complementarity_tolerance = -1.0;  ///< see penetration_tolerance
  /// Estimate the errors of every answer (OnlineResult::primal_estimate and
  /// dual_estimate; rom/error_indicator.hpp). Default true.
  bool estimate = true;
  /// Cap on the pairings of the estimate's correction (ErrorIndicatorOptions::
  /// pairing_iterations): 1 = the answer's own pairing only, cheaper and coarser
  /// where the answer's pairing is wrong (sliding contact). Default 20.
  int estimate_pairings = 20;
};

/// \brief Binding table of ContactCheckOptions.
const OptionTable<ContactCheckOptions>& contact_check_table();

/// \brief The settings given to an online method by name (rom/online_methods.hpp):
/// the active-set settings and the contact check as typed fields, every other
/// setting of the method as text by key (`extra`, as `--option KEY=VALUE` gives it),
/// read into the method's own options struct through its OptionTable.
struct OnlineSolverOptions : ActiveSetSettings, ContactCheckOptions {
  /// Method-specific settings by key, as text.
  std::map<std::string, std::string> extra;
};

/// \brief Throws InputError "online method 'm' has no option 'k'; it knows: ...".
[[noreturn]] void throw_unknown_option(const std::string& method, const std::string& key,
                                       const std::vector<OptionSpec>& known);

/// \brief `options` read into a method's options struct `S` through its table:
/// the typed fields of the bases that `S` shares with OnlineSolverOptions, then
/// every entry of OnlineSolverOptions::extra that the table declares; every member
/// is then checked against its declaration.
/// \param method named in messages
/// \param strict refuse a key of `extra` the table does not declare
/// \throws InputError naming the method, the key, the value and what was expected.
template <class S>
S read_options(const OptionTable<S>& table, const OnlineSolverOptions& options, const std::string& method,
               bool strict = true) {
  S s{};
  if constexpr (std::is_base_of_v<ActiveSetSettings, S>)
    static_cast<ActiveSetSettings&>(s) = static_cast<const ActiveSetSettings&>(options);
  if constexpr (std::is_base_of_v<ContactCheckOptions, S>)
    static_cast<ContactCheckOptions&>(s) = static_cast<const ContactCheckOptions&>(options);
  const std::string prefix = "online method " + quoted(method, 200) + " option ";
  for (const auto& [key, value] : options.extra) {
    if (table.find(key))
      table.read(s, key, value, prefix + key);
    else if (strict)
      throw_unknown_option(method, key, table.specs());
  }
  table.check(s, prefix);
  return s;
}

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

}  // namespace contactrom::rom
