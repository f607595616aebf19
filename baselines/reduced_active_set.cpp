#include <contactrom/baselines/reduced_active_set.hpp>

#include <contactrom/core/format.hpp>

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <contactrom/baselines/cpg.hpp>
#include <contactrom/baselines/full_dictionary.hpp>
#include <contactrom/baselines/online_methods.hpp>
#include <contactrom/rom/rebuild_fixed_point.hpp>
#include <contactrom/rom/selection_history.hpp>

namespace contactrom::baselines {

const rom::OptionTable<ReducedActiveSetOptions>& reduced_active_set_option_table() {
  static const rom::OptionTable<ReducedActiveSetOptions> t = [] {
    using O = ReducedActiveSetOptions;
    rom::OptionTable<O> o;
    o.include(rom::active_set_settings_table())
        .choice("init", &O::init, "starting point: empty, primal or cell",
                rom::warm_start_words({rom::WarmStart::Empty, rom::WarmStart::Primal, rom::WarmStart::Cell}))
        .choice("inner_solve", &O::inner_solve, "saddle-point solve: nonnegative or equality (textbook PDAS)",
                {{"nonnegative", InnerSolve::NonNegative}, {"equality", InnerSolve::Equality}})
        .choice("rebuild", &O::rebuild, "contact operators rebuilt on the changed rows only (partial) or all (full)",
                {{"partial", rom::OperatorRebuild::Partial}, {"full", rom::OperatorRebuild::Full}})
        .integer("anderson_depth", &O::anderson_depth, "Anderson depth of the rebuild point (0: plain)", 0, 1e6)
        .number("surface_step", &O::surface_step,
                "largest move of the contact surface (units of U) between the operators' point and the answer",
                Interval::greater_than(0))
        .integer("max_solves", &O::max_solves, "cap on the saddle-point solves of a query", 1, 1e9);
    return o;
  }();
  return t;
}

ReducedActiveSetOptions reduced_active_set_options(const rom::OnlineSolverOptions& options, const std::string& method) {
  return rom::read_options(reduced_active_set_option_table(), options, method, /*strict=*/false);
}

ReducedActiveSet::ReducedActiveSet(std::string name, const rom::ReducedModel& model, std::vector<int> dual_columns,
                                   const Options& options)
    : m_name(std::move(name)), m_model(model), m_columns(std::move(dual_columns)), m_options(options) {
  if (options.init == rom::WarmStart::Nearest)
    throw InputError(m_name + ": init must be empty, primal or cell");
  const int m = model.dictionary_size();
  std::vector<char> seen(m, 0);
  for (int p : m_columns) {
    if (p < 0 || p >= m)
      throw InputError("dual basis column " + std::to_string(p) + " out of range; the dictionary has " +
                       std::to_string(m) + " columns");
    if (seen[p]) throw InputError("dual basis column " + std::to_string(p) + " given twice");
    seen[p] = 1;
  }
  m_w.resize(model.dictionary().rows(), static_cast<Eigen::Index>(m_columns.size()));
  for (size_t i = 0; i < m_columns.size(); ++i) m_w.col(static_cast<Eigen::Index>(i)) = model.dictionary().col(m_columns[i]);
  // Support rows of W, as in the greedy: only they enter Ĉ and the violation.
  m_support = rom::SupportRows(m_w);
  if (options.max_iterations < 1)
    throw InputError("max iterations " + std::to_string(options.max_iterations) + " invalid; expected >= 1");
  // τ exactly as the greedy applies it (same default, same relative scale), so the
  // three methods are held to the same reduced constraint.
  rom::GreedyOptions g;
  g.tau = options.tau;
  g.tau_scaling = options.tau_scaling;
  m_threshold = rom::greedy_threshold(model, g);
  if (options.init == rom::WarmStart::Cell) {
    // Offline: this method's own (cold) solution at every training parameter, the
    // starting points of init = cell.
    std::vector<int> position(static_cast<size_t>(m), -1);
    for (size_t i = 0; i < m_columns.size(); ++i) position[static_cast<size_t>(m_columns[i])] = static_cast<int>(i);
    m_starts.resize(static_cast<size_t>(m));
    for (int c = 0; c < m; ++c) {
      rom::OnlineResult res;
      solve_from(model.dictionary_parameters()[static_cast<size_t>(c)], rom::WarmStart::Empty, res);
      Start& t = m_starts[static_cast<size_t>(c)];
      t.u_hat = res.u_hat;
      for (int p : res.selected) t.active.push_back(position[static_cast<size_t>(p)]);
    }
  }
}

void ReducedActiveSet::solve_reduced(const fom::Param& mu, rom::OnlineResult& res) const {
  solve_from(mu, m_options.init, res);
}

/// One query: the start at μ, the operators at the rebuild point x, the primal–dual
/// active set on them, and the storage its steps reuse.
struct ReducedActiveSet::Query : rom::ActiveSetStart {
  Query(const ReducedActiveSet& solver, const fom::Param& mu)
      : rom::ActiveSetStart(solver.m_model, mu),
        solver(solver),
        ops(solver.m_options.rebuild == rom::OperatorRebuild::Partial),
        operators(solver.m_options.time_operators),
        in_active(static_cast<size_t>(solver.m_w.cols()), 0),
        nnls(solver.m_options.nnls) {}

  const ReducedActiveSet& solver;
  rom::SupportOperators ops;    // pairing, C_R, g_R at the rebuild point
  rom::OperatorClock operators;  // time spent building the contact operators (optional)
  Eigen::VectorXd u_hat, lambda_i, u_s, v, violation, rhs;
  std::vector<int> start;  // the warm start's active set (positions in W)
  std::vector<int> active, next, solved;  // positions in W
  rom::SelectionHistory seen;             // active sets met on the current operators
  std::vector<char> in_active;
  rom::RowMajorMatrix c_hat_i;
  Eigen::MatrixXd z, schur;
  NnlsQp nnls;
  bool first = true;  // the warm start's set not used yet
  int solves = 0;

  /// Starting point: u_free (paper); the interpolated reduced coordinates of the
  /// training snapshots around μ (init = primal), the first active set then being the
  /// set of columns violated there; or (init = cell) this method's own solutions at
  /// those training parameters: their interpolated û and the union of their active sets.
  void start_at(const fom::Param& mu, rom::WarmStart init) {
    u_hat = u_start;
    if (init != rom::WarmStart::Cell || solver.m_starts.empty()) return;
    u_hat.setZero(solver.m_model.primal_rank());
    const std::vector<rom::ReducedModel::StencilPoint> stencil = solver.m_model.interpolation_stencil(mu);
    for (const auto& s : stencil) {
      const Start& t = solver.m_starts[static_cast<size_t>(s.column)];
      u_hat.noalias() += s.weight * t.u_hat;
      start.insert(start.end(), t.active.begin(), t.active.end());
    }
    nearest = rom::ReducedModel::nearest_column(stencil);
    std::sort(start.begin(), start.end());
    start.erase(std::unique(start.begin(), start.end()), start.end());
  }

  /// u_s = Φ_s x + u_off,s.
  void surface_displacement(const Eigen::VectorXd& x) {
    u_s.noalias() = solver.m_model.surface_basis() * x;
    u_s += off_s;
  }

  /// Step 1: the operators at x (surface rows only).
  /// `surface_known`: u_s already holds Φ_s x + u_off,s (x is the û whose step was just taken).
  void rebuild_operators(const Eigen::VectorXd& x, bool surface_known) {
    operators.start();
    if (!surface_known) surface_displacement(x);
    ops.rebuild(solver.m_model.problem().contact(), solver.m_support, u_s);
    operators.stop();
  }

  /// The physical test of the last solve at the operators just rebuilt at û itself:
  /// its gaps within the contact tolerances.
  bool gaps_within(const fom::ContactTolerances& tolerances, rom::SupportRows::ResidualsScratch& scratch) const {
    const fom::Problem& problem = solver.m_model.problem();
    return solver.m_support
        .residuals(ops.c, ops.g, u_s, solved, lambda_i, problem.contact().weights(), problem.displacement_scale(), scratch)
        .gaps_within(tolerances);
  }

  /// Step 2: û(x) by the primal–dual active set on the frozen operators, until its
  /// set is stable and every column is within τ at û. Returns false on a non-finite
  /// solve.
  bool solve_on_frozen_operators(rom::OnlineResult& res) {
    bool solved_here = false;
    seen.clear();
    while (solves < solver.m_options.max_solves) {
      if (!next_active_set(solved_here)) break;
      solve_saddle_point();
      solved = active;
      solved_here = true;
      res.iterations = ++solves;
      if (!(u_hat.allFinite() && lambda_i.allFinite())) return false;
    }
    return true;
  }

  /// The next active set from the violation of every column at û,
  /// Ĉû − ĝ = Wᵀ(C_R u_s − g_R): the columns whose multiplier left the cone drop out,
  /// every violated column comes in. With the non-negative inner solve a zero
  /// multiplier on a still-violated column keeps it (dropping and re-adding it would
  /// cycle). Returns false when the set is stable with every column within τ, or when
  /// it was met before on these operators (the primal–dual steps cycle: a column
  /// whose multiplier is zero leaves and is violated again; û(x) is then the last
  /// solve and the outer loop goes on from there).
  bool next_active_set(bool solved_here) {
    const int mw = static_cast<int>(solver.m_w.cols());
    const double threshold = solver.m_threshold;
    const bool nonnegative = solver.m_options.inner_solve == InnerSolve::NonNegative;
    surface_displacement(u_hat);
    solver.m_support.violation(ops.c, ops.g, u_s, v, violation);
    next.clear();
    if (first) next = start;  // the warm start's set (empty otherwise)
    for (size_t i = 0; i < active.size(); ++i) {
      const double l = lambda_i(static_cast<Eigen::Index>(i));
      const bool keep = nonnegative ? (l > 0.0 || violation(active[i]) > threshold) : l >= 0.0;
      if (keep) next.push_back(active[i]);
    }
    if (!first || start.empty())
      for (int p = 0; p < mw; ++p)
        if (!in_active[p] && violation(p) > threshold) next.push_back(p);
    const double worst = mw ? violation.maxCoeff() : -std::numeric_limits<double>::infinity();
    if (solved_here && next == active && worst <= threshold) return false;
    std::sort(next.begin(), next.end());
    if (seen.revisits(next, [](int p) { return p; })) return false;
    first = false;
    for (int p : active) in_active[p] = 0;
    active.swap(next);
    for (int p : active) in_active[p] = 1;
    return true;
  }

  /// The saddle-point system on the active set I by its Schur complement
  /// S = Ĉ_I K̂⁻¹ Ĉ_Iᵀ: û = u_free − K̂⁻¹Ĉ_Iᵀ λ̂_I.
  void solve_saddle_point() {
    const int na = static_cast<int>(active.size());
    if (na == 0) {
      u_hat = u_free;
      lambda_i.resize(0);
      return;
    }
    const rom::ReducedModel& model = solver.m_model;
    c_hat_i.resize(na, model.primal_rank());
    rhs.resize(na);
    // Rows of Ĉ_I = W_Iᵀ C_R Φ_s and entries of ĝ_I = W_Iᵀ (g_R − C_R u_off,s),
    // as in the greedy: from the rows where each active column is non-zero.
    operators.start();
    for (int i = 0; i < na; ++i)
      rhs(i) = solver.m_support.reduced_row(active[i], ops.c, ops.g, model.surface_basis_rows(), off_s, c_hat_i.row(i));
    operators.stop();
    k_inv.apply(c_hat_i.transpose(), z);  // K̂⁻¹ Ĉ_Iᵀ
    schur.noalias() = c_hat_i * z;
    rhs = c_hat_i * u_free - rhs;
    if (solver.m_options.inner_solve == InnerSolve::NonNegative) {
      // min ½ λᵀ S λ − rhsᵀ λ, λ ≥ 0: the saddle-point system on I with the sign
      // condition imposed (Lawson–Hanson; dependent rows are never freed together).
      nnls.compute(schur);
      lambda_i = nnls.solve(rhs);
      if (nnls.info() == Status::InvalidInput) lambda_i = Eigen::VectorXd::Constant(na, std::numeric_limits<double>::quiet_NaN());
    } else {
      lambda_i = rom::schur_multipliers(schur, rhs, solver.m_options.singular_tolerance);
    }
    u_hat.noalias() = u_free - z * lambda_i;
  }

  /// The answer: û, and the support, the columns of the last solve with a non-zero
  /// multiplier, as dictionary columns.
  void report(rom::OnlineResult& res) const {
    res.u_hat = u_hat;
    res.coefficients.resize(static_cast<Eigen::Index>(solved.size()));
    for (size_t i = 0; i < solved.size(); ++i) {
      const double l = lambda_i(static_cast<Eigen::Index>(i));
      if (l == 0.0) continue;
      res.coefficients(static_cast<Eigen::Index>(res.selected.size())) = l;
      res.selected.push_back(solver.m_columns[solved[i]]);
    }
    res.coefficients.conservativeResize(static_cast<Eigen::Index>(res.selected.size()));
    res.lambda = solver.m_model.reconstruct_dual(res.selected, res.coefficients);
    res.operator_time_s = operators.total();
  }
};

void ReducedActiveSet::solve_from(const fom::Param& mu, rom::WarmStart init, rom::OnlineResult& res) const {
  Query q(*this, mu);
  if (!q.begin(m_model, mu, init == rom::WarmStart::Primal ? init : rom::WarmStart::Empty, res)) return;
  q.start_at(mu, init);
  // Warm-started, the first search starts from the one made offline at the nearest
  // training snapshot, as the greedy's does (same pairing as a full search).
  q.seed(m_model, q.ops);

  // The fixed point x ↦ û(x) of the greedy's default schedule (rom/rebuild_fixed_point.hpp),
  // with this method's own solve on the frozen operators: û(x) by the primal–dual
  // active set on them until its set is stable; x extrapolated by Anderson, one
  // history over the query.
  struct Loop {
    Query& q;
    rom::OnlineResult& res;
    const fom::ContactTolerances tolerances;
    AndersonMixer mixer;
    Eigen::VectorXd x, x_s;  // where the operators are built, and its surface displacement
    rom::SupportRows::ResidualsScratch scratch;
    void rebuild(bool at_u_hat) {
      q.rebuild_operators(x, at_u_hat);  // at û, u_s is the one step() computed
      x_s = q.u_s;
    }
    bool physically_converged() { return q.gaps_within(tolerances, scratch); }
    int solves() const { return q.solves; }
    bool solve_frozen(int) { return q.solve_on_frozen_operators(res); }
    double step() {
      q.operators.start();  // surface displacements count as operator time, as in the greedy
      q.surface_displacement(q.u_hat);
      q.operators.stop();
      return rom::surface_step(q.u_s, x_s, q.solver.m_model.problem().displacement_scale());
    }
    void accept() { x = q.u_hat; }
    void extrapolate() { mixer.next(x, q.u_hat, x); }
  } loop{q, res, contact_tolerances(), AndersonMixer(m_options.anderson_depth), q.u_hat, {}, {}};
  const rom::RebuildLimits limits{m_options.max_iterations, m_options.max_solves, m_options.surface_step};
  switch (rom::run_rebuild_fixed_point(loop, limits)) {
    case rom::RebuildOutcome::Converged: res.converged = true; break;
    case rom::RebuildOutcome::NonFinite:
      res.status = Status::NumericalIssue;
      res.message = "reduced saddle-point solve produced a non-finite value";
      break;
    case rom::RebuildOutcome::AtCap: break;
  }
  q.report(res);
  if (res.status == Status::Success && !res.converged)
    res.message = m_name + " active set did not converge in " + std::to_string(m_options.max_iterations) +
                  " operator rebuilds (or " + std::to_string(m_options.max_solves) + " solves)";
}

double reduced_penetration(const rom::ReducedModel& model, const std::vector<int>& columns, const Eigen::VectorXd& u) {
  const fom::ContactModel& contact = model.problem().contact();
  const Eigen::VectorXd us = contact.restrict_to_surface(u);
  fom::ConstraintMatrix c;
  Eigen::VectorXd g;
  contact.assemble(contact.search(us), c, g);
  const Eigen::VectorXd v = c * us - g;
  double worst = -std::numeric_limits<double>::infinity();
  for (int p : columns) worst = std::max(worst, model.dictionary().col(p).dot(v));
  return worst;
}

}  // namespace contactrom::baselines
