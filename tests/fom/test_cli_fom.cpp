// CLI tests of `contactrom fom`: JSON contract, field files, and bad input
// (one-line error naming the value, non-zero exit, no partial files).
#define BOOST_TEST_MODULE fom_cli
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <sstream>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "common/run_command.hpp"

using contactrom::test::run_command;
namespace fs = std::filesystem;

namespace {
const std::string exe = CONTACTROM_EXE;
int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }
}  // namespace

BOOST_AUTO_TEST_CASE(json_summary_has_contract_keys) {
  const auto r = run_command(exe + " fom --problem hertz --param 0.1 --json");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"problem", "param", "solver", "iterations", "active", "time_s", "kkt"})
    BOOST_TEST(j.contains(key), key);
  for (const char* key : {"stationarity", "penetration", "negative_pressure", "complementarity"})
    BOOST_TEST(j["kkt"][key].get<double>() <= 1e-10, key);
  BOOST_TEST(j["problem"] == "hertz");
  BOOST_TEST(j["active"].get<int>() > 0);
}

BOOST_AUTO_TEST_CASE(peak_pressure_and_contact_length_follow_hertz_theory) {
  // hertz (two cylinders of radius 0.5, E = 1, ν = 0.3, plane strain): from the FOM's
  // force P, Hertz's half-width a = sqrt(4PR/(πE*)) and peak p0 = 2P/(πa). The
  // printed peak pressure is the nodal maximum (within 5 % of p0 here) and the contact
  // length the active nodes' tributary lengths (2a to within 10 %: one node spacing),
  // from either solver (Ipopt's multipliers are never exactly zero).
  for (const char* solver : {"active-set", "ipopt"})
  for (const double d : {0.05, 0.1, 0.2}) {
    const auto r = run_command(exe + " fom --problem hertz --param " + std::to_string(d) + " --solver " + solver +
                               " --json");
    BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
    const auto j = nlohmann::json::parse(r.out);
    const double force = j["contact_force"].get<double>(), e_star = 1.0 / (2.0 * (1.0 - 0.3 * 0.3));
    const double a = std::sqrt(4.0 * force * 0.5 / (M_PI * e_star)), p0 = 2.0 * force / (M_PI * a);
    BOOST_TEST_CONTEXT(solver << ", d = " << d) {
      BOOST_TEST(std::abs(j["peak_pressure"].get<double>() / p0 - 1.0) < 0.05);
      BOOST_TEST(std::abs(j["contact_length"].get<double>() / (2.0 * a) - 1.0) < 0.10);
      BOOST_TEST(!j.contains("contact_area"));
    }
  }
  const auto r = run_command(exe + " fom --problem hertz --param 0.1");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  BOOST_TEST(r.out.find("peak pressure") != std::string::npos, r.out);
  BOOST_TEST(r.out.find("consistent units") != std::string::npos, r.out);
}

BOOST_AUTO_TEST_CASE(out_writes_vtu_and_surface_csv) {
  const std::string dir = contactrom::test::temp_dir() + "/fields";
  const auto r = run_command(exe + " fom --problem ironing --param 2 --json --out " + dir);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const int rows = nlohmann::json::parse(r.out)["constraints"].get<int>();
  const std::string vtu = contactrom::test::slurp(dir + "/ironing.vtu");
  BOOST_TEST(vtu.find("<VTKFile type=\"UnstructuredGrid\"") != std::string::npos);
  BOOST_TEST(vtu.find("Name=\"contact_pressure\"") != std::string::npos);
  BOOST_TEST(vtu.find("Name=\"stress\"") != std::string::npos);
  const std::string csv = contactrom::test::slurp(dir + "/ironing_surface.csv");
  BOOST_TEST(csv.rfind("x,y,gap,pressure,u_x,u_y\n", 0) == 0);
  BOOST_TEST(lines(csv) == 1 + rows);  // header + one row per slave node
  BOOST_TEST(rows > 20);
  fs::remove_all(fs::path(dir).parent_path());
}

BOOST_AUTO_TEST_CASE(rope_surface_csv_has_reference_coordinates_and_transverse_deflection) {
  // The rope lies on y = 0; its deflection is u_y, and where the pressure is positive
  // the rope rests on the obstacle psi(x) = -0.2 (sin(pi x) - sin(3 pi x)) - 0.5.
  const std::string dir = contactrom::test::temp_dir() + "/rope";
  const auto r = run_command(exe + " fom --problem rope --param 20 --out " + dir);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  std::istringstream csv(contactrom::test::slurp(dir + "/rope_surface.csv"));
  std::string line;
  std::getline(csv, line);
  BOOST_TEST(line == "x,y,gap,pressure,u_x,u_y");
  int in_contact = 0;
  while (std::getline(csv, line)) {
    double x, y, gap, p, ux, uy;
    char c;
    std::istringstream row(line);
    row >> x >> c >> y >> c >> gap >> c >> p >> c >> ux >> c >> uy;
    BOOST_TEST_REQUIRE(!row.fail(), line);
    BOOST_TEST(y == 0.0);
    BOOST_TEST(ux == 0.0);
    if (p > 0.0) {
      ++in_contact;
      const double pi = std::acos(-1.0);
      BOOST_TEST(std::abs(uy - (-0.2 * (std::sin(pi * x) - std::sin(3 * pi * x)) - 0.5)) <= 1e-9, line);
    }
  }
  BOOST_TEST(in_contact > 10);
  const std::string vtu = contactrom::test::slurp(dir + "/rope.vtu");
  BOOST_TEST(vtu.find("Name=\"displacement\"") != std::string::npos);
  fs::remove_all(fs::path(dir).parent_path());
}

BOOST_AUTO_TEST_CASE(unknown_problem_is_one_line_error) {
  const auto r = run_command(exe + " fom --problem cylinder --param 0.1");
  BOOST_TEST(r.exit_code != 0);
  BOOST_TEST(lines(r.err) == 1);
  BOOST_TEST(r.err.find("cylinder") != std::string::npos);
  BOOST_TEST(r.err.find("hertz") != std::string::npos);  // lists what is expected
}

BOOST_AUTO_TEST_CASE(parameter_out_of_range_names_value_and_range) {
  const std::string dir = contactrom::test::temp_dir();
  const auto r = run_command(exe + " fom --problem hertz --param 0.5 --out " + dir + "/out");
  BOOST_TEST(r.exit_code != 0);
  BOOST_TEST(lines(r.err) == 1);
  BOOST_TEST(r.err.find("0.5") != std::string::npos);
  BOOST_TEST(r.err.find("(0, 0.3]") != std::string::npos);
  BOOST_TEST(!fs::exists(dir + "/out"));  // no partial output
  const auto r2 = run_command(exe + " fom --problem ironing2 --param 1");
  BOOST_TEST(r2.exit_code != 0);
  BOOST_TEST(r2.err.find("2 parameter") != std::string::npos);
  const auto r3 = run_command(exe + " fom --problem rope --param twelve");
  BOOST_TEST(r3.exit_code != 0);
  BOOST_TEST(r3.err.find("twelve") != std::string::npos);
  fs::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(missing_and_malformed_mesh_are_reported) {
  // A copy of hertz.toml whose mesh, hertz.geo next to it, is missing and then malformed.
  const std::string dir = contactrom::test::temp_dir();
  std::string text = contactrom::test::slurp(std::string(CONTACTROM_SOURCE_DIR) + "/problems/hertz.toml");
  text.replace(text.find("../meshes/hertz.geo"), std::string("../meshes/hertz.geo").size(), "hertz.geo");
  std::ofstream(dir + "/hertz.toml") << text;
  const std::string problem = " fom --problem " + dir + "/hertz.toml";
  auto r = run_command(exe + problem + " --param 0.1 --out " + dir + "/o");
  BOOST_TEST(r.exit_code != 0);
  BOOST_TEST(lines(r.err) == 1);
  BOOST_TEST(r.err.find("hertz.geo") != std::string::npos);
  {
    std::ofstream bad(dir + "/hertz.geo");
    bad << "this is not a gmsh file {{{\n";
  }
  r = run_command(exe + problem + " --param 0.1 --out " + dir + "/o");
  BOOST_TEST(r.exit_code != 0);
  BOOST_TEST(lines(r.err) == 1);
  BOOST_TEST(r.err.find("hertz.geo") != std::string::npos);
  BOOST_TEST(!fs::exists(dir + "/o"));
  fs::remove_all(dir);
}
