// A FOM status is a promise: `success` only when every residual it reports is
// below kFomKktTolerance, computed at the pairing recomputed from the solution;
// the common first problems (a block pressed on a block with flush ends, the
// punch on the beam) converge; subnormal parameters give meaningful residuals;
// a body left free to move rigidly is named before any solve.
#define BOOST_TEST_MODULE fom_fom_status
#include <boost/test/unit_test.hpp>
#include <filesystem>
#include <fstream>
#include <regex>

#include <contactrom/baselines/ipopt_qp.hpp>
#include "common/input_error.hpp"
#include "common/run_command.hpp"
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/contact_checks.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/fom/rigid_bodies.hpp>

using namespace contactrom;
namespace fs = std::filesystem;

namespace {

const std::string kSource = CONTACTROM_SOURCE_DIR;

std::string write_file(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

/// Two equal blocks [0,1] x [0,0.5] and [0,1] x [0.5,1], 4 x 2 quads each, with
/// flush ends (the corners of the contact curves coincide); the top block's
/// surface loop runs clockwise when `clockwise_top` (gmsh then writes its quads
/// clockwise).
std::string blocks_geo(bool clockwise_top) {
  return std::string(R"(
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 0.5, 0}; Point(4) = {0, 0.5, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Point(5) = {0, 0.5, 0}; Point(6) = {1, 0.5, 0}; Point(7) = {1, 1, 0}; Point(8) = {0, 1, 0};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
)") + (clockwise_top ? "Curve Loop(2) = {-8, -7, -6, -5};\n" : "Curve Loop(2) = {5, 6, 7, 8};\n") +
         R"(Plane Surface(2) = {2};
Transfinite Curve{1, 3, 5, 7} = 5; Transfinite Curve{2, 4, 6, 8} = 3;
Transfinite Surface{1}; Transfinite Surface{2}; Recombine Surface{1, 2};
Physical Surface("bottom", 1) = {1}; Physical Surface("top", 2) = {2};
Physical Curve("bottom_base", 11) = {1}; Physical Curve("bottom_top", 12) = {3};
Physical Curve("top_base", 13) = {5}; Physical Curve("top_top", 14) = {7};
)";
}

/// The problem file of the two blocks: bottom clamped, the top face of the top
/// block pushed down by d; `top_x` is the x condition of that face.
std::string blocks_toml(const std::string& mesh, const std::string& range, const std::string& top_x = "0.0") {
  return "[problem]\nname = \"blocks\"\nmesh = \"" + mesh + "\"\ndisplacement_scale = 0.1\n" +
         "[[parameters]]\nname = \"d\"\nrange = " + range + "\nlower_open = true\n" +
         "[[bodies]]\ngroup = \"bottom\"\nyoung = 1.0\npoisson = 0.3\n" +
         "[[bodies]]\ngroup = \"top\"\nyoung = 1.0\npoisson = 0.3\n" +
         "[[dirichlet]]\ngroup = \"bottom_base\"\ndisplacement = [0.0, 0.0]\n" +
         "[[dirichlet]]\ngroup = \"top_top\"\ndisplacement = [" + top_x + ", \"-d\"]\n" +
         "[[contact]]\nslave = \"top_base\"\nmaster = \"bottom_top\"\n";
}

/// Solves `problem` at `d` with both solvers: each converges, its residuals
/// (recomputed here) are below the tolerance, and the two agree.
void check_converges_honestly(const fom::Problem& problem, double d) {
  const fom::Param mu = fom::Param::Constant(1, d);
  const fom::FomSolution a = fom::ActiveSetSolver(problem).solve(mu);
  const fom::FomSolution b = baselines::IpoptQpSolver(problem).solve(mu);
  for (const fom::FomSolution* s : {&a, &b}) {
    BOOST_TEST_CONTEXT((s == &a ? "active set" : "ipopt") << " at d = " << d) {
      BOOST_TEST(s->status == Status::Success, s->message);
      const fom::KktResiduals k = fom::kkt_residuals(problem, mu, s->u, s->lambda);
      BOOST_TEST(k.stationarity <= fom::kFomKktTolerance);
      BOOST_TEST(k.penetration <= fom::kFomKktTolerance);
      BOOST_TEST(k.negative_pressure <= fom::kFomKktTolerance);
      // The solver's own residuals are the ones recomputed from its answer.
      BOOST_TEST(s->kkt.stationarity == k.stationarity);
    }
  }
  const double force = fom::contact_force(problem, a.lambda);
  BOOST_TEST(force > 0.0);
  BOOST_TEST(std::abs(fom::contact_force(problem, b.lambda) - force) <= 1e-5 * force);
}

}  // namespace

BOOST_AUTO_TEST_CASE(flush_ended_blocks_converge_with_small_residuals) {
  const std::string dir = contactrom::test::temp_dir();
  for (bool clockwise : {false, true}) {
    BOOST_TEST_CONTEXT("clockwise top block: " << clockwise) {
      const std::string geo = write_file(dir, "blocks.geo", blocks_geo(clockwise));
      const auto problem = fom::make_problem(write_file(dir, "blocks.toml", blocks_toml(geo, "[0.0, 0.1]")));
      for (double d : {0.001, 0.02, 0.05, 0.1}) check_converges_honestly(*problem, d);
    }
  }
  // A wide range with a large push (d = 0.45 of a block 0.5 high).
  const std::string geo = write_file(dir, "blocks.geo", blocks_geo(false));
  const auto wide = fom::make_problem(write_file(dir, "wide.toml", blocks_toml(geo, "[0.0, 1000.0]")));
  check_converges_honestly(*wide, 0.45);
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(punch_beam_converges_across_its_range) {
  const auto problem = fom::make_problem("punch_beam");
  for (double d : {0.03, 0.034, 0.035, 0.036, 0.04, 0.1}) {
    const fom::Param mu = fom::Param::Constant(1, d);
    const fom::FomSolution s = fom::ActiveSetSolver(*problem).solve(mu);
    BOOST_TEST_CONTEXT("d = " << d) {
      BOOST_TEST(s.status == Status::Success, s.message);
      BOOST_TEST(fom::kkt_residuals(*problem, mu, s.u, s.lambda).max() <= fom::kFomKktTolerance);
    }
  }
}

BOOST_AUTO_TEST_CASE(a_success_never_carries_large_residuals) {
  // A converged answer whose pressures are doubled (out of balance with the load)
  // or whose top body is pushed into the bottom one is not certified as a success.
  const auto problem = fom::make_problem("hertz");
  const fom::Param mu = fom::Param::Constant(1, 0.1);
  const fom::FomSolution good = fom::ActiveSetSolver(*problem).solve(mu);
  BOOST_REQUIRE(good.status == Status::Success);
  fom::FomSolution s = good;
  s.lambda *= 2.0;
  fom::certify_fom_solution(*problem, s);
  BOOST_TEST(s.status == Status::NoConvergence);
  BOOST_TEST(s.message.find("stationarity residual") != std::string::npos, s.message);
  fom::FomSolution p = good;
  const auto& contact = problem->contact();
  // The slave nodes are the first surface nodes (their y dofs: 1, 3, ...).
  for (int row = 0; row < contact.num_constraints(); ++row) p.u(contact.surface_dofs()[2 * row + 1]) -= 0.01;
  fom::certify_fom_solution(*problem, p);
  BOOST_TEST(p.status == Status::NoConvergence);
  // A NaN residual is never a success.
  fom::FomSolution n = fom::ActiveSetSolver(*problem).solve(mu);
  n.u(0) = std::numeric_limits<double>::quiet_NaN();
  fom::certify_fom_solution(*problem, n);
  BOOST_TEST(n.status == Status::NoConvergence);
}

BOOST_AUTO_TEST_CASE(subnormal_parameters_give_meaningful_residuals) {
  // d = 5e-324 carries one bit: the solution is exact to within what doubles can
  // hold, and the residuals say so instead of 0.95.
  const auto problem = fom::make_problem("hertz");
  for (double d : {5e-324, 1e-320, 1e-310, 1e-300}) {
    const fom::Param mu = fom::Param::Constant(1, d);
    for (int solver = 0; solver < 2; ++solver) {
      const fom::FomSolution s = solver == 0 ? fom::ActiveSetSolver(*problem).solve(mu)
                                             : baselines::IpoptQpSolver(*problem).solve(mu);
      BOOST_TEST_CONTEXT((solver == 0 ? "active set" : "ipopt") << " at d = " << d) {
        const fom::KktResiduals k = fom::kkt_residuals(*problem, mu, s.u, s.lambda);
        BOOST_TEST(k.stationarity <= 1e-6);
        BOOST_TEST(s.status == Status::Success, s.message);
        // (Ipopt's interior multipliers leave a complementarity of round-off
        // pressures times gaps, which its certificate leaves out.)
        BOOST_TEST(std::max({k.stationarity, k.penetration, k.negative_pressure}) <= fom::kFomKktTolerance);
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(a_body_free_in_one_direction_is_named_before_solving) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string geo = write_file(dir, "blocks.geo", blocks_geo(false));
  // The top block held in y only: it can slide in x.
  const std::string msg = contactrom::test::input_error_of([&] {
    const auto problem = fom::make_problem(write_file(dir, "free.toml", blocks_toml(geo, "[0.0, 0.1]", "\"free\"")));
    fom::ActiveSetSolver solver(*problem);
  });
  BOOST_TEST(msg.find("body 'top'") != std::string::npos, msg);
  BOOST_TEST(msg.find("translate in x") != std::string::npos, msg);
  BOOST_TEST(msg.find('\n') == std::string::npos, msg);
  // The CLI refuses it with exit code 2 and one line, before any solve.
  const auto r = contactrom::test::run_command(std::string(CONTACTROM_EXE) + " fom --problem " + dir +
                                               "/free.toml --param 0.05 --solver ipopt --json");
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(r.out.empty());
  BOOST_TEST(r.err.find("translate in x") != std::string::npos, r.err);
  // Held at one node only (both components): free to rotate about that node.
  std::string text = blocks_toml(geo, "[0.0, 0.1]");
  text = std::regex_replace(text, std::regex("group = \"top_top\"\ndisplacement = \\[0.0, \"-d\"\\]"),
                            "group = \"top_corner\"\ndisplacement = [0.0, \"-d\"]");
  write_file(dir, "blocks.geo", blocks_geo(false) + "Physical Point(\"top_corner\", 21) = {7};\n");
  const std::string rot = contactrom::test::input_error_of([&] {
    const auto problem = fom::make_problem(write_file(dir, "rot.toml", text));
    baselines::IpoptQpSolver solver(*problem);
  });
  BOOST_TEST(rot.find("body 'top'") != std::string::npos, rot);
  BOOST_TEST(rot.find("rotate about (1, 1)") != std::string::npos, rot);  // the held node
  // Every shipped problem holds its bodies.
  for (const char* name : {"hertz", "ironing", "ironing2", "punch_beam"})
    BOOST_CHECK_NO_THROW(fom::check_rigid_motions_held(*fom::make_problem(name)));
  fs::remove_all(dir);
}

namespace {

/// The two blocks with the bottom one [0, bottom_width] x [0, 0.5] and the top one
/// [x0, x0 + 1] x [y0, y0 + 0.5].
std::string shifted_blocks_geo(double bottom_width, double x0, double y0) {
  const auto n = [](double v) { return std::to_string(v); };
  return "Point(1) = {0, 0, 0}; Point(2) = {" + n(bottom_width) + ", 0, 0}; Point(3) = {" + n(bottom_width) +
         ", 0.5, 0}; Point(4) = {0, 0.5, 0};\n"
         "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
         "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
         "Point(5) = {" + n(x0) + ", " + n(y0) + ", 0}; Point(6) = {" + n(x0 + 1) + ", " + n(y0) + ", 0}; Point(7) = {" +
         n(x0 + 1) + ", " + n(y0 + 0.5) + ", 0}; Point(8) = {" + n(x0) + ", " + n(y0 + 0.5) + ", 0};\n"
         "Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};\n"
         "Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};\n"
         "Transfinite Curve{1, 3, 5, 7} = 5; Transfinite Curve{2, 4, 6, 8} = 3;\n"
         "Transfinite Surface{1}; Transfinite Surface{2}; Recombine Surface{1, 2};\n"
         "Physical Surface(\"bottom\", 1) = {1}; Physical Surface(\"top\", 2) = {2};\n"
         "Physical Curve(\"bottom_base\", 11) = {1}; Physical Curve(\"bottom_top\", 12) = {3};\n"
         "Physical Curve(\"top_base\", 13) = {5}; Physical Curve(\"top_top\", 14) = {7};\n";
}

bool any_contains(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& l : lines)
    if (l.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

/// A block [0.3, 0.7]² x [z0, z0 + 0.3] on a slab [0, 1]² x [−0.4, 0] (3D, tetrahedra),
/// the block's top moved by `top` and the slab's bottom clamped.
std::string blocks3d_toml(const std::string& dir, double z0, const std::string& top) {
  const std::string z = std::to_string(z0), z1 = std::to_string(z0 + 0.3);
  const std::string geo = write_file(
      dir, "b3.geo",
      "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, -0.4, 1, 1, 0.4};\nBox(2) = {0.3, 0.3, " + z + ", 0.4, 0.4, 0.3};\n"
      "e = 1e-6;\nPhysical Volume(\"slab\") = {1};\nPhysical Volume(\"block\") = {2};\n"
      "bb() = Surface In BoundingBox{0.3-e, 0.3-e, " + z + "-e, 0.7+e, 0.7+e, " + z + "+e};\n"
      "top() = Surface In BoundingBox{-e, -e, -e, 1+e, 1+e, e};\ntop() -= bb();\n"
      "Physical Surface(\"slab_top\") = top();\n"
      "Physical Surface(\"slab_bottom\") = Surface In BoundingBox{-e, -e, -0.4-e, 1+e, 1+e, -0.4+e};\n"
      "Physical Surface(\"block_bottom\") = bb();\n"
      "Physical Surface(\"block_top\") = Surface In BoundingBox{0.3-e, 0.3-e, " + z1 + "-e, 0.7+e, 0.7+e, " + z1 + "+e};\n"
      "Mesh.CharacteristicLengthMax = 0.2;\n");
  return write_file(dir, "b3.toml",
                    "[problem]\nname = \"b3\"\nmesh = \"" + geo + "\"\nformulation = \"3d\"\ndisplacement_scale = 0.02\n"
                    "[[parameters]]\nname = \"d\"\nrange = [0.0, 0.02]\nlower_open = true\n"
                    "[[bodies]]\ngroup = \"slab\"\nyoung = 1.0\npoisson = 0.3\n"
                    "[[bodies]]\ngroup = \"block\"\nyoung = 1.0\npoisson = 0.3\n"
                    "[[dirichlet]]\ngroup = \"slab_bottom\"\ndisplacement = [0.0, 0.0, 0.0]\n"
                    "[[dirichlet]]\ngroup = \"block_top\"\ndisplacement = " + top + "\n"
                    "[[contact]]\nslave = \"block_bottom\"\nmaster = \"slab_top\"\n");
}

BOOST_AUTO_TEST_CASE(in_3d_free_rigid_motions_are_named_and_overlaps_warned_about) {
  const std::string dir = contactrom::test::temp_dir();
  // Held in every direction, resting on the slab: no refusal, no warning.
  const auto held = fom::make_problem(blocks3d_toml(dir, 0.0, "[0.0, 0.0, \"-d\"]"));
  BOOST_CHECK_NO_THROW(fom::check_rigid_motions_held(*held));
  BOOST_TEST(fom::reference_contact_warnings(*held).empty());
  // The top free in x: the block slides in x.
  const std::string slide = contactrom::test::input_error_of([&] {
    const auto problem = fom::make_problem(blocks3d_toml(dir, 0.0, "[\"free\", 0.0, \"-d\"]"));
    fom::ActiveSetSolver solver(*problem);
  });
  BOOST_TEST(slide.find("body 'block' is free to translate in x (") != std::string::npos, slide);
  // Free in x and y: both translations and the rotation about the vertical axis
  // through the block's centre, which the top's z-components do not stop.
  const std::string plane = contactrom::test::input_error_of([&] {
    const auto problem = fom::make_problem(blocks3d_toml(dir, 0.0, "[\"free\", \"free\", \"-d\"]"));
    baselines::IpoptQpSolver solver(*problem);
  });
  BOOST_TEST(plane.find("free to translate in x and free to translate in y and free to rotate about the axis parallel"
                        " to z through (0.5, 0.5, 0.15)") != std::string::npos,
             plane);
  // The block sunk 0.05 (2.5 U) into the slab: warned about.
  const auto sunk = fom::reference_contact_warnings(*fom::make_problem(blocks3d_toml(dir, -0.05, "[0.0, 0.0, \"-d\"]")));
  BOOST_TEST(any_contains(sunk, "overlaps by 0.05"), (sunk.empty() ? "" : sunk[0]));
  // A master surface that takes in its slave surface: the error names the pair.
  const std::string toml = blocks3d_toml(dir, 0.0, "[0.0, 0.0, \"-d\"]");
  std::string geo = contactrom::test::slurp(dir + "/b3.geo");
  geo.replace(geo.find("top() -= bb();"), 14, "");
  write_file(dir, "b3.geo", geo);
  const std::string pair = contactrom::test::input_error_of([&] { fom::make_problem(toml); });
  BOOST_TEST(pair.find("key 'contact[0]': a contact pair's master surface contains its own slave node") !=
                 std::string::npos,
             pair);
  // Every shipped 3D problem holds its bodies and starts without overlap.
  for (const char* name : {"hertz3d", "ironing3d"}) {
    const auto problem = fom::make_problem(name);
    BOOST_CHECK_NO_THROW(fom::check_rigid_motions_held(*problem));
    BOOST_TEST(fom::reference_contact_warnings(*problem).empty());
  }
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(overlaps_and_unpaired_slave_nodes_are_warned_about_and_a_pair_that_never_meets_refused) {
  const std::string dir = contactrom::test::temp_dir();
  const auto build = [&](double width, double x0, double y0) {
    const std::string geo = write_file(dir, "s.geo", shifted_blocks_geo(width, x0, y0));
    return write_file(dir, "s.toml", blocks_toml(geo, "[0.0, 0.1]"));
  };
  // Flush and touching: nothing to say.
  BOOST_TEST(fom::reference_contact_warnings(*fom::make_problem(build(1.0, 0.0, 0.5))).empty());
  // Overlapping by 0.05, half the displacement scale U = 0.1 (> 10 %).
  const auto overlap = fom::reference_contact_warnings(*fom::make_problem(build(1.0, 0.0, 0.45)));
  BOOST_TEST(any_contains(overlap, "overlaps by 0.05"), (overlap.empty() ? "" : overlap[0]));
  // The slave curve 0.15 longer than the master: its last node is never paired.
  const auto beyond = fom::reference_contact_warnings(*fom::make_problem(build(0.85, 0.0, 0.5)));
  BOOST_TEST(any_contains(beyond, "1 of its 5 slave nodes lie just beyond the ends"), (beyond.empty() ? "" : beyond[0]));
  // The CLI prints them on stderr and in the JSON.
  const auto r = contactrom::test::run_command(std::string(CONTACTROM_EXE) + " fom --problem " + build(1.0, 0.0, 0.45) +
                                               " --param 0.05 --json");
  BOOST_TEST(r.exit_code == 0, r.err);
  BOOST_TEST(r.err.find("contactrom: warning: contact pair 0 (slave 'top_base' on master 'bottom_top') overlaps") !=
                 std::string::npos,
             r.err);
  BOOST_TEST(r.out.find("\"warnings\":[\"contact pair 0") != std::string::npos, r.out);
  // The top block beside the bottom one: no slave node ever faces the master.
  const std::string msg = contactrom::test::input_error_of([&] { fom::make_problem(build(1.0, 2.0, 0.5)); });
  BOOST_TEST(msg.find("no slave node facing its master curve") != std::string::npos, msg);
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(solutions_that_turn_elements_inside_out_are_warned_about) {
  // A solution of the KKT conditions may still be far outside the small-strain model;
  // a mirror image of a body (x ↦ −x: u = −2x) turns every element of it inside out.
  for (const char* name : {"hertz", "hertz3d"}) {
    const auto problem = fom::make_problem(name);
    const fom::Mesh& mesh = *problem->mesh();
    const int d = mesh.dim;
    const fom::ActiveSetSolver solver(*problem);
    const fom::FomSolution sol = solver.solve(0.5 * (problem->param_lower() + problem->param_upper()));
    BOOST_TEST(fom::solution_warnings(*problem, sol.u).empty(), name);  // an ordinary load
    Eigen::VectorXd mirror = Eigen::VectorXd::Zero(problem->num_dofs());
    std::vector<char> in_body(static_cast<size_t>(mesh.num_nodes()), 0);
    for (int e = 0; e < mesh.num_elements(); ++e)
      if (mesh.element_body(e) == 0)
        for (int n : mesh.element_nodes(e)) in_body[static_cast<size_t>(n)] = 1;
    for (int n = 0; n < mesh.num_nodes(); ++n)
      if (in_body[static_cast<size_t>(n)]) mirror(d * n) = -2.0 * mesh.nodes(0, n);
    const std::vector<std::string> w = fom::solution_warnings(*problem, mirror);
    BOOST_TEST_REQUIRE(w.size() == 1u, name);
    int total = 0;
    for (int e = 0; e < mesh.num_elements(); ++e) total += mesh.element_body(e) == 0;
    const std::string all = "turns " + std::to_string(total) + " of the " + std::to_string(total) + " elements of body '" +
                            mesh.body_names[0] + "' inside out";
    BOOST_TEST(w[0].find(all) != std::string::npos, w[0]);
  }
}

BOOST_AUTO_TEST_CASE(flush_blocks_in_3d_converge_with_the_uniaxial_force) {
  // Two blocks of the same footprint (a quarter model: hexahedra under tetrahedra, the
  // meshes do not match), the top pushed down by d: uniaxial stress, contact force
  // E d A / (h₁ + h₂) = d. The slave nodes on the master's boundary edges slide out
  // by the two meshes' different lateral expansion; they stay paired with the edge's
  // facet extended, as at the ends of a 2D master chain.
  const std::string dir = contactrom::test::temp_dir();
  const std::string geo = write_file(
      dir, "stack.geo",
      "SetFactory(\"OpenCASCADE\");\nBox(1) = {0,0,-0.5, 1,1,0.5};\nBox(2) = {0,0,0, 1,1,0.5};\ne = 1e-6;\n"
      "bs() = Abs(Boundary{ Volume{1}; });\nbc() = Unique(Abs(Boundary{ Surface{bs()}; }));\n"
      "Transfinite Curve{ bc() } = 3;\nTransfinite Surface{ bs() };\nRecombine Surface{ bs() };\n"
      "Transfinite Volume{1};\nRecombine Volume{1};\nMeshSize{ PointsOf{ Volume{2}; } } = 0.2;\n"
      "Physical Volume(\"bottom\") = {1};\nPhysical Volume(\"top\") = {2};\n"
      "Physical Surface(\"bottom_base\") = Surface In BoundingBox{-e,-e,-0.5-e, 1+e,1+e,-0.5+e};\n"
      "tz() = Surface In BoundingBox{-e,-e,-e, 1+e,1+e,e};\nts() = Abs(Boundary{ Volume{2}; });\n"
      "btop() = tz(); btop() -= ts();\ntface() = tz(); tface() -= btop();\n"
      "Physical Surface(\"bottom_top\") = btop();\nPhysical Surface(\"top_face\") = tface();\n"
      "Physical Surface(\"symx\") = Surface In BoundingBox{-e,-e,-0.5-e, e,1+e,0.5+e};\n"
      "Physical Surface(\"symy\") = Surface In BoundingBox{-e,-e,-0.5-e, 1+e,e,0.5+e};\n"
      "Physical Surface(\"top_lid\") = Surface In BoundingBox{-e,-e,0.5-e, 1+e,1+e,0.5+e};\n");
  const auto problem = fom::make_problem(write_file(
      dir, "stack.toml",
      "[problem]\nname = \"stack\"\nmesh = \"" + geo + "\"\nformulation = \"3d\"\ndisplacement_scale = 0.02\n"
      "[[parameters]]\nname = \"d\"\nrange = [0.0, 0.02]\nlower_open = true\n"
      "[[bodies]]\ngroup = \"bottom\"\nyoung = 1.0\npoisson = 0.3\n"
      "[[bodies]]\ngroup = \"top\"\nyoung = 1.0\npoisson = 0.3\n"
      "[[dirichlet]]\ngroup = \"bottom_base\"\ndisplacement = [\"free\", \"free\", 0.0]\n"
      "[[dirichlet]]\ngroup = \"top_lid\"\ndisplacement = [\"free\", \"free\", \"-d\"]\n"
      "[[dirichlet]]\ngroup = \"symx\"\ndisplacement = [0.0, \"free\", \"free\"]\n"
      "[[dirichlet]]\ngroup = \"symy\"\ndisplacement = [\"free\", 0.0, \"free\"]\n"
      "[[contact]]\nslave = \"top_face\"\nmaster = \"bottom_top\"\n"));
  const fom::ActiveSetSolver solver(*problem);
  for (double d : {0.005, 0.0105, 0.02}) {
    const fom::FomSolution sol = solver.solve(fom::Param::Constant(1, d));
    BOOST_TEST(sol.status == Status::Success, "d = " << d << ": " << sol.message);
    BOOST_TEST(sol.pairing_iterations < 20, "d = " << d);
    BOOST_TEST(std::abs(fom::contact_force(*problem, sol.lambda) - d) < 0.01 * d, "d = " << d);
  }
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(a_slave_that_faces_away_from_its_master_is_refused) {
  // The top block's top face as the slave: its nodes project onto the master (the
  // bottom block's top) with a positive gap, but its outward normal points up like
  // the master's; the face that meets the master is in no pair, so the blocks would
  // pass through each other with every residual zero. Whatever the curves' orientation.
  const std::string dir = contactrom::test::temp_dir();
  for (bool clockwise : {false, true}) {
    const std::string geo = write_file(dir, "blocks.geo", blocks_geo(clockwise));
    std::string toml = blocks_toml(geo, "[0.0, 0.1]");
    BOOST_CHECK_NO_THROW(fom::make_problem(write_file(dir, "ok.toml", toml)));
    toml.replace(toml.find("slave = \"top_base\""), 18, "slave = \"top_top\"");
    const std::string msg = contactrom::test::input_error_of([&] { fom::make_problem(write_file(dir, "away.toml", toml)); });
    BOOST_TEST(msg.find("contact pair 0 (slave 'top_top' on master 'bottom_top'): at each of its 5 paired slave nodes"
                        " the slave curve's outward normal points the same way as the master's") != std::string::npos,
               "clockwise " << clockwise << ": " << msg);
  }
  // 3D: the block's top face over the slab.
  std::string toml = contactrom::test::slurp(blocks3d_toml(dir, 0.0, "[0.0, 0.0, \"-d\"]"));
  toml.replace(toml.find("slave = \"block_bottom\""), 22, "slave = \"block_top\"");
  const std::string msg = contactrom::test::input_error_of([&] { fom::make_problem(write_file(dir, "away3.toml", toml)); });
  BOOST_TEST(msg.find("the slave surface's outward normal points the same way as the master's") != std::string::npos, msg);
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(a_loose_piece_of_a_body_is_named_by_where_it_is) {
  // A square [3, 3.5] x [0, 0.5] meshed into body 'top' but connected to nothing: the
  // body itself is held, the piece is not.
  const std::string dir = contactrom::test::temp_dir();
  std::string geo = blocks_geo(false);
  geo.replace(geo.find("Physical Surface(\"top\", 2) = {2};"), 33,
              "Point(9) = {3, 0, 0}; Point(10) = {3.5, 0, 0}; Point(11) = {3.5, 0.5, 0}; Point(12) = {3, 0.5, 0};\n"
              "Line(9) = {9, 10}; Line(10) = {10, 11}; Line(11) = {11, 12}; Line(12) = {12, 9};\n"
              "Curve Loop(3) = {9, 10, 11, 12}; Plane Surface(3) = {3};\n"
              "Transfinite Curve{9, 10, 11, 12} = 3; Transfinite Surface{3}; Recombine Surface{3};\n"
              "Physical Surface(\"top\", 2) = {2, 3};");
  const std::string msg = contactrom::test::input_error_of([&] {
    const auto problem = fom::make_problem(write_file(dir, "loose.toml", blocks_toml(write_file(dir, "loose.geo", geo), "[0.0, 0.1]")));
    fom::ActiveSetSolver solver(*problem);
  });
  BOOST_TEST(msg.find("body 'top' (its piece around (3.25, 0.25), not connected to the rest of it) is held by no"
                      " Dirichlet condition") != std::string::npos,
             msg);
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(a_default_displacement_scale_set_by_a_slide_is_warned_about) {
  // The top block slid by 0.6 and pressed by d ≤ 0.1 with no displacement_scale: U
  // defaults to the slide, six times the indentation, and the problem says so.
  const std::string dir = contactrom::test::temp_dir();
  const std::string geo = write_file(dir, "s.geo", shifted_blocks_geo(1.0, 0.0, 0.5));
  const auto without_scale = [](std::string text) {
    const std::string line = "displacement_scale = 0.1\n";
    return text.erase(text.find(line), line.size());
  };
  const auto slid = fom::make_problem(write_file(dir, "slid.toml", without_scale(blocks_toml(geo, "[0.0, 0.1]", "0.6"))));
  BOOST_TEST(slid->displacement_scale() == 0.6);
  const auto w = fom::reference_contact_warnings(*slid);
  BOOST_TEST_REQUIRE(w.size() == 1u);
  BOOST_TEST(w[0].find("displacement_scale is not set, so U = 0.6, the largest prescribed displacement (group "
                       "'top_top', component x), 6 times the smallest nonzero one (0.1)") == 0u, w[0]);
  // Pressed only, or with the scale set: nothing to say.
  BOOST_TEST(fom::reference_contact_warnings(
                 *fom::make_problem(write_file(dir, "pressed.toml", without_scale(blocks_toml(geo, "[0.0, 0.1]")))))
                 .empty());
  BOOST_TEST(fom::reference_contact_warnings(*fom::make_problem(write_file(dir, "set.toml", blocks_toml(geo, "[0.0, 0.1]", "0.6"))))
                 .empty());
}
