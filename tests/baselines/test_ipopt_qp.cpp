// Ipopt reference QP (baselines/ipopt_qp): cross-validation against the custom
// active-set solver on rope / hertz / ironing, failure reporting, warm start, and
// `contactrom fom --solver ipopt` through the CLI.
#define BOOST_TEST_MODULE baselines_ipopt_qp
#include <boost/test/unit_test.hpp>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <contactrom/baselines/ipopt_qp.hpp>
#include "common/run_command.hpp"
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/rope.hpp>

using namespace contactrom;
using baselines::IpoptOptions;
using baselines::IpoptQpSolver;
using fom::FomSolution;
using fom::Param;

namespace {

Param p1(double v) { return Param::Constant(1, v); }

/// Every problem is built (and meshed) once for the whole file.
const fom::Problem& problem(const std::string& name) {
  static std::map<std::string, std::unique_ptr<fom::Problem>> problems;
  auto& p = problems[name];
  if (!p) p = fom::make_problem(name);
  return *p;
}

/// Agreement tolerance of the acceptance criterion (the Ipopt cross-check: same solution to 1e-6).
constexpr double kAgreement = 1e-6;

/// Solves every μ with both solvers and checks that they agree; prints the worst case.
void cross_validate(const std::string& name, const std::vector<Param>& params) {
  const fom::Problem& p = problem(name);
  const fom::ActiveSetSolver active_set(p);
  const IpoptQpSolver ipopt(p);
  double max_h1 = 0.0, max_l2 = 0.0, max_kkt = 0.0;
  for (const Param& mu : params) {
    BOOST_TEST_CONTEXT(name << " mu = " << mu(0)) {
      const FomSolution ref = active_set.solve(mu);
      const FomSolution sol = ipopt.solve(mu);
      BOOST_TEST_REQUIRE(ref.status == Status::Success, ref.message);
      BOOST_TEST_REQUIRE(sol.status == Status::Success, sol.message);
      const fom::SolutionErrors e = fom::compare_solutions(p, sol.u, sol.lambda, ref.u, ref.lambda, 1e-8);
      BOOST_TEST(e.primal_h1 <= kAgreement);
      BOOST_TEST(e.dual_l2 <= kAgreement);
      BOOST_TEST(e.active_set_differences == 0);
      // The criteria above are the fom/kkt helpers; check they are what the brief names.
      BOOST_TEST(e.primal_h1 == fom::relative_h1_error(p, sol.u, ref.u));
      BOOST_TEST(e.dual_l2 == fom::relative_l2_pressure_error(p, sol.lambda, ref.lambda));
      // Ipopt's multipliers are pressures (≥ 0 up to round-off), and its own solution is a KKT point.
      BOOST_TEST(sol.lambda.minCoeff() >= -1e-12 * sol.lambda.cwiseAbs().maxCoeff());
      const fom::KktResiduals k = fom::kkt_residuals(p, mu, sol.u, sol.lambda);
      BOOST_TEST(k.max() <= 1e-8);
      BOOST_TEST(sol.active == ref.active);
      BOOST_TEST(sol.iterations > 0);
      BOOST_TEST(sol.pairing_iterations >= 1);
      max_h1 = std::max(max_h1, e.primal_h1);
      max_l2 = std::max(max_l2, e.dual_l2);
      max_kkt = std::max(max_kkt, k.max());
    }
  }
  BOOST_TEST_MESSAGE(name << ": " << params.size() << " parameters, max primal H1 disagreement " << max_h1
                          << ", max dual L2 disagreement " << max_l2 << ", max Ipopt KKT residual " << max_kkt);
}

std::vector<Param> rope_gammas() {
  std::vector<Param> out;
  for (int i = 0; i <= 16; ++i) out.push_back(p1(10.0 + 2.5 * i));  // 10, 12.5, ..., 50 (17 values)
  return out;
}

}  // namespace

BOOST_AUTO_TEST_CASE(agrees_with_active_set_on_rope_all_17_gammas) { cross_validate("rope", rope_gammas()); }

BOOST_AUTO_TEST_CASE(agrees_with_active_set_on_hertz) {
  cross_validate("hertz", {p1(0.01), p1(0.075), p1(0.15), p1(0.225), p1(0.3)});
}

BOOST_AUTO_TEST_CASE(agrees_with_active_set_on_ironing) {
  cross_validate("ironing", {p1(0), p1(1), p1(2), p1(3), p1(4)});
}

BOOST_AUTO_TEST_CASE(iteration_cap_gives_no_convergence_status_with_residuals) {
  IpoptOptions opt;
  opt.max_iterations = 1;
  for (const std::string name : {"rope", "hertz"}) {
    BOOST_TEST_CONTEXT(name) {
      const fom::Problem& p = problem(name);
      const Param mu = name == "rope" ? p1(20) : p1(0.15);
      FomSolution sol;
      BOOST_REQUIRE_NO_THROW(sol = IpoptQpSolver(p, opt).solve(mu));
      BOOST_TEST(sol.status == Status::NoConvergence);
      BOOST_TEST(sol.message.find("Maximum_Iterations_Exceeded") != std::string::npos, sol.message);
      BOOST_TEST(sol.message.find("stationarity") != std::string::npos, sol.message);
      // The last iterate is still returned, with consistent sizes.
      BOOST_TEST(sol.u.size() == p.num_dofs());
      BOOST_TEST(sol.lambda.size() == p.contact().num_constraints());
      BOOST_TEST(sol.u.allFinite());
      BOOST_TEST(sol.iterations == 1);
    }
  }
}

BOOST_AUTO_TEST_CASE(pairing_cap_gives_no_convergence_status) {
  IpoptOptions opt;
  opt.max_pairing_iterations = 1;
  const FomSolution sol = IpoptQpSolver(problem("hertz"), opt).solve(p1(0.3));
  BOOST_TEST(sol.status == Status::NoConvergence);
  BOOST_TEST(sol.message.find("pairing") != std::string::npos, sol.message);
  BOOST_TEST(sol.pairing_iterations == 1);
}

BOOST_AUTO_TEST_CASE(warm_start_from_converged_solution_settles_at_once) {
  const fom::Problem& p = problem("hertz");
  const Param mu = p1(0.2);
  const FomSolution ref = fom::ActiveSetSolver(p).solve(mu);
  BOOST_TEST_REQUIRE(ref.status == Status::Success, ref.message);
  const IpoptQpSolver ipopt(p);
  const FomSolution cold = ipopt.solve(mu);
  const FomSolution warm = ipopt.solve(mu, &ref);
  BOOST_TEST_REQUIRE(warm.status == Status::Success, warm.message);
  // Both stop on the same test (fom::pairing_change), but Ipopt's interior-point
  // solution differs from the active-set one by its tolerance, so it may need one
  // more re-pairing; never a full cold loop.
  BOOST_TEST(warm.pairing_iterations <= 2);
  BOOST_TEST(warm.pairing_iterations < cold.pairing_iterations);
  BOOST_TEST(warm.iterations < cold.iterations);
  BOOST_TEST(fom::relative_h1_error(p, warm.u, ref.u) <= kAgreement);
  BOOST_TEST(fom::relative_l2_pressure_error(p, warm.lambda, ref.lambda) <= kAgreement);
}

BOOST_AUTO_TEST_CASE(separated_rope_has_no_active_row) {
  fom::RopeOptions opt;
  opt.load = -100.0;  // pulls the rope away from the obstacle
  const auto p = fom::make_rope_problem(opt);
  const FomSolution sol = IpoptQpSolver(*p).solve(p1(30));
  BOOST_TEST_REQUIRE(sol.status == Status::Success, sol.message);
  BOOST_TEST(sol.active == 0);
  BOOST_TEST(sol.lambda.cwiseAbs().maxCoeff() <= 1e-8);
  const FomSolution ref = fom::ActiveSetSolver(*p).solve(p1(30));
  BOOST_TEST(fom::relative_h1_error(*p, sol.u, ref.u) <= kAgreement);
}

BOOST_AUTO_TEST_CASE(parameter_outside_range_throws_input_error) {
  BOOST_CHECK_THROW(IpoptQpSolver(problem("rope")).solve(p1(60)), InputError);
}

BOOST_AUTO_TEST_CASE(cli_fom_ipopt_prints_same_json_keys_as_active_set) {
  const std::string exe = CONTACTROM_EXE;
  const auto r = test::run_command(exe + " fom --problem rope --param 20 --solver ipopt --json");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  BOOST_TEST(std::count(r.out.begin(), r.out.end(), '\n') == 1);  // exactly one JSON object
  const auto j = nlohmann::json::parse(r.out);
  BOOST_TEST(j["solver"] == "ipopt");
  BOOST_TEST(j["status"] == "success");
  BOOST_TEST(j["problem"] == "rope");
  BOOST_TEST(j["iterations"].get<int>() > 0);
  BOOST_TEST(j["active"].get<int>() > 0);
  for (const char* key : {"stationarity", "penetration", "negative_pressure", "complementarity"}) {
    BOOST_TEST_REQUIRE(j["kkt"].contains(key), key);
    BOOST_TEST(j["kkt"][key].get<double>() <= 1e-8, key);
  }
  const auto a = test::run_command(exe + " fom --problem rope --param 20 --solver active-set --json");
  BOOST_TEST_REQUIRE(a.exit_code == 0, a.err);
  const auto ja = nlohmann::json::parse(a.out);
  for (const auto& item : ja.items()) BOOST_TEST(j.contains(item.key()), item.key());
  for (const auto& item : j.items()) BOOST_TEST(ja.contains(item.key()), item.key());
  BOOST_TEST(j["active"] == ja["active"]);
  BOOST_TEST(std::abs(j["contact_force"].get<double>() - ja["contact_force"].get<double>()) <=
             1e-8 * std::abs(ja["contact_force"].get<double>()));
}

BOOST_AUTO_TEST_CASE(cli_fom_ipopt_writes_the_field_files) {
  const std::string dir = test::temp_dir() + "/fields";
  const auto r = test::run_command(std::string(CONTACTROM_EXE) + " fom --problem rope --param 20 --solver ipopt --out " +
                                   dir);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  BOOST_TEST(std::filesystem::exists(dir + "/rope.vtu"));
  BOOST_TEST(std::filesystem::exists(dir + "/rope_surface.csv"));
  BOOST_TEST(test::slurp(dir + "/rope_surface.csv").rfind("x,y,gap,pressure,u_x,u_y\n", 0) == 0);
  std::filesystem::remove_all(std::filesystem::path(dir).parent_path());
}
