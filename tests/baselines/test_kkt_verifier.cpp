// KKT verifier (baselines/kkt_verifier): exact solutions pass, perturbed ones fail
// the matching residual, inconsistent input is a status, summaries take maxima.
#define BOOST_TEST_MODULE baselines_kkt_verifier
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include <contactrom/baselines/ipopt_qp.hpp>
#include <contactrom/baselines/kkt_verifier.hpp>
#include <contactrom/fom/active_set_solver.hpp>

using namespace contactrom;
using baselines::verify_solution;
using baselines::VerificationReport;
using baselines::VerificationSummary;
using fom::FomSolution;
using fom::Param;

namespace {

Param p1(double v) { return Param::Constant(1, v); }

/// Problems and their exact (active-set) solutions, built once for the file.
struct Case {
  std::unique_ptr<fom::Problem> problem;
  FomSolution exact;
};

const Case& exact_case(const std::string& name) {
  static std::map<std::string, Case> cases;
  Case& c = cases[name];
  if (!c.problem) {
    c.problem = fom::make_problem(name);
    c.exact = fom::ActiveSetSolver(*c.problem).solve(name == "rope" ? p1(20) : p1(0.15));
    BOOST_TEST_REQUIRE(c.exact.status == Status::Success, c.exact.message);
  }
  return c;
}

/// Index of the row with the largest pressure (certainly active).
int most_loaded_row(const Eigen::VectorXd& lambda) {
  Eigen::Index i = 0;
  lambda.maxCoeff(&i);
  return static_cast<int>(i);
}

}  // namespace

BOOST_AUTO_TEST_CASE(exact_solution_has_tiny_residuals_and_zero_self_error) {
  for (const std::string name : {"rope", "hertz"}) {
    BOOST_TEST_CONTEXT(name) {
      const Case& c = exact_case(name);
      const VerificationReport r = verify_solution(*c.problem, c.exact, &c.exact);
      BOOST_TEST(r.status == Status::Success);
      BOOST_TEST(r.kkt.stationarity <= 1e-10);
      BOOST_TEST(r.kkt.penetration <= 1e-10);
      BOOST_TEST(r.kkt.negative_pressure <= 1e-10);
      BOOST_TEST(r.kkt.complementarity <= 1e-10);
      BOOST_TEST(r.has_reference);
      BOOST_TEST(r.errors.primal_h1 == 0.0);
      BOOST_TEST(r.errors.dual_l2 == 0.0);
      BOOST_TEST(r.errors.active_set_differences == 0);
    }
  }
}

BOOST_AUTO_TEST_CASE(residuals_are_those_of_fom_kkt) {
  const Case& c = exact_case("hertz");
  const VerificationReport r = verify_solution(*c.problem, c.exact.mu, c.exact.u, c.exact.lambda);
  const fom::KktResiduals k = fom::kkt_residuals(*c.problem, c.exact.mu, c.exact.u, c.exact.lambda);
  BOOST_TEST(r.kkt.stationarity == k.stationarity);
  BOOST_TEST(r.kkt.penetration == k.penetration);
  BOOST_TEST(r.kkt.negative_pressure == k.negative_pressure);
  BOOST_TEST(r.kkt.complementarity == k.complementarity);
  BOOST_TEST(!r.has_reference);
}

BOOST_AUTO_TEST_CASE(negative_pressure_is_detected) {
  for (const std::string name : {"rope", "hertz"}) {
    BOOST_TEST_CONTEXT(name) {
      const Case& c = exact_case(name);
      Eigen::VectorXd lambda = c.exact.lambda;
      const int s = most_loaded_row(lambda);
      lambda(s) = -0.5 * lambda(s);
      const VerificationReport r = verify_solution(*c.problem, c.exact.mu, c.exact.u, lambda, &c.exact);
      BOOST_TEST(r.status == Status::Success);
      BOOST_TEST(r.kkt.negative_pressure >= 0.1);  // 0.5 λ_max / max|λ|, up to the changed max
      BOOST_TEST(r.kkt.stationarity >= 1e-4);      // the contact force no longer balances
      BOOST_TEST(r.errors.dual_l2 >= 1e-2);
      // The row still touches (zero gap in u and u_ref), so compare_solutions excuses it
      // as degenerate: the active-set count is not the detector here, the residual is.
      BOOST_TEST(r.errors.active_set_differences == 0);
    }
  }
}

BOOST_AUTO_TEST_CASE(penetration_is_detected) {
  // rope: move the whole rope 0.01 down, into the obstacle where it touches.
  {
    const Case& c = exact_case("rope");
    Eigen::VectorXd u = c.exact.u;
    for (int i : c.problem->free_dofs()) u(i) -= 0.01;
    const VerificationReport r = verify_solution(*c.problem, c.exact.mu, u, c.exact.lambda, &c.exact);
    BOOST_TEST(r.kkt.penetration >= 0.01);  // 0.01 / displacement scale 0.5 = 0.02
    BOOST_TEST(r.kkt.complementarity >= 1e-3);
    BOOST_TEST(r.errors.primal_h1 >= 1e-3);
  }
  // hertz: push every slave node 0.01 further down, into the bottom body.
  {
    const Case& c = exact_case("hertz");
    const auto& contact = dynamic_cast<const fom::NodeToSegmentContact&>(c.problem->contact());
    Eigen::VectorXd u = c.exact.u;
    for (int node : contact.slave_nodes())
      if (!c.problem->is_dirichlet()[2 * node + 1]) u(2 * node + 1) -= 0.01;
    const VerificationReport r = verify_solution(*c.problem, c.exact.mu, u, c.exact.lambda);
    BOOST_TEST(r.kkt.penetration >= 0.01);  // ≈ 0.01 / displacement scale 0.3
    BOOST_TEST(r.kkt.complementarity >= 1e-3);
  }
}

BOOST_AUTO_TEST_CASE(ipopt_reference_errors_are_small) {
  const Case& c = exact_case("hertz");
  const FomSolution ref = baselines::IpoptQpSolver(*c.problem).solve(c.exact.mu);
  BOOST_TEST_REQUIRE(ref.status == Status::Success, ref.message);
  const VerificationReport r = verify_solution(*c.problem, c.exact, &ref);
  BOOST_TEST(r.errors.primal_h1 <= 1e-6);
  BOOST_TEST(r.errors.dual_l2 <= 1e-6);
  BOOST_TEST(r.errors.active_set_differences == 0);
}

BOOST_AUTO_TEST_CASE(inconsistent_input_is_a_status_with_infinite_residuals) {
  const Case& c = exact_case("rope");
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::VectorXd short_u = c.exact.u.head(c.exact.u.size() - 1);
  VerificationReport r = verify_solution(*c.problem, c.exact.mu, short_u, c.exact.lambda, &c.exact);
  BOOST_TEST(r.status == Status::InvalidInput);
  BOOST_TEST(r.message.find("displacement") != std::string::npos, r.message);
  BOOST_TEST(r.kkt.stationarity == inf);
  BOOST_TEST(r.errors.primal_h1 == inf);

  r = verify_solution(*c.problem, c.exact.mu, c.exact.u, Eigen::VectorXd::Zero(3));
  BOOST_TEST(r.status == Status::InvalidInput);
  BOOST_TEST(r.message.find("pressure") != std::string::npos, r.message);

  Eigen::VectorXd nan_u = c.exact.u;
  nan_u(5) = std::numeric_limits<double>::quiet_NaN();
  r = verify_solution(*c.problem, c.exact.mu, nan_u, c.exact.lambda);
  BOOST_TEST(r.status == Status::InvalidInput);

  r = verify_solution(*c.problem, p1(30), c.exact.u, c.exact.lambda, &c.exact);  // reference at μ = 20
  BOOST_TEST(r.status == Status::InvalidInput);
  BOOST_TEST(r.message.find("another parameter") != std::string::npos, r.message);

  r = verify_solution(*c.problem, Param::Constant(2, 20.0), c.exact.u, c.exact.lambda);
  BOOST_TEST(r.status == Status::InvalidInput);
}

BOOST_AUTO_TEST_CASE(summary_takes_componentwise_maxima_and_means) {
  VerificationReport a, b, nan_report;
  a.kkt.stationarity = 1e-3, a.kkt.penetration = 1e-9, a.kkt.complementarity = 5e-4;
  a.has_reference = true, a.errors.primal_h1 = 1e-2, a.errors.dual_l2 = 3e-2, a.errors.active_set_differences = 2;
  b.kkt.negative_pressure = 2e-5, b.kkt.penetration = 4e-6;
  b.has_reference = true, b.errors.primal_h1 = 3e-2, b.errors.dual_l2 = 1e-2, b.errors.active_set_differences = 1;
  VerificationSummary s = baselines::summarize({a, b});
  BOOST_TEST(s.count == 2);
  BOOST_TEST(s.with_reference == 2);
  BOOST_TEST(s.invalid == 0);
  BOOST_TEST(s.max_kkt.stationarity == 1e-3);
  BOOST_TEST(s.max_kkt.penetration == 4e-6);
  BOOST_TEST(s.max_kkt.negative_pressure == 2e-5);
  BOOST_TEST(s.max_kkt.complementarity == 5e-4);
  BOOST_TEST(s.max_kkt_residual() == 1e-3);
  BOOST_TEST(s.max_primal_h1 == 3e-2);
  BOOST_TEST(s.max_dual_l2 == 3e-2);
  BOOST_TEST(s.mean_primal_h1 == 2e-2, boost::test_tools::tolerance(1e-12));
  BOOST_TEST(s.mean_dual_l2 == 2e-2, boost::test_tools::tolerance(1e-12));
  BOOST_TEST(s.max_active_set_differences == 2);
  BOOST_TEST(s.total_active_set_differences == 3);

  // A NaN residual must not hide: it counts as +infinity.
  nan_report.kkt.stationarity = std::numeric_limits<double>::quiet_NaN();
  s.add(nan_report);
  BOOST_TEST(s.count == 3);
  BOOST_TEST(std::isinf(s.max_kkt.stationarity));
  BOOST_TEST(s.with_reference == 2);  // no reference in the third report

  const auto fields = s.fields();
  BOOST_TEST(fields.size() == 14u);
  BOOST_TEST(fields.front().first == "count");
  BOOST_TEST(fields.front().second == 3.0);
  bool found = false;
  for (const auto& [key, value] : fields) {
    if (key != "max_primal_error") continue;
    found = true;
    BOOST_TEST(value == 3e-2);
  }
  BOOST_TEST(found);
}

BOOST_AUTO_TEST_CASE(empty_summary_is_zero) {
  const VerificationSummary s = baselines::summarize({});
  BOOST_TEST(s.count == 0);
  BOOST_TEST(s.max_kkt_residual() == 0.0);
  BOOST_TEST(s.mean_primal_h1 == 0.0);
}
