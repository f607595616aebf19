#include <contactrom/rom/fallback.hpp>

#include <cmath>
#include <string>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/contact_checks.hpp>
#include <contactrom/fom/contact_residuals.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/error_indicator.hpp>

namespace contactrom::rom {

FallbackSolver::FallbackSolver(const OnlineSolver& rom, FallbackOptions options)
    : m_rom(rom), m_options(std::move(options)) {
  // Written so that NaN is refused too.
  const auto positive = [](const char* name, double value) {
    if (!(value > 0.0) || !std::isfinite(value))
      throw InputError(std::string("fallback ") + name + " = " + format_number(value) + "; expected a finite number > 0");
  };
  positive("primal_tolerance", m_options.primal_tolerance);
  positive("dual_tolerance", m_options.dual_tolerance);
  positive("safety_factor", m_options.safety_factor);
  // Without an indicator every answer would go to the FOM. (A problem whose
  // estimates are NaN for another reason is allowed: the reason is each answer's.)
  if (!rom.estimates_errors())
    throw InputError("fallback: the " + rom.name() +
                     " solver estimates no error (its option estimate is off), so every query would go to the FOM; "
                     "expected a solver made with estimate on");
}

FallbackSolver::~FallbackSolver() = default;

const fom::ActiveSetSolver& FallbackSolver::fom_solver() const {
  std::call_once(m_once, [this] { m_fom = std::make_unique<fom::ActiveSetSolver>(m_rom.model().problem(), m_options.fom); });
  return *m_fom;
}

double FallbackSolver::fom_setup_time() const { return m_fom ? m_fom->setup_time() : 0.0; }

bool FallbackSolver::keeps(const OnlineResult& res, std::string& reason) const {
  const double f = m_options.safety_factor;
  if (res.status != Status::Success)
    reason = std::string("reduced status ") + to_string(res.status);
  else if (std::isnan(res.primal_estimate) || std::isnan(res.dual_estimate)) {
    const std::string why = no_error_estimate_reason(m_rom.model().problem());
    reason = "no error estimate to judge the answer by (" + (why.empty() ? std::string("the estimate is off") : why) + ")";
  } else if (!(f * res.primal_estimate <= m_options.primal_tolerance))
    reason = "primal estimate " + format_number(res.primal_estimate) + " x " + format_number(f) + " above " +
             format_number(m_options.primal_tolerance);
  else if (!(f * res.dual_estimate <= m_options.dual_tolerance))
    reason = "dual estimate " + format_number(res.dual_estimate) + " x " + format_number(f) + " above " +
             format_number(m_options.dual_tolerance);
  else
    reason.clear();
  return reason.empty();
}

FallbackAnswer FallbackSolver::solve(const fom::Param& mu) const {
  FallbackAnswer a;
  a.result = m_rom.solve(mu);
  a.rom_time_s = a.result.time_s;
  a.rom_status = a.result.status;
  a.rom_primal_estimate = a.result.primal_estimate;
  a.rom_dual_estimate = a.result.dual_estimate;
  if (keeps(a.result, a.reason)) return a;
  const fom::FomSolution sol = fom_solver().solve(mu);
  a.from_fom = true;
  a.fom_time_s = sol.time_s;
  OnlineResult& r = a.result;
  r.u = sol.u;
  r.lambda = sol.lambda;
  r.status = sol.status;
  r.message = sol.message;
  r.converged = sol.status == Status::Success;
  r.iterations = sol.iterations;
  r.u_hat.resize(0);
  r.selected.clear();
  r.coefficients.resize(0);
  r.primal_estimate = r.dual_estimate = 0.0;
  const fom::Problem& problem = m_rom.model().problem();
  r.contact = fom::contact_residuals(problem, problem.contact().restrict_to_surface(sol.u), sol.lambda);
  r.contact_force = fom::contact_force(problem, sol.lambda);
  r.time_s = a.rom_time_s + a.fom_time_s;
  a.warnings = fom::solution_warnings(problem, sol.u);
  return a;
}

}  // namespace contactrom::rom
