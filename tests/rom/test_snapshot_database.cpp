// HDF5 snapshot database (rom/snapshot_database.hpp): bitwise round trip, the
// layout seen from h5py, and one-line refusals of a missing file, a non-HDF5 file,
// a truncated file, another format_version, and a database built for another
// mesh or problem.
#define BOOST_TEST_MODULE rom_snapshot_database
#include <boost/test/unit_test.hpp>

#include <contactrom/rom/hdf5_io.hpp>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <unistd.h>

#include "common/input_error.hpp"
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace fs = std::filesystem;
using contactrom::InputError;
using contactrom::Status;
using contactrom::rom::SnapshotDatabase;
using contactrom::test::input_error_of;

namespace {

/// A fresh folder for this test run, removed at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("contactrom_test_db_" + std::to_string(::getpid()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

TempDir& temp() {
  static TempDir dir;
  return dir;
}

/// A synthetic database with random data (no FOM needed).
SnapshotDatabase synthetic(int n_snap, int n_dofs, int n_c) {
  std::mt19937 gen(42);
  std::normal_distribution<double> dist;
  SnapshotDatabase db;
  db.problem.name = "hertz";
  db.problem.fingerprint = "0123456789abcdef";
  db.created_by = "contactrom test";
  db.training_kind = "train";
  db.training_size = n_snap;
  db.problem.param_names = {"d"};
  db.parameters.resize(1, n_snap);
  db.primal.resize(n_dofs, n_snap);
  db.dual.resize(n_c, n_snap);
  for (int j = 0; j < n_snap; ++j) {
    db.parameters(0, j) = 0.3 * (j + 1) / n_snap;
    for (int i = 0; i < n_dofs; ++i) db.primal(i, j) = dist(gen);
    for (int i = 0; i < n_c; ++i) db.dual(i, j) = std::abs(dist(gen));
    db.status.push_back(j == 2 ? Status::NoConvergence : Status::Success);
    db.iterations.push_back(10 + j);
    db.pairing_iterations.push_back(3 + j);
    db.time_s.push_back(1e-3 * (j + 1));
  }
  db.setup_time_s = 0.25;
  db.wall_time_s = 1.5;
  db.threads = 2;
  db.problem.contact_points = Eigen::Matrix2Xd::Random(2, n_c);
  db.problem.contact_weights = Eigen::VectorXd::Constant(n_c, 0.1);
  db.problem.lifting_terms = Eigen::MatrixXd::Random(n_dofs, 1);
  return db;
}

bool bitwise_equal(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

/// The h5py cases need /usr/bin/python3 with h5py and numpy (tools/setup.sh
/// installs them): without them the case fails, it is not skipped.
void require_h5py() {
  BOOST_REQUIRE_MESSAGE(std::system("/usr/bin/python3 -c 'import h5py, numpy' > /dev/null 2>&1") == 0,
                        "/usr/bin/python3 with h5py and numpy is needed (tools/setup.sh installs them)");
}

}  // namespace

BOOST_AUTO_TEST_CASE(round_trip_is_bitwise) {
  const SnapshotDatabase db = synthetic(7, 301, 23);
  const std::string path = temp().file("round_trip.h5");
  contactrom::rom::write_database(path, db);
  const SnapshotDatabase back = contactrom::rom::read_database(path);
  BOOST_TEST(back.problem.name == db.problem.name);
  BOOST_TEST(back.problem.fingerprint == db.problem.fingerprint);
  BOOST_TEST(back.created_by == db.created_by);
  BOOST_TEST(back.training_kind == db.training_kind);
  BOOST_TEST(back.training_size == db.training_size);
  BOOST_TEST(back.problem.param_names == db.problem.param_names, boost::test_tools::per_element());
  BOOST_TEST(bitwise_equal(back.parameters, db.parameters));
  BOOST_TEST(bitwise_equal(back.primal, db.primal));
  BOOST_TEST(bitwise_equal(back.dual, db.dual));
  BOOST_TEST(back.status == db.status);
  BOOST_TEST(back.iterations == db.iterations, boost::test_tools::per_element());
  BOOST_TEST(back.pairing_iterations == db.pairing_iterations, boost::test_tools::per_element());
  BOOST_TEST(back.time_s == db.time_s, boost::test_tools::per_element());
  BOOST_TEST(back.setup_time_s == db.setup_time_s);
  BOOST_TEST(back.threads == db.threads);
  BOOST_TEST(back.successful_snapshots().size() == 6u);
  // No temporary file is left next to the database.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(temp().path))
    if (entry.path().filename().string().rfind("round_trip.h5", 0) == 0) ++files;
  BOOST_TEST(files == 1);
}

BOOST_AUTO_TEST_CASE(layout_as_seen_from_h5py) {
  require_h5py();
  const SnapshotDatabase db = synthetic(5, 40, 9);
  const std::string path = temp().file("layout.h5");
  contactrom::rom::write_database(path, db);
  // /primal is n_snap × n_dofs, row j = snapshot j; string attributes are fixed-length (bytes in h5py).
  char script[2048];
  std::snprintf(script, sizeof script,
                "/usr/bin/python3 -c \"import h5py, numpy as np; f = h5py.File('%s', 'r'); "
                "assert f['primal'].shape == (5, 40), f['primal'].shape; "
                "assert f['dual'].shape == (5, 9); assert f['parameters'].shape == (5, 1); "
                "assert f['status'].shape == (5,); assert list(f['status'][:]) == [0, 0, 1, 0, 0]; "
                "assert int(f.attrs['format_version']) == 2; assert f.attrs['problem'].decode() == 'hertz'; "
                "assert f.attrs['mesh_fingerprint'].decode() == '0123456789abcdef'; "
                "assert f['contact/points'].shape == (9, 2); assert f['contact/weights'].shape == (9,); "
                "assert f['lifting'].shape == (1, 40); "
                "assert abs(f['primal'][3, 17] - (%.17g)) == 0; assert abs(f['dual'][4, 8] - (%.17g)) == 0; "
                "assert abs(f['parameters'][1, 0] - (%.17g)) == 0\"",
                path.c_str(), db.primal(17, 3), db.dual(8, 4), db.parameters(0, 1));
  BOOST_TEST(std::system(script) == 0);
}

BOOST_AUTO_TEST_CASE(missing_file_is_refused) {
  const std::string path = temp().file("does_not_exist.h5");
  const std::string msg = input_error_of([&] { contactrom::rom::read_database(path); });
  BOOST_TEST(msg.find(path) != std::string::npos);
  BOOST_TEST(msg.find("not found") != std::string::npos);
  BOOST_TEST(msg.find('\n') == std::string::npos);
}

BOOST_AUTO_TEST_CASE(non_hdf5_file_is_refused) {
  const std::string path = temp().file("text.h5");
  std::ofstream(path) << "d,primal\n0.1,2\n";
  const std::string msg = input_error_of([&] { contactrom::rom::read_database(path); });
  BOOST_TEST(msg.find(path) != std::string::npos);
  BOOST_TEST(msg.find("not an HDF5 file") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(truncated_file_is_refused) {
  const SnapshotDatabase db = synthetic(20, 2000, 79);
  const std::string path = temp().file("truncated.h5");
  contactrom::rom::write_database(path, db);
  const auto size = fs::file_size(path);
  fs::resize_file(path, size / 2);
  const std::string msg = input_error_of([&] { contactrom::rom::read_database(path); });
  BOOST_TEST_MESSAGE("truncated file: " << msg);
  BOOST_TEST(msg.find(path) != std::string::npos);
  BOOST_TEST(msg.find("truncated or corrupt") != std::string::npos);
  BOOST_TEST(msg.find('\n') == std::string::npos);
}

BOOST_AUTO_TEST_CASE(other_format_version_is_refused) {
  require_h5py();
  const std::string path = temp().file("version1.h5");
  contactrom::rom::write_database(path, synthetic(3, 10, 4));
  const std::string cmd = "/usr/bin/python3 -c \"import h5py; f = h5py.File('" + path +
                          "', 'r+'); f.attrs['format_version'] = 1; f.close()\"";
  BOOST_REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string msg = input_error_of([&] { contactrom::rom::read_database(path); });
  BOOST_TEST(msg.find(path) != std::string::npos);
  BOOST_TEST(msg.find("format_version 1") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(foreign_hdf5_file_is_refused) {
  require_h5py();
  const std::string path = temp().file("foreign.h5");
  const std::string cmd =
      "/usr/bin/python3 -c \"import h5py, numpy; f = h5py.File('" + path + "', 'w', libver='v108'); f['x'] = numpy.zeros(3)\"";
  BOOST_REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string msg = input_error_of([&] { contactrom::rom::read_database(path); });
  BOOST_TEST(msg.find("no format_version") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(file_without_metadata_checksums_is_refused_before_hdf5_parses_it) {
  require_h5py();
  // h5py's default is the oldest file format: superblock version 0, no checksums.
  const std::string path = temp().file("superblock0.h5");
  const std::string cmd =
      "/usr/bin/python3 -c \"import h5py, numpy; f = h5py.File('" + path + "', 'w'); f['x'] = numpy.zeros(3)\"";
  BOOST_REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string msg = input_error_of([&] { contactrom::rom::read_database(path); });
  BOOST_TEST(msg.find(path) != std::string::npos);
  BOOST_TEST(msg.find("superblock version 0") != std::string::npos, msg);
  BOOST_TEST(msg.find('\n') == std::string::npos);
}

BOOST_AUTO_TEST_CASE(written_files_carry_valid_metadata_checksums) {
  // A database contactrom writes has superblock version 2, and every checksum in
  // it is right: h5py (an independent reader) opens it and reads every dataset.
  require_h5py();
  const std::string path = temp().file("checksums.h5");
  contactrom::rom::write_database(path, synthetic(3, 10, 4));
  std::ifstream in(path, std::ios::binary);
  char head[9];
  BOOST_REQUIRE(in.read(head, 9));
  BOOST_TEST(static_cast<int>(head[8]) == 2);
  const std::string cmd = "/usr/bin/python3 -c \"import h5py; f = h5py.File('" + path +
                          "', 'r'); [f[k][()] for k in f.keys() if isinstance(f[k], h5py.Dataset)]\"";
  BOOST_TEST(std::system(cmd.c_str()) == 0);
}

BOOST_AUTO_TEST_CASE(database_of_another_mesh_or_problem_is_refused) {
  auto hertz = contactrom::fom::make_problem("hertz");
  SnapshotDatabase db;
  db.problem.name = "hertz";
  db.problem.fingerprint = hertz->fingerprint();
  db.problem.param_names = {"d"};
  db.training_size = 1;                               // hertz --train 1: d = 0.3
  db.parameters = Eigen::MatrixXd::Constant(1, 1, 0.3);
  db.primal = Eigen::MatrixXd::Zero(hertz->num_dofs(), 1);
  db.dual = Eigen::MatrixXd::Zero(hertz->contact().num_constraints(), 1);
  BOOST_CHECK_NO_THROW(contactrom::rom::check_database(db, *hertz, "ok.h5"));

  SnapshotDatabase other_mesh = db;
  other_mesh.problem.fingerprint = "ffffffffffffffff";
  const std::string msg = input_error_of([&] { contactrom::rom::check_database(other_mesh, *hertz, "db.h5"); });
  BOOST_TEST_MESSAGE(msg);
  BOOST_TEST(msg.find("database 'db.h5' was built for mesh fingerprint ffffffffffffffff but the current hertz mesh is " +
                      hertz->fingerprint()) != std::string::npos);
  BOOST_TEST(msg.find("(the mesh differs") != std::string::npos, msg);
  // A database that stores its problem file: an edited file (here one comment more)
  // is named as the cause, not the mesh.
  SnapshotDatabase edited = other_mesh;
  edited.problem.text = hertz->definition().text + "# a note\n";
  const std::string msg3 = input_error_of([&] { contactrom::rom::check_database(edited, *hertz, "db.h5"); });
  BOOST_TEST(msg3.find("(the problem file's text differs from the copy the database stores") != std::string::npos, msg3);

  SnapshotDatabase other_problem = db;
  other_problem.problem.name = "ironing";
  const std::string msg2 = input_error_of([&] { contactrom::rom::check_database(other_problem, *hertz, "db.h5"); });
  BOOST_TEST(msg2.find("built for problem 'ironing'") != std::string::npos);

  // Same fingerprint but inconsistent sizes (a hand-edited file).
  SnapshotDatabase other_size = db;
  other_size.dual = Eigen::MatrixXd::Zero(3, 1);
  BOOST_CHECK_THROW(contactrom::rom::check_database(other_size, *hertz, "db.h5"), InputError);
}

BOOST_AUTO_TEST_CASE(unwritable_target_throws_input_error) {
  const std::string path = temp().file("no_such_folder/db.h5");
  const std::string msg = input_error_of([&] { contactrom::rom::write_database(path, synthetic(2, 5, 3)); });
  BOOST_TEST(msg.find(path) != std::string::npos);
  BOOST_TEST(!fs::exists(path));
}

BOOST_AUTO_TEST_CASE(flipped_bits_are_refused_never_read_as_other_numbers) {
  // Every dataset carries a checksum of its data: a single flipped bit anywhere in
  // the file is refused (metadata: HDF5's checksums; data: contactrom's), or lies
  // in bytes nobody reads, and the arrays read back unchanged.
  const SnapshotDatabase db = synthetic(6, 40, 8);
  const std::string good = temp().file("bits_good.h5"), bad = temp().file("bits_bad.h5");
  contactrom::rom::write_database(good, db);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::mt19937 gen(7);
  int refused = 0, unchanged = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string flipped = bytes;
    const size_t at = std::uniform_int_distribution<size_t>(0, flipped.size() - 1)(gen);
    flipped[at] = static_cast<char>(flipped[at] ^ (1 << std::uniform_int_distribution<int>(0, 7)(gen)));
    std::ofstream(bad, std::ios::binary | std::ios::trunc) << flipped;
    try {
      const SnapshotDatabase back = contactrom::rom::read_database(bad);
      BOOST_TEST_CONTEXT("bit flipped in byte " << at << " of " << bytes.size()) {
        BOOST_TEST(bitwise_equal(back.primal, db.primal));
        BOOST_TEST(bitwise_equal(back.dual, db.dual));
        BOOST_TEST(bitwise_equal(back.parameters, db.parameters));
        BOOST_TEST((back.status == db.status && back.iterations == db.iterations && back.time_s == db.time_s));
        BOOST_TEST(bitwise_equal(back.problem.lifting_terms, db.problem.lifting_terms));
      }
      ++unchanged;
    } catch (const InputError&) {
      ++refused;
    }
  }
  BOOST_TEST_MESSAGE(refused << " flips refused, " << unchanged << " in bytes nobody reads");
  BOOST_TEST(refused > 200);
}

BOOST_AUTO_TEST_CASE(links_and_storage_outside_the_file_are_refused) {
  require_h5py();
  const std::string path = temp().file("links.h5"), other = temp().file("elsewhere.h5");
  contactrom::rom::write_database(path, synthetic(4, 10, 3));
  // /time_s replaced by a link to a dataset of another file.
  const std::string linked = temp().file("linked.h5");
  fs::copy_file(path, linked, fs::copy_options::overwrite_existing);
  std::string cmd = "/usr/bin/python3 -c \"import h5py, numpy; g = h5py.File('" + other +
                    "', 'w'); g['t'] = numpy.zeros(4); g.close(); f = h5py.File('" + linked +
                    "', 'a'); del f['time_s']; f['time_s'] = h5py.ExternalLink('" + other + "', '/t')\"";
  BOOST_REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string e1 = input_error_of([&] { contactrom::rom::read_database(linked); });
  BOOST_TEST(e1.find("link to another file") != std::string::npos, e1);
  // /time_s stored in an external raw file.
  const std::string external = temp().file("external.h5");
  fs::copy_file(path, external, fs::copy_options::overwrite_existing);
  std::ofstream(temp().file("raw.bin"), std::ios::binary) << std::string(32, '\0');
  cmd = "/usr/bin/python3 -c \"import h5py; f = h5py.File('" + external + "', 'a'); del f['time_s']; "
        "f.create_dataset('time_s', shape=(4,), dtype='<f8', external=[('" + temp().file("raw.bin") + "', 0, 32)])\"";
  BOOST_REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string e2 = input_error_of([&] { contactrom::rom::read_database(external); });
  BOOST_TEST(e2.find("outside the file") != std::string::npos, e2);
}

BOOST_AUTO_TEST_CASE(checksum_by_pieces_equals_the_checksum_of_the_whole) {
  // The streamed /primal is checksummed block by block: every split of the data
  // (pieces of any size, lengths around lookup3's 12-byte blocks) gives the value
  // of the whole.
  std::vector<unsigned char> data(1000);
  for (size_t i = 0; i < data.size(); ++i) data[i] = static_cast<unsigned char>((i * 2654435761u) >> 13);
  for (size_t n : {size_t{0}, size_t{1}, size_t{11}, size_t{12}, size_t{13}, size_t{24}, size_t{25}, size_t{1000}}) {
    const std::uint32_t whole = contactrom::rom::hdf5::data_checksum(data.data(), n);
    for (size_t piece : {size_t{1}, size_t{5}, size_t{12}, size_t{17}, size_t{1000}}) {
      contactrom::rom::hdf5::DataChecksum sum(n);
      for (size_t at = 0; at < n; at += piece) sum.add(data.data() + at, std::min(piece, n - at));
      BOOST_TEST(sum.value() == whole, "length " << n << ", pieces of " << piece);
    }
  }
}
