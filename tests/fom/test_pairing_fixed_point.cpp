// fom/pairing_fixed_point.hpp: pairing_change() on hand-made two-row operators
// (closed forms, with and without its penetration term); through
// fom::ActiveSetSolver on hertz: a converged
// solution passes the stopping test it reports (re-pairing at it changes nothing
// beyond the tolerance), the cap gives no_convergence with the last change in the
// message, and Anderson acceleration reaches the same solution as the plain
// iteration in fewer pairing iterations.
#define BOOST_TEST_MODULE fom_pairing_fixed_point
#include <boost/test/unit_test.hpp>
#include <cmath>
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

/// A row-major constraint operator from dense rows.
ConstraintMatrix operator_of(const Eigen::MatrixXd& dense) { return dense.sparseView(); }

}  // namespace

BOOST_AUTO_TEST_CASE(pairing_change_on_a_hand_made_case) {
  // Two rows on two surface dofs, w = 1, U = 2. Row 0 carries pressure and
  // penetrates by 1e-3 (v = 1e-3/U relative); row 1 is open by 0.5 and unloaded.
  const Eigen::VectorXd weights = Eigen::VectorXd::Ones(2), lambda = Eigen::Vector2d(1.0, 0.0);
  const Eigen::VectorXd u_s = Eigen::Vector2d(1e-3, -0.5), g = Eigen::VectorXd::Zero(2);
  const double u_scale = 2.0, tol = 1e-8;
  const ConstraintMatrix c = operator_of(Eigen::Matrix2d::Identity());
  // Unchanged pairing: nothing changes but the penetration, which only the full test sees.
  BOOST_TEST(pairing_change(c, g, c, g, u_s, lambda, weights, u_scale, tol, true) == 1e-3 / u_scale);
  BOOST_TEST(pairing_change(c, g, c, g, u_s, lambda, weights, u_scale, tol, false) == 0.0);
  BOOST_TEST(pairing_change(c, g, c, g, u_s, lambda, weights, u_scale, tol) == 1e-3 / u_scale);  // default: on
  // A gap offset moved by 0.1 on the open row only: not a row that matters.
  const Eigen::VectorXd g_open = Eigen::Vector2d(0.0, 0.1);
  BOOST_TEST(pairing_change(c, g, c, g_open, u_s, lambda, weights, u_scale, tol, false) == 0.0);
  // The loaded row's gap offset moves by 4e-3: its gap changes by 4e-3 and it no
  // longer penetrates, so both tests give the gap change.
  const Eigen::VectorXd g_contact = Eigen::Vector2d(4e-3, 0.0);
  for (const bool penetration : {true, false})
    BOOST_TEST(std::abs(pairing_change(c, g, c, g_contact, u_s, lambda, weights, u_scale, tol, penetration) -
                        4e-3 / u_scale) <= 1e-17);
  // The loaded row's normal turns to (0.8, 0.6): the contact force C^T λ = (1, 0)
  // becomes (0.8, 0.6), a relative change of |(-0.2, 0.6)| = sqrt(0.4), which
  // dominates both tests.
  Eigen::Matrix2d turned = Eigen::Matrix2d::Identity();
  turned.row(0) << 0.8, 0.6;
  const ConstraintMatrix c_turned = operator_of(turned);
  for (const bool penetration : {true, false})
    BOOST_TEST(std::abs(pairing_change(c, g, c_turned, g, u_s, lambda, weights, u_scale, tol, penetration) -
                        std::sqrt(0.4)) <= 1e-15);
}

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
