#include <contactrom/rom/greedy_active_set.hpp>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ostream>
#include <string>
#include <utility>

#include <contactrom/core/anderson.hpp>
#include <contactrom/rom/rebuild_fixed_point.hpp>
#include <contactrom/rom/selection_history.hpp>

namespace contactrom::rom {

namespace {

/// Alg. 1's elimination: position of the most negative multiplier, −1 if none is.
int most_negative(const Eigen::Ref<const Eigen::VectorXd>& lambda) {
  int at = -1;
  double lowest = 0.0;
  for (int i = 0; i < lambda.size(); ++i)
    if (lambda(i) < lowest) lowest = lambda(i), at = i;
  return at;
}

/// Alg. 1's enrichment: the unselected column with the largest violation, where
/// entries ≤ τ count as zero ((·)^{+,τ}); −1 if there is none.
int most_violated(const Eigen::VectorXd& violation, const std::vector<char>& in_active, double tau) {
  int at = -1;
  double best = tau;
  for (int p = 0; p < violation.size(); ++p)
    if (!in_active[static_cast<size_t>(p)] && violation(p) > best) best = violation(p), at = p;
  return at;
}

/// Records a one-change step from selection `before` to `after`; true when `after`
/// was met before (a cycle).
bool revisits(SelectionHistory& seen, const std::vector<int>& before, const std::vector<int>& after) {
  const auto same = [](int p) { return p; };
  if (seen.empty()) (void)seen.revisits(before, same);
  return seen.revisits(after, same);
}

}  // namespace

const OptionTable<GreedyOptions>& greedy_option_table() {
  static const OptionTable<GreedyOptions> t = [] {
    OptionTable<GreedyOptions> o;
    o.include(active_set_settings_table())
        .choice("init", &GreedyOptions::init, "starting point: empty (paper Alg. 1), cell, nearest or primal",
                warm_start_words({WarmStart::Empty, WarmStart::Cell, WarmStart::Nearest, WarmStart::Primal}))
        .choice(
            "schedule", &GreedyOptions::schedule,
            "fixed-point (exact reduced solves, Anderson on the rebuild point), interleaved (one change per "
            "rebuild, Alg. 1 with safeguards), paper (Alg. 1 exactly) or nested",
            {{"fixed-point", GreedySchedule::FixedPoint},
             {"interleaved", GreedySchedule::Interleaved},
             {"paper", GreedySchedule::Interleaved},
             {"nested", GreedySchedule::Nested}},
            // paper: the interleaved schedule without Anderson nor the switch on a cycle
            [](GreedyOptions& g, const std::string& word) {
              if (word == "paper") g.anderson_depth = 0, g.nested_on_cycle = false;
            })
        .integer("anderson_depth", &GreedyOptions::anderson_depth,
                 "fixed-point and nested schedules: Anderson depth of the rebuild point (0: plain)", 0, 1e6)
        .number("surface_step", &GreedyOptions::surface_step,
                "fixed-point schedule: largest move of the contact surface (units of U) between the operators' "
                "point and the answer",
                Interval::greater_than(0))
        .integer("max_solves", &GreedyOptions::max_solves, "nested schedule: cap on the one-change solves of a query",
                 1, 1e9)
        .choice("rebuild", &GreedyOptions::rebuild,
                "contact operators rebuilt on the changed rows only (partial) or all (full)",
                {{"partial", OperatorRebuild::Partial}, {"full", OperatorRebuild::Full}})
        .choice("on_cycle", &GreedyOptions::nested_on_cycle,
                "interleaved schedule: on a revisited selection switch to nested, or continue",
                {{"nested", true}, {"continue", false}});
    return o;
  }();
  return t;
}

GreedyOptions greedy_options(const OnlineSolverOptions& options) {
  return read_options(greedy_option_table(), options, "greedy");
}

double greedy_threshold(const ReducedModel& model, const GreedyOptions& options) {
  const double tau = options.tau < 0.0 ? model.delta() : options.tau;
  if (options.tau_scaling != TauScaling::Relative) return tau;
  // Scale of D_dᵀ(Cu − g): the work of the largest dictionary force
  // Σ_s w_s |D[s,p]| through a gap of one displacement scale U.
  const Eigen::VectorXd& w = model.problem().contact().weights();
  double force = 0.0;
  for (int p = 0; p < model.dictionary_size(); ++p)
    force = std::max(force, w.dot(model.dictionary().col(p).cwiseAbs()));
  return tau * model.problem().displacement_scale() * force;
}

GreedyActiveSet::GreedyActiveSet(const ReducedModel& model, const Options& options)
    : m_model(model), m_options(options), m_threshold(greedy_threshold(model, options)),
      m_support(model.dictionary()) {}

/// Per-query quantities shared by both schedules.
struct GreedyActiveSet::Query : ActiveSetStart {
  Query(const GreedyActiveSet& solver, const fom::Param& mu)
      : ActiveSetStart(solver.m_model, mu), solver(solver), operators(solver.m_options.time_operators), ops(thread_operators()) {
    ops.reset(solver.m_options.rebuild == OperatorRebuild::Partial);
    if (solver.m_options.best_iterate_on_failure) {  // sized here, so that offer() does not allocate
      const int m = solver.m_model.dictionary_size();
      best.u_hat.resize(solver.m_model.primal_rank());
      best.lambda_i.reserve(static_cast<size_t>(m));
      best.selected.reserve(static_cast<size_t>(m));
    }
  }
  /// The operators' storage of the calling thread, reused by its queries (the
  /// pairing, the search memory and C_R hold a few dozen arrays).
  static SupportOperators& thread_operators() {
    thread_local SupportOperators ops;
    return ops;
  }
  const GreedyActiveSet& solver;
  OperatorClock operators;  // time spent building the contact operators (optional)
  SupportOperators& ops;  // pairing, C_R and g_R at the last rebuild point, and the search memory
  // Outcome, filled by the schedule: final û, the selection and its multipliers.
  Eigen::VectorXd u_hat, lambda_i;
  std::vector<int> selected;
  bool best_iterate_returned = false;  // not converged: the best iterate replaced the last one

  /// u_s = Φ_s x + u_off,s: the only place the primal enters the contact operators.
  void surface_displacement(const Eigen::VectorXd& x, Eigen::VectorXd& u_s) {
    operators.start();
    u_s.noalias() = solver.m_model.surface_basis() * x;
    u_s += off_s;
    operators.stop();
  }
  /// Step 1: the pairing, C_R and g_R of the support rows at u_s.
  void rebuild(const Eigen::VectorXd& u_s) {
    operators.start();
    ops.rebuild(solver.m_model.problem().contact(), solver.m_support, u_s);
    operators.stop();
  }
  /// Whether every column's violation at u_s, with the operators of the last rebuild
  /// (its fresh pairing when they were built at u_s), is within τ; left in `violation`.
  bool confirmed(const Eigen::VectorXd& u_s, Eigen::VectorXd& gap, Eigen::VectorXd& violation) const {
    solver.m_support.violation(ops.c, ops.g, u_s, gap, violation);
    const double worst = violation.size() > 0 ? violation.maxCoeff() : 0.0;
    if (solver.m_options.trace) *solver.m_options.trace << "greedy check at fresh pairing: max(violation)=" << worst << "\n";
    return worst <= solver.m_threshold;
  }
  /// Whether û moved by at most ε‖û‖ from x (Alg. 1's test).
  bool small_step(const Eigen::VectorXd& u_hat, const Eigen::VectorXd& x) const {
    return (u_hat - x).norm() <= solver.m_options.step_tolerance * u_hat.norm();
  }

  /// Best iterate with λ̂ ≥ 0 so far (smallest largest violation), for the iteration
  /// cap; in storage sized by the constructor.
  struct {
    bool valid = false;
    double violation = 0.0;
    Eigen::VectorXd u_hat;
    std::vector<double> lambda_i;
    std::vector<int> selected;
  } best;
  void offer(double max_violation, const Eigen::VectorXd& u, const Eigen::Ref<const Eigen::VectorXd>& l,
             const std::vector<int>& s) {
    if (!solver.m_options.best_iterate_on_failure || (best.valid && max_violation >= best.violation)) return;
    best.valid = true;
    best.violation = max_violation;
    best.u_hat = u;
    best.lambda_i.assign(l.data(), l.data() + l.size());
    best.selected = s;
  }
  /// Stores the outcome (copies: the schedule keeps its storage for the thread's next
  /// query): the last iterate, or the best one when `use_best` and one exists.
  void finish(bool use_best, const Eigen::VectorXd& u, const Eigen::Ref<const Eigen::VectorXd>& l,
              const std::vector<int>& s) {
    if (use_best && best.valid) {
      best_iterate_returned = true;
      u_hat = best.u_hat;
      lambda_i = Eigen::Map<const Eigen::VectorXd>(best.lambda_i.data(), static_cast<Eigen::Index>(best.lambda_i.size()));
      selected = best.selected;
      return;
    }
    u_hat = u;
    lambda_i = l;
    selected = s;
  }
};

namespace {

void numerical_issue(OnlineResult& res) {
  res.status = Status::NumericalIssue;
  res.message = "reduced saddle-point solve produced a non-finite value";
}

}  // namespace

void GreedyActiveSet::solve_reduced(const fom::Param& mu, OnlineResult& res) const {
  Query q(*this, mu);
  if (!q.begin(m_model, mu, m_options.init, res)) return;
  q.seed(m_model, q.ops);

  if (m_options.schedule == GreedySchedule::FixedPoint)
    solve_fixed_point(q, res);
  else if (m_options.schedule == GreedySchedule::Nested)
    solve_nested(q, res, m_options.max_iterations);
  else
    solve_interleaved(q, res);

  res.u_hat = std::move(q.u_hat);
  res.selected = std::move(q.selected);
  res.coefficients = std::move(q.lambda_i);
  res.lambda = m_model.reconstruct_dual(res.selected, res.coefficients);
  res.operator_time_s = q.operators.total();
  if (res.status == Status::Success && !res.converged) {
    const bool nested = m_options.schedule != GreedySchedule::Interleaved;
    res.message = "greedy active set did not converge in " + std::to_string(m_options.max_iterations) +
                  (nested ? " operator rebuilds (or " + std::to_string(m_options.max_solves) + " solves)" : " iterations") +
                  (q.best_iterate_returned ? "; best iterate with non-negative multipliers returned" : "");
  }
}

void schur_multipliers(const Eigen::Ref<const Eigen::MatrixXd>& schur, const Eigen::Ref<const Eigen::VectorXd>& rhs,
                       double singular_tolerance, Eigen::Ref<Eigen::VectorXd> lambda) {
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 16, 16>;
  thread_local Eigen::LDLT<Small> small;
  thread_local Eigen::LDLT<Eigen::MatrixXd> large;
  if (schur.rows() <= 16) {
    small.compute(schur);
    if (small.info() == Eigen::Success && small.rcond() > singular_tolerance) return void(lambda = small.solve(rhs));
  } else {
    large.compute(schur);
    if (large.info() == Eigen::Success && large.rcond() > singular_tolerance) return void(lambda = large.solve(rhs));
  }
  lambda = schur.completeOrthogonalDecomposition().solve(rhs);
}

Eigen::VectorXd schur_multipliers(const Eigen::Ref<const Eigen::MatrixXd>& schur,
                                  const Eigen::Ref<const Eigen::VectorXd>& rhs, double singular_tolerance) {
  Eigen::VectorXd lambda(rhs.size());
  schur_multipliers(schur, rhs, singular_tolerance, lambda);
  return lambda;
}

/// The interleaved schedule's state between its steps (paper Alg. 1 with the
/// safeguards of the file comment).
struct GreedyActiveSet::Interleaved {
  /// Starts a query: the warm start's selection and û, x = û. The state of a thread
  /// is reused by its queries (storage only: every field is set here or before use).
  void start(const GreedyActiveSet& solver, Query& query) {
    g = &solver, q = &query;
    u_hat = q->u_start, x = q->u_start, active = q->start_columns;
    in_active.assign(static_cast<size_t>(g->m_model.dictionary_size()), 0);
    for (int p : active) in_active[static_cast<size_t>(p)] = 1;
    mixer.reset(g->m_options.anderson_depth);
    seen.clear();
    solved.clear(), n_lambda = 0;
    pending = false, removed = added = -1, max_violation = 0.0;
    const int r = g->m_model.primal_rank();
    if (c_hat_i.cols() != r) c_hat_i.resize(0, r), w.resize(r, 0);  // another model: grown again by solve()
    q->surface_displacement(u_hat, u_s);
  }
  const GreedyActiveSet* g = nullptr;
  Query* q = nullptr;
  Eigen::VectorXd u_hat;
  Eigen::VectorXd x;    // where the operators are built (û^{k−1} in Alg. 1)
  Eigen::VectorXd u_s;  // Φ_s x + u_off,s
  Eigen::VectorXd gap, violation, rhs;
  // Ĉ_I, K̂⁻¹Ĉ_Iᵀ, S and λ̂_I in storage that only grows: the leading |I| rows/columns are used.
  RowMajorMatrix c_hat_i;
  Eigen::MatrixXd w, schur;
  Eigen::VectorXd lambda_storage;
  int n_lambda = 0;  // |I| of the last solve
  /// λ̂_I of the last solve.
  Eigen::VectorBlock<Eigen::VectorXd> lambda_i() { return lambda_storage.head(n_lambda); }
  SupportRows::RowsScratch rows;  // rows of C_R Φ_s shared by the selected columns
  std::vector<int> active, solved;  // the selection, and the one of the last solve
  std::vector<char> in_active;
  AndersonMixer mixer{0};  // of the rebuild point while the selection stays the same
  SelectionHistory seen;     // selections of the query so far
  bool pending = false;  // settled in the sense of Alg. 1: to be confirmed at û's fresh pairing
  int removed = -1, added = -1;  // the last step's change (positions in `solved` / columns)
  double max_violation = 0.0;

  /// After a rebuild at x = û where Alg. 1 had settled: Alg. 1 judged û with the
  /// operators of the previous point; whether every column (selected ones included)
  /// is within τ at the pairing of û itself. If not, iterating goes on with these
  /// operators.
  bool confirm() {
    if (!pending) return false;
    pending = false;
    return q->confirmed(u_s, gap, violation);
  }

  /// Step 2: the saddle-point system on I by its Schur complement S = Ĉ_I K̂⁻¹ Ĉ_Iᵀ,
  /// with the operators of the last rebuild. False on a non-finite value.
  bool solve() {
    const int na = static_cast<int>(active.size()), r = g->m_model.primal_rank();
    if (c_hat_i.rows() < na) {
      const int cap = std::max(2 * static_cast<int>(c_hat_i.rows()), std::max(na, 4));
      c_hat_i.resize(cap, r), w.resize(r, cap), schur.resize(cap, cap), rhs.resize(cap), lambda_storage.resize(cap);
    }
    // Rows of Ĉ_I = D_Iᵀ C_R Φ_s and entries of ĝ_I = D_Iᵀ (g_R − C_R u_off,s), from
    // the rows where each selected column is non-zero.
    q->operators.start();
    g->m_support.reduced_rows(active, q->ops.c, q->ops.g, g->m_model.surface_basis_rows(), q->off_s, c_hat_i, rhs, rows);
    q->operators.stop();
    n_lambda = na;
    if (na == 0) {
      u_hat = q->u_free;
    } else {
      const auto c_hat = c_hat_i.topRows(na);
      auto w_i = w.leftCols(na);
      q->k_inv.apply(c_hat.transpose(), w_i);  // K̂⁻¹ Ĉ_Iᵀ, r × |I|
      schur.topLeftCorner(na, na).noalias() = c_hat * w_i;
      for (int i = 0; i < na; ++i) rhs(i) = c_hat.row(i).dot(q->u_free) - rhs(i);  // Ĉ_I K̂⁻¹ f̂ − ĝ_I
      // |I| > r: min-norm
      schur_multipliers(schur.topLeftCorner(na, na), rhs.head(na), g->m_options.singular_tolerance, lambda_i());
      u_hat = q->u_free;
      u_hat.noalias() -= w_i * lambda_i();
    }
    solved = active;
    return u_hat.allFinite() && lambda_i().allFinite();
  }

  /// Step 3: one change — remove the most negative multiplier, else add the column
  /// most violated beyond τ (Ĉ û − ĝ = D_dᵀ (C_s u_s − g) for every column, with the
  /// operators of step 1). Returns whether the selection changed.
  bool one_change() {
    q->surface_displacement(u_hat, u_s);
    added = -1;
    max_violation = 0.0;
    removed = most_negative(lambda_i());
    if (removed >= 0) {
      in_active[static_cast<size_t>(active[removed])] = 0;
      active.erase(active.begin() + removed);
      return true;
    }
    g->m_support.violation(q->ops.c, q->ops.g, u_s, gap, violation);
    if (violation.size() > 0) max_violation = violation.maxCoeff();
    q->offer(max_violation, u_hat, lambda_i(), solved);
    added = most_violated(violation, in_active, g->m_threshold);
    if (added < 0) return false;
    in_active[static_cast<size_t>(added)] = 1;
    active.push_back(added);
    return true;
  }

  /// Step 4: Alg. 1's test (selection stable, û settled), then the next rebuild
  /// point. While the selection is unchanged and û still moves, the operators' fixed
  /// point in x is smooth and plain substitution may oscillate (the pairing's own
  /// fixed point, like the FOM's): x is Anderson-accelerated. A changed selection
  /// restarts the history; a settled û is confirmed at itself.
  void next_rebuild_point(bool changed) {
    pending = !changed && q->small_step(u_hat, x);
    if (changed || pending) {
      mixer.reset(g->m_options.anderson_depth);
      x = u_hat;
    } else {
      mixer.next(x, u_hat, x);
      if (x != u_hat) q->surface_displacement(x, u_s);  // else u_s is û's already
    }
  }

  /// One line per iteration for GreedyOptions::trace.
  void trace(int k, bool changed) {
    std::ostream* out = g->m_options.trace;
    if (!out) return;
    const int na = static_cast<int>(solved.size());
    *out << "greedy k=" << k + 1 << " |I|=" << na << " min(lambda)=" << (na ? lambda_i().minCoeff() : 0.0)
         << " max(violation)=" << max_violation << " step=" << (u_hat - x).norm() / std::max(u_hat.norm(), 1e-300)
         << " -> ";
    if (removed >= 0)
      *out << "remove " << solved[static_cast<size_t>(removed)];
    else if (changed)
      *out << "add " << added;
    else
      *out << "no change";
    *out << "\n";
  }

  /// A one-change step brought back a selection met before: one change per rebuild
  /// is cycling (each rebuild moves the operators under the steps, paper §4.1). The
  /// nested schedule settles the steps on frozen operators first; it goes on from
  /// here with the rebuilds left (k + 1 made).
  void hand_over_to_nested(OnlineResult& res, int k) {
    if (g->m_options.trace) *g->m_options.trace << "greedy: selection revisited, nested schedule from here\n";
    q->u_start = u_hat;
    q->start_columns = active;
    const int done = res.iterations;
    g->solve_nested(*q, res, g->m_options.max_iterations - k - 1);
    res.iterations += done;
  }
};

void GreedyActiveSet::solve_interleaved(Query& q, OnlineResult& res) const {
  thread_local Interleaved s;  // its storage serves the thread's next queries
  s.start(*this, q);
  const int k_max = m_options.max_iterations;
  for (int k = 0; k <= k_max; ++k) {
    // 1. Contact operators at x, from the surface rows only. Beyond Alg. 1, an
    //    iterate is returned only once the operators rebuilt at it confirm that no
    //    dictionary column (selected ones included) is violated by more than τ.
    q.rebuild(s.u_s);
    if (s.confirm()) {
      res.converged = true;
      break;
    }
    if (k == k_max) break;
    // 2. Saddle-point system on I.
    if (!s.solve()) {
      numerical_issue(res);
      break;
    }
    res.iterations = k + 1;
    // 3. One change.
    const bool changed = s.one_change();
    s.trace(k, changed);
    // 4. Settled (to be confirmed) or the next rebuild point; on a cycle, the nested schedule.
    s.next_rebuild_point(changed);
    if (changed && m_options.nested_on_cycle && k + 1 < k_max && revisits(s.seen, s.solved, s.active))
      return s.hand_over_to_nested(res, k);
  }
  q.finish(!res.converged && res.status == Status::Success, s.u_hat, s.lambda_i(), s.solved);
}

/// The nested schedule's state between its steps.
struct GreedyActiveSet::Nested {
  /// Starts a query: the start's selection and û, x = û. The state of a thread is
  /// reused by its queries (storage only: every field is set here or before use).
  void start(const GreedyActiveSet& solver, Query& query) {
    g = &solver, q = &query, dr = &solver.m_support.basis;
    x = q->u_start, u_hat = q->u_start;
    in_active.assign(static_cast<size_t>(g->m_model.dictionary_size()), 0);
    while (!cols.empty()) spare.push_back(std::move(cols.back())), cols.pop_back();
    for (int p : q->start_columns) {  // filled by make_column once the operators exist
      in_active[static_cast<size_t>(p)] = 1;
      take_spare().p = p;
    }
    mixer.reset(g->m_options.anderson_depth);
    seen.clear(), solved.clear();
    n_lambda = 0, pending = false, finite = true, solves = 0;
  }
  /// A selected column p with the operators frozen: its row Ĉ_p = d_pᵀ A of Ĉ_I,
  /// w_p = K̂⁻¹ Ĉ_pᵀ and z_p = D_dᵀ C_s Φ_s w_p, the change of every column's
  /// violation per unit λ̂_p (û = u_free − Σ λ̂_p w_p).
  struct Column {
    int p;
    Eigen::RowVectorXd c_hat;
    Eigen::MatrixXd w;  // r × 1
    Eigen::VectorXd z;
  };
  const GreedyActiveSet* g = nullptr;
  Query* q = nullptr;
  const Eigen::MatrixXd* dr = nullptr;  // D_d on the support rows R, |R| × m
  std::vector<Column> cols, spare;  // selected columns; unused ones, kept for their storage
  RowMajorMatrix a;        // A = C_R Φ_s (|R| × r)
  Eigen::VectorXd b;       // C_R u_off,s − g_R: A û + b is the gap on R
  Eigen::VectorXd v_free;  // every column's violation at u_free, D_Rᵀ (A u_free + b)
  Eigen::VectorXd gap, aw, violation, rhs, x, u_hat, u_s;
  Eigen::VectorXd u_s_hat;  // fixed-point schedule: surface displacement of û, Φ_s û + u_off,s
  // S and λ̂_I in storage that only grows: the leading |I| rows/columns are used.
  Eigen::MatrixXd schur;
  Eigen::VectorXd lambda_storage;
  int n_lambda = 0;  // |I| of the last solve
  std::vector<char> in_active;
  std::vector<int> solved;
  SelectionHistory seen;  // selections met on the current operators
  SupportRows::ResidualsScratch residuals_scratch;  // physically_converged
  std::vector<double> feasible;  // settle_exact: the non-negative multipliers of `cols`
  std::vector<int> blocked;      // settle_exact: columns not offered again on these operators
  AndersonMixer mixer{0};
  bool pending = false;  // settled: to be confirmed at the fresh pairing of û
  bool finite = true;    // every solve so far gave finite values
  int solves = 0;

  /// λ̂_I of the last solve.
  Eigen::VectorBlock<Eigen::VectorXd> lambda_i() { return lambda_storage.head(n_lambda); }
  /// Appends a column to the selection, in the storage of an unused one if any.
  Column& take_spare() {
    if (spare.empty()) spare.emplace_back();
    cols.push_back(std::move(spare.back()));
    spare.pop_back();
    return cols.back();
  }

  /// Fills `col` for dictionary column p on the current operators (its vectors keep
  /// their storage from one rebuild to the next).
  void make_column(Column& col, int p) {
    col.p = p;
    q->operators.start();  // Ĉ_p is the operator; w_p and z_p belong to the solve
    col.c_hat.setZero(g->m_model.primal_rank());
    for (int i : g->m_support.column_support[static_cast<size_t>(p)]) col.c_hat.noalias() += (*dr)(i, p) * a.row(i);
    q->operators.stop();
    q->k_inv.apply(col.c_hat.transpose(), col.w);
    aw.noalias() = a * col.w.col(0);
    col.z.resize(dr->cols());
    g->m_support.transpose_times(aw, col.z);
  }

  /// After a rebuild: A = C_R Φ_s, b = C_R u_off,s − g_R, every column's violation at
  /// u_free, and the selected columns' vectors.
  void freeze_operators() {
    q->operators.start();
    g->m_support.gap_operator(q->ops.c, q->ops.g, g->m_model.surface_basis_rows(), q->off_s, a, b);
    q->operators.stop();
    gap.noalias() = a * q->u_free;
    gap += b;
    v_free.resize(dr->cols());
    g->m_support.transpose_times(gap, v_free);
    for (auto& col : cols) make_column(col, col.p);
  }

  /// Step 2 on frozen operators: û, λ̂_I and every column's violation from the
  /// columns' vectors. False on a non-finite value.
  bool solve() {
    const int na = static_cast<int>(cols.size());
    u_hat = q->u_free;
    violation = v_free;
    if (schur.rows() < na) {
      const int cap = std::max(2 * static_cast<int>(schur.rows()), std::max(na, 4));
      schur.resize(cap, cap), rhs.resize(cap), lambda_storage.resize(cap);
    }
    n_lambda = na;
    if (na > 0) {
      auto lambda = lambda_i();
      for (int i = 0; i < na; ++i) {
        rhs(i) = v_free(cols[i].p);  // Ĉ_i u_free − ĝ_i
        for (int j = 0; j <= i; ++j) schur(i, j) = schur(j, i) = cols[i].c_hat.dot(cols[j].w.col(0));
      }
      schur_multipliers(schur.topLeftCorner(na, na), rhs.head(na), g->m_options.singular_tolerance, lambda);
      for (int i = 0; i < na; ++i) {
        u_hat.noalias() -= lambda(i) * cols[i].w.col(0);
        violation.noalias() -= lambda(i) * cols[i].z;
      }
    }
    ++solves;
    solved.resize(static_cast<size_t>(na));
    for (int i = 0; i < na; ++i) solved[static_cast<size_t>(i)] = cols[i].p;
    return u_hat.allFinite() && lambda_i().allFinite();
  }

  /// Steps 2–3 repeated on the frozen operators until nothing changes, a selection
  /// comes back (a cycle: rebuild) or the solve cap is reached. Returns whether the
  /// selection changed.
  bool settle(int rebuild) {
    bool changed = false;
    seen.clear();
    while (solves < g->m_options.max_solves) {
      if (!(finite = solve())) break;
      const int remove = most_negative(lambda_i());
      const double max_violation = violation.size() > 0 ? violation.maxCoeff() : 0.0;
      int add = -1;
      if (remove < 0) {
        q->offer(max_violation, u_hat, lambda_i(), solved);
        add = most_violated(violation, in_active, g->m_threshold);
      }
      trace_step(rebuild, remove, add, max_violation);
      if (remove >= 0) {
        in_active[static_cast<size_t>(cols[remove].p)] = 0;
        spare.push_back(std::move(cols[remove]));
        cols.erase(cols.begin() + remove);
      } else if (add >= 0) {
        in_active[static_cast<size_t>(add)] = 1;
        make_column(take_spare(), add);
      } else {
        break;
      }
      changed = true;
      if (seen.revisits(cols, [](const Column& col) { return col.p; })) break;  // met on these operators
    }
    return changed;
  }

  /// Step 4: settled on these operators and û close to where they were built:
  /// confirm at û's own pairing; else rebuild at the new point, Anderson-accelerated
  /// while the selection is unchanged (a smooth fixed point in x).
  void next_rebuild_point(bool changed, int rebuild) {
    const double step = (u_hat - x).norm(), size = u_hat.norm();
    if (g->m_options.trace)
      *g->m_options.trace << "greedy rebuild=" << rebuild << " step=" << step / std::max(size, 1e-300) << "\n";
    if (!changed && step <= g->m_options.step_tolerance * size) {
      pending = true;
      x = u_hat;
    } else if (!changed) {
      mixer.next(x, u_hat, x);
    } else {
      mixer.reset(g->m_options.anderson_depth);
      x = u_hat;
    }
  }

  /// Drops selected column i (position in `cols`) and its multiplier in `feasible`.
  void drop(int i) {
    in_active[static_cast<size_t>(cols[i].p)] = 0;
    spare.push_back(std::move(cols[i]));
    cols.erase(cols.begin() + i);
    if (static_cast<int>(feasible.size()) > i) feasible.erase(feasible.begin() + i);
  }

  /// The reduced problem on the frozen operators solved exactly (Lawson–Hanson on
  /// its dual, min_{λ̂ ≥ 0} ½ λ̂ᵀ S λ̂ − v_freeᵀ λ̂ over all columns, S = Ĉ K̂⁻¹ Ĉᵀ):
  /// the most violated column beyond τ enters with λ̂ = 0; when the equality solve on
  /// the selection gives a negative multiplier, the step from the feasible λ̂ towards
  /// it stops where the first multiplier reaches zero (the ratio test) and that column
  /// leaves. The multipliers stay non-negative, so no column is added and removed in
  /// turn, and the loop ends with λ̂ ≥ 0 and every unselected violation ≤ τ. A
  /// column that enters and leaves at once (dependent on the selection) is not tried
  /// again on these operators. Returns whether the selection changed.
  bool settle_exact(int rebuild) {
    bool changed = false;
    // A feasible start: the equality solve on the previous selection, its most
    // negative multiplier dropped until none is.
    for (;;) {
      if (!(finite = solve())) return changed;
      const int remove = most_negative(lambda_i());
      if (remove < 0) break;
      trace_step(rebuild, remove, -1, 0.0);
      drop(remove);
      changed = true;
    }
    feasible.assign(lambda_i().data(), lambda_i().data() + n_lambda);
    blocked.clear();
    while (solves < g->m_options.max_solves) {
      const double max_violation = violation.size() > 0 ? violation.maxCoeff() : 0.0;
      q->offer(max_violation, u_hat, lambda_i(), solved);
      const int add = most_violated(violation, in_active, g->m_threshold);
      trace_step(rebuild, -1, add, max_violation);
      if (add < 0) break;
      in_active[static_cast<size_t>(add)] = 1;
      make_column(take_spare(), add);
      feasible.push_back(0.0);
      changed = true;
      // Equality solves with the ratio test until the multipliers are non-negative.
      while (solves < g->m_options.max_solves) {
        if (!(finite = solve())) return changed;
        const auto z = lambda_i();
        if (z.size() == 0 || z.minCoeff() >= 0.0) break;
        double alpha = 1.0;
        int blocking = -1;
        for (int i = 0; i < z.size(); ++i)
          if (z(i) < 0.0) {
            const double a = feasible[static_cast<size_t>(i)] / (feasible[static_cast<size_t>(i)] - z(i));
            if (a < alpha || blocking < 0) alpha = a, blocking = i;
          }
        for (int i = 0; i < z.size(); ++i) feasible[static_cast<size_t>(i)] += alpha * (z(i) - feasible[static_cast<size_t>(i)]);
        for (int i = static_cast<int>(cols.size()) - 1; i >= 0; --i)
          if (i == blocking || feasible[static_cast<size_t>(i)] <= 0.0) {
            if (cols[i].p == add && alpha == 0.0) blocked.push_back(add);
            trace_step(rebuild, i, -1, 0.0);
            drop(i);
          }
      }
      feasible.assign(lambda_i().data(), lambda_i().data() + n_lambda);
      for (int p : blocked) in_active[static_cast<size_t>(p)] = 1;  // not offered again on these operators
    }
    for (int p : blocked) in_active[static_cast<size_t>(p)] = 0;
    for (const Column& col : cols) in_active[static_cast<size_t>(col.p)] = 1;
    return changed;
  }

  /// Physical test at the pairing of the last rebuild (made at û): on the support
  /// rows, the largest penetration and the separation under pressure of
  /// λ = D_d[:, I] λ̂_I, in units of U (fom/contact_residuals.hpp), within `tol`.
  bool physically_converged(const fom::ContactTolerances& tol) {
    const fom::ContactResiduals r =
        g->m_support.residuals(q->ops.c, q->ops.g, u_s, solved, lambda_i(), g->m_model.problem().contact().weights(),
                               g->m_model.problem().displacement_scale(), residuals_scratch);
    if (g->m_options.trace)
      *g->m_options.trace << "greedy physical test: penetration=" << r.penetration
                          << " U, separation under pressure=" << r.complementarity << " U\n";
    return r.gaps_within(tol);
  }

  void trace_step(int rebuild, int remove, int add, double max_violation) {
    std::ostream* out = g->m_options.trace;
    if (!out) return;
    const int na = static_cast<int>(cols.size());
    *out << "greedy rebuild=" << rebuild << " solve=" << solves << " |I|=" << na
         << " min(lambda)=" << (na ? lambda_i().minCoeff() : 0.0) << " max(violation)=" << max_violation << " -> ";
    if (remove >= 0)
      *out << "remove " << cols[remove].p;
    else if (add >= 0)
      *out << "add " << add;
    else
      *out << "no change";
    *out << "\n";
  }
};

void GreedyActiveSet::solve_nested(Query& q, OnlineResult& res, int max_rebuilds) const {
  thread_local Nested s;  // its storage serves the thread's next queries
  s.start(*this, q);
  for (int rebuild = 0;; ++rebuild) {
    // 1. Operators at x (surface rows only); a settled û is confirmed at its own pairing.
    q.surface_displacement(s.x, s.u_s);
    q.rebuild(s.u_s);
    if (s.pending) {
      if (q.confirmed(s.u_s, s.gap, s.violation)) {
        res.converged = true;
        break;
      }
      s.pending = false;
    }
    if (rebuild >= max_rebuilds || s.solves >= m_options.max_solves) break;
    s.freeze_operators();
    // 2–3. One-change steps on the frozen operators.
    const bool changed = s.settle(rebuild);
    if (!s.finite) {
      numerical_issue(res);
      break;
    }
    // 4. Settled, or the next rebuild point.
    s.next_rebuild_point(changed, rebuild);
  }
  res.iterations = s.solves;
  q.finish(!res.converged && res.status == Status::Success, s.u_hat, s.lambda_i(), s.solved);
}

void GreedyActiveSet::solve_fixed_point(Query& q, OnlineResult& res) const {
  thread_local Nested s;  // its storage serves the thread's next queries
  s.start(*this, q);
  // The greedy's side of the loop: û(x) by the exact one-change solve on the frozen
  // operators (settle_exact), x extrapolated by Anderson with one history.
  struct Loop {
    const GreedyActiveSet& g;
    Query& q;
    Nested& s;
    const fom::ContactTolerances tolerances;
    void rebuild(bool at_u_hat) {
      if (!at_u_hat) q.surface_displacement(s.x, s.u_s);  // else u_s is û's already
      q.rebuild(s.u_s);
    }
    bool physically_converged() { return s.physically_converged(tolerances); }
    int solves() const { return s.solves; }
    bool solve_frozen(int rebuild) {
      s.freeze_operators();
      s.settle_exact(rebuild);
      return s.finite;
    }
    double step() {
      q.surface_displacement(s.u_hat, s.u_s_hat);
      return surface_step(s.u_s_hat, s.u_s, g.m_model.problem().displacement_scale());
    }
    void accept() {
      s.x = s.u_hat;
      s.u_s.swap(s.u_s_hat);
    }
    void extrapolate() { s.mixer.next(s.x, s.u_hat, s.x); }
  } loop{*this, q, s, contact_tolerances()};
  const RebuildLimits limits{m_options.max_iterations, m_options.max_solves, m_options.surface_step};
  switch (run_rebuild_fixed_point(loop, limits, m_options.trace, "greedy")) {
    case RebuildOutcome::Converged: res.converged = true; break;
    case RebuildOutcome::NonFinite: numerical_issue(res); break;
    case RebuildOutcome::AtCap: break;
  }
  res.iterations = s.solves;
  q.finish(!res.converged && res.status == Status::Success, s.u_hat, s.lambda_i(), s.solved);
}

}  // namespace contactrom::rom
