// Acceptance tests of the FOM (issue 2): KKT conditions across every problem's
// range, Hertz theory, physics sanity checks, separated configuration.
#define BOOST_TEST_MODULE fom_active_set_solver
#include <Eigen/SparseCholesky>
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <tuple>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/rope.hpp>

using namespace contactrom;
using namespace contactrom::fom;

namespace {

/// Problems and solvers are built once per test module (meshing costs time).
struct Fixture {
  std::map<std::string, std::unique_ptr<Problem>> problems;
  std::map<std::string, std::unique_ptr<ActiveSetSolver>> solvers;
  ActiveSetSolver& solver(const std::string& name) {
    if (!problems.count(name)) {
      problems[name] = make_problem(name);
      solvers[name] = std::make_unique<ActiveSetSolver>(*problems[name]);
    }
    return *solvers[name];
  }
};
Fixture& fixture() {
  static Fixture f;
  return f;
}

Param p1(double v) { return Eigen::VectorXd::Constant(1, v); }

void check_kkt(const std::string& name, const std::vector<Param>& params) {
  ActiveSetSolver& s = fixture().solver(name);
  for (const Param& mu : params) {
    const FomSolution sol = s.solve(mu);
    BOOST_TEST_CONTEXT(name << " at " << mu.transpose()) {
      BOOST_TEST(sol.status == Status::Success, sol.message);
      const KktResiduals k = kkt_residuals(s.problem(), mu, sol.u, sol.lambda);
      BOOST_TEST(k.stationarity <= 1e-10);
      BOOST_TEST(k.penetration <= 1e-10);
      BOOST_TEST(k.negative_pressure <= 1e-10);
      BOOST_TEST(k.complementarity <= 1e-10);
      BOOST_TEST(sol.active > 0);
    }
  }
}

}  // namespace

BOOST_AUTO_TEST_CASE(kkt_rope_across_range) { check_kkt("rope", {p1(10), p1(17.5), p1(30), p1(42.5), p1(50)}); }
BOOST_AUTO_TEST_CASE(kkt_hertz_across_range) {
  check_kkt("hertz", {p1(1e-3), p1(0.075), p1(0.15), p1(0.225), p1(0.3)});
}
BOOST_AUTO_TEST_CASE(kkt_ironing_across_range) { check_kkt("ironing", {p1(0), p1(1), p1(2), p1(3), p1(4)}); }
BOOST_AUTO_TEST_CASE(kkt_ironing2_across_range) {
  check_kkt("ironing2", {Eigen::Vector2d(0, 0.1), Eigen::Vector2d(4, 0.3), Eigen::Vector2d(1, 0.2),
                         Eigen::Vector2d(2.5, 0.15), Eigen::Vector2d(4, 0.1), Eigen::Vector2d(0, 0.3)});
}
// ironing3d2 (3D, hexahedra under a tetrahedral punch, two parameters): KKT at the
// corners and inside, and a deeper indentation pressing harder at every slide.
BOOST_AUTO_TEST_CASE(kkt_ironing3d2_across_range_and_force_grows_with_the_indentation) {
  check_kkt("ironing3d2", {Eigen::Vector2d(0, 0.05), Eigen::Vector2d(4, 0.15), Eigen::Vector2d(2.5, 0.1)});
  ActiveSetSolver& s = fixture().solver("ironing3d2");
  for (double dx : {0.0, 2.5}) {
    double previous = 0.0;
    for (double dz : {0.05, 0.1, 0.15}) {
      const double force = contact_force(s.problem(), s.solve(Eigen::Vector2d(dx, dz)).lambda);
      BOOST_TEST(force > previous, "d_x " << dx << ", d_z " << dz);
      previous = force;
    }
  }
}

// Two-cylinder plane-strain Hertz theory: with P the FOM's contact force,
// a = sqrt(4 P R / (π E*)), p0 = 2P/(π a), p(x) = p0 sqrt(1 − x²/a²),
// R = (1/R1 + 1/R2)⁻¹ = 0.5, 1/E* = 2(1 − ν²)/E.
BOOST_AUTO_TEST_CASE(hertz_pressure_matches_theory) {
  ActiveSetSolver& s = fixture().solver("hertz");
  const ContactModel& contact = s.problem().contact();
  const Eigen::VectorXd& w = contact.weights();
  const Eigen::Matrix2Xd& x = contact.constraint_points();
  const double r = 0.5, e_star = 1.0 / (2.0 * (1.0 - 0.3 * 0.3));
  for (double d : {0.02, 0.04, 0.06}) {
    const FomSolution sol = s.solve(p1(d));
    const double force = contact_force(s.problem(), sol.lambda);
    const double a = std::sqrt(4.0 * force * r / (M_PI * e_star)), p0 = 2.0 * force / (M_PI * a);
    double num = 0.0, den = 0.0;
    for (int k = 0; k < w.size(); ++k) {
      const double ph = std::abs(x(0, k)) < a ? p0 * std::sqrt(1.0 - x(0, k) * x(0, k) / (a * a)) : 0.0;
      num += w(k) * std::pow(sol.lambda(k) - ph, 2);
      den += w(k) * ph * ph;
    }
    // FOM half-width: midway between the outermost active node and the next node, both sides.
    double half = 0.0;
    for (int side : {-1, 1}) {
      double last_active = 0.0, first_free = 1e9;
      for (int k = 0; k < w.size(); ++k) {
        const double xs = side * x(0, k);
        if (xs < -1e-12) continue;
        if (sol.lambda(k) > 0.0) last_active = std::max(last_active, xs);
      }
      for (int k = 0; k < w.size(); ++k) {
        const double xs = side * x(0, k);
        if (xs > last_active + 1e-12) first_free = std::min(first_free, xs);
      }
      half += 0.25 * (last_active + first_free);
    }
    BOOST_TEST_CONTEXT("d = " << d << ", P = " << force << ", a_Hertz = " << a << ", a_FOM = " << half) {
      BOOST_TEST(std::sqrt(num / den) <= 0.10);
      BOOST_TEST(std::abs(half - a) <= 0.15 * a);
    }
  }
}

BOOST_AUTO_TEST_CASE(hertz_force_grows_with_d) {
  ActiveSetSolver& s = fixture().solver("hertz");
  double previous = 0.0;
  for (int i = 1; i <= 10; ++i) {
    const double force = contact_force(s.problem(), s.solve(p1(0.03 * i)).lambda);
    BOOST_TEST(force > previous);
    previous = force;
  }
}

BOOST_AUTO_TEST_CASE(rope_contact_set_changes_with_gamma) {
  ActiveSetSolver& s = fixture().solver("rope");
  std::vector<Eigen::VectorXd> sets;
  for (double g : {10.0, 30.0, 50.0}) {
    const FomSolution sol = s.solve(p1(g));
    BOOST_TEST(sol.active > 0);
    sets.push_back((sol.lambda.array() > 0.0).cast<double>().matrix());
  }
  BOOST_TEST((sets[0] - sets[1]).cwiseAbs().sum() > 0.0);
  BOOST_TEST((sets[1] - sets[2]).cwiseAbs().sum() > 0.0);
}

// The pressure centroid (deformed x) of `ironing` follows the iron: monotone in
// d_x and within one slab element (6/49) of d_x.
BOOST_AUTO_TEST_CASE(ironing_pressure_centroid_follows_iron) {
  ActiveSetSolver& s = fixture().solver("ironing");
  const ContactModel& contact = s.problem().contact();
  const double element = 6.0 / 49.0;
  double previous = -1e9;
  for (int i = 0; i <= 8; ++i) {
    const double dx = 0.5 * i;
    const FomSolution sol = s.solve(p1(dx));
    const Eigen::VectorXd us = contact.restrict_to_surface(sol.u);
    double num = 0.0, den = 0.0;
    for (int k = 0; k < contact.num_constraints(); ++k) {
      const double wl = contact.weights()(k) * sol.lambda(k);
      num += wl * (contact.constraint_points()(0, k) + us(2 * k));
      den += wl;
    }
    const double centroid = num / den;
    BOOST_TEST_CONTEXT("d_x = " << dx << ", centroid = " << centroid) {
      BOOST_TEST(centroid > previous);
      BOOST_TEST(std::abs(centroid - dx) <= element);
    }
    previous = centroid;
  }
}

// A rope pulled upwards never touches the obstacle: λ = 0 and u is the
// unconstrained solution, computed here independently with a sparse Cholesky.
BOOST_AUTO_TEST_CASE(separated_configuration_is_unconstrained) {
  RopeOptions opt;
  opt.load = -100.0;
  auto problem = make_rope_problem(opt);
  ActiveSetSolver s(*problem);
  const Param mu = p1(20.0);
  const FomSolution sol = s.solve(mu);
  BOOST_TEST(sol.status == Status::Success);
  BOOST_TEST(sol.lambda.cwiseAbs().maxCoeff() == 0.0);
  const std::vector<int>& free = problem->free_dofs();
  const SparseMatrix k = problem->stiffness(mu);
  const Eigen::VectorXd f = problem->rhs(mu);
  Eigen::MatrixXd kff(free.size(), free.size());
  Eigen::VectorXd ff(free.size());
  for (size_t a = 0; a < free.size(); ++a) {
    ff(a) = f(free[a]);
    for (size_t b = 0; b < free.size(); ++b) kff(a, b) = k.coeff(free[a], free[b]);
  }
  const Eigen::VectorXd uf = kff.llt().solve(ff);
  double err = 0.0;
  for (size_t a = 0; a < free.size(); ++a) err = std::max(err, std::abs(sol.u(free[a]) - uf(a)));
  BOOST_TEST(err <= 1e-10 * uf.cwiseAbs().maxCoeff());
}

BOOST_AUTO_TEST_CASE(parameter_outside_range_is_rejected) {
  ActiveSetSolver& s = fixture().solver("hertz");
  BOOST_CHECK_THROW(s.solve(p1(0.0)), InputError);
  BOOST_CHECK_THROW(s.solve(p1(0.31)), InputError);
  BOOST_CHECK_THROW(parse_param(s.problem(), "abc"), InputError);
  BOOST_CHECK_THROW(make_problem("nonsense"), InputError);
}

BOOST_AUTO_TEST_CASE(working_set_gives_the_all_rows_solution) {
  // The dual QP on the working set (default) and on every row (margin < 0) are the
  // same QP solution; so the pairing loops take the same path (up to round-off at
  // the stopping tolerance) and the solutions agree, for a tiny margin too (the
  // working set then grows by the penetration check).
  for (const std::string name : {"hertz", "ironing", "rope"}) {
    const Problem& problem = fixture().solver(name).problem();
    ActiveSetOptions all_rows, tiny;
    all_rows.working_set_margin = -1.0;
    tiny.working_set_margin = 1e-9;
    const ActiveSetSolver reference(problem, all_rows), small(problem, tiny);
    const ActiveSetSolver& standard = fixture().solver(name);
    const double lo = problem.param_lower()(0), hi = problem.param_upper()(0);
    for (double t : {0.05, 0.5, 1.0}) {
      const Param mu = p1(lo + t * (hi - lo));
      const FomSolution a = reference.solve(mu);
      BOOST_TEST_CONTEXT(name << " at " << mu(0)) {
        BOOST_REQUIRE(a.status == Status::Success);
        for (const ActiveSetSolver* s : {&standard, &small}) {
          const FomSolution b = s->solve(mu);
          BOOST_REQUIRE(b.status == Status::Success);
          BOOST_TEST(std::abs(b.pairing_iterations - a.pairing_iterations) <= 1);
          BOOST_TEST((b.u - a.u).norm() <= 1e-10 * a.u.norm());
          BOOST_TEST((b.lambda - a.lambda).norm() <= 1e-9 * a.lambda.norm());
        }
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(working_set_grows_to_rows_that_penetrate) {
  // Warm-started from another parameter with a tiny margin, the first working set
  // (rows active there or touching there) misses rows that penetrate at the new
  // parameter. For `rope` (no pairing loop to catch them later) the penetration check
  // after the QP must add them; for `hertz` either that or the pairing loop does.
  for (const auto& [name, from, to] : {std::tuple<std::string, double, double>{"rope", 50.0, 10.0},
                                       std::tuple<std::string, double, double>{"rope", 10.0, 50.0},
                                       std::tuple<std::string, double, double>{"hertz", 0.1, 0.3}}) {
    const Problem& problem = fixture().solver(name).problem();
    ActiveSetOptions all_rows, tiny;
    all_rows.working_set_margin = -1.0;
    tiny.working_set_margin = 1e-9;
    const ActiveSetSolver reference(problem, all_rows), small(problem, tiny);
    const FomSolution warm = reference.solve(p1(from));
    const FomSolution a = reference.solve(p1(to));
    const FomSolution b = small.solve(p1(to), &warm);
    BOOST_TEST_CONTEXT(name << " from " << from << " to " << to) {
      BOOST_REQUIRE(b.status == Status::Success);
      BOOST_TEST(b.active == a.active);
      BOOST_TEST((b.u - a.u).norm() <= 1e-10 * a.u.norm());
      BOOST_TEST((b.lambda - a.lambda).norm() <= 1e-9 * a.lambda.norm());
      const KktResiduals k = kkt_residuals(problem, p1(to), b.u, b.lambda);
      BOOST_TEST(k.penetration <= 1e-10);
    }
  }
}

BOOST_AUTO_TEST_CASE(row_subset_and_hint_do_not_change_the_search) {
  // search_rows(u, rows, hint) pairs the listed rows exactly as search(u) does,
  // whatever the hint (here: the pairing of a perturbed displacement).
  const Problem& problem = fixture().solver("hertz").problem();
  const ContactModel& contact = problem.contact();
  const FomSolution sol = fixture().solver("hertz").solve(p1(0.2));
  const Eigen::VectorXd base = contact.restrict_to_surface(sol.u);
  std::vector<int> rows;
  for (int k = 5; k < contact.num_constraints(); k += 3) rows.push_back(k);
  unsigned state = 12345u;
  auto noise = [&state] {
    state = state * 1664525u + 1013904223u;
    return (static_cast<double>(state >> 8) / 16777216.0) - 0.5;
  };
  for (int trial = 0; trial < 200; ++trial) {
    const double scale = std::pow(10.0, -1.0 - 4.0 * (trial % 50) / 50.0);
    Eigen::VectorXd a = base, b = base;
    for (Eigen::Index i = 0; i < a.size(); ++i) a(i) += scale * noise(), b(i) += scale * noise();
    const Pairing hint = contact.search(a);
    const Pairing full = contact.search(b);
    const Pairing with_hint = contact.search_rows(b, nullptr, &hint);
    const Pairing subset = contact.search_rows(b, &rows, &hint);
    for (int k = 0; k < contact.num_constraints(); ++k) {
      BOOST_TEST(with_hint.segment[k] == full.segment[k]);
      BOOST_TEST(with_hint.xi[k] == full.xi[k]);
      const bool listed = std::find(rows.begin(), rows.end(), k) != rows.end();
      BOOST_TEST(subset.segment[k] == (listed ? full.segment[k] : -1));
      if (listed) BOOST_TEST((subset.normal.col(k) - full.normal.col(k)).norm() == 0.0);
    }
  }
}

BOOST_AUTO_TEST_CASE(condensation_matches_dense_inverse_columns) {
  // S = E_sᵀ K⁻¹ E_s read from the factor, the load responses and the surface
  // response agree with K⁻¹ applied column by column by an independent factorisation
  // (Eigen's simplicial LDLᵀ), i.e. with the former dense condensation K⁻¹E_s.
  for (const std::string name : {"hertz", "ironing"}) {
    const Problem& problem = fixture().solver(name).problem();
    const Param mu = 0.5 * (problem.param_lower() + problem.param_upper());
    Condensation cond;
    BOOST_REQUIRE(condense(problem, mu, cond));
    const std::vector<int>& free = problem.free_dofs();
    const int n = problem.num_dofs(), nf = static_cast<int>(free.size());
    std::vector<int> free_index(n, -1);
    for (int i = 0; i < nf; ++i) free_index[free[i]] = i;
    const SparseMatrix k = problem.stiffness(mu);
    const Eigen::SimplicialLDLT<SparseMatrix> ldlt(free_block(k, free_index, nf));
    BOOST_REQUIRE(ldlt.info() == Eigen::Success);
    const std::vector<int>& surf = problem.contact().surface_dofs();
    const int ns = static_cast<int>(surf.size());
    Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(nf, ns);
    for (int j = 0; j < ns; ++j)
      if (free_index[surf[j]] >= 0) unit(free_index[surf[j]], j) = 1.0;
    const Eigen::MatrixXd z = ldlt.solve(unit);  // K⁻¹E_s on the free dofs
    Eigen::MatrixXd s(ns, ns);
    for (int a = 0; a < ns; ++a)
      s.row(a) = free_index[surf[a]] >= 0 ? Eigen::RowVectorXd(z.row(free_index[surf[a]])) : Eigen::RowVectorXd::Zero(ns);
    BOOST_TEST_CONTEXT(name) {
      BOOST_TEST((cond.s - s).norm() <= 1e-10 * s.norm());
      const Eigen::VectorXd force = Eigen::VectorXd::LinSpaced(ns, -1.0, 2.0);
      Eigen::VectorXd expected = Eigen::VectorXd::Zero(n);
      const Eigen::VectorXd zf = z * force;
      for (int i = 0; i < nf; ++i) expected(free[i]) = zf(i);
      BOOST_TEST((cond.surface_response(force) - expected).norm() <= 1e-10 * expected.norm());
      for (int t = 0; t < problem.num_load_terms(); ++t) {
        const Eigen::VectorXd r = problem.external_load_terms()[t] - k * problem.lifting_terms()[t];
        Eigen::VectorXd rf(nf);
        for (int i = 0; i < nf; ++i) rf(i) = r(free[i]);
        const Eigen::VectorXd x = ldlt.solve(rf);
        Eigen::VectorXd u = problem.lifting_terms()[t];
        for (int i = 0; i < nf; ++i) u(free[i]) += x(i);
        BOOST_TEST((cond.z_load.col(t) - u).norm() <= 1e-10 * u.norm());
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(kkt_residuals_refuse_a_parameter_of_the_wrong_size_or_range) {
  // A μ of another size gave residuals of fewer load terms, with no error.
  const ActiveSetSolver& solver = fixture().solver("ironing2");
  const Problem& p = solver.problem();
  Param mu(2);
  mu << 2.0, 0.2;
  const FomSolution s = solver.solve(mu);
  BOOST_TEST_REQUIRE(s.status == Status::Success);
  BOOST_TEST(kkt_residuals(p, mu, s.u, s.lambda).max() <= 1e-10);
  Param nan_mu = mu;
  nan_mu(1) = std::nan("");
  for (const Param& bad : {Param(Param::Zero(0)), Param(Param::Constant(1, 2.0)), Param(Param::Constant(3, 0.2)), nan_mu})
    BOOST_CHECK_THROW(kkt_residuals(p, bad, s.u, s.lambda), InputError);
}
