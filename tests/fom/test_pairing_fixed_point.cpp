// fom/pairing_fixed_point.hpp: pairing_change() on hand-made two-row operators
// (closed forms, with and without its penetration term; a row without a pair counts
// only by its penetration under the new pairing); through
// fom::ActiveSetSolver on hertz: a converged
// solution passes the stopping test it reports (re-pairing at it changes nothing
// beyond the tolerance), the cap gives no_convergence with the last change in the
// message, and Anderson acceleration reaches the same solution as the plain
// iteration in fewer pairing iterations; at every cap, with and without Anderson,
// the result's pairing, operator, gap offsets, solution and change all belong to
// the last solve (and the FOM's u to its pairing).
#define BOOST_TEST_MODULE fom_pairing_fixed_point
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <memory>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/pairing_fixed_point.hpp>

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

BOOST_AUTO_TEST_CASE(a_row_without_a_pair_counts_only_by_its_penetration) {
  // Row 1 has no pair (empty row: v = 0, which would look like contact); the new
  // pairing pairs it 0.5 away (v' = -0.5). That is no change of the contact: the
  // test is the unchanged row 0's. Paired at a penetration of 0.1 instead, it is.
  const Eigen::VectorXd weights = Eigen::VectorXd::Ones(2), lambda = Eigen::Vector2d(1.0, 0.0);
  const Eigen::VectorXd u_s = Eigen::Vector2d(0.0, 0.0), g = Eigen::VectorXd::Zero(2);
  const double u_scale = 2.0, tol = 1e-8;
  Eigen::Matrix2d one_row = Eigen::Matrix2d::Zero();
  one_row(0, 0) = 1.0;
  const ConstraintMatrix c = operator_of(one_row), c_next = operator_of(Eigen::Matrix2d::Identity());
  const Eigen::VectorXd g_far = Eigen::Vector2d(0.0, 0.5), g_in = Eigen::Vector2d(0.0, -0.1);
  for (const bool penetration : {true, false})
    BOOST_TEST(pairing_change(c, g, c_next, g_far, u_s, lambda, weights, u_scale, tol, penetration) == 0.0);
  BOOST_TEST(std::abs(pairing_change(c, g, c_next, g_in, u_s, lambda, weights, u_scale, tol, true) - 0.1 / u_scale) <=
             1e-17);
  // The same row paired at v = 0 now, moved to −0.5: a gap that matters changed.
  BOOST_TEST(std::abs(pairing_change(c_next, g, c_next, g_far, u_s, lambda, weights, u_scale, tol, false) -
                      0.5 / u_scale) <= 1e-17);
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
  // The whole loop's mixing alone (no steps on the contact zone, which take over its
  // tail by default).
  ActiveSetOptions plain_options, anderson_options;
  plain_options.anderson_depth = 0;
  plain_options.zone_start = anderson_options.zone_start = 0.0;
  const FomSolution plain = ActiveSetSolver(hertz(), plain_options).solve(p1(0.3));
  const FomSolution anderson = ActiveSetSolver(hertz(), anderson_options).solve(p1(0.3));
  BOOST_TEST_REQUIRE(plain.status == Status::Success, plain.message);
  BOOST_TEST_REQUIRE(anderson.status == Status::Success, anderson.message);
  BOOST_TEST(relative_h1_error(hertz(), anderson.u, plain.u) <= 1e-9);
  BOOST_TEST(relative_l2_pressure_error(hertz(), anderson.lambda, plain.lambda) <= 1e-8);
  BOOST_TEST(anderson.pairing_iterations < plain.pairing_iterations);
  BOOST_TEST_MESSAGE("pairing iterations: plain " << plain.pairing_iterations << ", Anderson "
                                                  << anderson.pairing_iterations);
}

BOOST_AUTO_TEST_CASE(at_the_cap_the_result_belongs_to_the_last_solve) {
  // Solve k returns the FOM's solution at the k-th of five loads (so the pairing
  // moves at every step and never settles), whatever pairing it is given: what
  // matters here is that the result hands back exactly the operator the last call
  // received and the solution it returned.
  const Problem& p = hertz();
  const ContactModel& contact = p.contact();
  const ActiveSetSolver solver(p);
  std::vector<FomSolution> answers;
  for (const double d : {0.05, 0.3, 0.1, 0.25, 0.15}) answers.push_back(solver.solve(p1(d)));
  for (const auto& a : answers) BOOST_TEST_REQUIRE(a.status == Status::Success, a.message);
  for (const int depth : {0, 10}) {
    for (int cap = 1; cap <= 4; ++cap) {
      std::vector<ConstraintMatrix> cs;
      std::vector<Eigen::VectorXd> gs;
      std::vector<Pairing> pairings;
      std::vector<PairedSolution> solutions;
      auto solve_at = [&](const Pairing& pairing, const ConstraintMatrix& c, const Eigen::VectorXd& g,
                          const Eigen::VectorXd&) {
        const FomSolution& a = answers[solutions.size() % answers.size()];
        PairedSolution s;
        s.surface_displacement = contact.restrict_to_surface(a.u);
        s.lambda = a.lambda;
        cs.push_back(c);
        gs.push_back(g);
        pairings.push_back(pairing);
        solutions.push_back(s);
        return s;
      };
      PairingFixedPointOptions options;
      options.max_iterations = cap;
      options.anderson_depth = depth;
      const Eigen::VectorXd x = contact.restrict_to_surface(answers.back().u);
      const PairingFixedPointResult r =
          solve_pairing_fixed_point(contact, p.displacement_scale(), x, contact.search(x), options, solve_at);
      BOOST_TEST_CONTEXT("Anderson depth " << depth << ", cap " << cap) {
        BOOST_TEST_REQUIRE(r.status == Status::NoConvergence);
        BOOST_TEST_REQUIRE(r.iterations == cap);
        BOOST_TEST_REQUIRE(static_cast<int>(solutions.size()) == cap);
        BOOST_TEST(r.pairing.segment == pairings.back().segment);
        BOOST_TEST(r.pairing.xi == pairings.back().xi);
        BOOST_TEST(Eigen::MatrixXd(r.pairing.normal - pairings.back().normal).cwiseAbs().maxCoeff() == 0.0);
        BOOST_TEST(Eigen::MatrixXd(r.c - cs.back()).norm() == 0.0);
        BOOST_TEST((r.g - gs.back()).norm() == 0.0);
        BOOST_TEST((r.solution.lambda - solutions.back().lambda).norm() == 0.0);
        // The operator is the one of the returned pairing, and the change is the
        // stopping test of the returned solution at it.
        ConstraintMatrix c_own, c_next;
        Eigen::VectorXd g_own, g_next;
        contact.assemble(r.pairing, c_own, g_own);
        BOOST_TEST(Eigen::MatrixXd(r.c - c_own).norm() == 0.0);
        BOOST_TEST((r.g - g_own).norm() == 0.0);
        const Eigen::VectorXd& f = r.solution.surface_displacement;
        contact.assemble(contact.search_rows(f, nullptr, &r.pairing), c_next, g_next);
        const double change = pairing_change(r.c, r.g, c_next, g_next, f, r.solution.lambda, contact.weights(),
                                             p.displacement_scale(), options.tolerance);
        BOOST_TEST(r.residual > options.tolerance);
        BOOST_TEST(std::abs(r.residual - change) <= 1e-12 * change);
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(at_the_cap_the_fom_displacement_belongs_to_the_returned_pairing) {
  // u = u0 − K⁻¹ E_s C(pairing)ᵀ λ: with the FOM's own pairing and λ, K u − f + Cᵀλ = 0
  // holds to rounding whatever the cap (while the pairing recomputed from u differs).
  const Problem& p = hertz();
  for (int cap = 1; cap <= 3; ++cap) {
    ActiveSetOptions options;  // Anderson steps alone: the zone's would converge by the third
    options.zone_start = 0.0;
    options.max_pairing_iterations = cap;
    const FomSolution sol = ActiveSetSolver(p, options).solve(p1(0.3));
    BOOST_TEST_CONTEXT("cap " << cap) {
      BOOST_TEST_REQUIRE(sol.status == Status::NoConvergence);
      ConstraintMatrix c;
      Eigen::VectorXd g;
      p.contact().assemble(sol.pairing, c, g);
      const Eigen::VectorXd ctl = c.transpose() * sol.lambda;
      Eigen::VectorXd force = Eigen::VectorXd::Zero(p.num_dofs());
      const std::vector<int>& surf = p.contact().surface_dofs();
      for (size_t j = 0; j < surf.size(); ++j) force(surf[j]) += ctl(static_cast<Eigen::Index>(j));
      const Eigen::VectorXd ku_all = p.stiffness(sol.mu) * (sol.u - p.lifting(sol.mu)), f_all = p.rhs(sol.mu);
      const auto n_free = static_cast<Eigen::Index>(p.free_dofs().size());
      Eigen::VectorXd ku(n_free), f(n_free), ct(n_free);
      for (Eigen::Index j = 0; j < n_free; ++j) {
        const int i = p.free_dofs()[static_cast<size_t>(j)];
        ku(j) = ku_all(i), f(j) = f_all(i), ct(j) = force(i);
      }
      const double scale = std::max({ku.norm(), f.norm(), ct.norm()});
      BOOST_TEST((ku - f + ct).norm() <= 1e-9 * scale);
    }
  }
}
