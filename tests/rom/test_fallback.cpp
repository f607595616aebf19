// FallbackSolver (rom/fallback.hpp): a query the dictionary cannot represent is
// answered by the FOM (the same answer as the FOM's own), a query it represents
// well by the ROM; the tolerances decide.
#define BOOST_TEST_MODULE rom_fallback
#include <boost/test/unit_test.hpp>

#include <fstream>
#include <limits>
#include <memory>
#include <string>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/fallback.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/snapshot_database.hpp>

using namespace contactrom;

namespace {
fom::Param param(double d) { return fom::Param::Constant(1, d); }
}  // namespace

BOOST_AUTO_TEST_CASE(fom_answers_where_the_rom_cannot_and_rom_where_it_can) {
  const auto problem = fom::make_problem("hertz");
  const std::vector<fom::Param> train{param(0.02), param(0.03), param(0.04), param(0.05)};
  const rom::SnapshotDatabase db = rom::generate_snapshots(*problem, train, "train", 4, {});
  const rom::ReducedModel model(*problem, db);
  const auto solver = rom::make_online_solver("greedy", model);
  const rom::FallbackSolver fallback(*solver);
  const fom::ActiveSetSolver fom_solver(*problem);

  // Outside the dictionary's reach: the FOM's answer, and the output says so.
  const rom::FallbackAnswer deep = fallback.solve(param(0.3));
  BOOST_TEST(deep.from_fom);
  BOOST_TEST(!deep.reason.empty());
  BOOST_TEST(deep.fom_time_s > 0.0);
  const fom::FomSolution ref = fom_solver.solve(param(0.3));
  const fom::ReferenceErrors e = fom::reference_errors(*problem, deep.result.u, deep.result.lambda, ref.u, ref.lambda);
  BOOST_TEST(e.primal < 1e-10);
  BOOST_TEST(e.dual < 1e-10);
  BOOST_TEST(deep.result.status == Status::Success);

  // Inside: the ROM answers, and its true errors are within the tolerances.
  const rom::FallbackAnswer inside = fallback.solve(param(0.035));
  BOOST_TEST(!inside.from_fom);
  BOOST_TEST(inside.fom_time_s == 0.0);
  const fom::FomSolution ref_in = fom_solver.solve(param(0.035));
  const fom::ReferenceErrors ei = fom::reference_errors(*problem, inside.result.u, inside.result.lambda, ref_in.u, ref_in.lambda);
  BOOST_TEST(ei.primal <= rom::FallbackOptions().primal_tolerance);
  BOOST_TEST(ei.dual <= rom::FallbackOptions().dual_tolerance);

  // Tolerances below the answer's estimates send it to the FOM.
  rom::FallbackOptions strict;
  strict.primal_tolerance = 0.5 * strict.safety_factor * inside.result.primal_estimate;
  const rom::FallbackSolver picky(*solver, strict);
  BOOST_TEST(picky.solve(param(0.035)).from_fom);
}

BOOST_AUTO_TEST_CASE(a_solver_without_estimates_is_refused) {
  // With the estimate off every query would go to the FOM: refused when built.
  const auto problem = fom::make_problem("hertz");
  const rom::SnapshotDatabase db = rom::generate_snapshots(*problem, 12, {});
  const rom::ReducedModel model(*problem, db);
  const auto solver = rom::make_online_solver("greedy", model, rom::options_from_map("greedy", {{"estimate", "false"}}));
  BOOST_CHECK_EXCEPTION(rom::FallbackSolver fallback(*solver), InputError, [](const InputError& e) {
    return std::string(e.what()).find("estimates no error (its option estimate is off)") != std::string::npos;
  });
  // An answer whose estimates are NaN is not kept (as with a parameter-dependent stiffness).
  const auto estimating = rom::make_online_solver("greedy", model);
  const rom::FallbackSolver fallback(*estimating);
  rom::OnlineResult res = estimating->solve(param(0.1));
  std::string reason;
  BOOST_TEST(fallback.keeps(res, reason));
  res.dual_estimate = std::numeric_limits<double>::quiet_NaN();
  BOOST_TEST(!fallback.keeps(res, reason));
  BOOST_TEST(reason.find("no error estimate") == 0u, reason);
}

BOOST_AUTO_TEST_CASE(a_training_kind_the_reader_refuses_is_refused) {
  const auto problem = fom::make_problem("hertz");
  BOOST_CHECK_THROW(rom::generate_snapshots(*problem, {param(0.1)}, "uniform", 1), InputError);
  rom::SnapshotDatabase db = rom::generate_snapshots(*problem, {param(0.1)}, "train", 1);
  db.training_kind = "foo";
  BOOST_CHECK_THROW(rom::write_database("never_written.h5", db), InputError);
  BOOST_TEST(!std::ifstream("never_written.h5").good());
}
