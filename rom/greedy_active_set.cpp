#include "rom/greedy_active_set.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <ostream>
#include <string>
#include <utility>

#include "core/anderson.hpp"

namespace contactrom::rom {

namespace {

/// Integer greedy setting `key` = `value`, at least `minimum`.
int greedy_int_option(const std::string& key, const std::string& value, int minimum) {
  const long long v = parse_option_integer("greedy", key, value);
  if (v < minimum || v > 1000000000)
    throw InputError("greedy option " + key + " = '" + value + "' invalid; expected an integer >= " +
                     std::to_string(minimum));
  return static_cast<int>(v);
}

/// Greedy setting `key` = `value`, one of the named `choices`.
template <class T>
T greedy_choice(const std::string& key, const std::string& value,
                std::initializer_list<std::pair<const char*, T>> choices) {
  std::string names;
  for (const auto& [name, v] : choices) {
    if (value == name) return v;
    names += (names.empty() ? "" : " or ") + std::string(name);
  }
  throw InputError("greedy option " + key + " = '" + value + "' unknown; expected " + names);
}

/// Alg. 1's elimination: position of the most negative multiplier, −1 if none is.
int most_negative(const Eigen::VectorXd& lambda) {
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

/// Selections met one after the other (each stored sorted), to detect a cycle of
/// one-change steps. Its storage only grows, so clearing it does not free.
class SelectionHistory {
 public:
  void clear() { m_seen.clear(), m_start.assign(1, 0); }
  bool empty() const { return m_start.size() == 1; }
  /// Whether `selection` (any order) was met since the last clear(); records it if not.
  template <class Columns, class Index>
  bool revisits(const Columns& selection, Index index) {
    m_key.clear();
    for (const auto& c : selection) m_key.push_back(index(c));
    std::sort(m_key.begin(), m_key.end());
    for (size_t e = 0; e + 1 < m_start.size(); ++e)
      if (std::equal(m_key.begin(), m_key.end(), m_seen.begin() + m_start[e], m_seen.begin() + m_start[e + 1]))
        return true;
    m_seen.insert(m_seen.end(), m_key.begin(), m_key.end());
    m_start.push_back(static_cast<int>(m_seen.size()));
    return false;
  }

 private:
  std::vector<int> m_seen, m_start{0}, m_key;
};

/// Records a one-change step from selection `before` to `after`; true when `after`
/// was met before (a cycle).
bool revisits(SelectionHistory& seen, const std::vector<int>& before, const std::vector<int>& after) {
  const auto same = [](int p) { return p; };
  if (seen.empty()) (void)seen.revisits(before, same);
  return seen.revisits(after, same);
}

}  // namespace

WarmStart parse_warm_start(const std::string& method, const std::string& text) {
  if (text == "empty") return WarmStart::Empty;
  if (text == "cell") return WarmStart::Cell;
  if (text == "nearest") return WarmStart::Nearest;
  if (text == "primal") return WarmStart::Primal;
  throw InputError(method + " option init = '" + text + "' unknown; expected empty, cell, nearest or primal");
}

void warm_start_point(const ReducedModel& model, WarmStart init, const fom::Param& mu,
                      const Eigen::VectorXd& u_free, std::vector<int>& columns, Eigen::VectorXd& u_hat) {
  columns.clear();
  if (init == WarmStart::Empty || model.dictionary_size() == 0) {
    u_hat = u_free;
    return;
  }
  std::vector<ReducedModel::StencilPoint> stencil = model.interpolation_stencil(mu);
  if (init == WarmStart::Nearest) {
    const auto heaviest = std::max_element(stencil.begin(), stencil.end(), [](const auto& a, const auto& b) {
      return a.weight < b.weight;
    });
    stencil = {{heaviest->column, 1.0}};
  }
  // (A quadratic stencil for û, tried on hertz 30, needed more pairing updates on
  // average: the solutions are not smooth in μ where nodes enter contact.)
  if (init != WarmStart::Primal)
    for (const auto& s : stencil) columns.push_back(s.column);
  const Eigen::MatrixXd& coords = model.snapshot_coordinates();
  u_hat.setZero(model.primal_rank());
  for (const auto& s : stencil) u_hat.noalias() += s.weight * coords.col(s.column);
}

GreedyOptions greedy_options(const OnlineSolverOptions& options) {
  GreedyOptions g;
  g.tau = options.tau;
  if (options.tau_scaling == "absolute")
    g.tau_scaling = TauScaling::Absolute;
  else if (options.tau_scaling == "relative")
    g.tau_scaling = TauScaling::Relative;
  else
    throw InputError("tau scaling '" + options.tau_scaling + "' unknown; expected absolute or relative");
  if (options.max_iterations < 1)
    throw InputError("max iterations " + std::to_string(options.max_iterations) + " invalid; expected >= 1");
  if (!(options.step_tolerance >= 0.0))
    throw InputError("step tolerance " + std::to_string(options.step_tolerance) + " invalid; expected >= 0");
  g.max_iterations = options.max_iterations;
  g.step_tolerance = options.step_tolerance;
  g.time_operators = options.time_operators;
  for (const auto& [key, value] : options.extra) {
    if (key == "schedule") {
      g.schedule = greedy_choice<GreedySchedule>(
          key, value, {{"interleaved", GreedySchedule::Interleaved}, {"nested", GreedySchedule::Nested}});
    } else if (key == "anderson_depth") {
      g.anderson_depth = greedy_int_option(key, value, 0);
    } else if (key == "max_solves") {
      g.max_solves = greedy_int_option(key, value, 1);
    } else if (key == "init") {
      g.init = parse_warm_start("greedy", value);
    } else if (key == "rebuild") {
      g.rebuild = greedy_choice<OperatorRebuild>(
          key, value, {{"partial", OperatorRebuild::Partial}, {"full", OperatorRebuild::Full}});
    } else if (key == "on_cycle") {
      g.nested_on_cycle = greedy_choice<bool>(key, value, {{"nested", true}, {"continue", false}});
    }
  }
  return g;
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
struct GreedyActiveSet::Query {
  Query(const ReducedModel& model, const fom::Param& mu, bool time_operators)
      : k_inv(model, mu), operators(time_operators) {}
  ReducedStiffnessInverse k_inv;  // K̂(μ)⁻¹
  OperatorClock operators;  // time spent building the contact operators (optional)
  Eigen::VectorXd lift_s;  // surface lifting u_off,s(μ)
  Eigen::VectorXd u_free;  // unconstrained reduced solution K̂⁻¹ f̂
  Eigen::VectorXd u_start;  // starting û (GreedyOptions::init)
  std::vector<int> start_columns;  // starting selection
  // Outcome, filled by the schedule: final û, the selection and its multipliers.
  Eigen::VectorXd u_hat, lambda_i;
  std::vector<int> selected;
  bool best_iterate_returned = false;  // not converged: the best iterate replaced the last one

  /// Best iterate with λ̂ ≥ 0 so far (smallest largest violation), for the iteration cap.
  struct {
    bool valid = false;
    double violation = 0.0;
    Eigen::VectorXd u_hat, lambda_i;
    std::vector<int> selected;
  } best;
  void offer(double max_violation, const Eigen::VectorXd& u, const Eigen::VectorXd& l, const std::vector<int>& s) {
    if (best.valid && max_violation >= best.violation) return;
    best.valid = true;
    best.violation = max_violation;
    best.u_hat = u;
    best.lambda_i = l;
    best.selected = s;
  }
  /// Stores the outcome: the last iterate, or the best one when `use_best` and one exists.
  void finish(bool use_best, Eigen::VectorXd& u, Eigen::VectorXd& l, std::vector<int>& s) {
    if (use_best && best.valid) {
      u.swap(best.u_hat);
      l.swap(best.lambda_i);
      s.swap(best.selected);
      best_iterate_returned = true;
    }
    u_hat = std::move(u);
    lambda_i = std::move(l);
    selected = std::move(s);
  }
};

OnlineResult GreedyActiveSet::solve(const fom::Param& mu) const {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const int r = m_model.primal_rank(), nc = static_cast<int>(m_model.dictionary().rows());

  OnlineResult res;
  res.mu = mu;

  // K̂(μ)⁻¹ through the offline factor when K̂(μ) = θ₀(μ) K̂₀, else a per-query
  // factorisation of the r × r matrix.
  Query q(m_model, mu, m_options.time_operators);
  if (!q.k_inv.ok()) {
    res.status = Status::NumericalIssue;
    res.message = "Cholesky factorisation of the reduced stiffness failed";
    res.u_hat = Eigen::VectorXd::Zero(r);
    res.lambda = Eigen::VectorXd::Zero(nc);
    res.u = m_model.reconstruct_primal(res.u_hat, mu);
    res.time_s = std::chrono::duration<double>(clock::now() - t0).count();
    return res;
  }
  q.lift_s = m_model.surface_lifting(mu);
  q.u_free = q.k_inv.solve(m_model.reduced_rhs(mu));
  warm_start_point(m_model, m_options.init, mu, q.u_free, q.start_columns, q.u_start);

  if (m_options.schedule == GreedySchedule::Nested)
    solve_nested(q, res, m_options.max_iterations);
  else
    solve_interleaved(q, res);

  res.u_hat = std::move(q.u_hat);
  res.selected = std::move(q.selected);
  res.coefficients = std::move(q.lambda_i);
  res.lambda = m_model.reconstruct_dual(res.selected, res.coefficients);
  if (res.status == Status::Success && !res.converged) {
    res.status = Status::NoConvergence;
    const bool nested = m_options.schedule == GreedySchedule::Nested;
    res.message = "greedy active set did not converge in " + std::to_string(m_options.max_iterations) +
                  (nested ? " operator rebuilds (or " + std::to_string(m_options.max_solves) + " solves)" : " iterations") +
                  (q.best_iterate_returned ? "; best iterate with non-negative multipliers returned" : "");
  }
  const auto t1 = clock::now();
  res.time_s = std::chrono::duration<double>(t1 - t0).count();
  res.operator_time_s = q.operators.total();
  res.u = m_model.reconstruct_primal(res.u_hat, mu);
  res.reconstruction_time_s = std::chrono::duration<double>(clock::now() - t1).count();
  return res;
}

Eigen::VectorXd schur_multipliers(const Eigen::Ref<const Eigen::MatrixXd>& schur,
                                  const Eigen::Ref<const Eigen::VectorXd>& rhs, double singular_tolerance) {
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 16, 16>;
  thread_local Eigen::LDLT<Small> small;
  thread_local Eigen::LDLT<Eigen::MatrixXd> large;
  if (schur.rows() <= 16) {
    small.compute(schur);
    if (small.info() == Eigen::Success && small.rcond() > singular_tolerance) return small.solve(rhs);
  } else {
    large.compute(schur);
    if (large.info() == Eigen::Success && large.rcond() > singular_tolerance) return large.solve(rhs);
  }
  return schur.completeOrthogonalDecomposition().solve(rhs);
}

bool GreedyActiveSet::confirmed(const Eigen::VectorXd& violation) const {
  const double worst = violation.size() > 0 ? violation.maxCoeff() : 0.0;
  if (m_options.trace) *m_options.trace << "greedy check at fresh pairing: max(violation)=" << worst << "\n";
  return worst <= m_threshold;
}

void GreedyActiveSet::solve_interleaved(Query& q, OnlineResult& res) const {
  const fom::ContactModel& contact = m_model.problem().contact();
  const Eigen::MatrixXd& phi_s = m_model.surface_basis();
  const RowMajorMatrix& phi_s_rows = m_model.surface_basis_rows();
  const int r = m_model.primal_rank(), m = m_model.dictionary_size();
  const Eigen::VectorXd &u_free = q.u_free, &lift_s = q.lift_s;

  Eigen::VectorXd u_hat = q.u_start, lambda_i, v, violation, rhs;
  // Ĉ_I, K̂⁻¹Ĉ_Iᵀ and S in storage that only grows: the leading |I| rows/columns are used.
  RowMajorMatrix c_hat_i;
  Eigen::MatrixXd w, schur;
  SupportOperators ops(m_options.rebuild == OperatorRebuild::Partial);  // pairing, C_R and g_R at the previous iterate
  std::vector<int> active = q.start_columns, solved;
  std::vector<char> in_active(m, 0);
  for (int p : active) in_active[p] = 1;
  // Surface displacement of the current iterate, u_s = Φ_s û + u_off,s: the only
  // place the primal enters the contact operators.
  Eigen::VectorXd u_s = phi_s * u_hat + lift_s;
  // Where the operators are built (x = û^{k−1} in Alg. 1), and the Anderson mixer
  // of that point while the selection stays the same.
  Eigen::VectorXd x = u_hat;
  fom::AndersonMixer mixer(m_options.anderson_depth);

  bool pending = false;  // converged in the sense of Alg. 1, to be confirmed
  SelectionHistory seen;  // selections of the query so far
  for (int k = 0; k <= m_options.max_iterations; ++k) {
    // 1. Contact operators at the previous iterate, from the surface rows only.
    q.operators.start();
    ops.rebuild(contact, m_support, u_s);
    q.operators.stop();
    if (pending) {
      // Alg. 1 found no change and a settled û^k, but judged û^k with the operators
      // of û^{k−1}. Confirm at the pairing of û^k itself that no dictionary column
      // is violated by more than τ (selected columns included), so the returned
      // solution meets the reduced constraint at its own pairing; else go on.
      m_support.violation(ops.c, ops.g, u_s, v, violation);
      if (confirmed(violation)) {
        res.converged = true;
        break;
      }
      pending = false;
    }
    if (k == m_options.max_iterations) break;
    const int na = static_cast<int>(active.size());
    if (c_hat_i.rows() < na) {
      const int cap = std::max(2 * static_cast<int>(c_hat_i.rows()), std::max(na, 4));
      c_hat_i.resize(cap, r), w.resize(r, cap), schur.resize(cap, cap), rhs.resize(cap);
    }
    // Rows of Ĉ_I = D_Iᵀ C_R Φ_s and entries of ĝ_I = D_Iᵀ (g_R − C_R u_off,s), from
    // the rows where each selected column is non-zero.
    q.operators.start();
    for (int i = 0; i < na; ++i) rhs(i) = m_support.reduced_row(active[i], ops.c, ops.g, phi_s_rows, lift_s, c_hat_i.row(i));
    q.operators.stop();

    // 2. Saddle-point system by its Schur complement S = Ĉ_I K̂⁻¹ Ĉ_Iᵀ.
    if (na == 0) {
      u_hat = u_free;
      lambda_i.resize(0);
    } else {
      const auto c_hat = c_hat_i.topRows(na);
      auto w_i = w.leftCols(na);
      q.k_inv.apply(c_hat.transpose(), w_i);  // K̂⁻¹ Ĉ_Iᵀ, r × |I|
      schur.topLeftCorner(na, na).noalias() = c_hat * w_i;
      for (int i = 0; i < na; ++i) rhs(i) = c_hat.row(i).dot(u_free) - rhs(i);  // Ĉ_I K̂⁻¹ f̂ − ĝ_I
      // |I| > r: min-norm
      lambda_i = schur_multipliers(schur.topLeftCorner(na, na), rhs.head(na), m_options.singular_tolerance);
      u_hat.noalias() = u_free - w_i * lambda_i;
    }
    solved = active;
    res.iterations = k + 1;
    if (!u_hat.allFinite() || !lambda_i.allFinite()) {
      res.status = Status::NumericalIssue;
      res.message = "reduced saddle-point solve produced a non-finite value";
      break;
    }
    q.operators.start();
    u_s.noalias() = phi_s * u_hat;
    u_s += lift_s;
    q.operators.stop();

    // 3. One change: remove the most negative multiplier, else add the column most
    //    correlated with the thresholded violation.
    bool changed = false;
    double max_violation = 0.0;
    const int remove = most_negative(lambda_i);
    if (remove >= 0) {
      in_active[active[remove]] = 0;
      active.erase(active.begin() + remove);
      changed = true;
    } else {
      // Ĉ û − ĝ for every column = D_dᵀ (C_s u_s − g), from the support rows, with
      // the operators of step 1.
      m_support.violation(ops.c, ops.g, u_s, v, violation);
      if (m > 0) max_violation = violation.maxCoeff();
      if (m_options.best_iterate_on_failure) q.offer(max_violation, u_hat, lambda_i, solved);
      const int add = most_violated(violation, in_active, m_threshold);
      if (add >= 0) {
        in_active[add] = 1;
        active.push_back(add);
        changed = true;
      }
    }

    // 4. Converged when the active set is stable and û no longer moves.
    const double step = (u_hat - x).norm(), size = u_hat.norm();
    if (m_options.trace) {
      *m_options.trace << "greedy k=" << k + 1 << " |I|=" << na << " min(lambda)=" << (na ? lambda_i.minCoeff() : 0.0)
                       << " max(violation)=" << max_violation << " step=" << step / std::max(size, 1e-300) << " -> ";
      if (remove >= 0)
        *m_options.trace << "remove " << solved[remove];
      else if (changed)
        *m_options.trace << "add " << active.back();
      else
        *m_options.trace << "no change";
      *m_options.trace << "\n";
    }
    if (!changed && step <= m_options.step_tolerance * size) pending = true;
    next_rebuild_point(changed || pending, u_hat, x, mixer, u_s, q);
    if (changed && m_options.nested_on_cycle && k + 1 < m_options.max_iterations && revisits(seen, solved, active)) {
      // A selection came back: one change per rebuild is cycling (each rebuild
      // moves the operators under the steps, paper §4.1). The nested schedule
      // settles the steps on frozen operators first; it goes on from here.
      if (m_options.trace) *m_options.trace << "greedy: selection revisited, nested schedule from here\n";
      q.u_start = u_hat;
      q.start_columns = active;
      const int done = res.iterations;
      solve_nested(q, res, m_options.max_iterations - k - 1);
      res.iterations += done;
      return;
    }
  }

  q.finish(!res.converged && res.status == Status::Success, u_hat, lambda_i, solved);
}

void GreedyActiveSet::next_rebuild_point(bool plain, const Eigen::VectorXd& u_hat, Eigen::VectorXd& x,
                                         fom::AndersonMixer& mixer, Eigen::VectorXd& u_s, Query& q) const {
  // The selection is unchanged and û still moves: the operators' fixed point in x
  // is smooth there, and plain substitution may oscillate (the pairing's own
  // fixed point, like the FOM's); Anderson acceleration extrapolates it. A
  // changed selection restarts the history; a settled û is confirmed at itself.
  if (plain) {
    mixer = fom::AndersonMixer(m_options.anderson_depth);
    x = u_hat;
    return;
  }
  x = mixer.next(x, u_hat);
  q.operators.start();
  u_s.noalias() = m_model.surface_basis() * x;
  u_s += q.lift_s;
  q.operators.stop();
}

void GreedyActiveSet::solve_nested(Query& q, OnlineResult& res, int max_rebuilds) const {
  const fom::ContactModel& contact = m_model.problem().contact();
  const Eigen::MatrixXd& phi_s = m_model.surface_basis();
  const RowMajorMatrix& phi_s_rows = m_model.surface_basis_rows();
  const Eigen::MatrixXd& dr = m_support.basis;  // D_d on the support rows R, |R| × m
  const int r = m_model.primal_rank(), m = m_model.dictionary_size();
  const Eigen::VectorXd &u_free = q.u_free, &lift_s = q.lift_s;

  // A selected column p with the operators frozen: its row Ĉ_p = d_pᵀ A of Ĉ_I,
  // w_p = K̂⁻¹ Ĉ_pᵀ and z_p = D_dᵀ C_s Φ_s w_p, the change of every column's
  // violation per unit λ̂_p (û = u_free − Σ λ̂_p w_p).
  struct Column {
    int p;
    Eigen::RowVectorXd c_hat;
    Eigen::MatrixXd w;  // r × 1
    Eigen::VectorXd z;
  };
  std::vector<Column> cols, spare;  // selected columns; removed ones, kept for their storage
  RowMajorMatrix a;  // A = C_R Φ_s (|R| × r)
  Eigen::VectorXd b;       // C_R u_off,s − g_R: A û + b is the gap on R
  Eigen::VectorXd v_free;  // every column's violation at u_free, D_Rᵀ (A u_free + b)
  Eigen::VectorXd gap, aw, violation, lambda_i, rhs, x = q.u_start, u_hat = q.u_start;
  Eigen::MatrixXd schur;
  SupportOperators ops(m_options.rebuild == OperatorRebuild::Partial);  // pairing, C_R and g_R at the rebuild point x
  Eigen::VectorXd u_s;
  std::vector<char> in_active(m, 0);
  std::vector<int> solved;
  SelectionHistory seen;  // selections met on the current operators
  fom::AndersonMixer mixer(m_options.anderson_depth);
  for (int p : q.start_columns) {  // filled by make_column once the operators exist
    in_active[p] = 1;
    cols.emplace_back();
    cols.back().p = p;
  }

  // Fills `col` for dictionary column p on the current operators (its vectors keep
  // their storage from one rebuild to the next).
  auto make_column = [&](Column& col, int p) {
    col.p = p;
    q.operators.start();  // Ĉ_p is the operator; w_p and z_p belong to the solve
    col.c_hat.setZero(r);
    for (int i : m_support.column_support[static_cast<size_t>(p)]) col.c_hat.noalias() += dr(i, p) * a.row(i);
    q.operators.stop();
    q.k_inv.apply(col.c_hat.transpose(), col.w);
    aw.noalias() = a * col.w.col(0);
    col.z.noalias() = dr.transpose() * aw;
  };

  bool pending = false;  // settled: to be confirmed at the fresh pairing of û
  int solves = 0;
  for (int rebuild = 0;; ++rebuild) {
    // 1. Operators at x (surface rows only), A = C_R Φ_s and b.
    q.operators.start();
    u_s.noalias() = phi_s * x;
    u_s += lift_s;
    ops.rebuild(contact, m_support, u_s);
    q.operators.stop();
    if (pending) {  // x = û: is every column (selected ones included) within τ here?
      m_support.violation(ops.c, ops.g, u_s, gap, violation);
      if (confirmed(violation)) {
        res.converged = true;
        break;
      }
      pending = false;
    }
    if (rebuild >= max_rebuilds || solves >= m_options.max_solves) break;
    q.operators.start();
    m_support.gap_operator(ops.c, ops.g, phi_s_rows, lift_s, a, b);  // A = C_R Φ_s, b = C_R u_off,s − g_R
    q.operators.stop();
    gap.noalias() = a * u_free;
    gap += b;
    v_free.noalias() = dr.transpose() * gap;
    for (auto& col : cols) make_column(col, col.p);

    // 2–3. One-change steps on the frozen operators until nothing changes, a
    //      selection comes back (cycle) or the solve cap is reached.
    bool changed = false;
    seen.clear();
    while (solves < m_options.max_solves) {
      const int na = static_cast<int>(cols.size());
      u_hat = u_free;
      violation = v_free;
      lambda_i.resize(na);
      if (na > 0) {
        if (schur.rows() < na) {  // storage that only grows; the leading |I| entries are used
          const int cap = std::max(2 * static_cast<int>(schur.rows()), std::max(na, 4));
          schur.resize(cap, cap), rhs.resize(cap);
        }
        for (int i = 0; i < na; ++i) {
          rhs(i) = v_free(cols[i].p);  // Ĉ_i u_free − ĝ_i
          for (int j = 0; j <= i; ++j) schur(i, j) = schur(j, i) = cols[i].c_hat.dot(cols[j].w.col(0));
        }
        lambda_i = schur_multipliers(schur.topLeftCorner(na, na), rhs.head(na), m_options.singular_tolerance);
        for (int i = 0; i < na; ++i) {
          u_hat.noalias() -= lambda_i(i) * cols[i].w.col(0);
          violation.noalias() -= lambda_i(i) * cols[i].z;
        }
      }
      ++solves;
      solved.resize(static_cast<size_t>(na));
      for (int i = 0; i < na; ++i) solved[static_cast<size_t>(i)] = cols[i].p;
      if (!u_hat.allFinite() || !lambda_i.allFinite()) {
        res.status = Status::NumericalIssue;
        res.message = "reduced saddle-point solve produced a non-finite value";
        break;
      }

      const int remove = most_negative(lambda_i);
      const double max_violation = m > 0 ? violation.maxCoeff() : 0.0;
      int add = -1;
      if (remove < 0) {
        if (m_options.best_iterate_on_failure) q.offer(max_violation, u_hat, lambda_i, solved);
        add = most_violated(violation, in_active, m_threshold);
      }
      if (m_options.trace) {
        *m_options.trace << "greedy rebuild=" << rebuild << " solve=" << solves << " |I|=" << na
                         << " min(lambda)=" << (na ? lambda_i.minCoeff() : 0.0) << " max(violation)=" << max_violation
                         << " -> ";
        if (remove >= 0)
          *m_options.trace << "remove " << cols[remove].p;
        else if (add >= 0)
          *m_options.trace << "add " << add;
        else
          *m_options.trace << "no change";
        *m_options.trace << "\n";
      }
      if (remove >= 0) {
        in_active[cols[remove].p] = 0;
        spare.push_back(std::move(cols[remove]));
        cols.erase(cols.begin() + remove);
      } else if (add >= 0) {
        in_active[add] = 1;
        if (spare.empty()) spare.emplace_back();
        cols.push_back(std::move(spare.back()));
        spare.pop_back();
        make_column(cols.back(), add);
      } else {
        break;
      }
      changed = true;
      // This selection was met before on these operators: rebuild them.
      if (seen.revisits(cols, [](const Column& col) { return col.p; })) break;
    }
    if (res.status != Status::Success) break;

    // 4. Settled on these operators and û close to where they were built: confirm
    //    at the pairing of û itself; else rebuild at the (accelerated) new point.
    const double step = (u_hat - x).norm(), size = u_hat.norm();
    if (m_options.trace)
      *m_options.trace << "greedy rebuild=" << rebuild << " step=" << step / std::max(size, 1e-300) << "\n";
    if (!changed && step <= m_options.step_tolerance * size) {
      pending = true;
      x = u_hat;
    } else if (!changed) {
      x = mixer.next(x, u_hat);  // same selection: a smooth fixed point in x
    } else {
      mixer = fom::AndersonMixer(m_options.anderson_depth);
      x = u_hat;
    }
  }
  res.iterations = solves;

  q.finish(!res.converged && res.status == Status::Success, u_hat, lambda_i, solved);
}

}  // namespace contactrom::rom
