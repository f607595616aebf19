// The shipped 3D problem hertz3d (a sphere on a block, quarter model with symmetry
// planes): KKT residuals of the active-set FOM, the contact radius and peak
// pressure of the Hertz theory (from the computed contact force), the same force
// with slave and master swapped, and the active-set solution equal to Ipopt's on a
// coarser mesh of the same geometry.
#define BOOST_TEST_MODULE baselines_hertz3d
#include <unistd.h>

#include <boost/test/unit_test.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <contactrom/baselines/ipopt_qp.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>

using namespace contactrom;
using namespace contactrom::fom;

namespace {

const std::string kSource = CONTACTROM_SOURCE_DIR;

/// Text files in a fresh temporary folder, removed at scope exit.
struct TempDir {
  std::filesystem::path dir;
  TempDir() {
    dir = std::filesystem::temp_directory_path() / ("contactrom_test_hertz3d_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
  }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  BOOST_REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

/// The shipped problem file with its mesh path made absolute (and optionally edited).
std::string shipped_text() {
  return replaced(read_text(kSource + "/problems/hertz3d.toml"), "\"../meshes/hertz3d.geo\"",
                  "\"" + kSource + "/meshes/hertz3d.geo\"");
}

struct HertzFit {
  double a = 0.0, p0 = 0.0;  // fitted contact radius and peak pressure
};

/// Least-squares fit of the Hertz profile p² = p0² (1 − r²/a²) to the pressures of
/// the rows in contact (r: distance of the slave node from the axis).
HertzFit fit_profile(const Problem& problem, const Eigen::VectorXd& lambda) {
  const Eigen::MatrixXd& x = problem.contact().constraint_points();
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int k = 0; k < lambda.size(); ++k) {
    if (!(lambda(k) > 0)) continue;
    const double r2 = x(0, k) * x(0, k) + x(1, k) * x(1, k), p2 = lambda(k) * lambda(k);
    n += 1, sx += r2, sy += p2, sxx += r2 * r2, sxy += r2 * p2;
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx), intercept = (sy - slope * sx) / n;
  return {std::sqrt(-intercept / slope), std::sqrt(intercept)};
}

}  // namespace

// Hertz (sphere of radius R on a half-space, E* = E / (2(1 − ν²)) for two equal
// bodies): for the total force F (four quarters), a = (3FR / 4E*)^{1/3} and
// p0 = 3F / (2πa²).
BOOST_AUTO_TEST_CASE(contact_radius_and_peak_pressure_follow_hertz_theory) {
  const auto problem = make_problem(kSource + "/problems/hertz3d.toml");
  BOOST_TEST(problem->dofs_per_node() == 3);
  const ActiveSetSolver solver(*problem);
  const double e_star = 1.0 / (2.0 * (1.0 - 0.3 * 0.3)), radius = 1.0;
  for (double d : {0.01, 0.02}) {
    Param mu(1);
    mu << d;
    const FomSolution s = solver.solve(mu);
    BOOST_REQUIRE(s.status == Status::Success);
    BOOST_TEST(kkt_residuals(*problem, mu, s.u, s.lambda).max() <= 1e-10);
    const double force = 4.0 * contact_force(*problem, s.lambda);
    const double a = std::cbrt(3.0 * force * radius / (4.0 * e_star)), p0 = 3.0 * force / (2.0 * M_PI * a * a);
    const HertzFit fit = fit_profile(*problem, s.lambda);
    BOOST_TEST(std::abs(fit.a / a - 1.0) <= 0.03, "d = " << d << ": contact radius " << fit.a << ", Hertz " << a);
    BOOST_TEST(std::abs(fit.p0 / p0 - 1.0) <= 0.03, "d = " << d << ": peak pressure " << fit.p0 << ", Hertz " << p0);
  }
}

// Any slave/master choice: the block's disk as slave, the sphere's cap as master.
BOOST_AUTO_TEST_CASE(swapped_slave_and_master_give_the_same_force) {
  const TempDir tmp;
  std::string swapped = replaced(shipped_text(), "slave = \"sphere_cap\"", "slave = \"block_disk\"");
  swapped = replaced(swapped, "master = \"block_disk\"", "master = \"sphere_cap\"");
  const auto a = make_problem(tmp.write("a.toml", shipped_text())), b = make_problem(tmp.write("b.toml", swapped));
  const ActiveSetSolver sa(*a), sb(*b);
  Param mu(1);
  mu << 0.02;
  const FomSolution ua = sa.solve(mu), ub = sb.solve(mu);
  BOOST_REQUIRE(ua.status == Status::Success);
  BOOST_REQUIRE(ub.status == Status::Success);
  BOOST_TEST(kkt_residuals(*b, mu, ub.u, ub.lambda).max() <= 1e-10);
  const double fa = contact_force(*a, ua.lambda), fb = contact_force(*b, ub.lambda);
  BOOST_TEST(std::abs(fb / fa - 1.0) <= 0.02, "forces " << fa << " and " << fb);
}

// The custom active set and Ipopt solve the same QPs: the same active set and
// pressures to 1e-6 (of the largest) at three approaches, on a coarse mesh of the
// same geometry (hmin and alpha overridden before including the shipped .geo).
BOOST_AUTO_TEST_CASE(active_set_equals_ipopt_on_a_coarse_mesh) {
  const TempDir tmp;
  const std::string geo = tmp.write("coarse.geo", "hmin = 0.04;\nalpha = 0.25;\nInclude \"" + kSource +
                                                      "/meshes/hertz3d.geo\";\n");
  const auto problem =
      make_problem(tmp.write("coarse.toml", replaced(shipped_text(), "\"" + kSource + "/meshes/hertz3d.geo\"",
                                                     "\"" + geo + "\"")));
  const ActiveSetSolver active_set(*problem);
  const baselines::IpoptQpSolver ipopt(*problem);
  for (double d : {0.01, 0.03, 0.05}) {
    Param mu(1);
    mu << d;
    const FomSolution s = active_set.solve(mu), r = ipopt.solve(mu);
    BOOST_REQUIRE(s.status == Status::Success);
    BOOST_REQUIRE(r.status == Status::Success);
    BOOST_TEST(kkt_residuals(*problem, mu, s.u, s.lambda).max() <= 1e-10);
    const double scale = s.lambda.cwiseAbs().maxCoeff();
    BOOST_TEST(scale > 0.0);
    BOOST_TEST((s.lambda - r.lambda).cwiseAbs().maxCoeff() <= 1e-6 * scale, "d = " << d);
    for (int k = 0; k < s.lambda.size(); ++k)
      BOOST_TEST(((s.lambda(k) > 1e-6 * scale) == (r.lambda(k) > 1e-6 * scale)), "d = " << d << " row " << k);
  }
}
