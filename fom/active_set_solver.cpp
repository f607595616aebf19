#include <contactrom/fom/active_set_solver.hpp>

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <chrono>
#include <utility>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/parallel_for.hpp>
#include <contactrom/core/stopwatch.hpp>
#include <contactrom/fom/contact_zone.hpp>
#include <contactrom/fom/delassus.hpp>
#include <contactrom/fom/pairing_fixed_point.hpp>
#include <contactrom/fom/rigid_bodies.hpp>

namespace contactrom::fom {
namespace {

/// The dual QP of one pairing on a working set W of rows (see
/// ActiveSetOptions::working_set_margin): rows active or, at the iterate x, within
/// the margin of contact. The QP is solved on W; rows outside W are then checked at
/// the solution and the violated ones join W (repeat), so λ solves the QP of all
/// rows while the Delassus matrix is only |W| x |W|. `lambda` carries the
/// multipliers from one pairing to the next (working set and warm start).
class WorkingSetQp {
 public:
  WorkingSetQp(const Problem& problem, const Condensation& cond, const ActiveSetOptions& options,
               Eigen::VectorXd u0_s, Eigen::VectorXd lambda)
      : m_contact(problem.contact()), m_cond(cond), m_options(options), m_qp(options.qp),
        m_margin(options.working_set_margin * problem.displacement_scale()), m_u0_s(std::move(u0_s)),
        m_lambda(std::move(lambda)) {}

  /// Solves at the pairing whose operator is c, g; adds the QP's iterations to `iterations`.
  PairedSolution solve(const Pairing& pairing, const ConstraintMatrix& c, const Eigen::VectorXd& g,
                       const Eigen::VectorXd& x, int& iterations) {
    PairedSolution out;
    const int nc = m_contact.num_constraints();
    const Eigen::VectorXd h = c * m_u0_s - g;
    select_working_set(pairing, c * x - g);
    // Rows outside W must not penetrate at the QP's solution, to the QP's tolerance
    // (relative to |h|∞; W's part of h is no larger).
    const double tol = m_options.qp.relative_tolerance * (nc > 0 ? h.cwiseAbs().maxCoeff() : 0.0);
    for (;;) {
      const Eigen::VectorXd lambda_w = solve_on_working_set(c, h, iterations);
      if (!m_w_rows.empty() && m_qp.info() != Status::Success) {
        out.status = m_qp.info();
        break;
      }
      out.surface_displacement = m_u0_s - m_sct * lambda_w;
      if (!grow_working_set(pairing, c * out.surface_displacement - g, tol)) {
        m_lambda.setZero();
        for (size_t a = 0; a < m_w_rows.size(); ++a) m_lambda(m_w_rows[a]) = lambda_w(a);
        break;
      }
      for (Eigen::Index a = 0; a < lambda_w.size(); ++a) m_lambda(m_w_rows[a]) = lambda_w(a);
      m_w_rows.clear();
      for (int s = 0; s < nc; ++s)
        if (m_in_w[s]) m_w_rows.push_back(s);
    }
    out.lambda = m_lambda;
    return out;
  }

  /// Status of the last failed QP (for the message).
  Status qp_info() const { return m_qp.info(); }

 private:
  bool paired(const Pairing& pairing, int s) const { return !m_contact.has_pairing() || pairing.segment[s] >= 0; }

  void select_working_set(const Pairing& pairing, const Eigen::VectorXd& gap) {
    const int nc = m_contact.num_constraints();
    const bool all_rows = m_options.working_set_margin < 0.0;
    m_in_w.assign(nc, 0);
    m_w_rows.clear();
    for (int s = 0; s < nc; ++s)
      if (paired(pairing, s) && (all_rows || m_lambda(s) > 0.0 || gap(s) > -m_margin * m_contact.weights()(s)))
        m_in_w[s] = 1, m_w_rows.push_back(s);
  }

  /// λ_W of the QP on W (G_W = C_W S C_Wᵀ, h_W), warm-started from the current λ;
  /// leaves S C_Wᵀ in m_sct.
  Eigen::VectorXd solve_on_working_set(const ConstraintMatrix& c, const Eigen::VectorXd& h, int& iterations) {
    delassus_parts(c, m_w_rows, m_cond.s, m_sct);
    const int nw = static_cast<int>(m_w_rows.size());
    if (nw == 0) return Eigen::VectorXd();
    const Eigen::MatrixXd g_w = delassus(c, m_w_rows, m_sct);
    Eigen::VectorXd h_w(nw), warm_w(nw);
    for (int a = 0; a < nw; ++a) h_w(a) = h(m_w_rows[a]), warm_w(a) = m_lambda(m_w_rows[a]);
    Eigen::VectorXd lambda_w = m_qp.solve(g_w, h_w, {}, warm_w);
    iterations += m_qp.iterations();
    return lambda_w;
  }

  /// Adds the paired rows outside W that penetrate (gap v > tol); returns whether any did.
  bool grow_working_set(const Pairing& pairing, const Eigen::VectorXd& v, double tol) {
    bool grown = false;
    for (int s = 0; s < m_contact.num_constraints(); ++s)
      if (!m_in_w[s] && paired(pairing, s) && v(s) > tol) m_in_w[s] = 1, grown = true;
    return grown;
  }

  const ContactModel& m_contact;
  const Condensation& m_cond;
  const ActiveSetOptions& m_options;
  DualQpSolver m_qp;
  double m_margin;
  Eigen::VectorXd m_u0_s, m_lambda;
  std::vector<char> m_in_w;
  std::vector<int> m_w_rows;
  Eigen::MatrixXd m_sct;  // S C_Wᵀ, n_s x |W|
};

}  // namespace

bool condense(const Problem& problem, const Param& mu, Condensation& out, const std::vector<int>* order) {
  const std::vector<int>& free = problem.free_dofs();
  const int n = problem.num_dofs(), nf = static_cast<int>(free.size());
  std::vector<int> free_index(n, -1);
  for (int i = 0; i < nf; ++i) free_index[free[i]] = i;
  const SparseMatrix k = problem.stiffness(mu);
  Condensation cond;
  cond.free_dofs = free;

  // The free surface dofs are eliminated last, so S is the inverse of the Schur
  // complement held in the factor's trailing block.
  const std::vector<int>& surf = problem.contact().surface_dofs();
  const int ns = static_cast<int>(surf.size()), nt = problem.num_load_terms();
  std::vector<int> last, last_of_free(nf, -1);
  cond.surface_position.assign(ns, -1);
  for (int j = 0; j < ns; ++j) {
    const int f = free_index[surf[j]];
    if (f < 0) continue;
    if (last_of_free[f] < 0) last_of_free[f] = static_cast<int>(last.size()), last.push_back(f);
    cond.surface_position[j] = last_of_free[f];
  }
  cond.factor = std::make_unique<SparseCholesky>();
  const SparseMatrix kff = free_block(k, free_index, nf);
  if (order) cond.factor->compute(kff, last, *order);
  if (!order || cond.factor->info() == Status::InvalidInput) cond.factor->compute(kff, last);  // order of another size
  if (cond.factor->info() != Status::Success) return false;
  const Eigen::MatrixXd s_free = cond.factor->inverse_block();
  if (s_free.rows() != static_cast<Eigen::Index>(last.size())) return false;
  const std::vector<int>& pos = cond.surface_position;
  cond.s = Eigen::MatrixXd::Zero(ns, ns);
  for (int b = 0; b < ns; ++b)
    for (int a = 0; a < ns; ++a)
      if (pos[a] >= 0 && pos[b] >= 0) cond.s(a, b) = s_free(pos[a], pos[b]);

  // Unconstrained solutions of the load terms, lifting included.
  Eigen::MatrixXd rhs(nf, nt);
  for (int t = 0; t < nt; ++t) {
    const Eigen::VectorXd r = problem.external_load_terms()[t] - k * problem.lifting_terms()[t];
    for (int i = 0; i < nf; ++i) rhs(i, t) = r(free[i]);
  }
  const Eigen::MatrixXd x = cond.factor->solve(rhs);
  if (x.rows() != nf || !x.allFinite() || !cond.s.allFinite()) return false;
  cond.z_load = Eigen::MatrixXd::Zero(n, nt);
  for (int i = 0; i < nf; ++i) cond.z_load.row(free[i]) = x.row(i);
  for (int t = 0; t < nt; ++t) cond.z_load.col(t) += problem.lifting_terms()[t];
  out = std::move(cond);
  return true;
}

PairedSolution solve_at_pairing(const Problem& problem, const Condensation& cond, const ActiveSetOptions& options,
                                const Eigen::VectorXd& u0_s, const Pairing& pairing, const ConstraintMatrix& c,
                                const Eigen::VectorXd& g, const Eigen::VectorXd& x_s,
                                const Eigen::VectorXd& lambda_start, int& iterations) {
  WorkingSetQp qp(problem, cond, options, u0_s, lambda_start);
  return qp.solve(pairing, c, g, x_s, iterations);
}

PairingFixedPointResult solve_pairing_loop(const Problem& problem, const Condensation& cond,
                                           const ActiveSetOptions& options,
                                           const PairingFixedPointOptions& fixed_point, const Eigen::VectorXd& u0_s,
                                           const Eigen::VectorXd& x_s, Pairing pairing,
                                           const Eigen::VectorXd& lambda_start, int& iterations,
                                           const SearchMemory* memory, int* zone_iterations) {
  const ContactModel& contact = problem.contact();
  WorkingSetQp qp(problem, cond, options, u0_s, lambda_start);
  int zone_steps = 0;
  PairingFixedPointResult fp = solve_pairing_fixed_point(
      contact, problem.displacement_scale(), x_s, std::move(pairing), fixed_point,
      [&](const Pairing& p, const ConstraintMatrix& c, const Eigen::VectorXd& g, const Eigen::VectorXd& xk) {
        return qp.solve(p, c, g, xk, iterations);
      },
      [&](const PairedSolution& at, const Pairing& next, const SearchMemory& search_memory, Pairing& out) {
        return contact_zone_step(contact, cond.s, u0_s, problem.displacement_scale(), at, next, search_memory,
                                 options.zone, out, zone_steps);
      },
      memory ? *memory : SearchMemory());
  if (zone_iterations) *zone_iterations += zone_steps;
  return fp;
}

Eigen::MatrixXd unconstrained_load_responses(const Problem& problem, const Param& mu) {
  check_rigid_motions_held(problem);
  Condensation cond;
  if (!condense(problem, mu, cond)) throw InputError(singular_stiffness_message(problem));
  return std::move(cond.z_load);
}

Eigen::VectorXd Condensation::surface_response(const Eigen::VectorXd& surface_force) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(factor->trailing_size());
  for (size_t j = 0; j < surface_position.size(); ++j)
    if (surface_position[j] >= 0) f(surface_position[j]) += surface_force(j);
  const Eigen::VectorXd x = factor->solve_trailing(f);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(z_load.rows());
  for (size_t i = 0; i < free_dofs.size(); ++i) u(free_dofs[i]) = x(i);
  return u;
}

ActiveSetSolver::ActiveSetSolver(const Problem& problem, ActiveSetOptions options)
    : m_problem(problem), m_options(options) {
  // Before any factorisation: a rigid motion left free has no unique answer, and
  // in floating point the factorisation may well succeed on it.
  check_rigid_motions_held(problem);
  const auto t0 = std::chrono::steady_clock::now();
  if (!problem.stiffness_is_constant()) {
    // K(μ) changes with μ, its sparsity pattern does not: order the dofs once, here,
    // and let every query's factorisation reuse the order (it redoes the symbolic
    // analysis on its own matrix, so the order only affects the cost).
    Condensation probe;
    if (condense(problem, 0.5 * (problem.param_lower() + problem.param_upper()), probe))
      m_order = probe.factor->permutation();
    m_setup_time = seconds_since(t0);
    return;
  }
  m_constant = std::make_unique<Condensation>();
  Param mid = 0.5 * (problem.param_lower() + problem.param_upper());
  // A stiffness that cannot be factorised is a problem definition error (a body
  // held by nothing), not a numerical accident of one query.
  if (!condense(problem, mid, *m_constant)) throw InputError(singular_stiffness_message(problem));
  m_setup_time = seconds_since(t0);
}

FomSolution ActiveSetSolver::solve(const Param& mu, const FomSolution* warm) const {
  m_problem.check_param(mu);
  const ContactModel& contact = m_problem.contact();
  // A previous solution that fits: its λ, and its contact response u − u0 at its own
  // parameter (one without its parameter counts as one at this parameter).
  const bool use_warm = warm && warm->lambda.size() == contact.num_constraints() && warm->u.size() == m_problem.num_dofs();
  const auto response = [&](const Condensation& cond) -> Eigen::VectorXd {
    const Param& at = warm->mu.size() == mu.size() ? warm->mu : mu;
    return contact.restrict_to_surface(warm->u - cond.z_load * m_problem.load_coefficients(at));
  };
  const auto solve_one = [&](const Condensation& cond) {
    const Eigen::VectorXd r = use_warm ? response(cond) : Eigen::VectorXd();
    std::vector<ContactAnswer> one;
    one.push_back(contact_answer(cond, mu, use_warm ? &r : nullptr, use_warm ? &warm->lambda : nullptr));
    return std::move(finish(cond, std::move(one)).front());
  };
  if (m_constant) return solve_one(*m_constant);
  const auto t0 = std::chrono::steady_clock::now();
  Condensation cond;
  if (!condense(m_problem, mu, cond, m_order.empty() ? nullptr : &m_order)) {
    FomSolution s;
    s.mu = mu;
    s.status = Status::NumericalIssue;
    s.message = singular_stiffness_message(m_problem);
    return s;
  }
  FomSolution s = solve_one(cond);
  s.time_s = seconds_since(t0);  // includes the per-parameter factorisation
  return s;
}

ContactAnswer ActiveSetSolver::solve_contact(const Param& mu, const ContactAnswer* previous) const {
  m_problem.check_param(mu);
  const bool warm = previous && previous->solution.status == Status::Success;
  if (!m_constant) {  // a factorisation per query: solve() does it all, finish() has nothing left
    ContactAnswer a;
    a.solution = solve(mu, warm ? &previous->solution : nullptr);
    return a;
  }
  const bool fits =
      warm && previous->response_s.size() == static_cast<Eigen::Index>(m_problem.contact().surface_dofs().size());
  return contact_answer(*m_constant, mu, fits ? &previous->response_s : nullptr,
                        fits ? &previous->solution.lambda : nullptr);
}

std::vector<FomSolution> ActiveSetSolver::finish(std::vector<ContactAnswer> answers) const {
  if (m_constant) return finish(*m_constant, std::move(answers));
  std::vector<FomSolution> out;
  for (ContactAnswer& a : answers) out.push_back(std::move(a.solution));
  return out;
}

ContactAnswer ActiveSetSolver::contact_answer(const Condensation& cond, const Param& mu,
                                              const Eigen::VectorXd* response_s, const Eigen::VectorXd* lambda) const {
  const auto t0 = std::chrono::steady_clock::now();
  const ContactModel& contact = m_problem.contact();
  ContactAnswer a;
  FomSolution& sol = a.solution;
  sol.mu = mu;
  // 1. The unconstrained solution u0(μ): a combination of the condensed load terms.
  const Eigen::VectorXd u0_s = contact.restrict_to_surface(cond.z_load * m_problem.load_coefficients(mu));
  // 2. Start from u0, or from u0 plus a neighbour's contact response, with its multipliers.
  const Eigen::VectorXd x = response_s ? Eigen::VectorXd(u0_s + *response_s) : u0_s;
  // 3. The pairing fixed point around the exact dual QP of each pairing.
  const PairingFixedPointOptions fixed_point = pairing_options(m_options);
  PairingFixedPointResult fp =
      solve_pairing_loop(m_problem, cond, m_options, fixed_point, u0_s, x, contact.search(x),
                         lambda ? *lambda : Eigen::VectorXd::Zero(contact.num_constraints()), sol.iterations,
                         nullptr, &sol.zone_iterations);
  sol.pairing_iterations = fp.iterations;
  sol.status = fp.status;
  if (fp.solution.status != Status::Success)
    sol.message = "dual active-set QP failed: " + std::string(to_string(fp.solution.status));
  else if (fp.status != Status::Success)
    sol.message = pairing_no_convergence_message(fp, fixed_point);
  sol.lambda = std::move(fp.solution.lambda);
  sol.pairing = std::move(fp.pairing);
  a.c = std::move(fp.c);
  if (fp.solution.surface_displacement.size() == u0_s.size()) a.response_s = fp.solution.surface_displacement - u0_s;
  sol.time_s = seconds_since(t0);
  return a;
}

std::vector<FomSolution> ActiveSetSolver::finish(const Condensation& cond, std::vector<ContactAnswer> answers) const {
  // 4. The displacements u = u0 − K⁻¹ E_s Cᵀλ: one solve with the factor for all the
  //    answers that carry pressure, then each certified.
  const auto t0 = std::chrono::steady_clock::now();
  const int m = cond.factor->trailing_size();
  std::vector<int> loaded;
  for (size_t i = 0; i < answers.size(); ++i) {
    FomSolution& sol = answers[i].solution;
    sol.active = static_cast<int>((sol.lambda.array() > 0.0).count());
    if (sol.active > 0) loaded.push_back(static_cast<int>(i));
  }
  Eigen::MatrixXd forces = Eigen::MatrixXd::Zero(m, static_cast<Eigen::Index>(loaded.size()));
  for (size_t k = 0; k < loaded.size(); ++k) {
    const ContactAnswer& a = answers[static_cast<size_t>(loaded[k])];
    const Eigen::VectorXd f = a.c.transpose() * a.solution.lambda;
    for (size_t j = 0; j < cond.surface_position.size(); ++j)
      if (cond.surface_position[j] >= 0) forces(cond.surface_position[j], static_cast<Eigen::Index>(k)) += f(j);
  }
  const Eigen::MatrixXd x = loaded.empty() ? Eigen::MatrixXd() : cond.factor->solve_trailing(forces);
  const double shared = seconds_since(t0) / std::max<double>(1.0, static_cast<double>(answers.size()));
  std::vector<FomSolution> out;
  out.reserve(answers.size());
  size_t k = 0;
  for (size_t i = 0; i < answers.size(); ++i) {
    const auto t1 = std::chrono::steady_clock::now();
    FomSolution& sol = answers[i].solution;
    sol.u = cond.z_load * m_problem.load_coefficients(sol.mu);
    if (k < loaded.size() && loaded[k] == static_cast<int>(i)) {
      if (x.cols() == static_cast<Eigen::Index>(loaded.size()))
        for (size_t r = 0; r < cond.free_dofs.size(); ++r) sol.u(cond.free_dofs[r]) -= x(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k));
      ++k;
    }
    certify_fom_solution(m_problem, sol, m_options.kkt_tolerance);
    sol.time_s += shared + seconds_since(t1);
    out.push_back(std::move(sol));
  }
  return out;
}

FomSolution ActiveSetSolver::solve_at(const Param& mu, const Pairing& pairing, const Eigen::VectorXd& x_s) const {
  m_problem.check_param(mu);
  FomSolution sol;
  sol.mu = mu;
  if (!m_constant) {
    sol.status = Status::InvalidInput;
    sol.message = "a solve at a given pairing needs a factorised parameter-independent stiffness";
    return sol;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const ContactModel& contact = m_problem.contact();
  const Eigen::VectorXd u0 = m_constant->z_load * m_problem.load_coefficients(mu);
  const Eigen::VectorXd u0_s = contact.restrict_to_surface(u0);
  ConstraintMatrix c;
  Eigen::VectorXd g;
  contact.assemble(pairing, c, g);
  WorkingSetQp qp(m_problem, *m_constant, m_options, u0_s, Eigen::VectorXd::Zero(contact.num_constraints()));
  const PairedSolution at = qp.solve(pairing, c, g, x_s, sol.iterations);
  sol.pairing_iterations = 1;
  sol.status = at.status;
  if (at.status != Status::Success) sol.message = "dual active-set QP failed: " + std::string(to_string(at.status));
  std::vector<ContactAnswer> one(1);
  one[0].solution = std::move(sol);
  one[0].solution.lambda = at.lambda;
  one[0].solution.pairing = pairing;
  one[0].c = std::move(c);
  FomSolution out = std::move(finish(*m_constant, std::move(one)).front());
  out.time_s = seconds_since(t0);
  return out;
}

void certify_fom_solution(const Problem& problem, FomSolution& sol, double tolerance, bool complementarity) {
  if (sol.u.size() != problem.num_dofs() || sol.lambda.size() != problem.contact().num_constraints()) return;
  sol.kkt = kkt_residuals(problem, sol.mu, sol.u, sol.lambda);
  const KktResiduals& k = sol.kkt;
  const std::pair<const char*, double> checked[] = {{"stationarity", k.stationarity},
                                                    {"penetration", k.penetration},
                                                    {"negative-pressure", k.negative_pressure},
                                                    {"complementarity", complementarity ? k.complementarity : 0.0}};
  for (const auto& [name, value] : checked) {
    if (value <= tolerance || sol.status != Status::Success) continue;  // NaN fails the test
    sol.status = Status::NoConvergence;
    sol.message = std::string("the solver converged, but the ") + name + " residual of its solution at the pairing" +
                  " recomputed from it is " + format_number(value) + " > tolerance " + format_number(tolerance);
  }
}

PairingFixedPointOptions pairing_options(const ActiveSetOptions& options) {
  PairingFixedPointOptions o;
  o.max_iterations = options.max_pairing_iterations;
  o.tolerance = options.pairing_tolerance;
  o.anderson_depth = options.anderson_depth;
  o.anderson_restart = options.anderson_restart;
  o.zone_start = options.zone_start;
  o.zone_retry = options.zone_retry;
  return o;
}

void solve_in_chains(const ActiveSetSolver& solver, const std::vector<Param>& params, int chain, int threads,
                     const std::function<void(int, FomSolution&&)>& store, const ProgressCallback& progress) {
  // A chain runs on one worker, item after item: `pending` holds each chain's contact
  // answers, the last one the start of the next; the chain's last item finishes them.
  const int n = static_cast<int>(params.size());
  chain = std::max(chain, 1);
  std::vector<std::vector<ContactAnswer>> pending(static_cast<size_t>((n + chain - 1) / chain));
  parallel_for_chains(
      n, chain, threads,
      [&](int j) {
        std::vector<ContactAnswer>& answers = pending[static_cast<size_t>(j / chain)];
        answers.push_back(solver.solve_contact(params[static_cast<size_t>(j)], answers.empty() ? nullptr : &answers.back()));
        if ((j + 1) % chain != 0 && j + 1 != n) return;
        std::vector<FomSolution> solutions = solver.finish(std::move(answers));
        answers = {};
        const int first = j + 1 - static_cast<int>(solutions.size());
        for (size_t k = 0; k < solutions.size(); ++k) store(first + static_cast<int>(k), std::move(solutions[k]));
      },
      progress);
}

}  // namespace contactrom::fom
