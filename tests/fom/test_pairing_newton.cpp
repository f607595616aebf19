// fom/pairing_newton.hpp and NodeToSegmentContact::linearise_pairing: the pairing
// coordinates' derivatives against central differences of the search and of the
// assembly (hertz and ironing, at converged solutions); the Newton-stepped fixed
// point reaches the Anderson-only fixed point on ironing (where the plain iteration
// does not converge at all and Anderson needs several times more iterations), with
// fewer iterations when Newton steps resume after a failed one, and on
// hertz with the row cap lifted, with KKT residuals at rounding level; solve_at a
// solution's own pairing reproduces it; without a
// linearisation (3D, obstacles) no step is proposed.
#define BOOST_TEST_MODULE fom_pairing_newton
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <random>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/pairing_newton.hpp>

using namespace contactrom;
using namespace contactrom::fom;

namespace {

const Problem& problem(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Problem>> cache;
  auto& p = cache[name];
  if (!p) p = make_problem(name);
  return *p;
}

Param p1(double v) { return Eigen::VectorXd::Constant(1, v); }

std::vector<int> active_rows(const Eigen::VectorXd& lambda) {
  std::vector<int> rows;
  for (Eigen::Index r = 0; r < lambda.size(); ++r)
    if (lambda(r) > 0.0) rows.push_back(static_cast<int>(r));
  return rows;
}

}  // namespace

BOOST_AUTO_TEST_CASE(pairing_derivatives_match_central_differences) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (const auto& [name, d] : {std::pair<std::string, double>{"hertz", 0.2}, {"ironing", 2.0}}) {
    const Problem& p = problem(name);
    const ContactModel& contact = p.contact();
    const FomSolution sol = ActiveSetSolver(p).solve(p1(d));
    BOOST_TEST_REQUIRE(sol.status == Status::Success, sol.message);
    const Eigen::VectorXd u = contact.restrict_to_surface(sol.u);
    const std::vector<int> rows = active_rows(sol.lambda);
    BOOST_TEST_REQUIRE(!rows.empty());
    const Pairing pairing = contact.search(u);
    PairingLinearisation lin;
    BOOST_TEST_REQUIRE(contact.linearise_pairing(u, pairing, rows, lin));
    BOOST_TEST(lin.per_row == 2);
    // ∂q/∂u along random directions: q of the searches at u ± h v.
    const double h = 1e-6 * p.displacement_scale();
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd v(u.size());
      for (Eigen::Index i = 0; i < v.size(); ++i) v(i) = normal(rng);
      PairingLinearisation plus, minus;
      BOOST_TEST_REQUIRE(contact.linearise_pairing(u + h * v, contact.search(u + h * v), rows, plus));
      BOOST_TEST_REQUIRE(contact.linearise_pairing(u - h * v, contact.search(u - h * v), rows, minus));
      Eigen::VectorXd fd = (plus.q - minus.q) / (2.0 * h);
      for (Eigen::Index i = 1; i < fd.size(); i += 2) fd(i) = std::remainder(plus.q(i) - minus.q(i), 2.0 * M_PI) / (2.0 * h);
      const Eigen::VectorXd exact = lin.dq_du * v;
      BOOST_TEST((fd - exact).norm() <= 1e-5 * exact.norm(), name << ": |fd - exact| = " << (fd - exact).norm()
                                                                   << " of " << exact.norm());
    }
    // ∂C/∂q and ∂g/∂q: rows assembled at the pairing moved by ± h in one coordinate.
    const std::vector<int> one = {rows[rows.size() / 2]};
    PairingLinearisation lin1;
    BOOST_TEST_REQUIRE(contact.linearise_pairing(u, pairing, one, lin1));
    for (int j = 0; j < 2; ++j) {
      Pairing plus = pairing, minus = pairing;
      Eigen::VectorXd q = lin1.q;
      q(j) += 1e-7;
      contact.move_pairing(plus, one, q);
      q(j) -= 2e-7;
      contact.move_pairing(minus, one, q);
      ConstraintMatrix cp, cm;
      Eigen::VectorXd gp, gm;
      contact.assemble_rows(plus, one, cp, gp);
      contact.assemble_rows(minus, one, cm, gm);
      const Eigen::MatrixXd fd = (Eigen::MatrixXd(cp) - Eigen::MatrixXd(cm)) / 2e-7;
      const Eigen::MatrixXd exact = Eigen::MatrixXd(lin1.dc).row(j);
      BOOST_TEST((fd - exact).norm() <= 1e-6 * exact.norm(), name << " coordinate " << j);
      BOOST_TEST(std::abs((gp(0) - gm(0)) / 2e-7 - lin1.dg(j)) <= 1e-6 * std::max(std::abs(lin1.dg(j)), 1e-3));
    }
    // move_pairing of the coordinates themselves gives the pairing back.
    Pairing same = pairing;
    contact.move_pairing(same, rows, lin.q);
    BOOST_TEST(same.same_as(pairing, 1e-12));
  }
}

BOOST_AUTO_TEST_CASE(newton_steps_reach_the_anderson_fixed_point_on_ironing) {
  // Ironing: the plain iteration does not converge (an eigenvalue of the pairing
  // map's Jacobian above one), Anderson alone needs 30-60 iterations; with Newton
  // steps the same fixed point in a fraction of them.
  const Problem& p = problem("ironing");
  ActiveSetOptions anderson_only, plain;
  anderson_only.newton_start = 0.0;
  plain.newton_start = 0.0;
  plain.anderson_depth = 0;
  plain.max_pairing_iterations = 100;
  ActiveSetOptions restarted;  // the Anderson history cleared whenever the change grows
  restarted.anderson_restart = true;
  const ActiveSetSolver newton_solver(p), anderson_solver(p, anderson_only), plain_solver(p, plain),
      restarted_solver(p, restarted);
  int newton_total = 0, anderson_total = 0;
  for (const double dx : {0.5, 1.25, 2.0, 3.3}) {
    const FomSolution n = newton_solver.solve(p1(dx)), a = anderson_solver.solve(p1(dx));
    BOOST_TEST_REQUIRE(n.status == Status::Success, n.message);
    BOOST_TEST_REQUIRE(a.status == Status::Success, a.message);
    BOOST_TEST(plain_solver.solve(p1(dx)).status == Status::NoConvergence);
    BOOST_TEST((n.u - a.u).norm() <= 1e-10 * a.u.norm(), "dx = " << dx);
    BOOST_TEST((n.lambda - a.lambda).norm() <= 1e-9 * a.lambda.norm(), "dx = " << dx);
    BOOST_TEST(n.kkt.max() <= 1e-10);
    const FomSolution r = restarted_solver.solve(p1(dx));
    BOOST_TEST_REQUIRE(r.status == Status::Success, r.message);
    BOOST_TEST((r.u - a.u).norm() <= 1e-10 * a.u.norm(), "dx = " << dx);
    newton_total += n.pairing_iterations, anderson_total += a.pairing_iterations;
  }
  BOOST_TEST_MESSAGE("pairing iterations, 4 loads: Newton " << newton_total << ", Anderson " << anderson_total);
  BOOST_TEST(2 * newton_total <= anderson_total);
}

BOOST_AUTO_TEST_CASE(newton_steps_resume_after_a_failed_one) {
  // Ironing's first iterates jump (pairing change 0.1-0.7), where a Newton step may
  // leave the pairing it linearises and fail to reduce the change. Handing over to
  // Anderson only until the change halves (newton_retry, the default) reaches the same
  // fixed point as handing over for good (newton_retry = 0, from the default start or
  // the former 0.1), in fewer iterations over 16 loads.
  const Problem& p = problem("ironing");
  ActiveSetOptions for_good, former;
  for_good.newton_retry = 0.0;
  former.newton_retry = 0.0;
  former.newton_start = 0.1;
  BOOST_TEST(ActiveSetOptions().newton_retry > 0.0);
  const ActiveSetSolver retrying(p), giving_up(p, for_good), before(p, former);
  int retry_total = 0, for_good_total = 0, former_total = 0;
  for (int i = 0; i < 16; ++i) {
    const double dx = 4.0 * (i + 0.5) / 16.0;
    const FomSolution r = retrying.solve(p1(dx)), g = giving_up.solve(p1(dx)), f = before.solve(p1(dx));
    BOOST_TEST_REQUIRE(r.status == Status::Success, r.message);
    BOOST_TEST_REQUIRE(g.status == Status::Success, g.message);
    BOOST_TEST_REQUIRE(f.status == Status::Success, f.message);
    BOOST_TEST((r.u - f.u).norm() <= 1e-10 * f.u.norm(), "dx = " << dx);
    BOOST_TEST((r.lambda - f.lambda).norm() <= 1e-9 * f.lambda.norm(), "dx = " << dx);
    BOOST_TEST((g.u - f.u).norm() <= 1e-10 * f.u.norm(), "dx = " << dx);
    retry_total += r.pairing_iterations, for_good_total += g.pairing_iterations, former_total += f.pairing_iterations;
  }
  BOOST_TEST_MESSAGE("pairing iterations, 16 loads: retry " << retry_total << ", for good from 0.3 " << for_good_total
                                                            << ", for good from 0.1 " << former_total);
  BOOST_TEST(retry_total < for_good_total);
  BOOST_TEST(retry_total < former_total);
}

BOOST_AUTO_TEST_CASE(newton_on_hertz_with_the_row_cap_lifted) {
  // 27 rows carry the contact at d = 0.1: above the default cap, so the default
  // solver takes Anderson steps; lifting the cap gives Newton's quadratic
  // convergence to the same solution.
  const Problem& p = problem("hertz");
  ActiveSetOptions lifted;
  lifted.newton_max_active = 1000;
  const FomSolution n = ActiveSetSolver(p, lifted).solve(p1(0.1)), a = ActiveSetSolver(p).solve(p1(0.1));
  BOOST_TEST_REQUIRE(n.status == Status::Success, n.message);
  BOOST_TEST_REQUIRE(a.status == Status::Success, a.message);
  BOOST_TEST(n.active > ActiveSetOptions().newton_max_active);
  BOOST_TEST((n.u - a.u).norm() <= 1e-10 * a.u.norm());
  BOOST_TEST((n.lambda - a.lambda).norm() <= 1e-9 * a.lambda.norm());
  BOOST_TEST(n.pairing_iterations <= 8);
  BOOST_TEST(a.pairing_iterations >= 12);
}

BOOST_AUTO_TEST_CASE(no_step_without_a_linearisation_or_active_rows) {
  const Problem& rope = problem("rope");
  const ContactModel& contact = rope.contact();
  PairingLinearisation lin;
  BOOST_TEST(!contact.linearise_pairing(Eigen::VectorXd::Zero(contact.surface_dofs().size()), Pairing{}, {0}, lin));
  // hertz at a pairing with no pressure: nothing to linearise.
  const Problem& p = problem("hertz");
  const ContactModel& hc = p.contact();
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(hc.surface_dofs().size());
  const Pairing pairing = hc.search(u);
  ConstraintMatrix c;
  Eigen::VectorXd g;
  hc.assemble(pairing, c, g);
  Pairing out;
  const Eigen::MatrixXd s = Eigen::MatrixXd::Identity(u.size(), u.size());
  BOOST_TEST(!newton_pairing(hc, s, pairing, c, Eigen::VectorXd::Zero(hc.num_constraints()), u, pairing, 100, out));
}

BOOST_AUTO_TEST_CASE(solve_at_the_final_pairing_reproduces_the_solution) {
  // ActiveSetSolver::solve_at (the limit model of `contactrom bench`): one QP at a
  // solution's own pairing gives that solution back, in one pairing iteration.
  for (const auto& [name, d] : {std::pair<std::string, double>{"hertz", 0.15}, {"ironing", 1.5}}) {
    const Problem& p = problem(name);
    const ActiveSetSolver solver(p);
    const FomSolution s = solver.solve(p1(d));
    BOOST_TEST_REQUIRE(s.status == Status::Success, s.message);
    const FomSolution at = solver.solve_at(p1(d), s.pairing, p.contact().restrict_to_surface(s.u));
    BOOST_TEST_REQUIRE(at.status == Status::Success, at.message);
    BOOST_TEST(at.pairing_iterations == 1);
    BOOST_TEST((at.u - s.u).norm() <= 1e-12 * s.u.norm(), name);
    BOOST_TEST((at.lambda - s.lambda).norm() <= 1e-10 * s.lambda.norm(), name);
    BOOST_TEST(at.kkt.max() <= 1e-10);
  }
  // A stiffness that depends on μ has no single factorisation to reuse: refused.
  const Problem& rope = problem("rope");
  const FomSolution r = ActiveSetSolver(rope).solve_at(p1(20.0), Pairing{}, Eigen::VectorXd());
  BOOST_TEST(r.status == Status::InvalidInput);
}
