// fom/pairing_fixed_point.hpp through fom::ActiveSetSolver on hertz: a converged
// solution passes the stopping test it reports (re-pairing at it changes nothing
// beyond the tolerance), the cap gives no_convergence with the last change in the
// message, and Anderson acceleration reaches the same solution as the plain
// iteration in fewer pairing iterations.
#define BOOST_TEST_MODULE fom_pairing_fixed_point
#include <boost/test/unit_test.hpp>
#include <memory>

#include "fom/active_set_solver.hpp"
#include "fom/kkt.hpp"
#include "fom/pairing_fixed_point.hpp"

using namespace contactrom;
using namespace contactrom::fom;

namespace {

const Problem& hertz() {
  static const std::unique_ptr<Problem> p = make_problem("hertz");
  return *p;
}

Param p1(double v) { return Eigen::VectorXd::Constant(1, v); }

/// pairing_change() of a solution: its own pairing against the one found at its u.
double change_at(const FomSolution& sol, double tolerance) {
  const ContactModel& contact = hertz().contact();
  const Eigen::VectorXd u_s = contact.restrict_to_surface(sol.u);
  ConstraintMatrix c, c_next;
  Eigen::VectorXd g, g_next;
  contact.assemble(sol.pairing, c, g);
  contact.assemble(contact.search(u_s), c_next, g_next);
  return pairing_change(c, g, c_next, g_next, u_s, sol.lambda, contact.weights(), hertz().displacement_scale(),
                        tolerance);
}

}  // namespace

BOOST_AUTO_TEST_CASE(a_converged_solution_passes_its_stopping_test) {
  const ActiveSetOptions options;
  const ActiveSetSolver solver(hertz(), options);
  for (const double d : {0.05, 0.3}) {
    const FomSolution sol = solver.solve(p1(d));
    BOOST_TEST_REQUIRE(sol.status == Status::Success, sol.message);
    BOOST_TEST(sol.pairing_iterations > 1);  // the pairing did move
    // u is recomputed from λ with one more solve: the test holds to the tolerance
    // up to that solve's rounding.
    BOOST_TEST(change_at(sol, options.pairing_tolerance) <= 1e3 * options.pairing_tolerance, "d = " << d);
  }
}

BOOST_AUTO_TEST_CASE(the_cap_gives_no_convergence_with_the_last_change) {
  ActiveSetOptions options;
  options.max_pairing_iterations = 1;
  const FomSolution sol = ActiveSetSolver(hertz(), options).solve(p1(0.3));
  BOOST_TEST(sol.status == Status::NoConvergence);
  BOOST_TEST(sol.pairing_iterations == 1);
  BOOST_TEST(sol.message.find("did not settle in 1 fixed-point iterations (last change") != std::string::npos,
             sol.message);
  // The returned iterate is the QP solution of its pairing, but not a fixed point.
  BOOST_TEST(change_at(sol, options.pairing_tolerance) > options.pairing_tolerance);
}

BOOST_AUTO_TEST_CASE(anderson_reaches_the_plain_iterations_solution_in_fewer_iterations) {
  ActiveSetOptions plain_options;
  plain_options.anderson_depth = 0;
  const FomSolution plain = ActiveSetSolver(hertz(), plain_options).solve(p1(0.3));
  const FomSolution anderson = ActiveSetSolver(hertz()).solve(p1(0.3));
  BOOST_TEST_REQUIRE(plain.status == Status::Success, plain.message);
  BOOST_TEST_REQUIRE(anderson.status == Status::Success, anderson.message);
  BOOST_TEST(relative_h1_error(hertz(), anderson.u, plain.u) <= 1e-9);
  BOOST_TEST(relative_l2_pressure_error(hertz(), anderson.lambda, plain.lambda) <= 1e-8);
  BOOST_TEST(anderson.pairing_iterations < plain.pairing_iterations);
  BOOST_TEST_MESSAGE("pairing iterations: plain " << plain.pairing_iterations << ", Anderson "
                                                  << anderson.pairing_iterations);
}
