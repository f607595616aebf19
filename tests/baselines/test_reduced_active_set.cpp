// Tests of baselines/reduced_active_set.hpp, the block primal–dual active set on
// the reduced saddle-point system with a fixed dual basis W: closed-form solutions
// on the hand-written rope model (tests/common/tiny_rope.hpp; rope of 4 elements,
// γ = 10, load 200, Φ = I, dictionary [e₁, 3e₂, e₃]) for both inner solves, every
// start and sub-bases of the dictionary; agreement with the greedy on a ROM built
// from FOM snapshots (both solve the same reduced QP, whose û is unique);
// reduced_penetration by hand; refused inputs.
#define BOOST_TEST_MODULE baselines_reduced_active_set
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <set>

#include <contactrom/baselines/reduced_active_set.hpp>
#include "common/tiny_rope.hpp"
#include <contactrom/core/errors.hpp>
#include <contactrom/rom/greedy_active_set.hpp>
#include <contactrom/rom/offline.hpp>

using namespace contactrom;
using baselines::ReducedActiveSet;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

const rom::ReducedModel& hand_model() {
  static const rom::ReducedModel model = test::hand_rope_model(test::unit_rope_dictionary());
  return model;
}

const fom::Param gamma10 = VectorXd::Constant(1, 10.0);

std::set<int> as_set(const std::vector<int>& v) { return {v.begin(), v.end()}; }

/// λ̂ of dictionary column `column` in a result (0 if not selected).
double coefficient(const rom::OnlineResult& r, int column) {
  for (size_t j = 0; j < r.selected.size(); ++j)
    if (r.selected[j] == column) return r.coefficients(static_cast<Eigen::Index>(j));
  return 0.0;
}

}  // namespace

BOOST_AUTO_TEST_CASE(full_dictionary_reaches_the_hand_solution) {
  // From û = K⁻¹f = (−1.25, −1.25, −5/6) every column is violated; on all three u = ψ
  // and λ̂ = (184, −18.67, 152); without the middle one, u₂ = −0.8125 > ψ₂ and
  // λ̂ = (170, 110): the solution. The equality inner solve removes the negative
  // multiplier afterwards, the non-negative one inside the solve.
  for (baselines::InnerSolve inner : {baselines::InnerSolve::Equality, baselines::InnerSolve::NonNegative}) {
    for (rom::WarmStart init : {rom::WarmStart::Empty, rom::WarmStart::Primal, rom::WarmStart::Cell}) {
      baselines::ReducedActiveSetOptions options;
      options.inner_solve = inner;
      options.init = init;
      options.tau = 1e-12;
      const ReducedActiveSet solver("full-dictionary", hand_model(), {0, 1, 2}, options);
      const rom::OnlineResult r = solver.solve(gamma10);
      BOOST_TEST_CONTEXT("inner " << static_cast<int>(inner) << ", init " << static_cast<int>(init)) {
        BOOST_TEST(r.converged);
        BOOST_TEST(r.status == Status::Success);
        BOOST_TEST(as_set(r.selected) == (std::set<int>{0, 2}));
        BOOST_TEST((r.u_hat - Vector3d(-0.5, -0.8125, -0.5)).norm() <= 1e-12);
        BOOST_TEST(std::abs(coefficient(r, 0) - 170.0) <= 1e-9);
        BOOST_TEST(std::abs(coefficient(r, 2) - 110.0) <= 1e-9);
        BOOST_TEST((r.lambda - (VectorXd(5) << 0, 170, 0, 110, 0).finished()).norm() <= 1e-9);
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(a_sub_basis_constrains_only_its_columns) {
  // W = {3e₂}: only the middle node is held, u₂ = −0.9; rows 1 and 3 give
  // u₁ = (−50 − 36)/80 and u₃ = (−50 − 108)/240, and (Ku − f)₂ = 28 = 0.75 λ̂.
  const ReducedActiveSet middle("w", hand_model(), {1});
  BOOST_TEST(middle.dual_basis_size() == 1);
  BOOST_TEST((middle.dual_basis() - hand_model().dictionary().col(1)).norm() == 0.0);
  const rom::OnlineResult r = middle.solve(gamma10);
  BOOST_TEST(r.converged);
  BOOST_TEST(r.selected == (std::vector<int>{1}));
  BOOST_TEST((r.u_hat - Vector3d(-1.075, -0.9, -158.0 / 240.0)).norm() <= 1e-12);
  BOOST_TEST(std::abs(coefficient(r, 1) - 28.0 / 0.75) <= 1e-9);
  // W = {e₁, e₃}: the columns active at the full solution suffice.
  const rom::OnlineResult r2 = ReducedActiveSet("w", hand_model(), {2, 0}).solve(gamma10);
  BOOST_TEST(r2.converged);
  BOOST_TEST(as_set(r2.selected) == (std::set<int>{0, 2}));
  BOOST_TEST((r2.u_hat - Vector3d(-0.5, -0.8125, -0.5)).norm() <= 1e-12);
}

BOOST_AUTO_TEST_CASE(no_load_no_active_column) {
  const rom::ReducedModel unloaded = test::hand_rope_model(test::unit_rope_dictionary(), 0.0);
  const rom::OnlineResult r = ReducedActiveSet("w", unloaded, {0, 1, 2}).solve(gamma10);
  BOOST_TEST(r.converged);
  BOOST_TEST(r.selected.empty());
  BOOST_TEST(r.u_hat.norm() == 0.0);
}

BOOST_AUTO_TEST_CASE(reduced_penetration_by_hand) {
  // u = −1 on the interior nodes: C u − g = w(ψ − u) = (−0.0625, 0.125, 0.025, 0.125,
  // −0.0625); the columns e₁, 3e₂, e₃ see 0.125, 0.075, 0.125.
  const VectorXd u = (VectorXd(5) << 0, -1, -1, -1, 0).finished();
  BOOST_TEST(std::abs(baselines::reduced_penetration(hand_model(), {1}, u) - 0.075) <= 1e-15);
  BOOST_TEST(std::abs(baselines::reduced_penetration(hand_model(), {1, 2}, u) - 0.125) <= 1e-15);
  BOOST_TEST(baselines::reduced_penetration(hand_model(), {}, u) == -std::numeric_limits<double>::infinity());
}

BOOST_AUTO_TEST_CASE(agrees_with_the_greedy_on_a_snapshot_rom) {
  // Rope of 8 elements, 9 FOM snapshots, POD basis: the greedy and the full
  // dictionary solve the same reduced QP (û unique since K̂ is positive definite).
  const rom::ReducedModel& model = *test::rope_snapshot_rom().model;
  std::vector<int> all(static_cast<size_t>(model.dictionary_size()));
  for (size_t c = 0; c < all.size(); ++c) all[c] = static_cast<int>(c);
  const ReducedActiveSet block("full-dictionary", model, all);
  const rom::GreedyActiveSet greedy(model);
  BOOST_TEST(block.threshold() == greedy.threshold());  // the same reduced constraint
  for (double g = 12.5; g < 50.0; g += 5.0) {
    const fom::Param mu = VectorXd::Constant(1, g);
    const rom::OnlineResult a = block.solve(mu), b = greedy.solve(mu);
    BOOST_TEST_CONTEXT("gamma " << g) {
      BOOST_REQUIRE(a.converged);
      BOOST_REQUIRE(b.converged);
      BOOST_TEST((a.u - b.u).norm() <= 1e-6 * b.u.norm());
    }
  }
}

BOOST_AUTO_TEST_CASE(bad_bases_and_options_are_input_errors) {
  BOOST_CHECK_THROW(ReducedActiveSet("w", hand_model(), {0, 3}), InputError);     // out of range
  BOOST_CHECK_THROW(ReducedActiveSet("w", hand_model(), {1, 1}), InputError);     // repeated
  baselines::ReducedActiveSetOptions nearest;
  nearest.init = rom::WarmStart::Nearest;
  BOOST_CHECK_THROW(ReducedActiveSet("w", hand_model(), {0}, nearest), InputError);
  rom::OnlineSolverOptions generic;
  generic.extra["inner_solve"] = "exact";
  BOOST_CHECK_THROW(baselines::reduced_active_set_options(generic), InputError);
  generic.extra["inner_solve"] = "equality";
  BOOST_TEST((baselines::reduced_active_set_options(generic).inner_solve == baselines::InnerSolve::Equality));
}
