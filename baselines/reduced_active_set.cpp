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
#include <contactrom/rom/selection_history.hpp>

namespace contactrom::baselines {

const rom::OptionTable<ReducedActiveSetOptions>& reduced_active_set_option_table() {
  static const rom::OptionTable<ReducedActiveSetOptions> t = [] {
    using O = ReducedActiveSetOptions;
    rom::OptionTable<O> o;
    o.include(rom::active_set_settings_table())
        .choice("init", &O::init, "starting point: empty, primal or cell",
                {{"empty", rom::WarmStart::Empty}, {"primal", rom::WarmStart::Primal}, {"cell", rom::WarmStart::Cell}})
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
      const rom::OnlineResult res = solve_from(model.dictionary_parameters()[static_cast<size_t>(c)], rom::WarmStart::Empty);
      Start& t = m_starts[static_cast<size_t>(c)];
      t.u_hat = res.u_hat;
      for (int p : res.selected) t.active.push_back(position[static_cast<size_t>(p)]);
    }
  }
}

rom::OnlineResult ReducedActiveSet::solve_reduced(const fom::Param& mu) const { return solve_from(mu, m_options.init); }

rom::OnlineResult ReducedActiveSet::solve_from(const fom::Param& mu, rom::WarmStart init) const {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const fom::Problem& problem = m_model.problem();
  const fom::ContactModel& contact = problem.contact();
  const Eigen::MatrixXd& phi_s = m_model.surface_basis();
  const int r = m_model.primal_rank(), mw = static_cast<int>(m_w.cols()), nc = static_cast<int>(m_w.rows());

  rom::OnlineResult res;
  res.mu = mu;

  // K̂(μ)⁻¹ as in the greedy: the offline factor when K̂(μ) = θ₀(μ) K̂₀.
  const rom::ReducedStiffnessInverse k_inv(m_model, mu);
  if (!k_inv.ok()) {
    res.status = Status::NumericalIssue;
    res.message = "Cholesky factorisation of the reduced stiffness failed";
    res.u_hat = Eigen::VectorXd::Zero(r);
    res.lambda = Eigen::VectorXd::Zero(nc);
    res.u = m_model.reconstruct_primal(res.u_hat, mu);
    res.time_s = std::chrono::duration<double>(clock::now() - t0).count();
    return res;
  }

  const Eigen::VectorXd f_hat = m_model.reduced_rhs(mu);
  const Eigen::VectorXd lift_s = m_model.surface_lifting(mu);
  const Eigen::VectorXd u_free = k_inv.solve(f_hat);

  const rom::RowMajorMatrix& phi_s_rows = m_model.surface_basis_rows();
  // Starting point: u_free (paper); the interpolated reduced coordinates of the
  // training snapshots around μ (init = primal), the first active set then being the
  // set of columns violated there; or (init = cell) this method's own solutions at
  // those training parameters: their interpolated û and the union of their active sets.
  Eigen::VectorXd u_hat, lambda_i, u_s, v, violation, rhs;
  std::vector<int> start;  // positions in W
  int nearest = -1;        // training snapshot nearest to the start (−1: cold)
  if (init == rom::WarmStart::Cell && !m_starts.empty()) {
    u_hat.setZero(r);
    const std::vector<rom::ReducedModel::StencilPoint> stencil = m_model.interpolation_stencil(mu);
    for (const auto& s : stencil) {
      const Start& t = m_starts[static_cast<size_t>(s.column)];
      u_hat.noalias() += s.weight * t.u_hat;
      start.insert(start.end(), t.active.begin(), t.active.end());
    }
    nearest = rom::ReducedModel::nearest_column(stencil);
    std::sort(start.begin(), start.end());
    start.erase(std::unique(start.begin(), start.end()), start.end());
  } else {
    std::vector<int> unused;
    rom::warm_start_point(m_model, init == rom::WarmStart::Primal ? init : rom::WarmStart::Empty, mu, u_free,
                          unused, u_hat, &nearest);
  }
  rom::RowMajorMatrix c_hat_i;
  Eigen::MatrixXd z, schur;
  rom::SupportOperators ops(m_options.rebuild == rom::OperatorRebuild::Partial);  // pairing, C_R, g_R at û
  // Warm-started, the first search starts from the one made offline at the nearest
  // training snapshot, as the greedy's does (same pairing as a full search).
  if (nearest >= 0) ops.seed(m_model.snapshot_search_memory(nearest));
  std::vector<int> active, next, solved;  // positions in W
  rom::SelectionHistory seen;             // active sets met on the current operators
  std::vector<char> in_active(mw, 0);
  NnlsQp nnls(m_options.nnls);
  const bool nonnegative = m_options.inner_solve == InnerSolve::NonNegative;
  rom::OperatorClock operators(m_options.time_operators);

  // The fixed point x ↦ û(x) of the greedy's default schedule (rom::GreedySchedule::
  // FixedPoint), with this method's own solve on the frozen operators: operators
  // built at x; û(x) by the primal–dual active set on them until its set is stable;
  // x Anderson-accelerated (one history over the query) until the contact surface
  // moves by at most surface_step; then the physical test at û's own pairing.
  const fom::ContactTolerances tolerances = contact_tolerances();
  const double scale = problem.displacement_scale();
  rom::SupportRows::ResidualsScratch scratch;
  AndersonMixer mixer(m_options.anderson_depth);
  Eigen::VectorXd x = u_hat;  // where the operators are built
  bool pending = false, failed_test = false, first = true;
  int solves = 0;
  for (int rebuild = 0;; ++rebuild) {
    // 1. Operators at x (surface rows only); where x = û, the physical test at û's own pairing.
    operators.start();
    u_s.noalias() = phi_s * x;
    u_s += lift_s;
    ops.rebuild(contact, m_support, u_s);
    operators.stop();
    if (pending) {
      const fom::ContactResiduals r =
          m_support.residuals(ops.c, ops.g, u_s, solved, lambda_i, contact.weights(), scale, scratch);
      // Failing twice in a row: a fixed point of the reduced problem (see the greedy).
      if (r.gaps_within(tolerances) || failed_test) {
        res.converged = true;
        break;
      }
      failed_test = true;
    } else {
      failed_test = false;
    }
    pending = false;
    if (rebuild >= m_options.max_iterations || solves >= m_options.max_solves) break;

    // 2. û(x): primal–dual active set on the frozen operators, until its set is stable
    //    and every column is within τ at û.
    bool finite = true, solved_here = false;
    seen.clear();
    while (solves < m_options.max_solves) {
      // Violation of every column at the current û, Ĉû − ĝ = Wᵀ(C_R u_s − g_R).
      u_s.noalias() = phi_s * u_hat;
      u_s += lift_s;
      m_support.violation(ops.c, ops.g, u_s, v, violation);
      // Drop the columns whose multiplier left the cone, add every violated column.
      // With the non-negative inner solve a zero multiplier on a still-violated
      // column keeps it (dropping and re-adding it would cycle).
      next.clear();
      if (first) next = start;  // the warm start's set (empty otherwise)
      for (size_t i = 0; i < active.size(); ++i) {
        const double l = lambda_i(static_cast<Eigen::Index>(i));
        const bool keep = nonnegative ? (l > 0.0 || violation(active[i]) > m_threshold) : l >= 0.0;
        if (keep) next.push_back(active[i]);
      }
      if (!first || start.empty())
        for (int p = 0; p < mw; ++p)
          if (!in_active[p] && violation(p) > m_threshold) next.push_back(p);
      const double worst = mw ? violation.maxCoeff() : -std::numeric_limits<double>::infinity();
      if (solved_here && next == active && worst <= m_threshold) break;
      // A set met before on these operators: the primal–dual steps cycle (a column
      // whose multiplier is zero leaves and is violated again); û(x) is taken as the
      // last solve and the outer loop goes on from there.
      std::sort(next.begin(), next.end());
      if (seen.revisits(next, [](int p) { return p; })) break;
      first = false;
      for (int p : active) in_active[p] = 0;
      active.swap(next);
      for (int p : active) in_active[p] = 1;

      // Saddle-point system on I by its Schur complement S = Ĉ_I K̂⁻¹ Ĉ_Iᵀ.
      const int na = static_cast<int>(active.size());
      if (na == 0) {
        u_hat = u_free;
        lambda_i.resize(0);
      } else {
        c_hat_i.resize(na, r);
        rhs.resize(na);
        // Rows of Ĉ_I = W_Iᵀ C_R Φ_s and entries of ĝ_I = W_Iᵀ (g_R − C_R u_lift,s),
        // as in the greedy: from the rows where each active column is non-zero.
        operators.start();
        for (int i = 0; i < na; ++i) rhs(i) = m_support.reduced_row(active[i], ops.c, ops.g, phi_s_rows, lift_s, c_hat_i.row(i));
        operators.stop();
        k_inv.apply(c_hat_i.transpose(), z);  // K̂⁻¹ Ĉ_Iᵀ
        schur.noalias() = c_hat_i * z;
        rhs = c_hat_i * u_free - rhs;
        if (nonnegative) {
          // min ½ λᵀ S λ − rhsᵀ λ, λ ≥ 0: the saddle-point system on I with the sign
          // condition imposed (Lawson–Hanson; dependent rows are never freed together).
          nnls.compute(schur);
          lambda_i = nnls.solve(rhs);
          if (nnls.info() == Status::InvalidInput) lambda_i = Eigen::VectorXd::Constant(na, std::numeric_limits<double>::quiet_NaN());
        } else {
          lambda_i = rom::schur_multipliers(schur, rhs, m_options.singular_tolerance);
        }
        u_hat.noalias() = u_free - z * lambda_i;
      }
      solved = active;
      solved_here = true;
      res.iterations = ++solves;
      if (!(finite = u_hat.allFinite() && lambda_i.allFinite())) break;
    }
    if (!finite) {
      res.status = Status::NumericalIssue;
      res.message = "reduced saddle-point solve produced a non-finite value";
      break;
    }
    // 3. The next point: û itself once the surface moved by at most surface_step
    //    (then tested at its own pairing), else the Anderson extrapolation.
    if (rom::surface_step(m_model, u_hat, x) <= m_options.surface_step) {
      pending = true;
      x = u_hat;
    } else {
      mixer.next(x, u_hat, x);
    }
  }

  res.u_hat = u_hat;
  // Report the support: columns of the last solve with a non-zero multiplier.
  res.coefficients.resize(static_cast<Eigen::Index>(solved.size()));
  for (size_t i = 0; i < solved.size(); ++i) {
    const double l = lambda_i(static_cast<Eigen::Index>(i));
    if (l == 0.0) continue;
    res.coefficients(static_cast<Eigen::Index>(res.selected.size())) = l;
    res.selected.push_back(m_columns[solved[i]]);
  }
  res.coefficients.conservativeResize(static_cast<Eigen::Index>(res.selected.size()));
  res.lambda = m_model.reconstruct_dual(res.selected, res.coefficients);
  if (res.status == Status::Success && !res.converged) {
    res.status = Status::NoConvergence;
    res.message = m_name + " active set did not converge in " + std::to_string(m_options.max_iterations) +
                  " operator rebuilds (or " + std::to_string(m_options.max_solves) + " solves)";
  }
  const auto t1 = clock::now();
  res.time_s = std::chrono::duration<double>(t1 - t0).count();
  res.operator_time_s = operators.total();
  res.u = m_model.reconstruct_primal(u_hat, mu);
  res.reconstruction_time_s = std::chrono::duration<double>(clock::now() - t1).count();
  return res;
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
