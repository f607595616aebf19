// Tests of rom/convex_hull.hpp and the convex-hull CLI paths (paper appendix B):
// the monolithic dictionary and the projected operators against full-order
// assembly; rope with δ = 1e-7 reproduces its training set to rounding with
// 1ᵀα = 1, and selects the two training neighbours of every validation γ; the
// randomised projection basis is reproducible for a fixed seed and matches the SVD
// basis when L equals the dictionary rank; hertz runs its pairing fixed point, whose
// results pass the FOM's stopping test (fom::pairing_change) from the result alone;
// ironing is refused with the documented message; registry and option parsing.
#define BOOST_TEST_MODULE rom_convex_hull
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/run_command.hpp"
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/pairing_fixed_point.hpp>
#include <contactrom/rom/convex_hull.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_methods.hpp>

namespace rom = contactrom::rom;
namespace fom = contactrom::fom;
using contactrom::InputError;
using contactrom::Status;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

const std::string kExe = CONTACTROM_EXE;
const std::string kIroningMessage =
    "convex-hull needs a convex, parameter-independent feasible set; problem 'ironing' does not declare one (set "
    "convex_hull = true in its problem file's [rom] table when the pairing changes little over the parameter range)";

/// A problem with its snapshot database and FOM solver, built once per test program.
struct Setup {
  std::unique_ptr<fom::Problem> problem;
  rom::SnapshotDatabase db;
  std::unique_ptr<fom::ActiveSetSolver> fom_solver;
};

const Setup& setup(const std::string& name, int n) {
  static std::map<std::string, std::unique_ptr<Setup>> cache;
  auto& s = cache[name];
  if (!s) {
    s = std::make_unique<Setup>();
    s->problem = fom::make_problem(name);
    rom::OfflineOptions options;
    options.threads = 2;
    s->db = rom::generate_snapshots(*s->problem, n, options);
    s->fom_solver = std::make_unique<fom::ActiveSetSolver>(*s->problem);
  }
  return *s;
}

const Setup& rope() { return setup("rope", 9); }

rom::ReducedModel model_of(const Setup& s, double delta) {
  rom::ReducedModelOptions options;
  options.delta = delta;
  return rom::ReducedModel(*s.problem, s.db, options);
}

/// Database index of the training parameter equal to γ (−1 if none).
int training_index(const Setup& s, double gamma) {
  for (int j = 0; j < s.db.num_snapshots(); ++j)
    if (std::abs(s.db.parameter(j)(0) - gamma) < 1e-12) return j;
  return -1;
}

bool contains(const std::vector<int>& v, int x) { return std::find(v.begin(), v.end(), x) != v.end(); }

}  // namespace

BOOST_AUTO_TEST_CASE(monolithic_dictionary_and_projected_operators) {
  const Setup& s = rope();
  const fom::Problem& p = *s.problem;
  for (auto offset : {rom::OffsetKind::Dirichlet, rom::OffsetKind::Harmonic}) {
    rom::ReducedModelOptions mo;
    mo.delta = 1e-7;
    mo.offset = offset;
    const rom::ReducedModel model(p, s.db, mo);
    const rom::MonolithicDictionary dict(model);
    // Columns: stored snapshots u − u_lift over their pressures, whatever the model's offset.
    BOOST_TEST(dict.size() == 9);
    BOOST_TEST((dict.primal() - s.db.primal).cwiseAbs().maxCoeff() <= 1e-13 * s.db.primal.cwiseAbs().maxCoeff());
    BOOST_TEST((dict.dual() - s.db.dual).cwiseAbs().maxCoeff() == 0.0);
    BOOST_TEST(dict.monolithic().rows() == p.num_dofs() + p.contact().num_constraints());
    // B: orthonormal, zero on Dirichlet dofs, rank of svd(D_p, 1e-7).
    const MatrixXd& b = dict.projection_basis();
    BOOST_TEST(dict.projection_rank() == model.primal_rank());
    BOOST_TEST((b.transpose() * b - MatrixXd::Identity(b.cols(), b.cols())).cwiseAbs().maxCoeff() <= 1e-12);
    for (int i = 0; i < p.num_dofs(); ++i)
      if (p.is_dirichlet()[static_cast<std::size_t>(i)]) BOOST_TEST(b.row(i).norm() == 0.0);
    // Offline pieces against full-order assembly.
    const fom::Param mu = VectorXd::Constant(1, 23.0);
    const MatrixXd k_full = b.transpose() * (p.stiffness(mu) * dict.primal());
    BOOST_TEST((dict.projected_stiffness(mu) - k_full).norm() <= 1e-12 * k_full.norm());
    const VectorXd f_full = b.transpose() * p.rhs(mu);
    BOOST_TEST((dict.projected_rhs(mu) - f_full).norm() <= 1e-12 * f_full.norm());
    BOOST_REQUIRE(dict.constant_contact() != nullptr);  // rope: no pairing
    fom::ConstraintMatrix c;
    VectorXd g;
    const auto& surf = p.contact().surface_dofs();
    p.contact().assemble(p.contact().search(VectorXd::Zero(static_cast<Eigen::Index>(surf.size()))), c, g);
    const MatrixXd ct_dd = MatrixXd(c.transpose()) * dict.dual();
    MatrixXd full = MatrixXd::Zero(p.num_dofs(), dict.size());
    for (std::size_t a = 0; a < surf.size(); ++a) full.row(surf[a]) = ct_dd.row(static_cast<Eigen::Index>(a));
    const MatrixXd contact_full = b.transpose() * full;
    BOOST_TEST((*dict.constant_contact() - contact_full).norm() <= 1e-12 * contact_full.norm());
  }
}

BOOST_AUTO_TEST_CASE(rope_training_set_is_reproduced) {
  const Setup& s = rope();
  const rom::ReducedModel model = model_of(s, 1e-7);
  const rom::ConvexHullSolver solver(model);
  for (const fom::Param& mu : fom::training_set(*s.problem, 9)) {
    const rom::ConvexHullResult r = solver.solve_detailed(mu);
    const fom::FomSolution ref = s.fom_solver->solve(mu);
    const double primal = fom::relative_h1_error(*s.problem, r.online.u, ref.u);
    const double dual = fom::relative_l2_pressure_error(*s.problem, r.online.lambda, ref.lambda);
    const double sum_violation = std::abs(r.online.coefficients.sum() - 1.0);  // from the coefficients
    BOOST_TEST_MESSAGE("rope training gamma " << mu(0) << ": primal " << primal << " dual " << dual << " |1'a-1| "
                                              << sum_violation);
    BOOST_TEST(primal <= 1e-8);
    BOOST_TEST(dual <= 1e-8);
    BOOST_TEST(sum_violation <= 1e-10);
    BOOST_TEST(r.sum_violation == std::abs(r.alpha.sum() - 1.0));
    BOOST_TEST(r.online.converged);
    BOOST_TEST(r.online.status == Status::Success);
    BOOST_TEST(r.online.selected == std::vector<int>{training_index(s, mu(0))});
  }
}

BOOST_AUTO_TEST_CASE(rope_validation_selects_the_training_neighbours) {
  const Setup& s = rope();
  const rom::ReducedModel model = model_of(s, 1e-7);
  for (bool polish : {true, false}) {
    rom::ConvexHullOptions options;
    options.polish = polish;
    if (!polish) options.sum_weight = 1.0;  // the paper's variant: convexity from the weighted row only
    const rom::ConvexHullSolver solver(model, options);
    double max_sum = 0.0, max_pen = 0.0, max_comp = 0.0, max_primal = 0.0, max_dual = 0.0;
    for (const fom::Param& mu : fom::validation_set(*s.problem, 9)) {
      const rom::ConvexHullResult r = solver.solve_detailed(mu);
      const fom::FomSolution ref = s.fom_solver->solve(mu);
      const int below = training_index(s, mu(0) - 2.5), above = training_index(s, mu(0) + 2.5);
      BOOST_REQUIRE(below >= 0 && above >= 0);
      BOOST_TEST(contains(r.online.selected, below), "gamma " << mu(0) << " misses " << below);
      BOOST_TEST(contains(r.online.selected, above), "gamma " << mu(0) << " misses " << above);
      BOOST_TEST((r.alpha.array() >= 0.0).all());
      const fom::KktResiduals kkt = fom::kkt_residuals(*s.problem, mu, r.online.u, r.online.lambda);
      max_sum = std::max(max_sum, std::abs(r.online.coefficients.sum() - 1.0));
      max_pen = std::max(max_pen, kkt.penetration);
      max_comp = std::max(max_comp, kkt.complementarity);
      max_primal = std::max(max_primal, fom::relative_h1_error(*s.problem, r.online.u, ref.u));
      max_dual = std::max(max_dual, fom::relative_l2_pressure_error(*s.problem, r.online.lambda, ref.lambda));
    }
    BOOST_TEST_MESSAGE("rope validation (polish " << polish << "): max primal " << max_primal << ", dual " << max_dual
                                                  << ", |1'a-1| " << max_sum << ", penetration " << max_pen
                                                  << ", complementarity " << max_comp);
    BOOST_TEST(max_primal <= 2e-2);
    BOOST_TEST(max_dual <= 0.2);
    BOOST_TEST(max_comp <= 1e-3);
    if (polish) {  // exact convexity: the reconstruction stays in the (convex) feasible set
      BOOST_TEST(max_sum <= 1e-14);
      BOOST_TEST(max_pen <= 1e-12);
    } else {  // the paper's variant: convexity only through the weighted row
      BOOST_TEST(max_sum > 1e-8);
      BOOST_TEST(max_sum <= 1e-2);
      BOOST_TEST(max_pen <= 1e-2);
    }
  }
}

BOOST_AUTO_TEST_CASE(random_basis_is_reproducible_and_matches_svd_at_full_rank) {
  const Setup& s = rope();
  const rom::ReducedModel model = model_of(s, 1e-7);
  rom::ConvexHullOptions random;
  random.basis = rom::ProjectionBasis::Random;
  random.seed = 123;
  const rom::ConvexHullSolver a(model, random), b(model, random);
  BOOST_TEST(a.dictionary().projection_rank() == model.primal_rank());  // L defaults to the SVD rank
  BOOST_TEST((a.dictionary().projection_basis().array() == b.dictionary().projection_basis().array()).all());
  const std::vector<fom::Param> params = fom::validation_set(*s.problem, 9);
  for (const fom::Param& mu : params) {
    const VectorXd alpha_a = a.solve_detailed(mu).alpha, alpha_b = b.solve_detailed(mu).alpha;
    BOOST_TEST((alpha_a.array() == alpha_b.array()).all());  // bitwise
  }
  // Another seed gives another basis.
  random.seed = 124;
  const rom::ConvexHullSolver c(model, random);
  BOOST_TEST((c.dictionary().projection_basis() - a.dictionary().projection_basis()).norm() > 1e-3);

  // L = rank of the dictionary (SVD basis at δ = 0, the numerical rank): same column
  // space, hence the same projected problem and the same solution.
  rom::ConvexHullOptions svd;
  svd.basis_delta = 0.0;
  const rom::ConvexHullSolver full(model, svd);
  const int rank = full.dictionary().projection_rank();
  BOOST_TEST(rank == 9);
  for (std::uint64_t seed : {1u, 2u}) {
    random.seed = seed;
    random.rank_l = rank;
    const rom::ConvexHullSolver r(model, random);
    BOOST_TEST(r.dictionary().projection_rank() == rank);
    double diff = 0.0;
    for (const fom::Param& mu : params)
      diff = std::max(diff, (r.solve_detailed(mu).alpha - full.solve_detailed(mu).alpha).cwiseAbs().maxCoeff());
    BOOST_TEST_MESSAGE("random (seed " << seed << ", L = " << rank << ") vs SVD: max |alpha difference| " << diff);
    BOOST_TEST(diff <= 1e-8);
  }
}

BOOST_AUTO_TEST_CASE(hertz_runs_the_pairing_fixed_point) {
  const Setup& s = setup("hertz", 12);
  const rom::ReducedModel model = model_of(s, 1e-8);
  const rom::ConvexHullSolver solver(model);
  BOOST_TEST(solver.dictionary().constant_contact() == nullptr);  // pairing: rebuilt online
  // Training parameters: the snapshot itself is a self-consistent fixed point.
  for (int j : {2, 6, 11}) {
    const fom::Param mu = s.db.parameter(j);
    const rom::ConvexHullResult r = solver.solve_detailed(mu);
    const fom::FomSolution ref = s.fom_solver->solve(mu);
    BOOST_TEST(r.online.converged);
    BOOST_TEST(r.pairing_iterations >= 2);
    BOOST_TEST(r.sum_violation <= 1e-14);
    BOOST_TEST(fom::relative_h1_error(*s.problem, r.online.u, ref.u) <= 1e-8);
  }
  // Inside the training range (d ≥ 0.05): converged, on the simplex, errors bounded.
  for (double d : {0.0512, 0.1387, 0.2613}) {
    const fom::Param mu = VectorXd::Constant(1, d);
    const rom::ConvexHullResult r = solver.solve_detailed(mu);
    const fom::FomSolution ref = s.fom_solver->solve(mu);
    const double primal = fom::relative_h1_error(*s.problem, r.online.u, ref.u);
    BOOST_TEST_MESSAGE("hertz d " << d << ": primal " << primal << ", sparsity " << r.online.selected.size()
                                  << ", pairing iterations " << r.pairing_iterations);
    BOOST_TEST(r.online.converged);
    BOOST_TEST((r.alpha.array() >= 0.0).all());
    BOOST_TEST(r.sum_violation <= 1e-14);
    BOOST_TEST(primal <= 5e-2);
  }
}

BOOST_AUTO_TEST_CASE(hertz_queries_are_fixed_points_of_their_pairing) {
  // The stopping test of the shared pairing fixed point (fom::pairing_change(),
  // without its penetration term), evaluated here from the result alone: its own
  // pairing against the one found at its u_s.
  const Setup& s = setup("hertz", 12);
  const rom::ReducedModel model = model_of(s, 1e-8);
  const rom::ConvexHullSolver solver(model);
  const double tol = solver.options().pairing_tolerance;
  const fom::ContactModel& contact = s.problem->contact();
  auto change_at = [&](const rom::ConvexHullResult& r, bool penetration) {
    const VectorXd u_s = contact.restrict_to_surface(r.online.u);
    fom::ConstraintMatrix c, c_next;
    VectorXd g, g_next;
    contact.assemble(r.pairing, c, g);
    contact.assemble(contact.search(u_s), c_next, g_next);
    return fom::pairing_change(c, g, c_next, g_next, u_s, r.online.lambda, contact.weights(),
                               s.problem->displacement_scale(), tol, penetration);
  };
  const int j = 6;  // a training parameter: its snapshot is reproduced
  const fom::FomSolution ref = s.fom_solver->solve(s.db.parameter(j));
  for (const fom::Param& mu : {s.db.parameter(j), fom::Param(VectorXd::Constant(1, 0.1387))}) {
    const rom::ConvexHullResult r = solver.solve_detailed(mu);
    BOOST_TEST_REQUIRE(r.online.converged, r.online.message);
    BOOST_TEST(r.pairing_change <= tol);
    // u is recomputed from α over the full mesh: the test holds up to that rounding.
    BOOST_TEST(change_at(r, false) <= 10.0 * tol, "d = " << mu(0));
    BOOST_TEST_MESSAGE("hertz d " << mu(0) << ": pairing change " << change_at(r, false) << " (with penetration "
                                  << change_at(r, true) << "), pairing iterations " << r.pairing_iterations);
    if (mu(0) == s.db.parameter(j)(0)) BOOST_TEST(fom::relative_h1_error(*s.problem, r.online.u, ref.u) <= 1e-8);
  }
  // One pairing iteration is not a fixed point: the cap reports it, with the change.
  rom::ConvexHullOptions capped;
  capped.max_pairing_iterations = 1;
  const rom::ConvexHullResult r = rom::ConvexHullSolver(model, capped).solve_detailed(VectorXd::Constant(1, 0.1387));
  BOOST_TEST(!r.online.converged);
  BOOST_TEST(r.online.status == Status::NoConvergence);
  BOOST_TEST(r.pairing_iterations == 1);
  BOOST_TEST(r.online.message.find("did not settle in 1 fixed-point iterations (last change") != std::string::npos,
             r.online.message);
  BOOST_TEST(change_at(r, false) > tol);
}

BOOST_AUTO_TEST_CASE(applicability) {
  try {
    rom::check_convex_hull_applicable(*fom::make_problem("ironing"));
    BOOST_FAIL("ironing accepted");
  } catch (const InputError& e) {
    BOOST_TEST(std::string(e.what()) == kIroningMessage);
  }
  BOOST_CHECK_THROW(rom::check_convex_hull_applicable(*fom::make_problem("ironing2")), InputError);
  BOOST_CHECK_NO_THROW(rom::check_convex_hull_applicable(*rope().problem));
  BOOST_CHECK_NO_THROW(rom::check_convex_hull_applicable(*setup("hertz", 12).problem));
}

BOOST_AUTO_TEST_CASE(registry_and_options) {
  const Setup& s = rope();
  const rom::ReducedModel model = model_of(s, 1e-7);
  rom::OnlineSolverOptions options;
  options.extra = {{"basis", "random"}, {"rank_l", "4"}, {"seed", "3"}, {"polish", "false"}};
  const auto solver = rom::make_online_solver("convex-hull", model, options);
  BOOST_TEST(solver->name() == "convex-hull");
  const auto* hull = dynamic_cast<const rom::ConvexHullSolver*>(solver.get());
  BOOST_REQUIRE(hull != nullptr);
  BOOST_TEST(hull->dictionary().projection_rank() == 4);
  BOOST_TEST(hull->options().seed == 3u);
  BOOST_TEST(!hull->options().polish);
  // The base-class solve gives the same answer as solve_detailed.
  const fom::Param mu = VectorXd::Constant(1, 31.0);
  const rom::OnlineResult r = solver->solve(mu);
  BOOST_TEST(r.selected.size() == static_cast<std::size_t>(r.coefficients.size()));
  BOOST_TEST((r.u - hull->solve_detailed(mu).online.u).norm() == 0.0);
  for (const auto& bad : std::vector<std::pair<std::string, std::string>>{
           {"basis", "qr"}, {"rank_l", "100001"}, {"seed", "x"}, {"polish", "maybe"}, {"colour", "red"}}) {
    rom::OnlineSolverOptions o;
    o.extra[bad.first] = bad.second;
    BOOST_CHECK_THROW(rom::convex_hull_options(o), InputError);
  }
}

/// Rows of a hull-report CSV whose status is not success.
int not_success_rows(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> header;
  for (std::istringstream h(line); std::getline(h, cell, ',');) header.push_back(cell);
  const auto column = std::find(header.begin(), header.end(), "status") - header.begin();
  BOOST_REQUIRE(column < static_cast<long>(header.size()));
  int count = 0;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    for (long c = 0; c <= column; ++c) std::getline(row, cell, ',');
    count += cell != "success";
  }
  return count;
}

BOOST_AUTO_TEST_CASE(cli_online_hull_report_and_refusal) {
  namespace fs = std::filesystem;
  using contactrom::test::run_command;
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/rope.h5", iron = dir + "/iron.h5", csv = dir + "/report.csv";
  BOOST_REQUIRE_EQUAL(run_command(kExe + " offline --problem rope --out " + db).exit_code, 0);
  auto r = run_command(kExe + " online --db " + db + " --method convex-hull --delta 1e-7 --json");
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  auto j = nlohmann::json::parse(r.out);
  BOOST_TEST(j["method"].get<std::string>() == "convex-hull");
  BOOST_TEST(j["nonconverged"].get<int>() == 0);
  BOOST_TEST(j["mean_sparsity"].get<double>() == 2.0);

  r = run_command(kExe + " hull-report --db " + db + " --set training --delta 1e-7 --out " + csv + " --json");
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  j = nlohmann::json::parse(r.out);
  BOOST_TEST(j["max_primal_error"].get<double>() <= 1e-8);
  BOOST_TEST(j["max_sum_violation"].get<double>() <= 1e-10);
  BOOST_TEST(j["queries"].get<int>() == 9);
  const std::string text = contactrom::test::slurp(csv);
  BOOST_TEST(text.rfind("gamma,primal_error,dual_error,errors,sparsity,sum_violation,penetration,", 0) == 0u);
  BOOST_TEST(std::count(text.begin(), text.end(), '\n') == 10);

  // Every key hull-report --help lists for --option is accepted, and at its declared
  // default gives the same answers as no --option at all.
  const std::string help = run_command(kExe + " hull-report --help").out;
  std::string every_default;
  for (const rom::OptionSpec& spec : rom::online_method("convex-hull").options) {
    BOOST_TEST(help.find(spec.key) != std::string::npos, "hull-report --help does not list " << spec.key);
    every_default += " --option " + spec.key + "=" + spec.default_value;
  }
  r = run_command(kExe + " hull-report --db " + db + " --set training --delta 1e-7 --json" + every_default);
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  const auto with_defaults = nlohmann::json::parse(r.out);
  for (const char* key : {"max_primal_error", "max_dual_error", "mean_sparsity", "max_sum_violation"})
    BOOST_TEST(with_defaults[key].get<double>() == j[key].get<double>(), key);
  // The contact-check tolerances reach the statuses: with none allowed, the hull's
  // answers (a combination of two snapshots with different contact sets) are not
  // all reported success; --no-polish is --option polish=false.
  const std::string strict_csv = dir + "/strict.csv";
  r = run_command(kExe + " hull-report --db " + db + " --set training --delta 1e-7 --out " + strict_csv +
                  " --option penetration_tolerance=1e-300 --option complementarity_tolerance=1e-300");
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  BOOST_TEST(not_success_rows(contactrom::test::slurp(csv)) == 0);
  BOOST_TEST(not_success_rows(contactrom::test::slurp(strict_csv)) > 0);
  const auto no_polish = run_command(kExe + " hull-report --db " + db + " --set training --delta 1e-7 --json --no-polish");
  const auto polish_false = run_command(kExe + " hull-report --db " + db + " --set training --delta 1e-7 --json --option polish=false");
  BOOST_REQUIRE_EQUAL(no_polish.exit_code, 0);
  BOOST_REQUIRE_EQUAL(polish_false.exit_code, 0);
  BOOST_TEST(nlohmann::json::parse(no_polish.out)["max_sum_violation"] == nlohmann::json::parse(polish_false.out)["max_sum_violation"]);

  BOOST_REQUIRE_EQUAL(run_command(kExe + " offline --problem ironing --level 3 --out " + iron).exit_code, 0);
  for (const std::string& cmd : {kExe + " online --db " + iron + " --method convex-hull",
                                 kExe + " hull-report --db " + iron + " --out " + dir + "/iron.csv"}) {
    r = run_command(cmd);
    BOOST_TEST(r.exit_code == 2);
    BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    BOOST_TEST(r.err.find(kIroningMessage) != std::string::npos);
  }
  BOOST_TEST(!fs::exists(dir + "/iron.csv"));
  r = run_command(kExe + " hull-report --db " + dir + "/missing.h5");
  BOOST_TEST(r.exit_code != 0);
  BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  fs::remove_all(dir);
}
