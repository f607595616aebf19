// Adaptive training (rom/adaptive_training.hpp) on hertz: the first point it adds is
// where the initial model's true error (against the FOM) is largest, a run
// interrupted after a round and continued from its file ends with the database of an
// uninterrupted run, the database records every round, and bad settings are refused.
#define BOOST_TEST_MODULE rom_adaptive_training
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include <hdf5.h>

#include "common/run_command.hpp"
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/adaptive_training.hpp>
#include <contactrom/rom/database_merge.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/online_methods.hpp>

using namespace contactrom;

namespace {

/// Small settings: 40 candidates, a few snapshots, one thread.
rom::AdaptiveOptions small_options() {
  rom::AdaptiveOptions o;
  o.tolerance = 1e-3;
  o.candidates = 40;
  o.batch = 2;
  o.max_snapshots = 8;
  o.offline.threads = 1;
  return o;
}

struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted") {}
};

void check_same_database(const rom::SnapshotDatabase& a, const rom::SnapshotDatabase& b) {
  BOOST_REQUIRE_EQUAL(a.num_snapshots(), b.num_snapshots());
  BOOST_TEST((a.parameters == b.parameters));
  BOOST_TEST((a.primal == b.primal));
  BOOST_TEST((a.dual == b.dual));
  BOOST_TEST((a.status == b.status));
  BOOST_TEST(a.training_kind == b.training_kind);
  BOOST_TEST(a.training_size == b.training_size);
  const rom::AdaptiveRecord &ra = a.adaptive, &rb = b.adaptive;
  BOOST_TEST(ra.round_snapshots == rb.round_snapshots, boost::test_tools::per_element());
  BOOST_TEST(ra.round_added == rb.round_added, boost::test_tools::per_element());
  BOOST_TEST(ra.round_max_indicator == rb.round_max_indicator, boost::test_tools::per_element());
  BOOST_TEST(ra.round_mean_indicator == rb.round_mean_indicator, boost::test_tools::per_element());
  BOOST_TEST(ra.initial_snapshots == rb.initial_snapshots);
}

}  // namespace

BOOST_AUTO_TEST_CASE(first_point_added_is_where_the_true_error_is_largest) {
  const auto problem = fom::make_problem("hertz");
  // The primal estimate (its effectivity on hertz is close to 1), against the true
  // relative H¹ error: a continuous quantity with one largest value.
  rom::AdaptiveOptions o = small_options();
  o.indicator = "primal";
  o.batch = 1;
  o.max_snapshots = 3;  // the initial 2, then one
  const rom::AdaptiveTrainer trainer(*problem, o);
  const rom::SnapshotDatabase db = trainer.run();
  BOOST_REQUIRE_EQUAL(db.num_snapshots(), 3);
  const fom::Param added = db.parameter(2);

  // The true errors of the initial model at every candidate, against the FOM.
  rom::SnapshotDatabase initial = db;
  initial.parameters.conservativeResize(Eigen::NoChange, 2);
  initial.primal.conservativeResize(Eigen::NoChange, 2);
  initial.dual.conservativeResize(Eigen::NoChange, 2);
  initial.status.resize(2);
  const rom::ReducedModel model(*problem, initial, o.model);
  const auto solver = rom::make_online_solver("greedy", model);
  const fom::ActiveSetSolver fom_solver(*problem);
  const std::vector<fom::Param>& candidates = trainer.candidates();
  const auto references = rom::compute_references(fom_solver, candidates, 1);
  const rom::EvaluationSummary s = rom::evaluate_online(*solver, candidates, references);
  int worst = 0;
  const auto error = [&](int i) { return s.rows[i].primal_error; };
  for (int i = 1; i < static_cast<int>(candidates.size()); ++i)
    if (error(i) > error(worst)) worst = i;
  BOOST_TEST_MESSAGE("added d = " << added(0) << ", largest true error " << error(worst) << " at d = "
                                  << candidates[worst](0));
  BOOST_TEST(error(worst) > 0.05);  // the initial model (2 snapshots) is poor somewhere
  BOOST_TEST((added == candidates[worst]));
  int ties = 0;  // the largest error is one candidate's: the pick is not the first of a tie
  for (int i = 0; i < static_cast<int>(candidates.size()); ++i) ties += error(i) > (1.0 - 1e-6) * error(worst);
  BOOST_TEST(ties == 1);
  // The indicator ranks it as the round recorded.
  BOOST_TEST(db.adaptive.round_max_indicator[0] == trainer.indicator(solver->solve(added)),
             boost::test_tools::tolerance(1e-12));
}

BOOST_AUTO_TEST_CASE(rounds_are_recorded_and_the_indicator_falls) {
  const auto problem = fom::make_problem("hertz");
  std::vector<rom::AdaptiveRound> seen;
  rom::AdaptiveOptions o = small_options();
  o.on_round = [&](const rom::AdaptiveRound& r, const rom::SnapshotDatabase& db) {
    seen.push_back(r);
    BOOST_TEST(db.adaptive.num_rounds() == r.round + 1);  // the database holds the round
  };
  const rom::SnapshotDatabase db = rom::AdaptiveTrainer(*problem, o).run();
  const rom::AdaptiveRecord& rec = db.adaptive;
  BOOST_TEST(db.training_kind == "adaptive");
  BOOST_TEST(db.num_snapshots() == 8);
  BOOST_REQUIRE_EQUAL(rec.num_rounds(), 4);  // 2 + 2 + 2 + 2 snapshots, then the final evaluation
  BOOST_REQUIRE_EQUAL(static_cast<int>(seen.size()), rec.num_rounds());
  for (int k = 0; k < rec.num_rounds(); ++k) {
    BOOST_TEST(rec.round_snapshots[k] == 2 + 2 * k);
    BOOST_TEST(rec.round_added[k] == (k + 1 < rec.num_rounds() ? 2 : 0));
    BOOST_TEST(seen[k].candidates == o.candidates - 2 * k);  // the added candidates are not evaluated again
    BOOST_TEST(rec.round_mean_indicator[k] <= rec.round_max_indicator[k]);
  }
  BOOST_TEST(seen.back().stop == "max_snapshots");
  BOOST_TEST(rec.round_max_indicator.back() < rec.round_max_indicator.front());
  // Every added snapshot is a candidate; the file round-trips the record.
  const std::string path = test::temp_dir() + "/adaptive.h5";
  rom::write_database(path, db);
  const rom::SnapshotDatabase back = rom::read_database(path);
  check_same_database(db, back);
  BOOST_TEST(rom::adaptive_options_of(back).tolerance == o.tolerance);
  BOOST_TEST(rom::adaptive_options_of(back).indicator == "max");
  BOOST_TEST((back.adaptive.settings == rom::adaptive_record_table().to_values(o)));
  rom::check_database(back, *problem, path);  // an adaptive database is a valid database
  BOOST_CHECK_THROW(rom::database_validation_set(back, *problem), InputError);
}

BOOST_AUTO_TEST_CASE(an_interrupted_run_continued_from_its_file_equals_an_uninterrupted_one) {
  const auto problem = fom::make_problem("hertz");
  const rom::SnapshotDatabase whole = rom::AdaptiveTrainer(*problem, small_options()).run();

  // Interrupted after its second round; the file holds what on_round wrote last.
  const std::string path = test::temp_dir() + "/interrupted.h5";
  rom::AdaptiveOptions o = small_options();
  o.on_round = [&](const rom::AdaptiveRound& r, const rom::SnapshotDatabase& db) {
    rom::write_database(path, db);
    if (r.round == 1) throw Interrupted();
  };
  BOOST_CHECK_THROW(rom::AdaptiveTrainer(*problem, o).run(), Interrupted);
  const rom::SnapshotDatabase partial = rom::read_database(path);
  BOOST_TEST(partial.num_snapshots() == 6);
  const rom::SnapshotDatabase resumed = rom::AdaptiveTrainer(*problem, small_options()).resume(partial, path);
  check_same_database(whole, resumed);

  // A run that stopped at N = 4 and is continued with N = 8 ends the same too (the
  // round that stopped it is evaluated again).
  rom::AdaptiveOptions four = small_options();
  four.max_snapshots = 4;
  const rom::SnapshotDatabase stopped = rom::AdaptiveTrainer(*problem, four).run();
  BOOST_TEST(stopped.adaptive.round_added.back() == 0);
  check_same_database(whole, rom::AdaptiveTrainer(*problem, small_options()).resume(stopped, path));

  // Settings that change the candidates or their ranking cannot change on the way.
  rom::AdaptiveOptions other = small_options();
  other.seed = 2;
  BOOST_CHECK_THROW(rom::AdaptiveTrainer(*problem, other).resume(partial, path), InputError);
  other = small_options();
  other.indicator = "dual";
  BOOST_CHECK_THROW(rom::AdaptiveTrainer(*problem, other).resume(partial, path), InputError);
}

BOOST_AUTO_TEST_CASE(merge_refuses_an_adaptive_database_by_name) {
  const auto problem = fom::make_problem("hertz");
  rom::AdaptiveOptions o = small_options();
  o.max_snapshots = 4;
  const rom::SnapshotDatabase adaptive = rom::AdaptiveTrainer(*problem, o).run();
  const rom::SnapshotDatabase grid = rom::generate_snapshots(*problem, 3);
  for (const auto& [dbs, names] :
       {std::pair{std::vector{grid, adaptive}, std::vector<std::string>{"grid.h5", "run.h5"}},
        std::pair{std::vector{adaptive}, std::vector<std::string>{"run.h5"}}}) {
    try {
      rom::merge_in_training_order(dbs, names);
      BOOST_ERROR("an adaptive database was merged");
    } catch (const InputError& e) {
      const std::string msg = e.what();
      BOOST_TEST(msg.find("'run.h5'") != std::string::npos, msg);
      BOOST_TEST(msg.find("adaptive database") != std::string::npos, msg);
      BOOST_TEST(msg.find('\n') == std::string::npos, msg);
    }
  }
  // The CLI: exit 2 with that one line.
  const std::string dir = test::temp_dir();
  rom::write_database(dir + "/run.h5", adaptive);
  const auto r = test::run_command(std::string(CONTACTROM_EXE) + " merge " + dir + "/run.h5 --out " + dir + "/out.h5");
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(r.err.find("adaptive database") != std::string::npos, r.err);
  BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1, r.err);
  BOOST_TEST(!std::ifstream(dir + "/out.h5").good());
}

BOOST_AUTO_TEST_CASE(thread_count_does_not_change_the_database) {
  const auto problem = fom::make_problem("hertz");
  rom::AdaptiveOptions two = small_options();
  two.offline.threads = 2;
  two.max_snapshots = 6;
  rom::AdaptiveOptions one = two;
  one.offline.threads = 1;
  check_same_database(rom::AdaptiveTrainer(*problem, one).run(), rom::AdaptiveTrainer(*problem, two).run());
}

BOOST_AUTO_TEST_CASE(bad_options_are_refused) {
  const auto problem = fom::make_problem("hertz");
  const auto refused = [&](const std::function<void(rom::AdaptiveOptions&)>& change, const std::string& word) {
    rom::AdaptiveOptions o = small_options();
    change(o);
    try {
      rom::AdaptiveTrainer trainer(*problem, o);
      BOOST_ERROR("accepted a bad " << word);
    } catch (const InputError& e) {
      BOOST_TEST(std::string(e.what()).find(word) != std::string::npos, e.what());
    }
  };
  refused([](auto& o) { o.tolerance = 0.0; }, "tolerance");
  refused([](auto& o) { o.tolerance = std::numeric_limits<double>::quiet_NaN(); }, "tolerance");
  refused([](auto& o) { o.max_snapshots = 0; }, "max_snapshots");
  refused([](auto& o) { o.candidates = 0; }, "candidates");
  refused([](auto& o) { o.batch = 0; }, "batch");
  refused([](auto& o) { o.indicator = "both"; }, "indicator");
  refused([](auto& o) { o.method = "nope"; }, "nope");
  refused([](auto& o) { o.model.delta = 2.0; }, "delta");
}

namespace {

/// The group /adaptive of a database file, open for writing attributes with the
/// HDF5 API alone.
class AdaptiveGroup {
 public:
  explicit AdaptiveGroup(const std::string& path)
      : m_file(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT)), m_group(H5Gopen2(m_file, "adaptive", H5P_DEFAULT)),
        m_scalar(H5Screate(H5S_SCALAR)) {
    BOOST_REQUIRE(m_file >= 0 && m_group >= 0);
  }
  ~AdaptiveGroup() {
    H5Sclose(m_scalar);
    H5Gclose(m_group);
    H5Fclose(m_file);
  }
  /// (Re)writes the scalar attribute `name`.
  void put(const char* name, hid_t file_type, hid_t memory_type, const void* value) {
    if (H5Aexists(m_group, name) > 0) H5Adelete(m_group, name);
    const hid_t attr = H5Acreate2(m_group, name, file_type, m_scalar, H5P_DEFAULT, H5P_DEFAULT);
    BOOST_REQUIRE(attr >= 0);
    BOOST_REQUIRE(H5Awrite(attr, memory_type, value) >= 0);
    H5Aclose(attr);
  }

 private:
  hid_t m_file, m_group, m_scalar;
};

/// Replaces the settings of the group /adaptive of `path` by attributes in the
/// layout adaptive databases have always had: ε and δ 64-bit reals, N, M, B and the
/// seed 32-bit integers, the indicator and the method fixed-length strings.
void rewrite_settings_by_hand(const std::string& path) {
  AdaptiveGroup group(path);
  const double tolerance = 0.0375, delta = 1e-6;
  group.put("tolerance", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &tolerance);
  group.put("delta", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &delta);
  const int max_snapshots = 11, candidates = 40, batch = 3, seed = 5;
  group.put("max_snapshots", H5T_STD_I32LE, H5T_NATIVE_INT, &max_snapshots);
  group.put("candidates", H5T_STD_I32LE, H5T_NATIVE_INT, &candidates);
  group.put("batch", H5T_STD_I32LE, H5T_NATIVE_INT, &batch);
  group.put("seed", H5T_STD_I32LE, H5T_NATIVE_INT, &seed);
  for (const auto& [name, text] : {std::pair<const char*, std::string>{"indicator", "dual"}, {"method", "greedy"}}) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, text.size());
    H5Tset_strpad(type, H5T_STR_NULLPAD);
    group.put(name, type, type, text.data());
    H5Tclose(type);
  }
}

}  // namespace

BOOST_AUTO_TEST_CASE(a_database_whose_settings_were_written_by_hand_in_the_layout_loads) {
  // The settings are read by their declarations (adaptive_record_table()): a file in
  // the layout of /adaptive (docs/database_format.md) loads, with each value.
  const auto problem = fom::make_problem("hertz");
  rom::AdaptiveOptions o = small_options();
  o.max_snapshots = 4;
  const std::string path = test::temp_dir() + "/by_hand.h5";
  rom::write_database(path, rom::AdaptiveTrainer(*problem, o).run());
  rewrite_settings_by_hand(path);
  const rom::SnapshotDatabase db = rom::read_database(path);
  const rom::AdaptiveOptions back = rom::adaptive_options_of(db);
  BOOST_TEST(back.tolerance == 0.0375);
  BOOST_TEST(back.model.delta == 1e-6);
  BOOST_TEST(back.max_snapshots == 11);
  BOOST_TEST(back.candidates == 40);
  BOOST_TEST(back.batch == 3);
  BOOST_TEST(back.seed == 5);
  BOOST_TEST(back.indicator == "dual");
  BOOST_TEST(back.method == "greedy");
  BOOST_TEST(back.initial == db.training_size);
  BOOST_TEST(db.adaptive.settings.size() == rom::adaptive_record_table().specs().size());
  // Written again, the file holds the same attributes with the same values.
  rom::write_database(path + ".again.h5", db);
  BOOST_TEST((rom::read_database(path + ".again.h5").adaptive.settings == db.adaptive.settings));
}

BOOST_AUTO_TEST_CASE(a_recorded_setting_outside_its_declaration_is_refused_on_reading) {
  const auto problem = fom::make_problem("hertz");
  rom::AdaptiveOptions o = small_options();
  o.max_snapshots = 2;  // the initial set only: one round
  const std::string path = test::temp_dir() + "/bad_setting.h5";
  rom::write_database(path, rom::AdaptiveTrainer(*problem, o).run());
  {
    const int zero = 0;
    AdaptiveGroup(path).put("batch", H5T_STD_I32LE, H5T_NATIVE_INT, &zero);
  }
  try {
    rom::read_database(path);
    BOOST_ERROR("a batch of 0 was read");
  } catch (const InputError& e) {
    const std::string msg = e.what();
    BOOST_TEST(msg.find("attribute /adaptive/batch = '0' invalid; expected an integer in [1, 100000]") !=
                   std::string::npos,
               msg);
  }
}
