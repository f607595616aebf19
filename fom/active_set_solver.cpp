#include "fom/active_set_solver.hpp"

#include <Eigen/CholmodSupport>
#include <chrono>

#include "core/anderson.hpp"
#include "core/errors.hpp"
#include "core/stopwatch.hpp"
#include "fom/rigid_bodies.hpp"

namespace contactrom::fom {
namespace {

/// S C_Wᵀ (n_s x |W|) for the constraint rows W: column a is the sum of the
/// columns of the symmetric S picked by row W[a]'s (at most six) entries.
void delassus_parts(const ConstraintMatrix& c, const std::vector<int>& rows, const Eigen::MatrixXd& s,
                    Eigen::MatrixXd& sct) {
  sct.resize(s.rows(), static_cast<Eigen::Index>(rows.size()));
  for (size_t a = 0; a < rows.size(); ++a) {
    ConstraintMatrix::InnerIterator it(c, rows[a]);
    if (!it) {
      sct.col(a).setZero();
      continue;
    }
    sct.col(a).noalias() = it.value() * s.col(it.col());
    for (++it; it; ++it) sct.col(a).noalias() += it.value() * s.col(it.col());
  }
}

/// G_W = C_W S C_Wᵀ from S C_Wᵀ (|W| x |W|).
Eigen::MatrixXd delassus(const ConstraintMatrix& c, const std::vector<int>& rows, const Eigen::MatrixXd& sct) {
  const int nw = static_cast<int>(rows.size());
  Eigen::MatrixXd g(nw, nw);
  for (int a = 0; a < nw; ++a) {
    g.row(a).setZero();
    for (ConstraintMatrix::InnerIterator it(c, rows[a]); it; ++it) g.row(a).noalias() += it.value() * sct.row(it.col());
  }
  return g;
}

bool pairing_settled(const ConstraintMatrix& c, const Eigen::VectorXd& g, const ConstraintMatrix& c_next,
                     const Eigen::VectorXd& g_next, const Eigen::VectorXd& u_s, const Eigen::VectorXd& lambda,
                     const Eigen::VectorXd& w, double u_scale, double tol) {
  const Eigen::VectorXd force = c.transpose() * lambda;
  const double force_scale = std::max(force.norm(), 1e-300);
  if ((c_next.transpose() * lambda - force).norm() > tol * force_scale) return false;
  const Eigen::VectorXd v = (c * u_s - g).cwiseQuotient(w), v_next = (c_next * u_s - g_next).cwiseQuotient(w);
  for (int s = 0; s < v.size(); ++s) {
    if (v_next(s) > tol * u_scale) return false;  // penetration under the new pairing
    if ((lambda(s) > 0.0 || v(s) > -tol * u_scale) && std::abs(v_next(s) - v(s)) > tol * u_scale) return false;
  }
  return true;
}

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
  m_constant_ok = condense(problem, mid, *m_constant);
  // A stiffness that cannot be factorised is a problem definition error (a body
  // held by nothing), not a numerical accident of one query.
  if (!m_constant_ok) throw InputError(singular_stiffness_message(problem));
  m_setup_time = seconds_since(t0);
}

FomSolution ActiveSetSolver::solve(const Param& mu, const FomSolution* warm) const {
  m_problem.check_param(mu);
  if (m_constant) {
    if (!m_constant_ok) {
      FomSolution s;
      s.mu = mu;
      s.status = Status::NumericalIssue;
      s.message = "Cholesky factorisation of the stiffness failed (matrix not positive definite)";
      return s;
    }
    return solve_with(*m_constant, mu, warm);
  }
  const auto t0 = std::chrono::steady_clock::now();
  Condensation cond;
  if (!condense(m_problem, mu, cond, m_order.empty() ? nullptr : &m_order)) {
    FomSolution s;
    s.mu = mu;
    s.status = Status::NumericalIssue;
    s.message = singular_stiffness_message(m_problem);
    return s;
  }
  FomSolution s = solve_with(cond, mu, warm);
  s.time_s = seconds_since(t0);  // includes the per-parameter factorisation
  return s;
}

FomSolution ActiveSetSolver::solve_with(const Condensation& cond, const Param& mu, const FomSolution* warm) const {
  const auto t0 = std::chrono::steady_clock::now();
  const ContactModel& contact = m_problem.contact();
  const std::vector<int>& surf = contact.surface_dofs();
  const int nc = contact.num_constraints();
  FomSolution sol;
  sol.mu = mu;

  const Eigen::VectorXd u0 = cond.z_load * m_problem.load_coefficients(mu);
  Eigen::VectorXd u0_s(surf.size());
  for (size_t j = 0; j < surf.size(); ++j) u0_s(j) = u0(surf[j]);

  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(nc);
  // Start from the unconstrained solution, or from a previous solution if given.
  const bool use_warm = warm && warm->lambda.size() == nc && warm->u.size() == m_problem.num_dofs();
  if (use_warm) lambda = warm->lambda;
  Eigen::VectorXd x = use_warm ? contact.restrict_to_surface(warm->u) : u0_s;
  Pairing pairing = contact.search(x);

  DualQpSolver qp(m_options.qp);
  ConstraintMatrix c;
  Eigen::VectorXd g;
  Eigen::MatrixXd sct;  // S C_Wᵀ, n_s x |W|
  const double margin = m_options.working_set_margin * m_problem.displacement_scale();
  const bool all_rows = m_options.working_set_margin < 0.0;
  bool converged = false;
  // Fixed point x -> F(x) on the surface displacement: pairing from x, exact dual
  // QP for that pairing, F(x) = resulting surface displacement. Anderson
  // acceleration (Walker & Ni 2011, type II) on x; the QP is always solved exactly,
  // so the extrapolated x only chooses the pairing.
  AndersonMixer mixer(m_options.anderson_depth);
  for (int it = 0; it < m_options.max_pairing_iterations; ++it) {
    ++sol.pairing_iterations;
    contact.assemble(pairing, c, g);
    const Eigen::VectorXd h = c * u0_s - g;
    // Working set W: the rows that are active or, at the current iterate x,
    // within the margin of contact. The QP is solved on W; rows outside W are
    // then checked at the solution and the violated ones join W (repeat), so
    // λ solves the QP of all rows while the Delassus matrix is only |W| x |W|.
    auto paired = [&](int s) { return !contact.has_pairing() || pairing.segment[s] >= 0; };
    std::vector<char> in_w(nc, 0);
    std::vector<int> w_rows;
    {
      const Eigen::VectorXd gap = c * x - g;
      for (int s = 0; s < nc; ++s)
        if (paired(s) && (all_rows || lambda(s) > 0.0 || gap(s) > -margin * contact.weights()(s)))
          in_w[s] = 1, w_rows.push_back(s);
    }
    // Rows outside W must not penetrate at the QP's solution, to the QP's tolerance
    // (relative to |h|∞; W's part of h is no larger).
    const double tol = m_options.qp.relative_tolerance * (nc > 0 ? h.cwiseAbs().maxCoeff() : 0.0);
    Eigen::VectorXd lambda_w, f;
    bool qp_ok = true;
    for (;;) {
      delassus_parts(c, w_rows, cond.s, sct);
      const Eigen::MatrixXd g_w = delassus(c, w_rows, sct);
      const int nw = static_cast<int>(w_rows.size());
      Eigen::VectorXd h_w(nw), warm_w(nw);
      for (int a = 0; a < nw; ++a) h_w(a) = h(w_rows[a]), warm_w(a) = lambda(w_rows[a]);
      if (nw > 0) {
        lambda_w = qp.solve(g_w, h_w, {}, warm_w);
        sol.iterations += qp.iterations();
      } else {
        lambda_w.resize(0);
      }
      if (nw > 0 && qp.info() != Status::Success) {
        qp_ok = false;
        break;
      }
      f = u0_s - sct * lambda_w;
      const Eigen::VectorXd v = c * f - g;
      bool grown = false;
      for (int s = 0; s < nc; ++s)
        if (!in_w[s] && paired(s) && v(s) > tol) in_w[s] = 1, grown = true;
      if (!grown) break;
      for (int a = 0; a < nw; ++a) lambda(w_rows[a]) = lambda_w(a);
      w_rows.clear();
      for (int s = 0; s < nc; ++s)
        if (in_w[s]) w_rows.push_back(s);
    }
    if (!qp_ok) {
      sol.status = qp.info();
      sol.message = "dual active-set QP failed: " + std::string(to_string(qp.info()));
      break;
    }
    lambda.setZero();
    for (size_t a = 0; a < w_rows.size(); ++a) lambda(w_rows[a]) = lambda_w(a);
    if (!contact.has_pairing()) {
      converged = true;
      break;
    }
    // Converged when re-pairing at F(x) no longer changes the KKT system of
    // this solution: the forces Cᵀλ, the gaps of active/penetrating rows and
    // the penetration, each to `pairing_tolerance` (relative).
    const Pairing next = contact.search_rows(f, nullptr, &pairing);
    ConstraintMatrix c_next;
    Eigen::VectorXd g_next;
    contact.assemble(next, c_next, g_next);
    if (pairing_settled(c, g, c_next, g_next, f, lambda, contact.weights(), m_problem.displacement_scale(),
                        m_options.pairing_tolerance)) {
      converged = true;
      break;
    }
    x = mixer.next(x, f);
    pairing = contact.search_rows(x, nullptr, &next);
  }
  if (!converged && sol.status == Status::Success) {
    sol.status = Status::NoConvergence;
    sol.message = "contact pairing did not settle in " + std::to_string(m_options.max_pairing_iterations) +
                  " fixed-point iterations";
  }
  // The constraint operator of the returned solution is the one λ was solved with;
  // on convergence the pairing recomputed from u agrees with it to the tolerance.
  sol.active = static_cast<int>((lambda.array() > 0.0).count());
  // u = u0 − K⁻¹ E_s Cᵀλ: one solve with the factor.
  sol.u = u0;
  if (sol.active > 0) sol.u -= cond.surface_response(c.transpose() * lambda);
  sol.lambda = lambda;
  sol.pairing = pairing;
  sol.time_s = seconds_since(t0);
  return sol;
}

}  // namespace contactrom::fom
