// CPG baseline (baselines/cpg.hpp): the cone-projected greedy selection on synthetic
// dictionaries with a known answer (a cone spanned by a known subset), its stopping
// rule, edge cases and option parsing; then the CPG online solver on hertz 12
// (non-negative basis of snapshots, reduced-level KKT, registry).
#define BOOST_TEST_MODULE baselines_cpg
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>
#include <set>

#include <contactrom/baselines/cpg.hpp>
#include <contactrom/baselines/reduced_active_set.hpp>
#include <contactrom/core/nnls.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>

using namespace contactrom;
using baselines::cone_projected_greedy;
using baselines::cone_projection_errors;
using baselines::CpgBasis;
using baselines::CpgOptions;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// A synthetic pressure dictionary whose cone is spanned by `k` generators with
/// disjoint supports; the other columns are combinations of ALL generators with
/// coefficients in [0.05, 0.4] (so every combination is strictly inside the cone and
/// shorter than the longest generator). Columns are shuffled.
struct SyntheticCone {
  MatrixXd snapshots;
  VectorXd weights;
  std::set<int> generators;  // column indices of the generators
};

SyntheticCone synthetic_cone(int rows, int k, int combinations, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> value(0.2, 1.0), coef(0.05, 0.4), weight(0.5, 1.5);
  MatrixXd g = MatrixXd::Zero(rows, k);
  const int block = rows / k;
  for (int i = 0; i < k; ++i)
    for (int s = i * block; s < (i + 1) * block; ++s) g(s, i) = value(gen);
  const int m = k + combinations;
  MatrixXd all(rows, m);
  all.leftCols(k) = g;
  for (int j = 0; j < combinations; ++j) {
    VectorXd a(k);
    for (int i = 0; i < k; ++i) a(i) = coef(gen);
    all.col(k + j) = g * a;
  }
  std::vector<int> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), gen);
  SyntheticCone out;
  out.snapshots.resize(rows, m);
  for (int j = 0; j < m; ++j) {
    out.snapshots.col(j) = all.col(order[j]);
    if (order[j] < k) out.generators.insert(j);
  }
  out.weights.resize(rows);
  for (int s = 0; s < rows; ++s) out.weights(s) = weight(gen);
  return out;
}

/// Hertz-like pressure bumps λ_j(x) = sqrt(max(0, a_j² − (x − c_j)²)) of varying
/// width and centre: a non-negative dictionary without an exact low-dimensional cone.
MatrixXd bump_dictionary(int rows, int m, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> width(0.05, 0.4), centre(-0.3, 0.3), height(0.5, 2.0);
  MatrixXd d(rows, m);
  for (int j = 0; j < m; ++j) {
    const double a = width(gen), c = centre(gen), h = height(gen);
    for (int s = 0; s < rows; ++s) {
      const double x = -1.0 + 2.0 * s / (rows - 1);
      d(s, j) = h * std::sqrt(std::max(0.0, a * a - (x - c) * (x - c)));
    }
  }
  return d;
}

/// Independent cone-projection error of column j on the columns `basis`, with the
/// matrix-form NNLS on explicitly weighted columns.
double reference_error(const MatrixXd& d, const VectorXd& w, const std::vector<int>& basis, int j) {
  const VectorXd sw = w.cwiseSqrt();
  MatrixXd a(d.rows(), static_cast<Eigen::Index>(basis.size()));
  for (size_t i = 0; i < basis.size(); ++i) a.col(static_cast<Eigen::Index>(i)) = sw.asDiagonal() * d.col(basis[i]);
  const VectorXd b = sw.asDiagonal() * d.col(j);
  if (basis.empty()) return b.norm() > 0 ? 1.0 : 0.0;
  Nnls nnls;
  nnls.compute(a);
  const VectorXd x = nnls.solve(b);
  return (b - a * x).norm() / b.norm();
}

}  // namespace

BOOST_AUTO_TEST_CASE(default_tolerances_follow_the_paper) {
  // The shipped problem files carry the paper's tolerances; rope has none (1e-2).
  BOOST_TEST(baselines::default_cpg_tolerance(*fom::make_problem("hertz")) == 1e-2);
  BOOST_TEST(baselines::default_cpg_tolerance(*fom::make_problem("ironing")) == 5e-2);
  BOOST_TEST(baselines::default_cpg_tolerance(*fom::make_problem("ironing2")) == 5e-2);
  BOOST_TEST(baselines::default_cpg_tolerance(*fom::make_problem("rope")) == 1e-2);
}

BOOST_AUTO_TEST_CASE(synthetic_cone_selects_exactly_its_generators) {
  for (unsigned seed : {1u, 2u, 3u}) {
    for (double tol : {1e-2, 1e-10}) {
      const SyntheticCone cone = synthetic_cone(60, 6, 30, seed);
      CpgOptions options;
      options.tolerance = tol;
      const CpgBasis basis = cone_projected_greedy(cone.snapshots, cone.weights, options);
      BOOST_TEST(basis.status == Status::Success);
      BOOST_TEST(basis.columns.size() == cone.generators.size());
      const std::set<int> selected(basis.columns.begin(), basis.columns.end());
      BOOST_TEST((selected == cone.generators));
      // The first vector is the snapshot of largest norm (a generator here).
      Eigen::Index longest = 0;
      (cone.weights.cwiseSqrt().asDiagonal() * cone.snapshots).colwise().norm().maxCoeff(&longest);
      BOOST_TEST(basis.columns.front() == longest);
      // Every snapshot lies in the cone: all projection errors at round-off.
      BOOST_TEST(basis.worst_error() <= 1e-10);
      BOOST_TEST(basis.history.back() <= 1e-10);
      for (int j = 0; j < cone.snapshots.cols(); ++j)
        BOOST_TEST(reference_error(cone.snapshots, cone.weights, basis.columns, j) <= 1e-10);
    }
  }
}

BOOST_AUTO_TEST_CASE(greedy_stops_at_the_tolerance) {
  const MatrixXd d = bump_dictionary(80, 40, 7);
  const VectorXd w = VectorXd::Constant(80, 2.0 / 79);
  for (double tol : {0.2, 0.05, 0.01}) {
    CpgOptions options;
    options.tolerance = tol;
    const CpgBasis basis = cone_projected_greedy(d, w, options);
    BOOST_TEST_MESSAGE("tolerance " << tol << ": " << basis.columns.size() << " vectors, worst error "
                                    << basis.worst_error());
    BOOST_TEST(basis.status == Status::Success);
    BOOST_REQUIRE(basis.columns.size() >= 2u);
    BOOST_REQUIRE(basis.history.size() == basis.columns.size());
    // After the last addition the worst error of the unselected snapshots is within
    // the tolerance; before it, it was not.
    BOOST_TEST(basis.history.back() <= tol);
    BOOST_TEST(basis.history[basis.history.size() - 2] > tol);
    std::vector<int> before(basis.columns.begin(), basis.columns.end() - 1);
    double worst_before = 0.0, worst_after = 0.0;
    for (int j = 0; j < d.cols(); ++j) {
      worst_before = std::max(worst_before, reference_error(d, w, before, j));
      worst_after = std::max(worst_after, reference_error(d, w, basis.columns, j));
    }
    BOOST_TEST(worst_before > tol);
    BOOST_TEST(worst_after <= tol);
    BOOST_TEST(std::abs(worst_after - basis.worst_error()) <= 1e-10);
    // The last vector added was the worst approximated snapshot before its addition.
    const VectorXd e_before = cone_projection_errors(d, w, before);
    Eigen::Index worst = 0;
    e_before.maxCoeff(&worst);
    BOOST_TEST(worst == basis.columns.back());
    // Selected vectors are snapshots, hence non-negative; no snapshot twice.
    const std::set<int> distinct(basis.columns.begin(), basis.columns.end());
    BOOST_TEST(distinct.size() == basis.columns.size());
    for (int p : basis.columns) BOOST_TEST(d.col(p).minCoeff() >= 0.0);
  }
}

BOOST_AUTO_TEST_CASE(euclidean_norm_without_weights) {
  const SyntheticCone cone = synthetic_cone(30, 3, 10, 11);
  const CpgBasis basis = cone_projected_greedy(cone.snapshots, VectorXd(), {});
  const std::set<int> selected(basis.columns.begin(), basis.columns.end());
  BOOST_TEST((selected == cone.generators));
  BOOST_TEST(basis.tolerance == 1e-2);  // tolerance < 0 reads as 1e-2
}

BOOST_AUTO_TEST_CASE(edge_cases) {
  // Empty dictionary: empty basis, nothing to approximate.
  CpgBasis empty = cone_projected_greedy(MatrixXd(5, 0), VectorXd::Ones(5), {});
  BOOST_TEST(empty.columns.empty());
  BOOST_TEST(empty.status == Status::Success);
  BOOST_TEST(empty.worst_error() == 0.0);
  // All-zero snapshots (no contact anywhere): never selected, error 0.
  CpgBasis zeros = cone_projected_greedy(MatrixXd::Zero(5, 4), VectorXd::Ones(5), {});
  BOOST_TEST(zeros.columns.empty());
  BOOST_TEST(zeros.worst_error() == 0.0);
  // A zero column among others is never selected.
  MatrixXd d = bump_dictionary(40, 10, 3);
  d.col(4).setZero();
  CpgOptions tight;
  tight.tolerance = 0.0;
  CpgBasis all = cone_projected_greedy(d, VectorXd(), tight);
  BOOST_TEST(std::count(all.columns.begin(), all.columns.end(), 4) == 0);
  BOOST_TEST(all.worst_error() <= 1e-12);
  // Tolerance 1: the largest snapshot alone (every error is ≤ 1).
  CpgOptions loose;
  loose.tolerance = 1.0;
  BOOST_TEST(cone_projected_greedy(d, VectorXd(), loose).columns.size() == 1u);
  // Size cap reached above the tolerance: NoConvergence, basis of the cap's size.
  CpgOptions capped;
  capped.tolerance = 1e-6;
  capped.max_size = 2;
  const CpgBasis c = cone_projected_greedy(d, VectorXd(), capped);
  BOOST_TEST(c.status == Status::NoConvergence);
  BOOST_TEST(c.columns.size() == 2u);
  BOOST_TEST(c.worst_error() > 1e-6);
  // Bad input.
  CpgOptions above;
  above.tolerance = 1.5;
  BOOST_CHECK_THROW(cone_projected_greedy(d, VectorXd(), above), InputError);
  BOOST_CHECK_THROW(cone_projected_greedy(d, VectorXd::Ones(3), {}), InputError);
  BOOST_CHECK_THROW(cone_projected_greedy(d, -VectorXd::Ones(40), {}), InputError);
  BOOST_CHECK_THROW(cone_projection_errors(d, VectorXd(), {10}), InputError);
}

BOOST_AUTO_TEST_CASE(options_from_the_registry_extras) {
  rom::OnlineSolverOptions o;
  BOOST_TEST(baselines::cpg_options(o).tolerance < 0.0);  // problem default
  o.extra["cpg_tolerance"] = "0.05";
  o.extra["cpg_max_size"] = "7";
  const CpgOptions c = baselines::cpg_options(o);
  BOOST_TEST(c.tolerance == 0.05);
  BOOST_TEST(c.max_size == 7);
  o.extra["cpg_tolerance"] = "-1";  // the documented default: the problem's tolerance
  BOOST_TEST(baselines::cpg_options(o).tolerance < 0.0);
  for (const char* bad : {"abc", "", "2", "nan"}) {
    rom::OnlineSolverOptions b;
    b.extra["cpg_tolerance"] = bad;
    BOOST_CHECK_THROW(baselines::cpg_options(b), InputError);
  }
  rom::OnlineSolverOptions b;
  b.extra["cpg_max_size"] = "2.5";
  BOOST_CHECK_THROW(baselines::cpg_options(b), InputError);
  rom::OnlineSolverOptions inner;
  inner.extra["inner_solve"] = "sideways";
  BOOST_CHECK_THROW(baselines::reduced_active_set_options(inner), InputError);
}

BOOST_AUTO_TEST_CASE(ironing_level7_basis_needs_many_vectors) {
  // With the pressure on the slab every snapshot has its own support: the cone of
  // the 129 level-7 snapshots needs at least 30 of them at tolerance 5e-2.
  const auto problem = fom::make_problem("ironing");
  rom::OfflineOptions offline;
  offline.threads = 2;
  const rom::SnapshotDatabase db = rom::generate_snapshots(*problem, 7, offline);
  const rom::ReducedModel model(*problem, db);
  const baselines::CpgActiveSet cpg(model);
  BOOST_TEST_MESSAGE("ironing level 7: CPG basis of " << cpg.basis().columns.size() << " vectors");
  BOOST_TEST(cpg.basis().tolerance == 5e-2);
  BOOST_TEST(cpg.basis().columns.size() >= 30u);
}

BOOST_AUTO_TEST_CASE(hertz_basis_and_online_solver) {
  const auto problem = fom::make_problem("hertz");
  rom::OfflineOptions offline;
  offline.threads = 2;
  const rom::SnapshotDatabase db = rom::generate_snapshots(*problem, 30, offline);
  const rom::ReducedModel model(*problem, db);
  const baselines::CpgActiveSet cpg(model);
  const CpgBasis& basis = cpg.basis();
  BOOST_TEST_MESSAGE("hertz 30: CPG basis of " << basis.columns.size() << " of " << model.dictionary_size()
                                               << " snapshots, worst error " << basis.worst_error());
  BOOST_TEST(basis.tolerance == 1e-2);
  BOOST_TEST(basis.status == Status::Success);
  BOOST_TEST(basis.worst_error() <= 1e-2);
  BOOST_TEST(basis.columns.size() < static_cast<size_t>(model.dictionary_size()));
  BOOST_TEST((cpg.dual_columns() == basis.columns));
  // The basis vectors are pressure snapshots: non-negative columns of the dictionary.
  for (Eigen::Index i = 0; i < cpg.dual_basis().cols(); ++i) {
    BOOST_TEST(cpg.dual_basis().col(i).minCoeff() >= 0.0);
    BOOST_TEST(cpg.dual_basis().col(i) == model.dictionary().col(basis.columns[i]));
  }
  // Online: converged, λ̂ ≥ 0, reduced constraint Wᵀ(Cu − g) ≤ τ at the returned u.
  // validation[0], d = 0.00375, lies far below the smallest training load (0.01):
  // its answer (a pressure error of 0.5) converges and is flagged inaccurate.
  const std::vector<fom::Param> validation = fom::validation_set(*problem, 30);
  for (size_t i = 0; i < validation.size(); i += 12) {
    const rom::OnlineResult res = cpg.solve(validation[i]);
    BOOST_TEST(res.converged);
    BOOST_TEST(res.status == (i == 0 ? Status::Inaccurate : Status::Success), "d = " << validation[i](0));
    BOOST_TEST(!res.selected.empty());
    BOOST_TEST(res.coefficients.minCoeff() > 0.0);
    BOOST_TEST(res.lambda.minCoeff() >= 0.0);
    for (int p : res.selected) BOOST_TEST(std::count(basis.columns.begin(), basis.columns.end(), p) == 1);
    BOOST_TEST(baselines::reduced_penetration(model, cpg.dual_columns(), res.u) <= cpg.threshold() + 1e-10);
  }
  // Registry: "cpg" with an explicit tolerance.
  rom::OnlineSolverOptions options;
  options.extra["cpg_tolerance"] = "0.05";
  const auto solver = rom::make_online_solver("cpg", model, options);
  BOOST_TEST(solver->name() == "cpg");
  const auto* typed = dynamic_cast<const baselines::CpgActiveSet*>(solver.get());
  BOOST_REQUIRE(typed);
  BOOST_TEST(typed->basis().tolerance == 0.05);
  BOOST_TEST(typed->basis().columns.size() <= basis.columns.size());

  // time_operators only reads the clock: the same result, with the share of the
  // contact-operator construction in [0, time_s] (−1 when not measured).
  rom::OnlineSolverOptions timed_options;
  timed_options.time_operators = true;
  const auto timed = rom::make_online_solver("cpg", model, timed_options);
  const auto plain = rom::make_online_solver("cpg", model);
  for (size_t i = 5; i < validation.size(); i += 40) {
    const rom::OnlineResult a = plain->solve(validation[i]), b = timed->solve(validation[i]);
    BOOST_TEST(a.operator_time_s == -1.0);
    BOOST_TEST(b.operator_time_s >= 0.0);
    BOOST_TEST(b.operator_time_s <= b.time_s);
    BOOST_TEST(a.iterations == b.iterations);
    BOOST_TEST((a.selected == b.selected));
    BOOST_TEST((a.u_hat - b.u_hat).norm() == 0.0);
  }

  // Warm starts: from the interpolated training coordinates (init=primal) or from
  // CPG's own solutions at the training parameters around μ (init=cell, their û
  // interpolated and their active sets joined). On every validation query both
  // converge to the cold start's solution — for a fixed pairing the reduced QP on the
  // CPG cone has one minimiser, so they agree to the resolution of the fixed point's
  // stop (each stops once the contact surface moved by ≤ 1e-3 U between the point
  // where the operators were built and û; measured up to 3e-4 apart: 1e-3) — and
  // init=cell needs fewer solves than the cold start.
  for (const char* init : {"primal", "cell"}) {
    rom::OnlineSolverOptions warm_options;
    warm_options.extra["init"] = init;
    const auto warm = rom::make_online_solver("cpg", model, warm_options);
    double cold_iterations = 0.0, warm_iterations = 0.0;
    for (const fom::Param& mu : validation) {
      const rom::OnlineResult a = plain->solve(mu), b = warm->solve(mu);
      BOOST_TEST_CONTEXT("init " << init << ", d = " << mu(0)) {
        BOOST_REQUIRE(b.converged);
        BOOST_TEST(b.coefficients.minCoeff() > 0.0);
        BOOST_TEST((b.u_hat - a.u_hat).norm() <= 1e-3 * a.u_hat.norm());
        BOOST_TEST(baselines::reduced_penetration(model, cpg.dual_columns(), b.u) <= cpg.threshold() + 1e-10);
      }
      cold_iterations += a.iterations;
      warm_iterations += b.iterations;
    }
    BOOST_TEST_MESSAGE("CPG mean solves: cold " << cold_iterations / validation.size() << ", init=" << init << " "
                                                << warm_iterations / validation.size());
    if (std::string(init) == "cell") BOOST_TEST(warm_iterations < cold_iterations);
    // The partial rebuild (its first search, warm-started, seeded by the search
    // made offline at the nearest training snapshot) against searching every row in
    // full: the same operators, hence bitwise the same answer.
    warm_options.extra["rebuild"] = "full";
    const auto searched = rom::make_online_solver("cpg", model, warm_options);
    for (size_t i = 0; i < validation.size(); i += 3) {
      const rom::OnlineResult a = warm->solve(validation[i]), b = searched->solve(validation[i]);
      BOOST_TEST_CONTEXT("init " << init << ", rebuild=full, d = " << validation[i](0)) {
        BOOST_TEST(a.iterations == b.iterations);
        BOOST_TEST((a.selected == b.selected));
        BOOST_TEST((a.u_hat - b.u_hat).norm() == 0.0);
      }
    }
  }
  // At a training parameter init=cell starts from the solution there: a solve or two
  // confirm it (the stored solution is itself converged only to the stop's resolution).
  {
    rom::OnlineSolverOptions warm_options;
    warm_options.extra["init"] = "cell";
    const auto warm = rom::make_online_solver("cpg", model, warm_options);
    for (int c = 0; c < model.dictionary_size(); c += 7) {
      const fom::Param& mu = model.dictionary_parameters()[static_cast<size_t>(c)];
      const rom::OnlineResult a = plain->solve(mu), b = warm->solve(mu);
      BOOST_TEST(b.converged);
      BOOST_TEST(b.iterations <= 3, "column " << c << ": " << b.iterations << " solves");
      BOOST_TEST((b.u_hat - a.u_hat).norm() <= 1e-3 * a.u_hat.norm(), "column " << c);
    }
  }
  // init=nearest (a greedy setting) and nonsense are refused.
  for (const char* bad : {"nearest", "lukewarm"}) {
    rom::OnlineSolverOptions o;
    o.extra["init"] = bad;
    try {
      rom::make_online_solver("cpg", model, o);
      BOOST_ERROR("init=" << bad << " accepted");
    } catch (const InputError& e) {
      BOOST_TEST(std::string(e.what()).find(std::string("'") + bad + "'") != std::string::npos, e.what());
      BOOST_TEST(std::string(e.what()).find("expected empty, primal or cell") != std::string::npos, e.what());
    }
  }
}
