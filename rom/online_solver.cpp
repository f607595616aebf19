#include <contactrom/rom/online_solver.hpp>

#include <chrono>

#include <contactrom/core/format.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/error_indicator.hpp>

namespace contactrom::rom {

const OptionTable<ActiveSetSettings>& active_set_settings_table() {
  static const OptionTable<ActiveSetSettings> t = [] {
    OptionTable<ActiveSetSettings> o;
    o.number("tau", &ActiveSetSettings::tau, "penetration threshold of the reduced constraint; < 0: delta of the model")
        .choice("tau_scaling", &ActiveSetSettings::tau_scaling,
                "absolute (paper) or relative to the dictionary's force scale",
                {{"absolute", TauScaling::Absolute}, {"relative", TauScaling::Relative}})
        .integer("max_iterations", &ActiveSetSettings::max_iterations, "iteration cap k_max", 1, 1e6)
        .number("step_tolerance", &ActiveSetSettings::step_tolerance,
                "relative change of u_hat under which the iteration may stop", Interval::at_least(0))
        .flag("time_operators", &ActiveSetSettings::time_operators,
              "measure the time spent building the contact operators");
    return o;
  }();
  return t;
}

const OptionTable<ContactCheckOptions>& contact_check_table() {
  static const OptionTable<ContactCheckOptions> t = [] {
    OptionTable<ContactCheckOptions> o;
    o.number("penetration_tolerance", &ContactCheckOptions::penetration_tolerance,
             "largest penetration (units of U) of an answer reported success; < 0: the problem's [rom] value, else "
             "5e-2")
        .number("complementarity_tolerance", &ContactCheckOptions::complementarity_tolerance,
                "largest separation under pressure (units of U) of an answer reported success; < 0: the problem's "
                "[rom] value, else 5e-2")
        .flag("estimate", &ContactCheckOptions::estimate,
              "estimate the primal and dual errors of every answer at the full order on the contact surface")
        .integer("estimate_pairings", &ContactCheckOptions::estimate_pairings,
                 "cap on the pairings of the estimate's correction; 1: the answer's own pairing only (cheaper, "
                 "coarser on sliding contact)",
                 1, 1000);
    return o;
  }();
  return t;
}

void throw_unknown_option(const std::string& method, const std::string& key, const std::vector<OptionSpec>& known) {
  std::vector<std::string> keys;
  for (const OptionSpec& s : known) keys.push_back(s.key);
  throw InputError("online method " + quoted(method, 200) + " has no option " + quoted(key, 200) +
                   "; it knows: " + (keys.empty() ? "none" : join(keys, ", ")));
}

fom::ContactTolerances OnlineSolver::contact_tolerances() const {
  return m_tolerances_set ? m_tolerances : fom::default_contact_tolerances(model().problem());
}

OnlineResult OnlineSolver::start_query(const fom::Param& mu) const {
  model().problem().check_param(mu);
  OnlineResult res;
  res.mu = mu;
  return res;
}

void OnlineSolver::finish_query(std::chrono::steady_clock::time_point t0, OnlineResult& res) const {
  using clock = std::chrono::steady_clock;
  if (res.status == Status::Success && !res.converged) {
    res.status = Status::NoConvergence;
    if (res.message.empty()) res.message = name() + " did not converge";
  }
  const auto t1 = clock::now();
  res.time_s = std::chrono::duration<double>(t1 - t0).count();
  res.u = reconstruct_primal(res);
  res.reconstruction_time_s = std::chrono::duration<double>(clock::now() - t1).count();
  const AnswerSearch* search = check_contact(model(), contact_tolerances(), res);
  if (m_indicator && search) estimate_errors(*m_indicator, *search, res, m_estimate_pairings, answer_combines_snapshots());
}

Eigen::VectorXd OnlineSolver::reconstruct_primal(const OnlineResult& res) const {
  return model().reconstruct_primal(res.u_hat, res.mu);
}

void estimate_errors(const ErrorIndicator& indicator, const AnswerSearch& search, OnlineResult& res, int pairings,
                     bool combination) {
  const Eigen::VectorXd u_s = indicator.problem().contact().restrict_to_surface(res.u);
  const SnapshotCombination snapshots{res.selected, res.coefficients};
  const ErrorEstimate e = indicator.estimate(res.mu, res.u_hat, res.lambda, search.pairing, u_s, pairings,
                                             &search.memory, combination ? &snapshots : nullptr);
  res.primal_estimate = e.primal;
  res.dual_estimate = e.dual;
  res.absolute_estimates = e.absolute;
  res.estimate_time_s = e.time_s;
  res.time_s += e.time_s;
}

const AnswerSearch* check_contact(const ReducedModel& model, const fom::ContactTolerances& tolerances,
                                  OnlineResult& res) {
  const fom::Problem& problem = model.problem();
  if (res.u.size() != problem.num_dofs() || res.lambda.size() != problem.contact().num_constraints()) return nullptr;
  res.contact_force = fom::contact_force(problem, res.lambda);
  const auto t0 = std::chrono::steady_clock::now();
  // The search starts from the memory of the one made offline at the nearest
  // training snapshot: same pairing as a full search, most rows settled at once.
  thread_local AnswerSearch search;
  const int nearest = ReducedModel::nearest_column(model.interpolation_stencil(res.mu));
  if (nearest >= 0)
    search.memory = model.snapshot_search_memory(nearest);
  else
    search.memory = fom::SearchMemory();
  const Eigen::VectorXd u_s = problem.contact().restrict_to_surface(res.u);
  problem.contact().search_rows(u_s, nullptr, nullptr, search.memory, search.pairing);
  res.contact = fom::contact_residuals(problem, search.pairing, u_s, res.lambda);
  res.check_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  res.time_s += res.check_time_s;
  // Judged on the answer's own scale: far below U, U's tolerances would pass a
  // gap as large as the whole answer.
  const fom::ScaledContactTolerances own = fom::tolerances_on_own_scale(tolerances, u_s, problem.displacement_scale());
  if (res.status == Status::Success && !res.contact.within(own.tolerances)) {
    res.status = Status::Inaccurate;
    res.message = "full-order contact residuals above tolerance: " + res.contact.describe(own.tolerances);
    if (own.scale < 1.0)
      res.message += "; tolerances taken relative to the answer's own largest surface displacement, " +
                     format_number(own.scale) + " U";
    if (!(res.lambda.array() > 0.0).any()) res.message += " (no contact pressure anywhere)";
  }
  return &search;
}

}  // namespace contactrom::rom
