#include "rom/online_solver.hpp"

#include <chrono>

#include "fom/kkt.hpp"
#include "rom/error_indicator.hpp"

namespace contactrom::rom {

fom::ContactTolerances OnlineSolver::contact_tolerances() const {
  return m_tolerances_set ? m_tolerances : fom::default_contact_tolerances(model().problem());
}

OnlineResult OnlineSolver::solve(const fom::Param& mu) const {
  OnlineResult res = solve_reduced(mu);
  const fom::Pairing* pairing = check_contact(model(), contact_tolerances(), res);
  if (m_indicator && pairing) estimate_errors(*m_indicator, *pairing, res);
  return res;
}

void estimate_errors(const ErrorIndicator& indicator, const fom::Pairing& pairing, OnlineResult& res) {
  const Eigen::VectorXd u_s = indicator.problem().contact().restrict_to_surface(res.u);
  const ErrorEstimate e = indicator.estimate(res.mu, res.u_hat, res.lambda, pairing, u_s);
  res.primal_estimate = e.primal;
  res.dual_estimate = e.dual;
  res.absolute_estimates = e.absolute;
  res.estimate_time_s = e.time_s;
  res.time_s += e.time_s;
}

const fom::Pairing* check_contact(const ReducedModel& model, const fom::ContactTolerances& tolerances, OnlineResult& res) {
  const fom::Problem& problem = model.problem();
  if (res.u.size() != problem.num_dofs() || res.lambda.size() != problem.contact().num_constraints()) return nullptr;
  res.contact_force = fom::contact_force(problem, res.lambda);
  const auto t0 = std::chrono::steady_clock::now();
  // The search starts from the memory of the one made offline at the nearest
  // training snapshot: same pairing as a full search, most rows settled at once.
  thread_local fom::SearchMemory memory;
  thread_local fom::Pairing pairing;
  const int nearest = ReducedModel::nearest_column(model.interpolation_stencil(res.mu));
  if (nearest >= 0)
    memory = model.snapshot_search_memory(nearest);
  else
    memory = fom::SearchMemory();
  const Eigen::VectorXd u_s = problem.contact().restrict_to_surface(res.u);
  problem.contact().search_rows(u_s, nullptr, nullptr, memory, pairing);
  res.contact = fom::contact_residuals(problem, pairing, u_s, res.lambda);
  res.check_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  res.time_s += res.check_time_s;
  if (res.status == Status::Success && !res.contact.within(tolerances)) {
    res.status = Status::Inaccurate;
    res.message = "full-order contact residuals above tolerance: " + res.contact.describe(tolerances);
  }
  return &pairing;
}

}  // namespace contactrom::rom
