// Splitting and merging databases (rom/database_merge.hpp, `offline --part`,
// `merge`): parts cover the training set contiguously and in balance, the merge of
// the parts equals the whole run bitwise, and incompatible databases are refused.
#define BOOST_TEST_MODULE rom_database_merge
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <filesystem>

#include "common/database_checks.hpp"
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/database_merge.hpp>
#include <contactrom/rom/offline.hpp>

namespace fs = std::filesystem;
using contactrom::InputError;
using contactrom::rom::merge_databases;
using contactrom::rom::part_range;
using contactrom::rom::SnapshotDatabase;
using contactrom::test::check_same_snapshots;
using contactrom::test::hertz;
using contactrom::test::run_command;
using contactrom::test::work_dir;

namespace {

const std::string exe = CONTACTROM_EXE;

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

contactrom::rom::OfflineOptions chains_of_two() {
  contactrom::rom::OfflineOptions o;
  o.chain = 2;
  return o;
}

}  // namespace

BOOST_AUTO_TEST_CASE(parts_are_contiguous_balanced_whole_chains_and_cover_everything) {
  for (int chain : {1, 3, 8})
    for (int n : {0, 1, 7, 30, 121})
      for (int parts : {1, 2, 3, 8}) {
        const int chains = (n + chain - 1) / chain;
        int expected_begin = 0;
        for (int k = 1; k <= parts; ++k) {
          const auto [begin, end] = part_range(n, k, parts, chain);
          BOOST_TEST(begin == expected_begin);
          BOOST_TEST(begin % chain == 0);  // a part starts a chain
          const int held = (end - begin + chain - 1) / chain;  // chains, the last one maybe short
          BOOST_TEST(held >= chains / parts);
          BOOST_TEST(held <= chains / parts + 1);
          expected_begin = end;
        }
        BOOST_TEST(expected_begin == n);
      }
  BOOST_CHECK_THROW(part_range(10, 0, 2, 1), InputError);
  BOOST_CHECK_THROW(part_range(10, 3, 2, 1), InputError);
  BOOST_CHECK_THROW(part_range(10, 1, 0, 1), InputError);
}

BOOST_AUTO_TEST_CASE(merge_of_the_parts_equals_the_whole) {
  // Chains of 2: parts that split the list at chain boundaries compute what the whole does.
  const auto params = contactrom::fom::training_set(hertz(), 7);
  const SnapshotDatabase whole = contactrom::rom::generate_snapshots(hertz(), params, "train", 7, chains_of_two());
  std::vector<SnapshotDatabase> parts;
  for (int k = 1; k <= 3; ++k) {
    const auto [begin, end] = part_range(7, k, 3, 2);
    parts.push_back(contactrom::rom::generate_snapshots(
        hertz(), std::vector<contactrom::fom::Param>(params.begin() + begin, params.begin() + end), "train", 7,
        chains_of_two()));
  }
  check_same_snapshots(merge_databases(parts, {"a", "b", "c"}), whole);
}

BOOST_AUTO_TEST_CASE(merge_of_parts_on_disk_refers_to_them_and_writes_the_whole) {
  // Parts read without their primal snapshots are merged by reference (and in
  // another order by append_snapshots); writing copies the snapshots one by one.
  const auto params = contactrom::fom::training_set(hertz(), 7);
  const SnapshotDatabase whole = contactrom::rom::generate_snapshots(hertz(), params, "train", 7, chains_of_two());
  std::vector<SnapshotDatabase> parts;
  std::vector<std::string> names;
  for (int k = 1; k <= 3; ++k) {
    const auto [begin, end] = part_range(7, k, 3, 2);
    names.push_back(work_dir() + "/disk_part" + std::to_string(k) + ".h5");
    contactrom::rom::write_database(names.back(), contactrom::rom::generate_snapshots(
        hertz(), std::vector<contactrom::fom::Param>(params.begin() + begin, params.begin() + end), "train", 7,
        chains_of_two()));
    parts.push_back(contactrom::rom::read_database(names.back(), false));
  }
  const SnapshotDatabase merged = merge_databases(parts, names);
  BOOST_TEST(!merged.primal_in_memory());
  BOOST_TEST(merged.primal_files == names);
  const std::string out = work_dir() + "/disk_merged.h5";
  contactrom::rom::write_database(out, merged);
  check_same_snapshots(contactrom::rom::read_database(out), whole);
  // The last part appended to the first two (reordered into training order).
  const SnapshotDatabase appended = contactrom::rom::append_snapshots(
      merge_databases({parts[2], parts[0]}, {names[2], names[0]}), "x", parts[1], params);
  contactrom::rom::write_database(out, appended);
  check_same_snapshots(contactrom::rom::read_database(out), whole);
  // In memory and on disk do not mix.
  BOOST_CHECK_THROW(merge_databases({parts[0], whole}, {"a", "b"}), std::invalid_argument);
}

BOOST_AUTO_TEST_CASE(incompatible_databases_and_repeated_parameters_are_refused) {
  const SnapshotDatabase a = contactrom::rom::generate_snapshots(hertz(), 2);
  auto refused = [&](const SnapshotDatabase& b, const std::string& what) {
    try {
      merge_databases({a, b}, {"a.h5", "b.h5"});
      BOOST_ERROR(what << " accepted");
    } catch (const InputError& e) {
      const std::string msg = e.what();
      BOOST_TEST((msg.find("a.h5") != std::string::npos && msg.find("b.h5") != std::string::npos), msg);
      BOOST_TEST(msg.find(what) != std::string::npos, msg);
    }
  };
  SnapshotDatabase b = a;
  b.problem.fingerprint = "00000000deadbeef";
  refused(b, "fingerprint");
  b = a;
  b.training_size = 3;
  refused(b, "training set");
  b = a;
  b.problem.name = "ironing";
  refused(b, "problem");
  BOOST_CHECK_THROW(merge_databases({a, a}, {"a.h5", "a2.h5"}), InputError);  // same parameters twice
}

BOOST_AUTO_TEST_CASE(cli_offline_parts_merge_into_the_whole_run) {
  const std::string dir = work_dir();
  auto r = run_command(exe + " offline --problem hertz --train 9 --threads 1 --out " + dir + "/whole.h5");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  for (int k : {1, 2}) {
    r = run_command(exe + " offline --problem hertz --train 9 --threads 1 --part " + std::to_string(k) + "/2 --out " +
                    dir + "/part" + std::to_string(k) + ".h5");
    BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  }
  r = run_command(exe + " merge " + dir + "/part1.h5 " + dir + "/part2.h5 --out " + dir + "/merged.h5 --json");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  BOOST_TEST(lines(r.out) == 1);
  check_same_snapshots(contactrom::rom::read_database(dir + "/merged.h5"),
                       contactrom::rom::read_database(dir + "/whole.h5"));

  // A part twice: one line, exit code 2, no output file.
  r = run_command(exe + " merge " + dir + "/part1.h5 " + dir + "/part1.h5 --out " + dir + "/twice.h5");
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(lines(r.err) == 1, r.err);
  BOOST_TEST(!fs::exists(dir + "/twice.h5"));
  r = run_command(exe + " offline --problem hertz --train 9 --part 3/2 --out " + dir + "/bad.h5");
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(r.err.find("3/2") != std::string::npos, r.err);
  BOOST_TEST(!fs::exists(dir + "/bad.h5"));
}

BOOST_AUTO_TEST_CASE(cli_offline_append_completes_a_part_into_the_whole_run) {
  const std::string dir = work_dir();
  auto r = run_command(exe + " offline --problem hertz --train 9 --threads 1 --out " + dir + "/whole9.h5");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const SnapshotDatabase whole = contactrom::rom::read_database(dir + "/whole9.h5");

  // The second half appended to the first, and the first appended to the second:
  // both are the whole run, in training order.
  for (const auto& [first, second] : {std::pair<int, int>{1, 2}, std::pair<int, int>{2, 1}}) {
    const std::string db = dir + "/append" + std::to_string(first) + ".h5";
    r = run_command(exe + " offline --problem hertz --train 9 --threads 1 --part " + std::to_string(first) +
                    "/2 --out " + db);
    BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
    const int before = contactrom::rom::read_database(db).num_snapshots();
    r = run_command(exe + " offline --problem hertz --train 9 --threads 1 --part " + std::to_string(second) +
                    "/2 --append " + db + " --json");
    BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
    BOOST_TEST(lines(r.out) == 1);
    BOOST_TEST(r.out.find("\"snapshots\":" + std::to_string(9 - before)) != std::string::npos, r.out);
    check_same_snapshots(whole, contactrom::rom::read_database(db));
  }

  // Without --part and --train, the parameters the database lacks (here none).
  const std::string db = dir + "/append1.h5";
  r = run_command(exe + " offline --problem hertz --threads 1 --append " + db + " --json");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  BOOST_TEST(r.out.find("\"snapshots\":0") != std::string::npos, r.out);
  check_same_snapshots(whole, contactrom::rom::read_database(db));
}

BOOST_AUTO_TEST_CASE(cli_offline_append_to_another_database_is_refused_and_leaves_it_intact) {
  const std::string dir = work_dir();
  const std::string db = dir + "/part_of_7.h5";
  auto r = run_command(exe + " offline --problem hertz --train 7 --threads 1 --part 1/2 --out " + db);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const std::string before = contactrom::test::slurp(db);
  for (const std::string& args : std::vector<std::string>{"--problem ironing --level 3", "--problem hertz --refine 1 --train 7",
                                 "--problem hertz --train 8", "--problem hertz --train 7 --out " + dir + "/x.h5"}) {
    r = run_command(exe + " offline " + args + " --threads 1 --append " + db);
    BOOST_TEST_CONTEXT(args) {
      BOOST_TEST(r.exit_code == 2);
      BOOST_TEST(lines(r.err) == 1, r.err);
      BOOST_TEST(contactrom::test::slurp(db) == before);
    }
  }
  BOOST_TEST(!fs::exists(dir + "/x.h5"));
}
