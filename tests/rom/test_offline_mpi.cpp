// Tests of the MPI offline stage (built with CONTACTROM_MPI): mpirun -np 2 and 3
// write a database whose arrays are bit-identical to the serial run's (2D and 3D); bad input
// and I/O errors end every rank with a non-zero code, one message and no file;
// `mpirun -np 2 reduce` shares the POD and gives the serial basis to rounding.
#define BOOST_TEST_MODULE rom_offline_mpi
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "common/database_checks.hpp"
#include <contactrom/rom/reduced_model_file.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace fs = std::filesystem;
using contactrom::rom::read_database;
using contactrom::rom::SnapshotDatabase;
using contactrom::test::check_same_snapshots;
using contactrom::test::run_command;
using contactrom::test::work_dir;

namespace {

const std::string exe = CONTACTROM_EXE;

/// mpirun with N ranks, allowed as root (as in CI) and on more ranks than cores.
std::string mpirun(int ranks) {
  return std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ") + CONTACTROM_MPIEXEC +
         " --oversubscribe -np " + std::to_string(ranks) + " ";
}

/// Lines of `text` that carry a contactrom message (mpirun adds its own summary).
int contactrom_lines(const std::string& text) {
  int n = 0;
  for (size_t pos = 0; (pos = text.find("contactrom: ", pos)) != std::string::npos; ++pos) ++n;
  return n;
}

}  // namespace

BOOST_AUTO_TEST_CASE(mpi_offline_is_bit_identical_to_serial) {
  const std::string serial = work_dir() + "/serial.h5";
  auto r = run_command(exe + " offline --problem hertz --train 13 --threads 1 --out " + serial);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const SnapshotDatabase a = read_database(serial);
  for (int ranks : {2, 3}) {
    const std::string path = work_dir() + "/mpi" + std::to_string(ranks) + ".h5";
    r = run_command(mpirun(ranks) + exe + " offline --problem hertz --train 13 --threads 1 --json --out " + path);
    BOOST_TEST_CONTEXT(ranks << " ranks") {
      BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
      BOOST_TEST(std::count(r.out.begin(), r.out.end(), '\n') == 1);  // one JSON object, from rank 0
      BOOST_TEST(r.out.find("\"ranks\":" + std::to_string(ranks)) != std::string::npos, r.out);
      const SnapshotDatabase b = read_database(path);
      check_same_snapshots(a, b);
      BOOST_TEST(b.threads == ranks);
    }
  }
}

BOOST_AUTO_TEST_CASE(mpi_offline_of_a_3d_problem_is_bit_identical_to_serial) {
  // hertz3d (tetrahedra, node-to-face contact): each rank meshes and factorises on
  // its own, rank 0 gathers; the snapshots are those of one serial run.
  const std::string serial = work_dir() + "/serial3d.h5", path = work_dir() + "/mpi3d.h5";
  auto r = run_command(exe + " offline --problem hertz3d --train 4 --threads 1 --out " + serial);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  r = run_command(mpirun(2) + exe + " offline --problem hertz3d --train 4 --threads 1 --out " + path);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const SnapshotDatabase a = read_database(serial), b = read_database(path);
  BOOST_TEST(a.num_dofs() > 10000);  // 3D: three dofs per node
  BOOST_TEST(a.successful_snapshots().size() == 4u);
  check_same_snapshots(a, b);
  BOOST_TEST(b.threads == 2);
}

BOOST_AUTO_TEST_CASE(parts_merge_and_append_of_a_3d_problem_equal_one_run) {
  // hertz3d: `--part k/K` files merged (in either order) and a part completed by
  // `--append` hold the snapshots of one serial run, bit for bit.
  const std::string d = work_dir(), train = " offline --problem hertz3d --train 4 --threads 1";
  auto r = run_command(exe + train + " --out " + d + "/whole3d.h5");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  for (const char* part : {"1", "2"}) {
    r = run_command(exe + train + " --part " + part + "/2 --out " + d + "/part" + part + "_3d.h5");
    BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  }
  r = run_command(exe + " merge --out " + d + "/merged3d.h5 " + d + "/part2_3d.h5 " + d + "/part1_3d.h5");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  r = run_command(exe + train + " --append " + d + "/part1_3d.h5");
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const SnapshotDatabase whole = read_database(d + "/whole3d.h5");
  BOOST_TEST(whole.num_dofs() > 10000);
  BOOST_TEST(whole.successful_snapshots().size() == 4u);
  check_same_snapshots(whole, read_database(d + "/merged3d.h5"));
  check_same_snapshots(whole, read_database(d + "/part1_3d.h5"));
}

BOOST_AUTO_TEST_CASE(mpi_offline_append_completes_a_serial_part) {
  const std::string serial = work_dir() + "/serial11.h5", db = work_dir() + "/append.h5";
  auto r = run_command(exe + " offline --problem hertz --train 11 --threads 1 --out " + serial);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  r = run_command(exe + " offline --problem hertz --train 11 --threads 1 --part 1/3 --out " + db);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  r = run_command(mpirun(2) + exe + " offline --problem hertz --train 11 --threads 1 --append " + db);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  check_same_snapshots(read_database(serial), read_database(db));
}

BOOST_AUTO_TEST_CASE(mpi_offline_bad_argument_fails_on_every_rank_with_one_message) {
  const std::string db = work_dir() + "/bad.h5";
  for (const std::string args : {"--problem cylinder --train 3", "--problem hertz --train 0", "--problem hertz"}) {
    const auto r = run_command(mpirun(2) + exe + " offline " + args + " --out " + db);
    BOOST_TEST_CONTEXT(args) {
      BOOST_TEST(r.exit_code != 0);
      BOOST_TEST(contactrom_lines(r.err) == 1, r.err);
      BOOST_TEST(!fs::exists(db));
    }
  }
}

BOOST_AUTO_TEST_CASE(mpi_refusals_end_every_rank_without_waiting) {
  // Settings refused after the ranks had begun the shared POD left the others waiting
  // in it; `timeout` turns such a hang into 124. A command that does not share its
  // work over ranks is refused under mpirun rather than run once per rank.
  const std::string dir = work_dir(), db = dir + "/refusals.h5";
  BOOST_REQUIRE(run_command(exe + " offline --problem rope --out " + db).exit_code == 0);
  const std::vector<std::string> refused = {" reduce --db " + db + " --option init=bogus --out " + dir + "/r.h5",
                                            " reduce --db " + db + " --pod svd --out " + dir + "/r.h5",
                                            std::string(" fom --problem rope --param 20 --json"),
                                            " online --db " + db + " --param 20"};
  for (const std::string& args : refused) {
    const auto r = run_command("timeout 120 env " + mpirun(2) + exe + args);
    BOOST_TEST_CONTEXT(args) {
      BOOST_TEST(r.exit_code != 0);
      BOOST_TEST(r.exit_code != 124);
      BOOST_TEST(contactrom_lines(r.err) == 1, r.err);
      BOOST_TEST(r.out.empty(), r.out);
      BOOST_TEST(!fs::exists(dir + "/r.h5"));
    }
  }
}

BOOST_AUTO_TEST_CASE(mpi_offline_unwritable_target_fails_with_one_message_and_no_file) {
  const std::string target = work_dir() + "/no/such/dir/x.h5";
  const auto r = run_command(mpirun(2) + exe + " offline --problem hertz --train 3 --threads 1 --out " + target);
  BOOST_TEST(r.exit_code != 0);
  BOOST_TEST(contactrom_lines(r.err) == 1, r.err);
  BOOST_TEST(r.err.find("no/such/dir/x.h5") != std::string::npos, r.err);
  BOOST_TEST(!fs::exists(target));
}

namespace {

/// sin of the largest principal angle between the spans of two orthonormal bases.
double subspace_distance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const Eigen::MatrixXd residual = a - b * (b.transpose() * a);
  return Eigen::JacobiSVD<Eigen::MatrixXd>(residual).singularValues()(0);
}

}  // namespace

BOOST_AUTO_TEST_CASE(mpi_reduce_shares_the_pod_and_gives_the_serial_basis) {
  const std::string dir = work_dir(), db = dir + "/reduce40.h5";
  auto r = run_command(exe + " offline --problem hertz --train 40 --threads 1 --out " + db);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const auto reduce = [&](const std::string& launcher, const std::string& pod, const std::string& out) {
    const auto res = run_command(launcher + exe + " reduce --db " + db + " --method greedy --delta 1e-10 --pod " + pod +
                                 " --threads 1 --out " + out);
    BOOST_TEST_REQUIRE(res.exit_code == 0, res.err);
    return contactrom::rom::OnlineModel::load(out);
  };
  const auto svd = reduce("", "svd", dir + "/rom_svd.h5");
  const auto serial = reduce("", "snapshots", dir + "/rom_serial.h5");
  const auto ranks = reduce(mpirun(2), "snapshots", dir + "/rom_mpi.h5");
  const int rank = svd.model().primal_rank();
  BOOST_TEST(rank >= 5);
  for (const auto* other : {&serial, &ranks}) {
    BOOST_TEST_REQUIRE(other->model().primal_rank() == rank);
    const Eigen::VectorXd a = svd.model().singular_values().head(rank), b = other->model().singular_values().head(rank);
    BOOST_TEST(((a - b).array().abs() / a.array()).maxCoeff() <= 1e-10);
    BOOST_TEST(subspace_distance(other->model().basis(), svd.model().basis()) <= 1e-8);
  }
  BOOST_TEST(subspace_distance(ranks.model().basis(), serial.model().basis()) <= 1e-8);
}

BOOST_AUTO_TEST_CASE(mpi_adaptive_offline_equals_the_serial_run) {
  // Every rank runs the loop and answers its share of the candidates (the indicators
  // gathered on every rank); the FOM batches are spread over the ranks and gathered
  // on every rank, so the database is the serial one, indicators bit for bit.
  const std::string args = " offline --problem hertz --adaptive --tolerance 0.001 --candidates 40 --batch 3"
                           " --max-snapshots 8 --threads 1 --out ";
  const std::string serial = work_dir() + "/adaptive_serial.h5";
  auto r = run_command(exe + args + serial);
  BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
  const SnapshotDatabase a = read_database(serial);
  for (int ranks : {2, 3}) {
    const std::string parallel = work_dir() + "/adaptive_mpi" + std::to_string(ranks) + ".h5";
    r = run_command(mpirun(ranks) + exe + args + parallel + " --json");
    BOOST_TEST_REQUIRE(r.exit_code == 0, r.err);
    BOOST_TEST(std::count(r.out.begin(), r.out.end(), '\n') == 1);  // one JSON object, from rank 0
    BOOST_TEST(r.out.find("\"ranks\":" + std::to_string(ranks)) != std::string::npos, r.out);
    const SnapshotDatabase b = read_database(parallel);
    check_same_snapshots(a, b);
    BOOST_TEST(a.adaptive.round_snapshots == b.adaptive.round_snapshots, boost::test_tools::per_element());
    BOOST_TEST(a.adaptive.round_max_indicator == b.adaptive.round_max_indicator, boost::test_tools::per_element());
    BOOST_TEST(a.adaptive.round_mean_indicator == b.adaptive.round_mean_indicator, boost::test_tools::per_element());
    BOOST_TEST(contactrom_lines(r.err) == a.adaptive.num_rounds());  // one progress line per round, from rank 0
  }
}
