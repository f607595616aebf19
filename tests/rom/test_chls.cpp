// Tests of rom/chls.hpp and `contactrom chls`: exact least squares on the
// probability simplex (closed-form distances to segments and simplices, interior
// points recovered exactly, KKT conditions on random data, edge cases), the
// leave-one-out CHLS test on synthetic snapshots (convex combinations of other
// snapshots have zero error, a point off the hull has its known distance), and the
// CLI (JSON keys, CSV, bad input).
#define BOOST_TEST_MODULE rom_chls
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "common/random_problems.hpp"
#include "common/run_command.hpp"
#include <contactrom/rom/chls.hpp>

using contactrom::Status;
using contactrom::rom::chls_leave_one_out;
using contactrom::rom::SimplexLeastSquares;
using contactrom::test::gaussian;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// Random matrix with orthonormal columns (rows ≥ cols).
MatrixXd orthonormal(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& gen) {
  Eigen::HouseholderQR<MatrixXd> qr(gaussian(rows, cols, gen));
  return qr.householderQ() * MatrixXd::Identity(rows, cols);
}

void check_on_simplex(const VectorXd& alpha) {
  BOOST_TEST((alpha.array() >= 0.0).all());
  BOOST_TEST(std::abs(alpha.sum() - 1.0) <= 1e-14);
}

const std::string kExe = CONTACTROM_EXE;

}  // namespace

BOOST_AUTO_TEST_CASE(distance_to_a_segment_has_closed_form) {
  // Hull of e1, e2 in R^3 is the segment {(t, 1 − t, 0)}.
  MatrixXd a = MatrixXd::Zero(3, 2);
  a(0, 0) = a(1, 1) = 1.0;
  SimplexLeastSquares ls;
  ls.compute(a);
  // Above the midpoint: distance h, coefficients (1/2, 1/2).
  VectorXd alpha = ls.solve(Eigen::Vector3d(0.5, 0.5, 0.3));
  BOOST_TEST(ls.info() == Status::Success);
  check_on_simplex(alpha);
  BOOST_TEST(std::abs(ls.residual_norm() - 0.3) <= 1e-15);
  BOOST_TEST(std::abs(alpha(0) - 0.5) <= 1e-15);
  // Beyond the vertex e1: the projection is clamped to e1, distance √2.
  alpha = ls.solve(Eigen::Vector3d(2.0, -1.0, 0.0));
  check_on_simplex(alpha);
  BOOST_TEST(alpha(0) == 1.0);
  BOOST_TEST(alpha(1) == 0.0);
  BOOST_TEST(std::abs(ls.residual_norm() - std::sqrt(2.0)) <= 1e-15);
  BOOST_TEST(ls.support().size() == 1u);
}

BOOST_AUTO_TEST_CASE(distance_to_a_rotated_simplex_in_a_tall_space) {
  // Vertices Q e_1..Q e_n of a simplex in R^40 (Q orthonormal, so the QR reduction of
  // tall problems is exercised); the point is the centroid lifted by h along Q e_{n+1}.
  std::mt19937_64 gen(7);
  const int n = 6;
  const double h = 0.3;
  const MatrixXd q = orthonormal(40, n + 1, gen);
  const MatrixXd a = q.leftCols(n);
  const VectorXd b = a * VectorXd::Constant(n, 1.0 / n) + h * q.col(n);
  SimplexLeastSquares ls;
  const VectorXd alpha = ls.compute(a).solve(b);
  BOOST_TEST(ls.info() == Status::Success);
  check_on_simplex(alpha);
  BOOST_TEST(std::abs(ls.residual_norm() - h) <= 1e-13);
  BOOST_TEST((alpha.array() - 1.0 / n).abs().maxCoeff() <= 1e-12);
}

BOOST_AUTO_TEST_CASE(interior_points_are_recovered_exactly) {
  std::mt19937_64 gen(11);
  const MatrixXd a = gaussian(30, 8, gen);  // affinely independent columns
  VectorXd truth = VectorXd::Zero(8);
  truth(1) = 0.2, truth(4) = 0.5, truth(6) = 0.3;
  SimplexLeastSquares ls;
  const VectorXd alpha = ls.compute(a).solve(a * truth);
  BOOST_TEST(ls.info() == Status::Success);
  check_on_simplex(alpha);
  BOOST_TEST(ls.residual_norm() / (a * truth).norm() <= 1e-13);
  BOOST_TEST((alpha - truth).cwiseAbs().maxCoeff() <= 1e-12);
}

BOOST_AUTO_TEST_CASE(random_problems_satisfy_the_kkt_conditions) {
  // KKT of min ½‖Aα − b‖² on the simplex: with w = Aᵀ(b − Aα), w_j is the same value
  // ν on the support and w_j ≤ ν elsewhere.
  std::mt19937_64 gen(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Index rows = 5 + trial % 7, cols = 3 + (trial * 5) % 17;
    const MatrixXd a = gaussian(rows, cols, gen);
    const VectorXd b = gaussian(rows, 1, gen) * 2.0;
    SimplexLeastSquares ls;
    const VectorXd alpha = ls.compute(a).solve(b);
    BOOST_TEST(ls.info() == Status::Success);
    check_on_simplex(alpha);
    const VectorXd w = a.transpose() * (b - a * alpha);
    const double scale = a.colwise().norm().maxCoeff() * std::max(b.norm(), (a * alpha).norm());
    double nu = 0.0;
    for (auto j : ls.support()) nu += w(j) / static_cast<double>(ls.support().size());
    for (Eigen::Index j = 0; j < cols; ++j) {
      if (alpha(j) > 0.0)
        BOOST_TEST(std::abs(w(j) - nu) <= 1e-10 * scale);
      else
        BOOST_TEST(w(j) - nu <= 1e-10 * scale);
    }
    // No vertex does better than the solution.
    for (Eigen::Index j = 0; j < cols; ++j) BOOST_TEST(ls.residual_norm() <= (a.col(j) - b).norm() + 1e-12);
  }
}

BOOST_AUTO_TEST_CASE(a_cap_stops_the_run_only_where_it_is_reached) {
  // Same loop as NNLS (core/lawson_hanson.hpp): a cap at or above the changes the
  // run needs leaves it untouched; a lower one stops at a point of the simplex.
  std::mt19937_64 gen(23);
  const MatrixXd a = gaussian(12, 30, gen);
  const VectorXd b = gaussian(12, 1, gen);
  SimplexLeastSquares uncapped;
  const VectorXd alpha = uncapped.compute(a).solve(b);
  BOOST_REQUIRE((uncapped.info() == Status::Success));
  const int needed = uncapped.iterations();
  BOOST_REQUIRE(needed > 3);
  for (int cap = 1; cap <= needed + 2; ++cap) {
    contactrom::rom::SimplexLeastSquaresOptions options;
    options.max_iterations = cap;
    SimplexLeastSquares capped(options);
    const VectorXd beta = capped.compute(a).solve(b);
    BOOST_TEST_CONTEXT("cap " << cap) {
      BOOST_TEST(beta.minCoeff() >= 0.0);
      BOOST_TEST(beta.sum() == 1.0, boost::test_tools::tolerance(1e-14));
      if (cap >= needed) {
        BOOST_TEST((capped.info() == Status::Success));
        BOOST_TEST((beta - alpha).norm() == 0.0);
      } else {
        BOOST_TEST((capped.info() == Status::NoConvergence));
        BOOST_TEST(capped.residual_norm() >= uncapped.residual_norm());
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(edge_cases) {
  SimplexLeastSquares ls;
  // One column: α = 1.
  const VectorXd one = ls.compute(Eigen::Vector3d(1.0, 2.0, 3.0)).solve(Eigen::Vector3d(0.0, 0.0, 0.0));
  BOOST_TEST(one.size() == 1);
  BOOST_TEST(one(0) == 1.0);
  BOOST_TEST(std::abs(ls.residual_norm() - std::sqrt(14.0)) <= 1e-14);
  // Duplicated columns (rank-deficient): the distance is still exact.
  MatrixXd dup(2, 3);
  dup << 1.0, 1.0, 0.0, 0.0, 0.0, 1.0;
  const VectorXd alpha = ls.compute(dup).solve(Eigen::Vector2d(1.0, 1.0));
  check_on_simplex(alpha);
  BOOST_TEST(std::abs(ls.residual_norm() - std::sqrt(0.5)) <= 1e-14);
  // Invalid input.
  ls.compute(MatrixXd(0, 0));
  BOOST_TEST(ls.info() == Status::InvalidInput);
  ls.compute(dup).solve(VectorXd::Zero(5));
  BOOST_TEST(ls.info() == Status::InvalidInput);
  MatrixXd bad = dup;
  bad(0, 0) = std::nan("");
  ls.compute(bad);
  BOOST_TEST(ls.info() == Status::InvalidInput);
}

BOOST_AUTO_TEST_CASE(leave_one_out_on_synthetic_snapshots) {
  // Snapshots in R^50: e1, e2, 0.3 e1 + 0.7 e2 (a convex combination of the first two),
  // p = ½(e1 + e2) + h e3 (off the hull by h), all rotated by an orthonormal Q.
  std::mt19937_64 gen(5);
  const double h = 0.25;
  const MatrixXd q = orthonormal(50, 3, gen);
  MatrixXd s(50, 4);
  s.col(0) = q.col(0);
  s.col(1) = q.col(1);
  s.col(2) = 0.3 * q.col(0) + 0.7 * q.col(1);
  s.col(3) = 0.5 * (q.col(0) + q.col(1)) + h * q.col(2);
  const auto r = chls_leave_one_out(s);
  BOOST_TEST(r.errors.size() == 4);
  BOOST_TEST(r.errors(2) <= 1e-10);  // inside the hull of the others
  BOOST_TEST(std::abs(r.coefficients(0, 2) - 0.3) <= 1e-12);
  BOOST_TEST(std::abs(r.coefficients(1, 2) - 0.7) <= 1e-12);
  BOOST_TEST(r.coefficients(2, 2) == 0.0);
  const double expected = h / std::sqrt(0.5 + h * h);  // distance h relative to ‖p‖
  BOOST_TEST(std::abs(r.errors(3) - expected) <= 1e-13);
  // e1 is a vertex: its distance to the hull of {e2, 0.3e1 + 0.7e2, p} is positive.
  BOOST_TEST(r.errors(0) > 0.1);
  for (Eigen::Index k = 0; k < 4; ++k) {
    BOOST_TEST(std::abs(r.coefficients.col(k).sum() - 1.0) <= 1e-14);
    BOOST_TEST(r.status[static_cast<std::size_t>(k)] == Status::Success);
  }
  BOOST_TEST(r.max_error == r.errors.maxCoeff());
  BOOST_TEST(std::abs(r.mean_error - r.errors.mean()) <= 1e-16);
}

BOOST_AUTO_TEST_CASE(many_convex_combinations_have_zero_error) {
  // 5 random extreme snapshots and 10 random convex combinations of them: every
  // combination, left out, is still a combination of the extremes.
  std::mt19937_64 gen(9);
  const MatrixXd ext = gaussian(200, 5, gen);
  MatrixXd s(200, 15);
  s.leftCols(5) = ext;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 5; k < 15; ++k) {
    VectorXd w(5);
    for (int i = 0; i < 5; ++i) w(i) = u(gen);
    s.col(k) = ext * (w / w.sum());
  }
  const auto r = chls_leave_one_out(s);
  for (int k = 5; k < 15; ++k) BOOST_TEST(r.errors(k) <= 1e-10);
  for (int k = 0; k < 5; ++k) BOOST_TEST(r.errors(k) > 1e-3);
}

BOOST_AUTO_TEST_CASE(leave_one_out_rejects_bad_input) {
  BOOST_CHECK_THROW(chls_leave_one_out(MatrixXd::Ones(4, 1)), contactrom::InputError);
  MatrixXd bad = MatrixXd::Ones(4, 3);
  bad(1, 1) = std::numeric_limits<double>::infinity();
  BOOST_CHECK_THROW(chls_leave_one_out(bad), contactrom::InputError);
}

BOOST_AUTO_TEST_CASE(cli_chls_rope) {
  namespace fs = std::filesystem;
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/rope.h5", csv = dir + "/chls.csv";
  auto r = contactrom::test::run_command(kExe + " offline --problem rope --out " + db);
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  r = contactrom::test::run_command(kExe + " chls --db " + db + " --out " + csv + " --json");
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  const auto j = nlohmann::json::parse(r.out);
  BOOST_TEST(j["chls_error"].size() == 9u);
  BOOST_TEST(j["max_chls_error"].get<double>() >= j["mean_chls_error"].get<double>());
  BOOST_TEST(j["max_chls_error"].get<double>() < 0.1);  // the convex-subset hypothesis holds for rope
  const std::string text = contactrom::test::slurp(csv);
  BOOST_TEST(text.rfind("gamma,chls_error,", 0) == 0u);
  BOOST_TEST(std::count(text.begin(), text.end(), '\n') == 10);
  // Bad input: one line on stderr, non-zero exit, no output file left.
  r = contactrom::test::run_command(kExe + " chls --db " + dir + "/missing.h5 --out " + dir + "/x.csv");
  BOOST_TEST(r.exit_code != 0);
  BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  BOOST_TEST(r.err.find("missing.h5") != std::string::npos);
  BOOST_TEST(!fs::exists(dir + "/x.csv"));
  r = contactrom::test::run_command(kExe + " chls --db " + db + " --out " + dir + "/no/such/dir/x.csv");
  BOOST_TEST(r.exit_code != 0);
  BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  fs::remove_all(dir);
}
