#include "rom/greedy_active_set.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ostream>

namespace contactrom::rom {

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

OnlineResult GreedyActiveSet::solve(const fom::Param& mu) const {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const fom::Problem& problem = m_model.problem();
  const fom::ContactModel& contact = problem.contact();
  const Eigen::MatrixXd& phi_s = m_model.surface_basis();
  const Eigen::MatrixXd& dict = m_model.dictionary();
  const int r = m_model.primal_rank(), m = m_model.dictionary_size(), nc = static_cast<int>(dict.rows());

  OnlineResult res;
  res.mu = mu;

  // K̂(μ)⁻¹ through the offline Cholesky factor when K̂(μ) = θ₀(μ) K̂₀, else a
  // per-query factorisation of the r × r matrix.
  Eigen::LLT<Eigen::MatrixXd> local;
  const Eigen::LLT<Eigen::MatrixXd>* llt = m_model.single_term_factor();
  double inv_theta = 1.0;
  if (llt) {
    inv_theta = 1.0 / problem.stiffness_coefficients(mu)(0);
  } else {
    local.compute(m_model.reduced_stiffness(mu));
    llt = &local;
  }
  if (llt->info() != Eigen::Success || !std::isfinite(inv_theta)) {
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
  const Eigen::VectorXd u_free = inv_theta * llt->solve(f_hat);  // unconstrained reduced solution

  Eigen::VectorXd u_hat = u_free, u_prev, lambda_i, g, y, v, violation, rhs;
  Eigen::MatrixXd c_hat_i, w, schur;
  fom::ConstraintMatrix c;
  fom::Pairing pairing;
  std::vector<int> active, solved;
  std::vector<char> in_active(m, 0);
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
  // Surface displacement of the current iterate, u_s = Φ_s û + u_off,s: the only
  // place the primal enters the contact operators.
  Eigen::VectorXd u_s = phi_s * u_hat + lift_s;
  // Best iterate with λ̂ ≥ 0 (smallest largest violation), for the iteration cap.
  struct {
    bool valid = false;
    double violation = 0.0;
    Eigen::VectorXd u_hat, lambda_i;
    std::vector<int> selected;
  } best_iterate;

  bool pending = false;  // converged in the sense of Alg. 1, to be confirmed
  for (int k = 0; k <= m_options.max_iterations; ++k) {
    // 1. Contact operators at the previous iterate, from the surface rows only.
    pairing = contact.search_rows(u_s, &m_support.rows, k > 0 ? &pairing : nullptr);
    contact.assemble(pairing, c, g);
    if (pending) {
      // Alg. 1 found no change and a settled û^k, but judged û^k with the operators
      // of û^{k−1}. Confirm at the pairing of û^k itself that no dictionary column
      // is violated by more than τ (selected columns included), so the returned
      // solution meets the reduced constraint at its own pairing; else go on.
      m_support.violation(c, g, u_s, v, violation);
      const double worst = m > 0 ? violation.maxCoeff() : 0.0;
      if (m_options.trace) *m_options.trace << "greedy check at fresh pairing: max(violation)=" << worst << "\n";
      if (worst <= m_threshold) {
        res.converged = true;
        break;
      }
      pending = false;
    }
    if (k == m_options.max_iterations) break;
    const int na = static_cast<int>(active.size());
    c_hat_i.resize(na, r);
    rhs.resize(na);
    for (int i = 0; i < na; ++i) {
      // Row of Ĉ_I = D_Iᵀ C_s Φ_s and entry of ĝ_I = D_Iᵀ (g − C_s u_off,s),
      // through y = C_sᵀ d_p (n_s): O(nnz(C) + n_s r) per selected column.
      const auto d = dict.col(active[i]);
      y.noalias() = c.transpose() * d;
      c_hat_i.row(i).noalias() = y.transpose() * phi_s;
      rhs(i) = d.dot(g) - y.dot(lift_s);
    }

    // 2. Saddle-point system by its Schur complement S = Ĉ_I K̂⁻¹ Ĉ_Iᵀ.
    u_prev = u_hat;
    if (na == 0) {
      u_hat = u_free;
      lambda_i.resize(0);
    } else {
      w = inv_theta * llt->solve(c_hat_i.transpose());  // K̂⁻¹ Ĉ_Iᵀ, r × |I|
      schur.noalias() = c_hat_i * w;
      rhs = c_hat_i * u_free - rhs;  // Ĉ_I K̂⁻¹ f̂ − ĝ_I
      ldlt.compute(schur);
      if (ldlt.info() == Eigen::Success && ldlt.rcond() > m_options.singular_tolerance)
        lambda_i = ldlt.solve(rhs);
      else  // dependent rows (e.g. |I| > r): least-squares, minimum-norm multipliers
        lambda_i = schur.completeOrthogonalDecomposition().solve(rhs);
      u_hat.noalias() = u_free - w * lambda_i;
    }
    solved = active;
    res.iterations = k + 1;
    if (!u_hat.allFinite() || !lambda_i.allFinite()) {
      res.status = Status::NumericalIssue;
      res.message = "reduced saddle-point solve produced a non-finite value";
      break;
    }
    u_s.noalias() = phi_s * u_hat;
    u_s += lift_s;

    // 3. One change: remove the most negative multiplier, else add the column most
    //    correlated with the thresholded violation.
    bool changed = false;
    double max_violation = 0.0;
    int remove = -1;
    double most_negative = 0.0;
    for (int i = 0; i < na; ++i)
      if (lambda_i(i) < most_negative) most_negative = lambda_i(i), remove = i;
    if (remove >= 0) {
      in_active[active[remove]] = 0;
      active.erase(active.begin() + remove);
      changed = true;
    } else {
      // Ĉ û − ĝ for every column = D_dᵀ (C_s u_s − g), from the support rows, with
      // the operators of step 1.
      m_support.violation(c, g, u_s, v, violation);
      int add = -1;
      if (m > 0) max_violation = violation.maxCoeff();
      if (m_options.best_iterate_on_failure && (!best_iterate.valid || max_violation < best_iterate.violation)) {
        best_iterate.valid = true;
        best_iterate.violation = max_violation;
        best_iterate.u_hat = u_hat;
        best_iterate.lambda_i = lambda_i;
        best_iterate.selected = solved;
      }
      double best = m_threshold;  // (·)^{+,τ}: entries ≤ τ count as zero
      for (int p = 0; p < m; ++p)
        if (!in_active[p] && violation(p) > best) best = violation(p), add = p;
      if (add >= 0) {
        in_active[add] = 1;
        active.push_back(add);
        changed = true;
      }
    }

    // 4. Converged when the active set is stable and û no longer moves.
    const double step = (u_hat - u_prev).norm(), size = u_hat.norm();
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
  }

  if (!res.converged && res.status == Status::Success && best_iterate.valid) {
    u_hat = best_iterate.u_hat;
    lambda_i = best_iterate.lambda_i;
    solved = best_iterate.selected;
  }
  res.u_hat = u_hat;
  res.selected = solved;
  res.coefficients = lambda_i;
  res.lambda = m_model.reconstruct_dual(solved, lambda_i);
  if (res.status == Status::Success && !res.converged) {
    res.status = Status::NoConvergence;
    res.message = "greedy active set did not converge in " + std::to_string(m_options.max_iterations) + " iterations" +
                  (best_iterate.valid && m_options.best_iterate_on_failure ? "; best iterate with non-negative multipliers returned" : "");
  }
  const auto t1 = clock::now();
  res.time_s = std::chrono::duration<double>(t1 - t0).count();
  res.u = m_model.reconstruct_primal(u_hat, mu);
  res.reconstruction_time_s = std::chrono::duration<double>(clock::now() - t1).count();
  return res;
}

}  // namespace contactrom::rom
