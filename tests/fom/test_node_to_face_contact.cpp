// Node-to-face contact (fom/node_to_face_contact): projections onto triangles and
// bilinear quads against closed forms, the bucket-grid search against a search of
// every facet, tributary areas, nodes beyond the master's boundary left unpaired,
// the 3D contact patch test (a block pressed on a block with a nested, non-matching
// mesh: uniform pressure exact), and rigid translations (no force, no contact).
#define BOOST_TEST_MODULE fom_node_to_face_contact
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <random>

#include "common/box_mesh.hpp"
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/node_to_face_contact.hpp>
#include <contactrom/fom/problem.hpp>

using namespace contactrom;
using namespace contactrom::fom;
using Eigen::Vector3d;

namespace {

/// A rotation about a fixed axis, and a shift: projections must not depend on the frame.
Eigen::Matrix3d some_rotation() { return Eigen::AngleAxisd(0.7, Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix(); }

/// Two boxes: the base [0,1]^2 x [0,1] (cells `nb` across) under the punch
/// [0,w]x[0,1]x[1+gap,2+gap] (cells `np` across), both `tets` or hexahedra.
Mesh two_blocks(int nb, int np, bool tets, double punch_width = 1.0, double gap = 0.0) {
  test::BoxSpec base, punch;
  base.name = "base", punch.name = "punch";
  base.cells = {nb, nb, 1}, punch.cells = {np, np, 1};
  punch.origin = Vector3d(0.0, 0.0, 1.0 + gap);
  punch.size = Vector3d(punch_width, 1.0, 1.0);
  base.tets = punch.tets = tets;
  return test::union_of({test::box_mesh(base), test::box_mesh(punch)});
}

// The punch's top pushed down by d on rollers (x0, y0 and the base's bottom hold
// one component each): uniaxial compression of the stack, σ_zz = −E d / 2.
const char* kPatch = R"(
[problem]
name = "patch3d"
mesh = "blocks.msh"
formulation = "3d"

[[parameters]]
name = "d"
range = [0.0, 0.1]

[[bodies]]
group = "base"
young = 2.0
poisson = 0.3

[[bodies]]
group = "punch"
young = 2.0
poisson = 0.3

[[dirichlet]]
group = "base_bottom"
displacement = ["free", "free", 0.0]

[[dirichlet]]
group = "base_x0"
displacement = [0.0, "free", "free"]

[[dirichlet]]
group = "base_y0"
displacement = ["free", 0.0, "free"]

[[dirichlet]]
group = "punch_x0"
displacement = [0.0, "free", "free"]

[[dirichlet]]
group = "punch_y0"
displacement = ["free", 0.0, "free"]

[[dirichlet]]
group = "punch_top"
displacement = ["free", "free", "-d"]

[[contact]]
slave = "punch_bottom"
master = "base_top"
)";

std::unique_ptr<Problem> build(const std::string& text, Mesh mesh) {
  return build_problem(parse_problem_text(text, "/tmp/patch3d.toml"), std::move(mesh));
}

}  // namespace

BOOST_AUTO_TEST_CASE(triangle_projection_matches_closed_forms) {
  const Eigen::Matrix3d r = some_rotation();
  const Vector3d shift(0.3, -1.2, 2.0);
  auto t = [&](const Vector3d& x) -> Vector3d { return r * x + shift; };
  const Vector3d a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  // Above the inside: the foot point, weights of b and c = x/2, y/2.
  FacetProjection p = project_on_triangle(t({0.5, 0.7, 0.3}), t(a), t(b), t(c));
  BOOST_TEST(std::abs(p.xi - 0.25) <= 1e-14);
  BOOST_TEST(std::abs(p.eta - 0.35) <= 1e-14);
  BOOST_TEST(std::abs(p.distance2 - 0.09) <= 1e-14);
  BOOST_TEST((p.edge == -1 && p.vertex == -1));
  BOOST_TEST((p.point - t({0.5, 0.7, 0.0})).norm() <= 1e-14);
  // Beyond the hypotenuse b-c (edge 1): its midpoint (1, 1, 0).
  p = project_on_triangle(t({1.5, 1.5, 1.0}), t(a), t(b), t(c));
  BOOST_TEST(p.edge == 1);
  BOOST_TEST(std::abs(p.xi - 0.5) <= 1e-14);
  BOOST_TEST(std::abs(p.eta - 0.5) <= 1e-14);
  BOOST_TEST(std::abs(p.distance2 - 1.5) <= 1e-13);
  // Beyond the corner a: the vertex.
  p = project_on_triangle(t({-1.0, -1.0, 0.5}), t(a), t(b), t(c));
  BOOST_TEST(p.vertex == 0);
  BOOST_TEST((std::abs(p.xi) + std::abs(p.eta)) <= 1e-14);
  BOOST_TEST(std::abs(p.distance2 - 2.25) <= 1e-13);
}

BOOST_AUTO_TEST_CASE(quad_projection_matches_closed_forms) {
  const Eigen::Matrix3d r = some_rotation();
  const Vector3d shift(-0.4, 0.9, 1.1);
  auto t = [&](const Vector3d& x) -> Vector3d { return r * x + shift; };
  // A planar square [0,2]^2: ξ = x − 1, η = y − 1.
  const std::array<Vector3d, 4> square = {t({0, 0, 0}), t({2, 0, 0}), t({2, 2, 0}), t({0, 2, 0})};
  FacetProjection p = project_on_quad(t({0.5, 1.5, 0.4}), square);
  BOOST_TEST(std::abs(p.xi + 0.5) <= 1e-13);
  BOOST_TEST(std::abs(p.eta - 0.5) <= 1e-13);
  BOOST_TEST(std::abs(p.distance2 - 0.16) <= 1e-13);
  // Beyond the side x = 2 (edge 1): (2, 1, 0), ξ = 1, η = 0.
  p = project_on_quad(t({3.0, 1.0, 0.0}), square);
  BOOST_TEST(p.edge == 1);
  BOOST_TEST(std::abs(p.xi - 1.0) <= 1e-14);
  BOOST_TEST(std::abs(p.eta) <= 1e-14);
  BOOST_TEST(std::abs(p.distance2 - 1.0) <= 1e-13);
  // A warped quad (one corner lifted): a point at distance h along the unit normal
  // of x(ξ0, η0) projects back onto (ξ0, η0), the closed form of the closest point
  // (the residual is normal to both tangents there, and h is small).
  const std::array<Vector3d, 4> warped = {t({0, 0, 0}), t({2, 0, 0}), t({2.2, 2.1, 0.5}), t({0, 2, 0})};
  for (const auto& [xi0, eta0] : {std::pair{0.3, -0.4}, std::pair{-0.8, 0.9}, std::pair{0.95, 0.95}}) {
    const double n[4] = {0.25 * (1 - xi0) * (1 - eta0), 0.25 * (1 + xi0) * (1 - eta0), 0.25 * (1 + xi0) * (1 + eta0),
                         0.25 * (1 - xi0) * (1 + eta0)};
    Vector3d x = Vector3d::Zero(), dxi = Vector3d::Zero(), deta = Vector3d::Zero();
    const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    for (int a = 0; a < 4; ++a) {
      x += n[a] * warped[a];
      dxi += 0.25 * sx[a] * (1 + sy[a] * eta0) * warped[a];
      deta += 0.25 * sy[a] * (1 + sx[a] * xi0) * warped[a];
    }
    const double h = 0.05;
    p = project_on_quad(x + h * dxi.cross(deta).normalized(), warped);
    BOOST_TEST(std::abs(p.xi - xi0) <= 1e-12, "xi0 " << xi0);
    BOOST_TEST(std::abs(p.eta - eta0) <= 1e-12, "eta0 " << eta0);
    BOOST_TEST(std::abs(std::sqrt(p.distance2) - h) <= 1e-12);
  }
}

// The bucket grid finds the closest facet of every slave node: the same distance
// as trying every facet, on a rough master surface with moved nodes.
BOOST_AUTO_TEST_CASE(grid_search_finds_the_closest_facet) {
  for (bool tets : {false, true}) {
    const Mesh mesh = two_blocks(7, 5, tets);
    std::vector<ContactPairFacets> pairs(1);
    pairs[0].slave = mesh.faces.at("punch_bottom");
    pairs[0].master = mesh.faces.at("base_top");
    const NodeToFaceContact contact(mesh.nodes, pairs);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> small(-0.05, 0.05), big(-0.3, 0.3);
    Eigen::VectorXd us(static_cast<Eigen::Index>(contact.surface_dofs().size()));
    for (Eigen::Index i = 0; i < us.size(); ++i) us(i) = i < 3 * contact.num_constraints() ? big(rng) : small(rng);
    const Pairing p = contact.search(us);
    int paired = 0;
    for (int k = 0; k < contact.num_constraints(); ++k) {
      const Vector3d x = mesh.nodes.col(contact.slave_nodes()[k]) + us.segment<3>(3 * k);
      double best = 1e300;
      for (const auto& f : pairs[0].master) {
        auto y = [&](int a) -> Vector3d {
          const int node = f[a];
          int s = 0;
          while (contact.surface_dofs()[3 * s] != 3 * node) ++s;
          return mesh.nodes.col(node) + us.segment<3>(3 * s);
        };
        const FacetProjection pr = f[3] < 0 ? project_on_triangle(x, y(0), y(1), y(2)) : project_on_quad(x, {y(0), y(1), y(2), y(3)});
        best = std::min(best, pr.distance2);
      }
      if (p.segment[k] < 0) continue;
      ++paired;
      const auto& f = pairs[0].master[p.segment[k]];
      Vector3d q = Vector3d::Zero();
      const double w[4] = {f[3] < 0 ? 1 - p.xi[k] - p.eta[k] : 0.25 * (1 - p.xi[k]) * (1 - p.eta[k]),
                           f[3] < 0 ? p.xi[k] : 0.25 * (1 + p.xi[k]) * (1 - p.eta[k]),
                           f[3] < 0 ? p.eta[k] : 0.25 * (1 + p.xi[k]) * (1 + p.eta[k]),
                           f[3] < 0 ? 0.0 : 0.25 * (1 - p.xi[k]) * (1 + p.eta[k])};
      for (int a = 0; a < (f[3] < 0 ? 3 : 4); ++a) {
        int s = 0;
        while (contact.surface_dofs()[3 * s] != 3 * f[a]) ++s;
        q += w[a] * (mesh.nodes.col(f[a]) + us.segment<3>(3 * s));
      }
      BOOST_TEST(std::abs((x - q).squaredNorm() - best) <= 1e-13 * (1 + best), "row " << k);
      BOOST_TEST(std::abs(p.normal.col(k).norm() - 1.0) <= 1e-14);
    }
    BOOST_TEST(paired > contact.num_constraints() / 2);
  }
}

BOOST_AUTO_TEST_CASE(tributary_areas_sum_to_the_slave_area_and_overhanging_nodes_are_unpaired) {
  for (bool tets : {false, true}) {
    // The punch is 1.5 wide on a base 1 wide: slave nodes at x > 1 have no master facet below.
    const Mesh mesh = two_blocks(2, 6, tets, 1.5);
    std::vector<ContactPairFacets> pairs(1);
    pairs[0].slave = mesh.faces.at("punch_bottom");
    pairs[0].master = mesh.faces.at("base_top");
    const NodeToFaceContact contact(mesh.nodes, pairs);
    BOOST_TEST(std::abs(contact.weights().sum() - 1.5) <= 1e-14);
    BOOST_TEST(contact.num_constraints() == 7 * 7);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(contact.surface_dofs().size()));
    const Pairing p = contact.search(zero);
    ConstraintMatrix c;
    Eigen::VectorXd g;
    contact.assemble(p, c, g);
    for (int k = 0; k < contact.num_constraints(); ++k) {
      const double x = mesh.nodes(0, contact.slave_nodes()[k]);
      BOOST_TEST((p.segment[k] >= 0) == (x <= 1.0 + 1e-12), "x = " << x);
      if (p.segment[k] < 0) {
        BOOST_TEST(c.row(k).norm() == 0.0);
        BOOST_TEST(g(k) == 0.0);
      } else {
        BOOST_TEST((p.normal.col(k) - Vector3d(0, 0, 1)).norm() <= 1e-14);
        BOOST_TEST(std::abs(g(k)) <= 1e-15);  // touching in the reference configuration
      }
    }
  }
}

// Patch test: the punch (slave, 4x4 cells across) on the base (master, 2x2): the
// meshes do not match but nest, so the slave nodes' tributary areas integrate the
// master's shape functions exactly and the uniform contact pressure E d / 2 (with
// the linear displacement field) is the discrete solution, to rounding.
BOOST_AUTO_TEST_CASE(patch_test_uniform_pressure_is_exact) {
  for (bool tets : {false, true}) {
    const auto problem = build(kPatch, two_blocks(2, 4, tets));
    const ActiveSetSolver solver(*problem);
    const double d = 0.04, e = 2.0, nu = 0.3, strain = d / 2;
    Param mu(1);
    mu << d;
    const FomSolution s = solver.solve(mu);
    BOOST_REQUIRE(s.status == Status::Success);
    BOOST_TEST(s.active == problem->contact().num_constraints());
    for (int k = 0; k < s.lambda.size(); ++k) BOOST_TEST(std::abs(s.lambda(k) - e * strain) <= 1e-11, "row " << k);
    const Mesh& m = *problem->mesh();
    double err = 0.0;
    for (int i = 0; i < m.num_nodes(); ++i) {
      const Vector3d x = m.nodes.col(i);
      err = std::max(err, (s.u.segment<3>(3 * i) - Vector3d(nu * strain * x(0), nu * strain * x(1), -strain * x(2))).norm());
    }
    BOOST_TEST(err <= 1e-12, (tets ? "tetrahedra" : "hexahedra") << ": max displacement error " << err);
    const KktResiduals r = kkt_residuals(*problem, mu, s.u, s.lambda);
    BOOST_TEST(r.max() <= 1e-10);
  }
}

// Both bodies, 0.01 apart, moved rigidly by the same vector (their held faces
// prescribed it): no force, no contact, the pairing and the gaps of the reference
// configuration.
BOOST_AUTO_TEST_CASE(rigid_translation_makes_no_force_and_no_contact) {
  const std::string text = std::string(R"(
[problem]
name = "rigid3d"
mesh = "blocks.msh"
formulation = "3d"

[[parameters]]
name = "t"
range = [0.0, 1.0]

[[bodies]]
group = "base"

[[bodies]]
group = "punch"

[[dirichlet]]
group = "base_bottom"
displacement = ["0.13*t", "-0.07*t", "0.05*t"]

[[dirichlet]]
group = "punch_top"
displacement = ["0.13*t", "-0.07*t", "0.05*t"]

[[contact]]
slave = "punch_bottom"
master = "base_top"
)");
  for (bool tets : {false, true}) {
    const auto problem = build(text, two_blocks(3, 4, tets, 1.0, 0.01));
    const ActiveSetSolver solver(*problem);
    Param mu(1);
    mu << 1.0;
    const FomSolution s = solver.solve(mu);
    BOOST_REQUIRE(s.status == Status::Success);
    BOOST_TEST(s.active == 0);
    BOOST_TEST(s.lambda.cwiseAbs().maxCoeff() == 0.0);
    const Vector3d shift(0.13, -0.07, 0.05);
    for (int i = 0; i < problem->mesh()->num_nodes(); ++i)
      BOOST_TEST((s.u.segment<3>(3 * i) - shift).norm() <= 1e-13);
    // Same pairing as the reference, and C(shift) shift − g = the reference gaps (0).
    const ContactModel& contact = problem->contact();
    const Eigen::VectorXd us = contact.restrict_to_surface(s.u);
    const Pairing moved = contact.search(us), still = contact.search(Eigen::VectorXd::Zero(us.size()));
    BOOST_TEST(moved.same_as(still, 1e-12));
    ConstraintMatrix c;
    Eigen::VectorXd g;
    contact.assemble(moved, c, g);
    const Eigen::VectorXd gaps = -(c * us - g).cwiseQuotient(contact.weights());
    BOOST_TEST((gaps.array() - 0.01).abs().maxCoeff() <= 1e-14);
  }
}
