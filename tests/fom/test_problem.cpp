// Tests of fom/problem.hpp: a problem built (build_problem, no gmsh) from a problem
// text and a two-quad mesh written here — a unit block standing on a 2 × 1 base —
// checked in closed form: Dirichlet dofs and lifting, consistent traction loads,
// the affine parameter mapping of K and of the loads against direct assembly, the
// right-hand side, the contact rows, the displacement scale, the H¹ Gram matrix on
// constant fields; refusals of a definition that does not fit the mesh; the rope's
// terms; parameter parsing.
#define BOOST_TEST_MODULE fom_problem
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <string>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/elasticity.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/fom/problem_file.hpp>
#include <contactrom/fom/rope.hpp>

#include <stdexcept>

using namespace contactrom;
using Eigen::MatrixXd;
using Eigen::Vector2d;
using Eigen::VectorXd;

namespace {

/// Base: quad 0-1-2-3 = (0,0) (2,0) (2,1) (0,1); block: quad 4-5-6-7 = (0.5,1) (1.5,1)
/// (1.5,2) (0.5,2), touching the base along y = 1 with its own nodes. Curves run
/// with their body on the left.
fom::Mesh two_quads() {
  fom::Mesh m;
  m.nodes.resize(2, 8);
  m.nodes << 0, 2, 2, 0, 0.5, 1.5, 1.5, 0.5,  //
      0, 0, 1, 1, 1, 1, 2, 2;
  m.quads = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  m.quad_body = {0, 1};
  m.body_names = {"base", "block"};
  const auto curve = [&](const std::string& name, std::vector<int> nodes) {
    for (size_t i = 0; i + 1 < nodes.size(); ++i) m.segments[name].push_back({nodes[i], nodes[i + 1]});
    m.curve_nodes[name] = std::move(nodes);
  };
  curve("base_bottom", {0, 1});
  curve("base_top", {2, 3});
  curve("block_bottom", {4, 5});
  curve("block_top", {6, 7});
  curve("block_left", {7, 4});
  return m;
}

const char* kText = R"(
[problem]
name = "two_quads"
mesh = "two_quads.msh"

[[parameters]]
name = "d"
range = [0.0, 0.2]

[[parameters]]
name = "E"
range = [1.0, 3.0]

[[bodies]]
group = "base"
young = "E"
poisson = 0.3

[[bodies]]
group = "block"
young = 2.0
poisson = 0.25

[[dirichlet]]
group = "base_bottom"
displacement = [0.0, 0.0]

[[dirichlet]]
group = "block_top"
displacement = ["free", "-d"]

[[traction]]
group = "block_left"
traction = ["0.5*d", 1.0]

[[contact]]
slave = "block_bottom"
master = "base_top"
)";

std::unique_ptr<fom::Problem> build(const std::string& text = kText, fom::Mesh mesh = two_quads()) {
  return fom::build_problem(fom::parse_problem_text(text, "/tmp/two_quads.toml"), std::move(mesh));
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  BOOST_REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

const fom::Param mu = Vector2d(0.15, 2.5);  // d, E

}  // namespace

BOOST_AUTO_TEST_CASE(dirichlet_dofs_and_lifting) {
  const auto p = build();
  BOOST_TEST(p->num_dofs() == 16);
  BOOST_TEST(p->num_params() == 2);
  // Both components of nodes 0, 1; only y of nodes 6, 7 (x is "free").
  std::vector<char> expected(16, 0);
  for (int dof : {0, 1, 2, 3, 13, 15}) expected[static_cast<size_t>(dof)] = 1;
  BOOST_TEST(p->is_dirichlet() == expected);
  BOOST_TEST(p->free_dofs() == (std::vector<int>{4, 5, 6, 7, 8, 9, 10, 11, 12, 14}));
  VectorXd lift = VectorXd::Zero(16);
  lift(13) = lift(15) = -0.15;
  BOOST_TEST((p->lifting(mu) - lift).norm() <= 1e-15);
  // The largest prescribed displacement over the box: |−d| at d = 0.2.
  BOOST_TEST(std::abs(p->displacement_scale() - 0.2) <= 1e-15);
}

BOOST_AUTO_TEST_CASE(traction_gives_half_the_segment_force_to_each_end) {
  // block_left is one segment of length 1 (nodes 7, 4): each end gets ½·(0.5d, 1).
  const auto p = build();
  const VectorXd phi = p->load_coefficients(mu);
  VectorXd fext = VectorXd::Zero(16);
  for (int k = 0; k < p->num_load_terms(); ++k) fext += phi(k) * p->external_load_terms()[static_cast<size_t>(k)];
  VectorXd expected = VectorXd::Zero(16);
  for (int node : {4, 7}) expected.segment<2>(2 * node) = Vector2d(0.25 * 0.15, 0.5);
  BOOST_TEST((fext - expected).norm() <= 1e-15);
  // Load terms: the constant one and the one of d; E moves neither load nor lifting.
  BOOST_TEST(p->num_load_terms() == 2);
}

BOOST_AUTO_TEST_CASE(stiffness_is_affine_in_the_parameters) {
  // θ(μ) = (1, E): the block's constant modulus and the base's E; K(μ) equals the
  // direct assembly with the moduli evaluated at μ.
  const auto p = build();
  BOOST_TEST(p->num_stiffness_terms() == 2);
  BOOST_TEST(!p->stiffness_is_constant());
  const VectorXd theta = p->stiffness_coefficients(mu);
  BOOST_TEST((theta - Vector2d(1.0, 2.5)).norm() == 0.0);
  const std::vector<fom::Material> mats = p->materials(mu);
  BOOST_REQUIRE(mats.size() == 2u);
  BOOST_TEST(mats[0].young == 2.5);
  BOOST_TEST(mats[1].young == 2.0);
  BOOST_TEST(mats[1].poisson == 0.25);
  const MatrixXd direct(fom::assemble_stiffness(*p->mesh(), mats));
  const MatrixXd k(p->stiffness(mu));
  BOOST_TEST((k - direct).norm() <= 1e-13 * direct.norm());
  // Rigid translations and each body's rotation are in the kernel of K.
  VectorXd tx = VectorXd::Zero(16), rot = VectorXd::Zero(16);
  for (int i = 0; i < 8; ++i) tx(2 * i) = 1.0;
  for (int i = 4; i < 8; ++i) rot.segment<2>(2 * i) = Vector2d(-p->mesh()->nodes(1, i), p->mesh()->nodes(0, i));
  BOOST_TEST((k * tx).norm() <= 1e-13 * k.norm());
  BOOST_TEST((k * rot).norm() <= 1e-13 * k.norm());
  // apply_stiffness: the same product without forming K(μ), for any vector.
  const VectorXd v = VectorXd::LinSpaced(16, -1.0, 2.0);
  BOOST_TEST((p->apply_stiffness(mu, v) - k * v).norm() <= 1e-14 * (k * v).norm());
}

BOOST_AUTO_TEST_CASE(rhs_is_the_load_minus_the_lifting_response_off_dirichlet_rows) {
  const auto p = build();
  const VectorXd phi = p->load_coefficients(mu);
  VectorXd fext = VectorXd::Zero(16);
  for (int k = 0; k < p->num_load_terms(); ++k) fext += phi(k) * p->external_load_terms()[static_cast<size_t>(k)];
  VectorXd expected = fext - MatrixXd(p->stiffness(mu)) * p->lifting(mu);
  for (int i = 0; i < 16; ++i)
    if (p->is_dirichlet()[static_cast<size_t>(i)]) expected(i) = 0.0;
  BOOST_TEST((p->rhs(mu) - expected).norm() <= 1e-14 * expected.norm());
}

BOOST_AUTO_TEST_CASE(free_block_drops_dirichlet_rows_and_columns) {
  const auto p = build();
  const MatrixXd k(p->stiffness(mu));
  std::vector<int> index(16, -1);
  const std::vector<int>& free = p->free_dofs();
  for (size_t i = 0; i < free.size(); ++i) index[static_cast<size_t>(free[i])] = static_cast<int>(i);
  const MatrixXd kff(fom::free_block(p->stiffness(mu), index, static_cast<int>(free.size())));
  for (size_t a = 0; a < free.size(); ++a)
    for (size_t b = 0; b < free.size(); ++b)
      BOOST_TEST(kff(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) == k(free[a], free[b]));
}

BOOST_AUTO_TEST_CASE(contact_rows_are_the_slave_nodes) {
  const auto p = build();
  const fom::ContactModel& c = p->contact();
  BOOST_TEST(c.num_constraints() == 2);
  // Slave nodes 4, 5 first, then the master nodes 2, 3.
  BOOST_TEST(c.surface_dofs() == (std::vector<int>{8, 9, 10, 11, 4, 5, 6, 7}));
  BOOST_TEST((c.weights() - Vector2d(0.5, 0.5)).norm() == 0.0);
  // Touching in the reference configuration: zero gaps, normal (0, 1) of the base.
  fom::ConstraintMatrix cm;
  VectorXd g;
  const fom::Pairing pairing = c.search(VectorXd::Zero(8));
  c.assemble(pairing, cm, g);
  BOOST_TEST(g.norm() == 0.0);
  for (int k = 0; k < 2; ++k) BOOST_TEST((pairing.normal.col(k) - Vector2d(0.0, 1.0)).norm() <= 1e-15);
}

BOOST_AUTO_TEST_CASE(h1_gram_of_a_constant_field_is_the_area) {
  // ∇u = 0 for a constant u = t: (u, u)_H¹ = |t|² × area (2 + 1).
  const auto p = build();
  VectorXd u = VectorXd::Zero(16);
  for (int i = 0; i < 8; ++i) u.segment<2>(2 * i) = Vector2d(0.3, -0.4);
  BOOST_TEST(std::abs(u.dot(p->h1_gram() * u) - 3.0 * 0.25) <= 1e-14);
}

BOOST_AUTO_TEST_CASE(definitions_that_do_not_fit_the_mesh_are_refused) {
  // A body that is not a surface of the mesh.
  BOOST_CHECK_THROW(build(replaced(kText, "group = \"block\"", "group = \"lid\"")), InputError);
  // A Dirichlet group that does not exist.
  BOOST_CHECK_THROW(build(replaced(kText, "group = \"base_bottom\"", "group = \"floor\"")), InputError);
  // Two Dirichlet groups prescribing different values at their shared node 7.
  const std::string clash = std::string(kText) + "\n[[dirichlet]]\ngroup = \"block_left\"\ndisplacement = [\"free\", 0.0]\n";
  BOOST_CHECK_THROW(build(clash), InputError);
  // Equal values where they meet are accepted.
  const std::string same = std::string(kText) + "\n[[dirichlet]]\ngroup = \"block_left\"\ndisplacement = [\"free\", \"-d\"]\n";
  BOOST_CHECK_NO_THROW(build(same));
  // A surface of the mesh without a [[bodies]] entry.
  fom::Mesh three = two_quads();
  three.body_names.push_back("lid");
  three.quads.push_back({4, 5, 6, 7});
  three.quad_body.push_back(2);
  BOOST_CHECK_THROW(build(kText, three), InputError);
}

BOOST_AUTO_TEST_CASE(rope_terms_in_closed_form) {
  // 4 elements, h = ¼: left elements (x < ½) scaled by γ, right ones by 30; tributary
  // weights h inside and h/2 at the ends; load −f·w.
  fom::RopeOptions options;
  options.elements = 4;
  const auto p = fom::make_rope_problem(options);
  BOOST_TEST(p->num_dofs() == 5);
  BOOST_TEST(p->dofs_per_node() == 1);
  BOOST_TEST(p->free_dofs() == (std::vector<int>{1, 2, 3}));
  const fom::Param gamma = VectorXd::Constant(1, 20.0);
  BOOST_TEST((p->stiffness_coefficients(gamma) - Vector2d(20.0, 30.0)).norm() == 0.0);
  MatrixXd left = MatrixXd::Zero(5, 5), right = MatrixXd::Zero(5, 5);
  for (int e = 0; e < 4; ++e) {
    MatrixXd& k = e < 2 ? left : right;
    k.block<2, 2>(e, e) += 4.0 * (MatrixXd(2, 2) << 1, -1, -1, 1).finished();
  }
  BOOST_TEST((MatrixXd(p->stiffness_term(0)) - left).norm() == 0.0);
  BOOST_TEST((MatrixXd(p->stiffness_term(1)) - right).norm() == 0.0);
  const VectorXd fext = p->external_load_terms()[0];
  BOOST_TEST((fext - (VectorXd(5) << 0, -100, -100, -100, 0).finished()).norm() <= 1e-12);
  BOOST_TEST(p->lifting(gamma).norm() == 0.0);
  BOOST_CHECK_THROW(fom::make_rope_problem(fom::RopeOptions{1}), InputError);
}

BOOST_AUTO_TEST_CASE(rope_nodes_are_the_uniform_grid_and_parts_must_agree) {
  // The rope has no mesh; its nodes (for output) are x_i = i / elements.
  fom::RopeOptions options;
  options.elements = 4;
  const auto p = fom::make_rope_problem(options);
  BOOST_TEST(p->mesh() == nullptr);
  BOOST_TEST((fom::rope_nodes(*p) - (VectorXd(5) << 0.0, 0.25, 0.5, 0.75, 1.0).finished()).norm() == 0.0);
  // The default rope is `--problem rope`'s, with the fingerprint its databases store
  // (the value databases of format version 2 hold: they rebuild this problem).
  BOOST_TEST(fom::make_problem("rope")->fingerprint() == "7ce20918bc2496ed");
  BOOST_TEST(fom::make_rope_problem()->fingerprint() != p->fingerprint());
  // A Problem's parts must agree in size: here a stiffness term of the wrong size.
  fom::ProblemParts parts;
  parts.is_dirichlet.assign(3, 0);
  parts.stiffness_terms = {fom::SparseMatrix(2, 2)};
  parts.stiffness_coefficients = {fom::AffineExpression::constant_value(1.0, 1)};
  parts.lifting_terms = parts.external_load_terms = {VectorXd::Zero(3)};
  parts.load_coefficients = {fom::AffineExpression::constant_value(1.0, 1)};
  parts.contact = std::make_unique<fom::ObstacleContact>(VectorXd::LinSpaced(3, 0.0, 1.0), VectorXd::Zero(3),
                                                         VectorXd::Ones(3));
  parts.h1_gram = fom::SparseMatrix(3, 3);
  BOOST_CHECK_THROW(fom::Problem(std::move(parts)), std::invalid_argument);
}

BOOST_AUTO_TEST_CASE(parameters_are_parsed_and_range_checked) {
  const auto p = build();
  const fom::Param q = fom::parse_param(*p, "0.1,2");
  BOOST_TEST((q - Vector2d(0.1, 2.0)).norm() == 0.0);
  BOOST_CHECK_THROW(fom::parse_param(*p, "0.1"), InputError);    // one value for two parameters
  BOOST_CHECK_THROW(fom::parse_param(*p, "0.5,2"), InputError);  // d outside [0, 0.2]
  BOOST_CHECK_THROW(p->check_param(Vector2d(0.1, 4.0)), InputError);
}
