// contactrom fom --problem P --param V[,V2] [--solver active-set|ipopt] [--out DIR] [--json]
// Solves one FOM query and prints a summary (or one JSON object with --json);
// --out DIR writes DIR/<problem>.vtu (displacement, stress, pressure) and
// DIR/<problem>_surface.csv (x, y, gap, pressure, u_x, u_y).
#include <algorithm>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include <contactrom/baselines/ipopt_qp.hpp>

#include <contactrom/core/format.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/contact_checks.hpp>
#include <contactrom/fom/field_output.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct FomArgs {
  std::string problem, param, solver = "active-set", out;
  int refine = 0;
  bool json = false;
};

void run_fom(const FomArgs& a) {
  fom::ProblemOptions popt;
  popt.refine = a.refine;
  auto problem = fom::make_problem(a.problem, popt);
  declare_problem_inputs(*problem);
  const fom::Param mu = parse_problem_param(*problem, a.param);
  std::vector<std::string> warnings = fom::reference_contact_warnings(*problem);
  for (const std::string& w : warnings) std::cerr << "contactrom: warning: " << w << "\n";
  const std::unique_ptr<fom::FullOrderSolver> solver = baselines::make_fom_solver(*problem, a.solver);
  const double setup = solver->setup_time();
  const fom::FomSolution sol = solver->solve(mu);
  // A failed solve may carry no field at all (its status and message say why).
  const bool has_fields = sol.u.size() == problem->num_dofs() && sol.lambda.size() == problem->contact().num_constraints();
  if (!has_fields)
    throw InputError("the " + a.solver + " solver returned no solution for problem " + quoted(problem->name(), 200) + " (status " +
                     to_string(sol.status) + (sol.message.empty() ? "" : ": " + sol.message) + ")");
  const fom::KktResiduals& kkt = sol.kkt;  // the residuals the status was certified with
  for (const std::string& w : fom::solution_warnings(*problem, sol.u)) {
    std::cerr << "contactrom: warning: " << w << "\n";
    warnings.push_back(w);
  }
  if (!a.out.empty()) {
    fom::write_fields(a.out, problem->name(), *problem, mu, sol.u, sol.lambda);
  }
  nlohmann::json j;
  j["problem"] = problem->name();
  j["param"] = param_json(mu);
  j["solver"] = a.solver;
  j["status"] = to_string(sol.status);
  if (!sol.message.empty()) j["message"] = sol.message;
  j["iterations"] = sol.iterations;
  j["pairing_iterations"] = sol.pairing_iterations;
  j["zone_iterations"] = sol.zone_iterations;
  j["active"] = sol.active;
  j["dofs"] = problem->num_dofs();
  j["constraints"] = problem->contact().num_constraints();
  j["time_s"] = sol.time_s;
  j["setup_time_s"] = setup;
  j["contact_force"] = fom::contact_force(*problem, sol.lambda);
  // The contact zone: its peak pressure and its size, the tributary lengths (2D) or
  // areas (3D) of the rows that carry pressure, above 1e-8 of the peak (Ipopt's
  // interior point leaves multipliers of round-off size on every row that does not).
  const Eigen::VectorXd& weights = problem->contact().weights();
  const double peak = sol.lambda.size() > 0 ? std::max(0.0, sol.lambda.maxCoeff()) : 0.0;
  double extent = 0.0;
  for (Eigen::Index k = 0; k < sol.lambda.size(); ++k)
    if (sol.lambda(k) > 1e-8 * peak) extent += weights(k);
  const bool three_d = problem->dofs_per_node() == 3;
  j["peak_pressure"] = peak;
  j[three_d ? "contact_area" : "contact_length"] = extent;
  j["kkt"] = kkt_json(kkt);
  j["warnings"] = warnings;
  if (a.json) {
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "problem " << problem->name() << "  " << problem->range_text() << "\n"
            << "param   " << j["param"].dump() << "   solver " << a.solver << "   status " << j["status"].get<std::string>()
            << (sol.message.empty() ? "" : " (" + sol.message + ")") << "\n"
            << "active contact rows " << sol.active << " of " << problem->contact().num_constraints()
            << ", active-set iterations " << sol.iterations << ", pairing iterations " << sol.pairing_iterations
            << " (contact zone " << sol.zone_iterations << ")\n"
            << std::setprecision(3) << "contact force " << j["contact_force"].get<double>()
            << (three_d ? "" : " per unit thickness") << ", peak pressure " << j["peak_pressure"].get<double>()
            << (three_d ? ", contact area " : ", contact length ") << extent << "\n"
            << "  (consistent units: lengths in the mesh's unit, pressures and stresses in the unit of E)\n"
            << "time " << sol.time_s * 1e3 << " ms (setup " << setup * 1e3 << " ms)\n"
            << "KKT (relative): stationarity " << kkt.stationarity << ", penetration " << kkt.penetration
            << ", negative pressure " << kkt.negative_pressure << ", complementarity " << kkt.complementarity << "\n";
  if (!a.out.empty()) std::cout << "fields written to " << a.out << "/\n";
}

CommandRegistrar reg("fom", [](CLI::App& app) {
  auto args = std::make_shared<FomArgs>();
  auto* sub = app.add_subcommand("fom", "Solve one full-order contact problem");
  sub->add_option("--problem", args->problem, "a shipped problem (contactrom problems) or a problem file path")->required();
  sub->add_option("--param", args->param, "parameter values V or V1,V2,... in the problem's order (contactrom problems)")->required();
  add_integer(sub, "--refine", args->refine, "extra uniform mesh refinements (each splits every quad in four)", 0, 6);
  add_word(sub, "--solver", args->solver, "active-set (default) | ipopt", {"active-set", "ipopt"});
  sub->add_option("--out", args->out, "folder for <problem>.vtu and <problem>_surface.csv")
      ->check(non_empty_path());
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_fom(*args); });
});

}  // namespace
}  // namespace contactrom::cli
