// Problem files: the reader (keys, affine expressions, sampling plans), the
// data-driven builder (any curves as slave/master, several pairs, E affine in the
// parameters), and the CLI's refusal of malformed files (one line naming file,
// line and key; exit 2; no output).
#define BOOST_TEST_MODULE fom_problem_file
#include <boost/test/unit_test.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include <contactrom/baselines/ipopt_qp.hpp>
#include "common/run_command.hpp"
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>

using namespace contactrom;
using contactrom::test::run_command;
namespace fs = std::filesystem;

namespace {

const std::string kExe = CONTACTROM_EXE;
const std::string kSource = CONTACTROM_SOURCE_DIR;

std::string read_text(const std::string& path) { return contactrom::test::slurp(path); }

/// The shipped hertz.toml with its mesh path made absolute, so that copies can live anywhere.
std::string hertz_text() {
  std::string t = read_text(kSource + "/problems/hertz.toml");
  return std::regex_replace(t, std::regex("\\.\\./meshes/"), kSource + "/meshes/");
}

std::string write_temp(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  BOOST_REQUIRE_MESSAGE(at != std::string::npos, "test setup: '" << from << "' not in the file");
  return text.replace(at, from.size(), to);
}

fom::FomSolution solve(const fom::Problem& p, const fom::Param& mu) { return fom::ActiveSetSolver(p).solve(mu); }

}  // namespace

BOOST_AUTO_TEST_CASE(affine_expressions) {
  fom::ParameterSpace s;
  s.add("d", 0.0, 0.3, true);
  s.add("E_base", 0.5, 20.0);
  const auto e = fom::parse_affine_expression("0.5*E_base - d + 0.1", s);
  BOOST_TEST(e.constant == 0.1);
  BOOST_TEST(e.coefficients(0) == -1.0);
  BOOST_TEST(e.coefficients(1) == 0.5);
  BOOST_TEST(fom::parse_affine_expression("-d", s).coefficients(0) == -1.0);
  BOOST_TEST(fom::parse_affine_expression(" 2e-1 ", s).constant == 0.2);
  BOOST_TEST(e.min_over(s) == 0.5 * 0.5 - 0.3 + 0.1);
  BOOST_TEST(e.max_over(s) == 0.5 * 20.0 + 0.1);
  for (const char* bad : {"d*E_base", "E", "2*", "d d", "", "1/d", "d*2", "nan", "0.5*", "+"})
    BOOST_CHECK_THROW(fom::parse_affine_expression(bad, s), InputError);
  try {
    fom::parse_affine_expression("0.5*Ebase", s);
  } catch (const InputError& err) {
    BOOST_TEST(std::string(err.what()).find("unknown parameter 'Ebase'") != std::string::npos);
    BOOST_TEST(std::string(err.what()).find("d, E_base") != std::string::npos);
  }
}

BOOST_AUTO_TEST_CASE(parameter_parsing_and_ranges) {
  fom::ParameterSpace s;
  s.add("d", 0.0, 0.3, true);
  BOOST_TEST(s.parse("0.3", "hertz")(0) == 0.3);
  for (const char* bad : {"0", "0.30000000001", "", " ", "0.1,", "abc", "nan", "inf", "0.1,0.2"})
    BOOST_CHECK_THROW(s.parse(bad, "hertz"), InputError);
  try {
    s.parse("0.30000000001", "hertz");
  } catch (const InputError& err) {
    BOOST_TEST(std::string(err.what()).find("0.30000000001") != std::string::npos);  // the value as given
  }
  BOOST_CHECK_THROW(s.add("e", 1.0, 1.0), InputError);
  BOOST_CHECK_THROW(s.add("d", 0.0, 1.0), InputError);
}

BOOST_AUTO_TEST_CASE(sampling_plans) {
  fom::ParameterSpace open;
  open.add("d", 0.0, 0.3, true);
  fom::SamplingPlan uniform;  // the hertz convention d_i = 0.3 i / n
  const auto train = uniform.points_for(open, 30);
  BOOST_TEST(train.size() == 30u);
  for (int i = 1; i <= 30; ++i) BOOST_TEST(train[i - 1](0) == 0.3 * i / 30);
  fom::SamplingPlan mid;
  mid.kind = fom::SamplingPlan::Kind::Midpoints;
  mid.of = 120;
  const auto val = mid.points_for(open, 30);
  BOOST_TEST(val.size() == 119u);
  BOOST_TEST(std::abs(val.front()(0) - 0.3 * 1.5 / 120) < 1e-15);
  BOOST_TEST(std::abs(val.back()(0) - 0.3 * 119.5 / 120) < 1e-15);

  fom::ParameterSpace box;
  box.add("x", 0.0, 4.0);
  box.add("y", 0.1, 0.3);
  fom::SamplingPlan nested;
  nested.kind = fom::SamplingPlan::Kind::Nested;
  BOOST_TEST(nested.points_for(box, 3).size() == 81u);  // 9 x 9
  fom::SamplingPlan next;
  next.kind = fom::SamplingPlan::Kind::NextLevel;
  const auto fine = next.points_for(box, 3);
  BOOST_TEST(fine.size() == 17u * 17u - 81u);  // level 4 minus level 3
  // No point of the next level lies on the coarse grid.
  for (const auto& p : fine) {
    const double ix = p(0) / 4.0 * 8, iy = (p(1) - 0.1) / 0.2 * 8;
    BOOST_TEST(!(std::abs(ix - std::round(ix)) < 1e-9 && std::abs(iy - std::round(iy)) < 1e-9));
  }
  // Latin hypercube: one point per stratum in each parameter, same points for the same seed.
  fom::SamplingPlan random;
  random.kind = fom::SamplingPlan::Kind::Random;
  random.seed = 7;
  const auto r1 = random.points_for(box, 10), r2 = random.points_for(box, 10);
  for (int d = 0; d < 2; ++d) {
    std::vector<int> hits(10, 0);
    for (const auto& p : r1) ++hits[static_cast<size_t>((p(d) - box.lower(d)) / (box.upper(d) - box.lower(d)) * 10)];
    for (int h : hits) BOOST_TEST(h == 1);
  }
  for (size_t k = 0; k < r1.size(); ++k) BOOST_TEST((r1[k] - r2[k]).norm() == 0.0);
  BOOST_CHECK_THROW(nested.points_for(box, 25), InputError);
}

BOOST_AUTO_TEST_CASE(grid_end_points_are_exactly_the_bounds) {
  // 0.1 * 6 / 6 = 0.10000000000000002: a grid computed as lo + (hi - lo) k / n
  // leaves the range (0, 0.1] at n = 3, 6, 7, 12.
  fom::ParameterSpace small;
  small.add("d", 0.0, 0.1, true);
  fom::ParameterSpace closed;
  closed.add("x", -0.3, 0.1);
  for (int n : {3, 6, 7, 12, 30}) {
    for (const fom::ParameterSpace* space : {&small, &closed}) {
      fom::SamplingPlan uniform;
      const auto points = uniform.points_for(*space, n);
      BOOST_TEST(points.back()(0) == 0.1, "n = " << n);
      for (const auto& p : points) BOOST_TEST(space->contains(p), "n = " << n << ": " << p(0) << " is outside");
      fom::SamplingPlan mid;
      mid.kind = fom::SamplingPlan::Kind::Midpoints;
      for (const auto& p : mid.points_for(*space, n)) BOOST_TEST(space->contains(p));
    }
  }
  fom::SamplingPlan nested;
  nested.kind = fom::SamplingPlan::Kind::Nested;
  for (int level = 1; level <= 6; ++level) {
    const auto points = nested.points_for(small, level);
    BOOST_TEST(points.back()(0) == 0.1);
    for (const auto& p : points) BOOST_TEST(small.contains(p));
  }
}

BOOST_AUTO_TEST_CASE(shipped_hertz_file_gives_the_hertz_problem) {
  const auto p = fom::make_problem("hertz");
  BOOST_TEST(p->num_dofs() == 2 * 1034);
  BOOST_TEST(p->contact().num_constraints() == 79);
  BOOST_TEST(p->stiffness_is_constant());
  BOOST_TEST(p->num_load_terms() == 1);  // the lifting of d alone
  BOOST_TEST(fom::training_set(*p, 30).size() == 30u);
  BOOST_TEST(fom::validation_set(*p, 30).size() == 119u);
  // Hertz theory (plane strain, equal cylinders R = 1, E = 1, nu = 0.3) for a small
  // d: the contact force is positive and the contact is closed near the origin.
  const auto sol = solve(*p, fom::Param::Constant(1, 0.1));
  BOOST_TEST(sol.status == Status::Success);
  BOOST_TEST(sol.active > 0);
}

BOOST_AUTO_TEST_CASE(swapped_slave_and_master_agree_with_the_original) {
  // Any curve may be the slave: the master's outward normal comes from its own body.
  const std::string dir = contactrom::test::temp_dir();
  std::string swapped = hertz_text();
  swapped = replace_once(swapped, "slave = \"top_arc\"", "slave = \"@\"");
  swapped = replace_once(swapped, "master = \"bottom_arc\"", "master = \"top_arc\"");
  swapped = replace_once(swapped, "slave = \"@\"", "slave = \"bottom_arc\"");
  const auto a = fom::make_problem("hertz");
  const auto b = fom::make_problem(write_temp(dir, "swapped.toml", swapped));
  for (double d : {0.05, 0.1, 0.2, 0.3}) {
    const fom::Param mu = fom::Param::Constant(1, d);
    const auto sa = solve(*a, mu), sb = solve(*b, mu);
    BOOST_TEST_REQUIRE(sb.status == Status::Success);
    const double fa = fom::contact_force(*a, sa.lambda), fb = fom::contact_force(*b, sb.lambda);
    BOOST_TEST_MESSAGE("d = " << d << ": force " << fa << " (top slave) vs " << fb << " (bottom slave)");
    BOOST_TEST(std::abs(fa - fb) <= 0.02 * fa);
    const auto kkt = fom::kkt_residuals(*b, mu, sb.u, sb.lambda);
    BOOST_TEST(kkt.stationarity <= 1e-10);
    BOOST_TEST(kkt.penetration <= 1e-10);
  }
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(young_modulus_as_a_parameter_agrees_with_fixed_values) {
  // K(mu) affine in E: the same as files with E fixed, at three points.
  const std::string dir = contactrom::test::temp_dir();
  std::string text = hertz_text();
  text = replace_once(text, "lower_open = true              # d in (0, 0.3]",
                      "lower_open = true\n\n[[parameters]]\nname = \"E\"\nrange = [0.5, 20.0]");
  text = replace_once(text, "group = \"bottom\"\nyoung = 1.0", "group = \"bottom\"\nyoung = \"E\"");
  const auto affine = fom::make_problem(write_temp(dir, "affine.toml", text));
  BOOST_TEST(!affine->stiffness_is_constant());
  for (const auto& [d, e] : {std::pair{0.1, 0.5}, std::pair{0.2, 3.0}, std::pair{0.3, 20.0}}) {
    std::string fixed = hertz_text();
    char young[64];
    std::snprintf(young, sizeof young, "young = %.17g", e);
    fixed = replace_once(fixed, "group = \"bottom\"\nyoung = 1.0", std::string("group = \"bottom\"\n") + young);
    const auto ref = fom::make_problem(write_temp(dir, "fixed.toml", fixed));
    const auto sa = solve(*affine, (fom::Param(2) << d, e).finished());
    const auto sr = solve(*ref, fom::Param::Constant(1, d));
    BOOST_TEST_REQUIRE(sa.status == Status::Success);
    BOOST_TEST((sa.u - sr.u).norm() <= 1e-10 * sr.u.norm());
    BOOST_TEST((sa.lambda - sr.lambda).norm() <= 1e-9 * sr.lambda.norm());
  }
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(plane_stress_equals_plane_strain_without_poisson_effect) {
  // With nu = 0 both formulations have the same constitutive matrix.
  const std::string dir = contactrom::test::temp_dir();
  std::string strain = hertz_text();
  for (int k = 0; k < 2; ++k) strain = replace_once(strain, "poisson = 0.3", "poisson = 0.0");
  const std::string stress = replace_once(strain, "formulation = \"plane_strain\"", "formulation = \"plane_stress\"");
  const auto a = fom::make_problem(write_temp(dir, "strain.toml", strain));
  const auto b = fom::make_problem(write_temp(dir, "stress.toml", stress));
  BOOST_TEST((a->stiffness_term(0) - b->stiffness_term(0)).norm() <= 1e-14 * a->stiffness_term(0).norm());
  std::string stress3 = replace_once(hertz_text(), "formulation = \"plane_strain\"", "formulation = \"plane_stress\"");
  const auto c = fom::make_problem(write_temp(dir, "stress3.toml", stress3));
  // With nu = 0.3 plane stress is softer: a smaller force for the same d.
  const fom::Param mu = fom::Param::Constant(1, 0.1);
  const auto h = fom::make_problem("hertz");
  BOOST_TEST(fom::contact_force(*c, solve(*c, mu).lambda) < fom::contact_force(*h, solve(*h, mu).lambda));
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(two_contact_pairs_fom_agrees_with_ipopt) {
  // punch_beam: three bodies, two pairs, a traction.
  const auto p = fom::make_problem("punch_beam");
  const auto& contact = dynamic_cast<const fom::NodeToSegmentContact&>(p->contact());
  BOOST_TEST(contact.num_pairs() == 2);
  const baselines::IpoptQpSolver ipopt(*p);
  bool second_pair_active = false;
  for (double d : {0.02, 0.06, 0.1, 0.15, 0.2}) {
    const fom::Param mu = fom::Param::Constant(1, d);
    const auto s = solve(*p, mu);
    BOOST_TEST_REQUIRE(s.status == Status::Success);
    const auto kkt = fom::kkt_residuals(*p, mu, s.u, s.lambda);
    BOOST_TEST(kkt.stationarity <= 1e-10);
    BOOST_TEST(kkt.penetration <= 1e-10);
    BOOST_TEST(kkt.negative_pressure <= 1e-10);
    BOOST_TEST(kkt.complementarity <= 1e-10);
    const auto r = ipopt.solve(mu);
    BOOST_TEST_REQUIRE(r.status == Status::Success);
    BOOST_TEST((s.u - r.u).cwiseAbs().maxCoeff() <= 1e-6 * p->displacement_scale());
    // Pressures agree to 1e-5 (relative to max(1, max λ)): at d = 0.06 a beam node
    // barely separates (gap 3e-7, no pressure in the exact solution) and Ipopt's
    // barrier moves 1.5e-6 of pressure from its neighbour onto it (λ ≈ μ / gap); the
    // displacements agree to 1e-6 U (above) and the KKT residuals to 1e-10.
    BOOST_TEST((s.lambda - r.lambda).cwiseAbs().maxCoeff() <= 1e-5 * std::max(1.0, s.lambda.cwiseAbs().maxCoeff()));
    for (int row = 0; row < contact.num_constraints(); ++row)
      second_pair_active = second_pair_active || (contact.pair_of_row(row) == 1 && s.lambda(row) > 0);
  }
  BOOST_TEST(second_pair_active);  // the beam does reach the foundation
}

namespace {

struct BadCase {
  const char* what;
  const char* from;  // replaced in hertz.toml (empty: appended)
  const char* to;
  const char* key;   // the key the message must name
};

}  // namespace

BOOST_AUTO_TEST_CASE(malformed_files_give_one_line_naming_file_line_and_key) {
  const std::vector<BadCase> cases = {
      {"missing key", "name = \"d\"\n", "", "parameters[0].name"},
      {"unknown group", "group = \"bottom_clamp\"", "group = \"bottom_clmp\"", "dirichlet[0].group"},
      {"unknown parameter", "[0.0, \"-d\"]", "[0.0, \"-dd\"]", "dirichlet[1].displacement[1]"},
      {"non-affine expression", "[0.0, \"-d\"]", "[0.0, \"-d*d\"]", "dirichlet[1].displacement[1]"},
      {"lo >= hi", "range = [0.0, 0.3]", "range = [0.3, 0.3]", "parameters[0].range"},
      {"width overflows", "range = [0.0, 0.3]", "range = [-1.7e308, 1.7e308]", "parameters[0].range"},
      {"surface without body", "[[bodies]]\ngroup = \"top\"\nyoung = 1.0\npoisson = 0.3\n", "", "bodies"},
      {"unknown key", "poisson = 0.3", "poison = 0.3", "bodies[0].poison"},
      {"negative modulus", "young = 1.0", "young = -1.0", "bodies[0].young"},
      {"syntax error", "range = [0.0, 0.3]", "range = [0.0, 0.3", ""},
  };
  const std::string dir = contactrom::test::temp_dir();
  for (const BadCase& c : cases) {
    BOOST_TEST_CONTEXT(c.what) {
      std::string text = hertz_text();
      text = replace_once(text, c.from, c.to);
      const std::string file = write_temp(dir, "bad.toml", text);
      const std::string out = dir + "/out";
      const auto r = run_command(kExe + " fom --problem " + file + " --param 0.1 --json --out " + out);
      BOOST_TEST(r.exit_code == 2);
      BOOST_TEST(r.out.empty());
      BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1, r.err);
      BOOST_TEST(r.err.find(file) != std::string::npos, r.err);
      if (*c.key) BOOST_TEST(r.err.find("key '" + std::string(c.key)) != std::string::npos, r.err);
      if (std::string(c.what) != "surface without body") BOOST_TEST(r.err.find(", line ") != std::string::npos, r.err);
      BOOST_TEST(!fs::exists(out));
    }
  }
  // A slave curve inside a body: two squares of one body share the curve "mid".
  const std::string geo = write_temp(dir, "inner.geo", R"(
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Point(5) = {1, 2, 0}; Point(6) = {0, 2, 0};
Point(7) = {0, -1, 0}; Point(8) = {1, -1, 0}; Point(9) = {1, -0.1, 0}; Point(10) = {0, -0.1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {3, 5}; Line(6) = {5, 6}; Line(7) = {6, 4};
Line(8) = {7, 8}; Line(9) = {8, 9}; Line(10) = {9, 10}; Line(11) = {10, 7};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7}; Plane Surface(2) = {2};
Curve Loop(3) = {8, 9, 10, 11}; Plane Surface(3) = {3};
Transfinite Curve{:} = 3; Transfinite Surface{1, 2, 3}; Recombine Surface{1, 2, 3};
Physical Surface("block", 1) = {1, 2};
Physical Surface("base", 2) = {3};
Physical Curve("mid", 11) = {3};
Physical Curve("block_top", 12) = {6};
Physical Curve("base_top", 13) = {10};
Physical Curve("base_bottom", 14) = {8};
)");
  const std::string inner = write_temp(dir, "inner.toml", "[problem]\nname = \"inner\"\nmesh = \"" + geo +
      "\"\n[[parameters]]\nname = \"d\"\nrange = [0.0, 0.1]\n[[bodies]]\ngroup = \"block\"\n[[bodies]]\ngroup = \"base\"\n"
      "[[dirichlet]]\ngroup = \"base_bottom\"\ndisplacement = [0.0, 0.0]\n[[dirichlet]]\ngroup = \"block_top\"\n"
      "displacement = [0.0, \"-d\"]\n[[contact]]\nslave = \"mid\"\nmaster = \"base_top\"\n");
  const auto ri = run_command(kExe + " fom --problem " + inner + " --param 0.05 --out " + dir + "/out");
  BOOST_TEST(ri.exit_code == 2);
  BOOST_TEST(std::count(ri.err.begin(), ri.err.end(), '\n') == 1, ri.err);
  BOOST_TEST(ri.err.find("'mid'") != std::string::npos, ri.err);
  BOOST_TEST(ri.err.find("inside a body") != std::string::npos, ri.err);
  BOOST_TEST(ri.err.find("key 'contact[0].slave'") != std::string::npos, ri.err);
  BOOST_TEST(!fs::exists(dir + "/out"));
  // A parameter outside the file's range.
  const std::string file = write_temp(dir, "good.toml", hertz_text());
  const auto r = run_command(kExe + " fom --problem " + file + " --param 0.31 --out " + dir + "/out");
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(r.err.find("d = '0.31' is outside") != std::string::npos, r.err);
  BOOST_TEST(!fs::exists(dir + "/out"));
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(dirichlet_on_a_physical_point) {
  // hertz with the top body's load face free in x except at one physical point:
  // the same solution as the file that fixes the whole face in x would not hold,
  // but the problem must be well posed and the point's x displacement exactly 0.
  const std::string dir = contactrom::test::temp_dir();
  std::string geo = read_text(kSource + "/meshes/hertz.geo");
  geo += "\nPhysical Point(\"top_corner\", 21) = {12};\n";
  write_temp(dir, "hertz.geo", geo);
  std::string text = hertz_text();
  text = std::regex_replace(text, std::regex(kSource + "/meshes/hertz.geo"), "hertz.geo");
  text = replace_once(text, "displacement = [0.0, \"-d\"]", "displacement = [\"free\", \"-d\"]");
  text += "\n[[dirichlet]]\ngroup = \"top_corner\"\ndisplacement = [0.0, \"free\"]\n";
  const auto p = fom::make_problem(write_temp(dir, "point.toml", text));
  const auto& corner = p->mesh()->group_nodes("top_corner");
  BOOST_TEST_REQUIRE(corner.size() == 1u);
  const auto s = solve(*p, fom::Param::Constant(1, 0.1));
  BOOST_TEST(s.status == Status::Success);
  BOOST_TEST(s.u(2 * corner[0]) == 0.0);
  BOOST_TEST(p->is_dirichlet()[2 * corner[0]] == 1);
  BOOST_TEST(fom::kkt_residuals(*p, fom::Param::Constant(1, 0.1), s.u, s.lambda).stationarity <= 1e-10);
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(database_rebuilds_the_problem_without_its_files) {
  // offline on a copy of the problem file and mesh; delete both; online still runs.
  const std::string dir = contactrom::test::temp_dir();
  fs::copy_file(kSource + "/meshes/ironing.geo", dir + "/ironing.geo");
  std::string text = read_text(kSource + "/problems/ironing.toml");
  text = replace_once(text, "../meshes/ironing.geo", "ironing.geo");
  const std::string file = write_temp(dir, "my_ironing.toml", text);
  auto r = run_command(kExe + " offline --problem " + file + " --level 2 --threads 2 --out " + dir + "/db.h5");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  fs::remove(file);
  fs::remove(dir + "/ironing.geo");
  r = run_command(kExe + " online --db " + dir + "/db.h5 --method greedy --param 1.3 --json");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const auto j = nlohmann::json::parse(r.out);
  BOOST_TEST(j["problem"] == "ironing");
  fs::remove_all(dir);
}
