// The greedy active set (rom/greedy_active_set.hpp, paper Alg. 1) on a problem
// small enough to follow by hand: the rope of 4 elements (3 free dofs, 5 obstacle
// rows), γ = 10, load 200, with the identity as primal basis and a dictionary of
// three columns e₁, 3e₂, e₃ (one per interior node, the middle one scaled so that
// the greedy picks it first and must later remove it). Every step's selection,
// displacement and multipliers are derived below from the 3 × 3 system; then the
// KKT conditions of the reduced problem on ROMs built from FOM snapshots, and the
// reproduction of a training snapshot at its own parameter.
//
// The rope and the hand model are described in tests/common/tiny_rope.hpp; under
// load 200 at γ = 10
//   K = [ 80 −40 0 ; −40 160 −120 ; 0 −120 240 ],  f = −50 per node,
// and with multipliers λ̂ on the columns d_p stationarity reads
// K û − f = Σ_p λ̂_p w d_p (restricted to the free nodes).
#define BOOST_TEST_MODULE rom_greedy_closed_form
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <memory>
#include <set>

#include "common/tiny_rope.hpp"
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/greedy_active_set.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/rebuild_fixed_point.hpp>
#include <contactrom/rom/reduced_model.hpp>

using namespace contactrom;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

constexpr double kGamma = 10.0;

using test::rope4;

const rom::ReducedModel& hand_model() {
  static const rom::ReducedModel model = test::hand_rope_model(test::unit_rope_dictionary());
  return model;
}

/// Paper Alg. 1 exactly: empty start, plain substitution, no switch on a cycle, and
/// with a cap of k iterations the k-th iterate itself (not the best one).
rom::GreedyOptions paper_options(int cap) {
  rom::GreedyOptions o;
  o.schedule = rom::GreedySchedule::Interleaved;
  o.init = rom::WarmStart::Empty;
  o.anderson_depth = 0;
  o.nested_on_cycle = false;
  o.best_iterate_on_failure = false;
  o.tau = 1e-12;
  o.max_iterations = cap;
  return o;
}

std::set<int> as_set(const std::vector<int>& v) { return {v.begin(), v.end()}; }

/// λ̂ of the selected columns in the given column order.
VectorXd coefficients_of(const rom::OnlineResult& r, const std::vector<int>& columns) {
  VectorXd out = VectorXd::Zero(static_cast<Eigen::Index>(columns.size()));
  for (size_t i = 0; i < columns.size(); ++i)
    for (size_t j = 0; j < r.selected.size(); ++j)
      if (r.selected[j] == columns[i]) out(static_cast<Eigen::Index>(i)) = r.coefficients(static_cast<Eigen::Index>(j));
  return out;
}

const fom::Param gamma10 = VectorXd::Constant(1, kGamma);

}  // namespace

BOOST_AUTO_TEST_CASE(hand_model_is_the_rope_with_identity_basis) {
  // The hand-written terms are the rope's own: K_q on the free dofs, f_ext, w, ψ.
  const fom::Problem& p = rope4();
  BOOST_REQUIRE(p.num_dofs() == 5);
  BOOST_REQUIRE(p.free_dofs() == (std::vector<int>{1, 2, 3}));
  const rom::ReducedModel& m = hand_model();
  for (int q = 0; q < 2; ++q) {
    const MatrixXd k = MatrixXd(p.stiffness_term(q)).block(1, 1, 3, 3);
    BOOST_TEST((k - m.reduced_stiffness_terms()[static_cast<size_t>(q)]).norm() == 0.0, "term " << q);
  }
  const MatrixXd k = (MatrixXd(3, 3) << 80, -40, 0, -40, 160, -120, 0, -120, 240).finished();
  BOOST_TEST((m.reduced_stiffness(gamma10) - k).norm() <= 1e-13);
  BOOST_TEST((m.reduced_rhs(gamma10) - Vector3d::Constant(-50.0)).norm() <= 1e-13);
  BOOST_TEST((p.contact().weights() - (VectorXd(5) << 0.125, 0.25, 0.25, 0.25, 0.125).finished()).norm() <= 1e-15);
  // g = −w ψ: ψ = (−0.5, −0.5, −0.9, −0.5, −0.5) at x = 0, ¼, ½, ¾, 1.
  fom::ConstraintMatrix c;
  VectorXd g;
  p.contact().assemble(p.contact().search(VectorXd::Zero(5)), c, g);
  const VectorXd psi = (VectorXd(5) << -0.5, -0.5, -0.9, -0.5, -0.5).finished();
  BOOST_TEST((g + p.contact().weights().cwiseProduct(psi)).norm() <= 1e-15);
  BOOST_TEST((MatrixXd(c) + MatrixXd(p.contact().weights().asDiagonal())).norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(every_step_of_alg1_by_hand) {
  const rom::ReducedModel& m = hand_model();
  // Step 1, I = ∅: û = K⁻¹f = (−1.25, −1.25, −5/6). Violations w(ψ_i − u_i)·scale:
  // 0.1875, 3·0.0875 = 0.2625, 0.0833: the scaled middle column is added.
  {
    const rom::OnlineResult r = rom::GreedyActiveSet(m, paper_options(1)).solve(gamma10);
    BOOST_TEST(r.selected.empty());
    BOOST_TEST((r.u_hat - Vector3d(-1.25, -1.25, -5.0 / 6.0)).norm() <= 1e-13);
  }
  // Step 2, I = {1}: u₂ = −0.9, then row 1: u₁ = (−50 − 36)/80 = −1.075 and row 3:
  // u₃ = (−50 − 108)/240 = −0.658333; (Ku − f)₂ = 28 = 0.75 λ̂₁ → λ̂₁ = 37.333 ≥ 0.
  // Violations 0.14375 (column 0) and 0.0395833 (column 2): column 0 is added.
  {
    const rom::OnlineResult r = rom::GreedyActiveSet(m, paper_options(2)).solve(gamma10);
    BOOST_TEST(as_set(r.selected) == (std::set<int>{1}));
    BOOST_TEST((r.u_hat - Vector3d(-1.075, -0.9, -158.0 / 240.0)).norm() <= 1e-13);
    BOOST_TEST(std::abs(coefficients_of(r, {1})(0) - 28.0 / 0.75) <= 1e-11);
  }
  // Step 3, I = {1, 0}: u = (−0.5, −0.9, −0.658333); (Ku − f)₁ = 46 → λ̂₀ = 184,
  // (Ku − f)₂ = 5 → λ̂₁ = 6.667; column 2 still violated (0.0395833): added.
  {
    const rom::OnlineResult r = rom::GreedyActiveSet(m, paper_options(3)).solve(gamma10);
    BOOST_TEST(as_set(r.selected) == (std::set<int>{0, 1}));
    BOOST_TEST((r.u_hat - Vector3d(-0.5, -0.9, -158.0 / 240.0)).norm() <= 1e-13);
    BOOST_TEST((coefficients_of(r, {0, 1}) - Eigen::Vector2d(184.0, 5.0 / 0.75)).norm() <= 1e-11);
  }
  // Step 4, I = {0, 1, 2}: u = ψ; (Ku − f) = (46, −14, 38) → λ̂ = (184, −18.667, 152):
  // the middle column's multiplier is negative, it is removed.
  {
    const rom::OnlineResult r = rom::GreedyActiveSet(m, paper_options(4)).solve(gamma10);
    BOOST_TEST(as_set(r.selected) == (std::set<int>{0, 1, 2}));
    BOOST_TEST((r.u_hat - Vector3d(-0.5, -0.9, -0.5)).norm() <= 1e-13);
    BOOST_TEST((coefficients_of(r, {0, 1, 2}) - Vector3d(184.0, -14.0 / 0.75, 152.0)).norm() <= 1e-11);
  }
  // Step 5, I = {0, 2}: u₁ = u₃ = −0.5, row 2: 160u₂ = −50 − 20 − 60 → u₂ = −0.8125
  // (above ψ₂ = −0.9: column 1 satisfied); λ̂ = (42.5, 27.5)/0.25 = (170, 110). No
  // change; the next iteration finds û unmoved and the confirmation passes.
  const rom::OnlineResult r = rom::GreedyActiveSet(m, paper_options(50)).solve(gamma10);
  BOOST_TEST(r.converged);
  BOOST_TEST(r.status == Status::Success);
  BOOST_TEST(as_set(r.selected) == (std::set<int>{0, 2}));
  BOOST_TEST((r.u_hat - Vector3d(-0.5, -0.8125, -0.5)).norm() <= 1e-13);
  BOOST_TEST((coefficients_of(r, {0, 2}) - Eigen::Vector2d(170.0, 110.0)).norm() <= 1e-11);
  // Full fields: u with the Dirichlet ends, λ = D_I λ̂_I.
  BOOST_TEST((r.u - (VectorXd(5) << 0, -0.5, -0.8125, -0.5, 0).finished()).norm() <= 1e-13);
  BOOST_TEST((r.lambda - (VectorXd(5) << 0, 170, 0, 110, 0).finished()).norm() <= 1e-11);
  BOOST_TEST(r.iterations >= 5);
}

BOOST_AUTO_TEST_CASE(threshold_scalings) {
  // Absolute: τ itself, or δ of the model when τ < 0. Relative: τ·U·max_p Σ_s w_s|D[s,p]|
  // with U = 0.5 (the rope's displacement scale) and the largest column force
  // 3·¼ = 0.75 (the middle column).
  rom::GreedyOptions o;
  o.tau = 0.01;
  BOOST_TEST(rom::greedy_threshold(hand_model(), o) == 0.01);
  o.tau = -1.0;
  BOOST_TEST(rom::greedy_threshold(hand_model(), o) == hand_model().delta());
  o.tau = 0.01;
  o.tau_scaling = rom::TauScaling::Relative;
  BOOST_TEST(std::abs(rom::greedy_threshold(hand_model(), o) - 0.01 * 0.5 * 0.75) <= 1e-17);
}

BOOST_AUTO_TEST_CASE(hand_solution_is_the_fom_solution) {
  // Φ = I and a dictionary spanning every contact row of the solution: the ROM is the
  // FOM, so the FOM's solution is the hand one above.
  const fom::FomSolution s = fom::ActiveSetSolver(rope4()).solve(gamma10);
  BOOST_REQUIRE(s.status == Status::Success);
  BOOST_TEST((s.u - (VectorXd(5) << 0, -0.5, -0.8125, -0.5, 0).finished()).norm() <= 1e-12);
  BOOST_TEST((s.lambda - (VectorXd(5) << 0, 170, 0, 110, 0).finished()).norm() <= 1e-9);
}

BOOST_AUTO_TEST_CASE(every_schedule_and_start_reaches_the_hand_solution) {
  // The reduced QP has one solution; the nested schedule, the warm starts and the
  // default options all end there.
  std::vector<std::pair<const char*, rom::GreedyOptions>> variants;
  variants.emplace_back("default", rom::GreedyOptions{});
  rom::GreedyOptions nested;
  nested.schedule = rom::GreedySchedule::Nested;
  variants.emplace_back("nested", nested);
  rom::GreedyOptions interleaved;
  interleaved.schedule = rom::GreedySchedule::Interleaved;
  variants.emplace_back("interleaved", interleaved);
  for (rom::WarmStart init : {rom::WarmStart::Empty, rom::WarmStart::Nearest, rom::WarmStart::Primal}) {
    rom::GreedyOptions o;
    o.init = init;
    variants.emplace_back("init", o);
  }
  for (auto& [label, options] : variants) {
    options.tau = 1e-12;
    const rom::OnlineResult r = rom::GreedyActiveSet(hand_model(), options).solve(gamma10);
    BOOST_TEST_CONTEXT(label << " (init " << static_cast<int>(options.init) << ")") {
      BOOST_TEST(r.converged);
      BOOST_TEST(as_set(r.selected) == (std::set<int>{0, 2}));
      BOOST_TEST((r.u_hat - Vector3d(-0.5, -0.8125, -0.5)).norm() <= 1e-12);
    }
  }
}

BOOST_AUTO_TEST_CASE(a_satisfied_start_needs_no_column) {
  // Load 0: the rope stays at u = 0, above ψ everywhere; Alg. 1 adds nothing.
  const rom::ReducedModel model = test::hand_rope_model(test::unit_rope_dictionary(), 0.0);
  const rom::OnlineResult r = rom::GreedyActiveSet(model, paper_options(50)).solve(gamma10);
  BOOST_TEST(r.converged);
  BOOST_TEST(r.selected.empty());
  BOOST_TEST(r.u_hat.norm() == 0.0);
  BOOST_TEST(r.lambda.norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(training_parameter_reproduces_its_snapshot) {
  const test::RopeSnapshotRom& s = test::rope_snapshot_rom();
  for (const auto& init : {rom::WarmStart::Cell, rom::WarmStart::Empty}) {
    rom::GreedyOptions options;
    options.init = init;
    const rom::GreedyActiveSet greedy(*s.model, options);
    for (int j = 0; j < s.db.num_snapshots(); ++j) {
      const fom::Param mu = s.db.parameter(j);
      const rom::OnlineResult r = greedy.solve(mu);
      const VectorXd u = s.db.primal.col(j) + s.problem->lifting(mu);
      BOOST_TEST_CONTEXT("init " << static_cast<int>(init) << ", gamma " << mu(0)) {
        BOOST_TEST(r.converged);
        BOOST_TEST((r.u - u).norm() <= 1e-8 * u.norm());
        // From the snapshot's own column (init cell) the pressure is the snapshot's;
        // from the empty start only its reduced force ΦᵀCᵀλ is determined (r < n_c).
        const VectorXd dl = r.lambda - s.db.dual.col(j);
        if (init == rom::WarmStart::Cell) BOOST_TEST(dl.norm() <= 1e-6 * s.db.dual.col(j).norm());
        const VectorXd force = s.model->basis().transpose() * (MatrixXd(s.c).transpose() * dl);
        BOOST_TEST(force.norm() <= 1e-6 * s.db.dual.col(j).norm());
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(converged_result_meets_the_reduced_kkt_conditions) {
  // Between the training values: K̂û − f̂ + Ĉ_Iᵀλ̂ = 0, λ̂ ≥ 0, every column's reduced
  // violation D_dᵀ(Cu − g) ≤ τ and = 0 on the selected ones. The rope's constraint is
  // linear (C = −diag(w), g = −wψ on every dof), so Ĉ = D_dᵀ C Φ is formed densely here.
  const test::RopeSnapshotRom& s = test::rope_snapshot_rom();
  const rom::ReducedModel& m = *s.model;
  const fom::ConstraintMatrix& c = s.c;
  const VectorXd& g = s.g;
  const MatrixXd c_hat = m.dictionary().transpose() * MatrixXd(c) * m.basis();
  for (const auto& schedule : {rom::GreedySchedule::Interleaved, rom::GreedySchedule::Nested}) {
    rom::GreedyOptions options;
    options.schedule = schedule;
    const rom::GreedyActiveSet greedy(m, options);
    for (double gamma = 12.5; gamma < 50.0; gamma += 5.0) {
      const fom::Param mu = VectorXd::Constant(1, gamma);
      const rom::OnlineResult r = greedy.solve(mu);
      BOOST_TEST_CONTEXT("schedule " << static_cast<int>(schedule) << ", gamma " << gamma) {
        BOOST_REQUIRE(r.converged);
        VectorXd residual = m.reduced_stiffness(mu) * r.u_hat - m.reduced_rhs(mu);
        for (size_t i = 0; i < r.selected.size(); ++i)
          residual += r.coefficients(static_cast<Eigen::Index>(i)) * c_hat.row(r.selected[i]).transpose();
        BOOST_TEST(residual.norm() <= 1e-9 * m.reduced_rhs(mu).norm());
        if (r.coefficients.size() > 0) BOOST_TEST(r.coefficients.minCoeff() >= 0.0);
        const VectorXd violation = m.dictionary().transpose() * (c * r.u - g);
        BOOST_TEST(violation.maxCoeff() <= greedy.threshold());
        for (int p : r.selected) BOOST_TEST(std::abs(violation(p)) <= 1e-9 * g.cwiseAbs().maxCoeff());
      }
    }
  }
}

// The outer loop shared by the greedy and the baselines (rom/rebuild_fixed_point.hpp)
// on a scripted map: û(x) = a·x on a one-dof "surface" (scale U = 1), the physical
// test answering as told. Plain substitution (extrapolate: x = û) from x = 1 gives
// x_k = a^k and steps (1 − a)a^k, so the rebuild count is known in closed form.
namespace {
struct ScriptedLoop {
  double a = 0.5;
  bool physical = true;     // the answer of the test at û's own pairing
  bool finite = true;
  Eigen::VectorXd x = Eigen::VectorXd::Ones(1), u_hat = Eigen::VectorXd::Ones(1);
  int rebuilds = 0, tests = 0, n_solves = 0;
  bool tested_at_u_hat = false;
  void rebuild(bool at_u_hat) {
    ++rebuilds;
    tested_at_u_hat = at_u_hat;
  }
  bool physically_converged() {
    ++tests;
    BOOST_TEST(tested_at_u_hat);  // the test only ever runs at x = û
    return physical;
  }
  int solves() const { return n_solves; }
  bool solve_frozen(int) {
    ++n_solves;
    u_hat = a * x;
    return finite;
  }
  double step() { return rom::surface_step(u_hat, x, 1.0); }
  void accept() { x = u_hat; }
  void extrapolate() { x = u_hat; }
};
}  // namespace

BOOST_AUTO_TEST_CASE(rebuild_fixed_point_stops_when_the_step_is_resolved_and_the_test_passes) {
  ScriptedLoop loop;
  const rom::RebuildLimits limits{50, 1000, 1e-3};
  BOOST_TEST(static_cast<int>(rom::run_rebuild_fixed_point(loop, limits)) ==
             static_cast<int>(rom::RebuildOutcome::Converged));
  // Steps 2^-(k+1) for k = 0, 1, …: the first ≤ 1e-3 is k = 9 (2^-10), after 10
  // solves; one more rebuild at û holds the test.
  BOOST_TEST(loop.n_solves == 10);
  BOOST_TEST(loop.rebuilds == 11);
  BOOST_TEST(loop.tests == 1);
}

BOOST_AUTO_TEST_CASE(rebuild_fixed_point_returns_a_reduced_fixed_point_that_fails_the_test_twice) {
  ScriptedLoop loop;
  loop.a = 1.0;  // û(x) = x: a fixed point at once
  loop.physical = false;
  const rom::RebuildLimits limits{50, 1000, 1e-3};
  BOOST_TEST(static_cast<int>(rom::run_rebuild_fixed_point(loop, limits)) ==
             static_cast<int>(rom::RebuildOutcome::Converged));
  BOOST_TEST(loop.tests == 2);  // failed, solved once more at û, failed again: no further iteration helps
  BOOST_TEST(loop.n_solves == 2);
}

BOOST_AUTO_TEST_CASE(rebuild_fixed_point_reports_its_caps_and_non_finite_solves) {
  ScriptedLoop slow;
  slow.a = 0.99;  // steps 0.01·0.99^k stay above 1e-3 for 229 solves
  BOOST_TEST(static_cast<int>(rom::run_rebuild_fixed_point(slow, rom::RebuildLimits{7, 1000, 1e-3})) ==
             static_cast<int>(rom::RebuildOutcome::AtCap));
  BOOST_TEST(slow.n_solves == 7);  // rebuilds 0 … 6 solve, rebuild 7 is the cap
  ScriptedLoop capped;
  capped.a = 0.99;
  BOOST_TEST(static_cast<int>(rom::run_rebuild_fixed_point(capped, rom::RebuildLimits{50, 3, 1e-3})) ==
             static_cast<int>(rom::RebuildOutcome::AtCap));
  BOOST_TEST(capped.n_solves == 3);
  ScriptedLoop broken;
  broken.finite = false;
  BOOST_TEST(static_cast<int>(rom::run_rebuild_fixed_point(broken, rom::RebuildLimits{50, 1000, 1e-3})) ==
             static_cast<int>(rom::RebuildOutcome::NonFinite));
  BOOST_TEST(broken.n_solves == 1);
}
