// fom/contact_zone.hpp and NodeToSegmentContact::linearise_pairing: the pairing
// coordinates' derivatives against central differences of the search and of the
// assembly (hertz and ironing, at converged solutions); the pairing loop with the
// contact zone's steps reaches the fixed point of the loop with Anderson steps alone
// (hertz, ironing — where the plain iteration does not converge at all —, ironing2
// and punch_beam), in a fraction of its whole-loop iterations, with KKT residuals at
// rounding level; the zone's Newton steps (ironing's default; hertz with the row cap
// lifted) reach the zone's Anderson fixed point in fewer zone solves; resuming zone
// steps after a failed proposal reaches the same fixed point as handing over for
// good; a zone above its row cap is not iterated; solve_at a solution's own pairing
// reproduces it; without active rows or a pairing support (3D, obstacles) no step is
// proposed.
#define BOOST_TEST_MODULE fom_contact_zone
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <random>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/contact_zone.hpp>
#include <contactrom/fom/kkt.hpp>

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

/// The same fixed point: displacements to 1e-10, pressures to 1e-9 (relative).
void same_solution(const FomSolution& a, const FomSolution& b, const std::string& what) {
  BOOST_TEST((a.u - b.u).norm() <= 1e-10 * b.u.norm(), what);
  BOOST_TEST((a.lambda - b.lambda).norm() <= 1e-9 * b.lambda.norm(), what);
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

BOOST_AUTO_TEST_CASE(zone_steps_reach_the_anderson_fixed_point) {
  // The loop with the zone's steps (the default) against the loop with Anderson steps
  // alone: the same solution, in a fraction of the whole-loop iterations. On ironing
  // the plain iteration does not converge at all (an eigenvalue of the pairing map's
  // Jacobian above one).
  ActiveSetOptions anderson_only, plain;
  anderson_only.zone_start = 0.0;
  plain.zone_start = 0.0;
  plain.anderson_depth = 0;
  plain.max_pairing_iterations = 100;
  ActiveSetOptions restarted;  // the Anderson history cleared whenever the change grows
  restarted.anderson_restart = true;
  struct Case {
    std::string name;
    std::vector<double> loads;
  };
  for (const Case& c : {Case{"hertz", {0.05, 0.1, 0.2}}, Case{"ironing", {0.5, 1.25, 2.0, 3.3}},
                        Case{"punch_beam", {0.05, 0.1, 0.2}}}) {
    const Problem& p = problem(c.name);
    const ActiveSetSolver zone_solver(p), anderson_solver(p, anderson_only), plain_solver(p, plain),
        restarted_solver(p, restarted);
    int zone_total = 0, anderson_total = 0, zone_solves = 0;
    for (const double d : c.loads) {
      const std::string what = c.name + " at " + std::to_string(d);
      const FomSolution z = zone_solver.solve(p1(d)), a = anderson_solver.solve(p1(d));
      BOOST_TEST_REQUIRE(z.status == Status::Success, z.message);
      BOOST_TEST_REQUIRE(a.status == Status::Success, a.message);
      same_solution(z, a, what);
      BOOST_TEST(z.kkt.max() <= 1e-10, what);
      BOOST_TEST(a.zone_iterations == 0);
      if (c.name == "ironing") {
        BOOST_TEST(plain_solver.solve(p1(d)).status == Status::NoConvergence);
        const FomSolution r = restarted_solver.solve(p1(d));
        BOOST_TEST_REQUIRE(r.status == Status::Success, r.message);
        same_solution(r, a, what + " (restarted)");
      }
      zone_total += z.pairing_iterations, anderson_total += a.pairing_iterations, zone_solves += z.zone_iterations;
    }
    BOOST_TEST_MESSAGE(c.name << ": whole-loop iterations with zone steps " << zone_total << " (and " << zone_solves
                              << " zone solves), with Anderson alone " << anderson_total);
    BOOST_TEST(2 * zone_total <= anderson_total, c.name);
  }
}

BOOST_AUTO_TEST_CASE(zone_newton_steps_need_fewer_zone_solves) {
  // Ironing's zone (6-7 rows) takes Newton steps by default; hertz's (27 rows at
  // d = 0.1) Anderson steps unless the cap is lifted. Newton's quadratic convergence
  // reaches the same solution in fewer zone solves than Anderson's linear one.
  for (const auto& [name, d] : {std::pair<std::string, double>{"ironing", 1.25}, {"hertz", 0.1}}) {
    const Problem& p = problem(name);
    ActiveSetOptions newton, anderson;
    newton.zone.newton_max_active = 1000;
    anderson.zone.newton_max_active = 0;
    const FomSolution n = ActiveSetSolver(p, newton).solve(p1(d)), a = ActiveSetSolver(p, anderson).solve(p1(d));
    BOOST_TEST_REQUIRE(n.status == Status::Success, n.message);
    BOOST_TEST_REQUIRE(a.status == Status::Success, a.message);
    same_solution(n, a, name);
    BOOST_TEST_MESSAGE(name << ": zone solves with Newton steps " << n.zone_iterations << ", with Anderson steps "
                            << a.zone_iterations);
    BOOST_TEST(n.zone_iterations > 0);
    BOOST_TEST(n.zone_iterations < a.zone_iterations, name);
  }
  BOOST_TEST(ActiveSetSolver(problem("hertz")).solve(p1(0.1)).active > ContactZoneOptions().newton_max_active);
}

BOOST_AUTO_TEST_CASE(no_zone_above_its_row_cap) {
  // hertz at d = 0.1 has 27 rows in contact: with a cap of 20 the whole loop runs
  // alone (Anderson steps), to the same solution.
  const Problem& p = problem("hertz");
  ActiveSetOptions capped;
  capped.zone.max_rows = 20;
  const FomSolution c = ActiveSetSolver(p, capped).solve(p1(0.1)), z = ActiveSetSolver(p).solve(p1(0.1));
  BOOST_TEST_REQUIRE(c.status == Status::Success, c.message);
  BOOST_TEST_REQUIRE(z.status == Status::Success, z.message);
  BOOST_TEST(c.active > capped.zone.max_rows);
  BOOST_TEST(c.zone_iterations == 0);
  BOOST_TEST(z.zone_iterations > 0);
  same_solution(c, z, "capped");
  BOOST_TEST(c.pairing_iterations > z.pairing_iterations);
}

BOOST_AUTO_TEST_CASE(zone_steps_resume_after_a_failed_proposal) {
  // Ironing's first iterates jump (pairing change 0.1-0.7), where the zone's rows may
  // still change and a proposal fail to reduce the loop's change. Handing over to
  // Anderson only until the change halves (zone_retry, the default) reaches the same
  // fixed point as handing over for good (zone_retry = 0).
  const Problem& p = problem("ironing");
  ActiveSetOptions for_good;
  for_good.zone_retry = 0.0;
  BOOST_TEST(ActiveSetOptions().zone_retry > 0.0);
  const ActiveSetSolver retrying(p), giving_up(p, for_good);
  for (int i = 0; i < 16; ++i) {
    const double dx = 4.0 * (i + 0.5) / 16.0;
    const FomSolution r = retrying.solve(p1(dx)), g = giving_up.solve(p1(dx));
    BOOST_TEST_REQUIRE(r.status == Status::Success, r.message);
    BOOST_TEST_REQUIRE(g.status == Status::Success, g.message);
    same_solution(r, g, "dx = " + std::to_string(dx));
  }
}

BOOST_AUTO_TEST_CASE(no_step_without_active_rows_or_a_pairing_support) {
  const Problem& rope = problem("rope");
  const ContactModel& contact = rope.contact();
  PairingLinearisation lin;
  BOOST_TEST(!contact.linearise_pairing(Eigen::VectorXd::Zero(contact.surface_dofs().size()), Pairing{}, {0}, lin));
  std::vector<int> dofs;
  BOOST_TEST(!contact.pairing_support(Pairing{}, {0}, 1, dofs));
  // hertz at a pairing with no pressure: no zone.
  const Problem& p = problem("hertz");
  const ContactModel& hc = p.contact();
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(hc.surface_dofs().size());
  const Pairing pairing = hc.search(u);
  PairedSolution at;
  at.surface_displacement = u;
  at.lambda = Eigen::VectorXd::Zero(hc.num_constraints());
  Pairing out;
  int steps = 0;
  const Eigen::MatrixXd s = Eigen::MatrixXd::Identity(u.size(), u.size());
  BOOST_TEST(!contact_zone_step(hc, s, u, 1.0, at, pairing, SearchMemory(), ContactZoneOptions(), out, steps));
  BOOST_TEST(steps == 0);
  // The support of a paired row: its slave node and the master nodes its segment's
  // normals read, widening with the reach.
  const FomSolution sol = ActiveSetSolver(p).solve(p1(0.1));
  const std::vector<int> rows = active_rows(sol.lambda);
  std::vector<int> near, far;
  BOOST_TEST_REQUIRE(hc.pairing_support(sol.pairing, {rows[0]}, 0, near));
  BOOST_TEST_REQUIRE(hc.pairing_support(sol.pairing, {rows[0]}, 2, far));
  BOOST_TEST(near.size() == 2u * (1 + 4));  // slave node, master nodes j − 1 … j + 2
  BOOST_TEST(far.size() == 2u * (1 + 8));
  ConstraintMatrix c;
  Eigen::VectorXd g;
  hc.assemble_rows(sol.pairing, {rows[0]}, c, g);
  for (ConstraintMatrix::InnerIterator it(c, 0); it; ++it)
    BOOST_TEST(std::binary_search(near.begin(), near.end(), static_cast<int>(it.col())));
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
