#pragma once
// Shared by the offline-stage tests: the hertz problem, a temporary folder for the
// run, and the comparisons of two snapshot databases.
#include <boost/test/unit_test.hpp>

#include <cstring>
#include <filesystem>
#include <string>

#include "common/run_command.hpp"
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace contactrom::test {

/// The shipped hertz problem, built once per test program.
inline const fom::Problem& hertz() {
  static const auto problem = fom::make_problem("hertz");
  return *problem;
}

/// A temporary folder for this test program, removed when it ends.
inline const std::string& work_dir() {
  struct WorkDir {
    std::string path = temp_dir();
    ~WorkDir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const WorkDir dir;
  return dir.path;
}

/// Same sizes and the same bytes.
inline bool bitwise_equal(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

/// Checks that `b` holds the snapshots of `a` bitwise, for the same problem and
/// training set (the timing fields and `threads` may differ).
inline void check_same_snapshots(const rom::SnapshotDatabase& a, const rom::SnapshotDatabase& b) {
  BOOST_TEST(b.problem.name == a.problem.name);
  BOOST_TEST(b.problem.fingerprint == a.problem.fingerprint);
  BOOST_TEST(b.training_kind == a.training_kind);
  BOOST_TEST(b.training_size == a.training_size);
  BOOST_TEST(b.problem.param_names == a.problem.param_names);
  BOOST_TEST(bitwise_equal(b.parameters, a.parameters));
  BOOST_TEST(bitwise_equal(b.primal, a.primal));
  BOOST_TEST(bitwise_equal(b.dual, a.dual));
  BOOST_TEST(b.status == a.status);
  BOOST_TEST(b.iterations == a.iterations);
  BOOST_TEST(b.pairing_iterations == a.pairing_iterations);
}

/// Checks that `b` holds the snapshots of `a` at the same parameters to `tolerance`
/// (largest difference relative to the largest entry, primal and dual separately):
/// the same FOM answers computed from other starts.
inline void check_close_snapshots(const rom::SnapshotDatabase& a, const rom::SnapshotDatabase& b, double tolerance) {
  BOOST_TEST(bitwise_equal(b.parameters, a.parameters));
  BOOST_TEST_REQUIRE(b.primal.cols() == a.primal.cols());
  BOOST_TEST((b.primal - a.primal).cwiseAbs().maxCoeff() <= tolerance * a.primal.cwiseAbs().maxCoeff());
  BOOST_TEST((b.dual - a.dual).cwiseAbs().maxCoeff() <= tolerance * a.dual.cwiseAbs().maxCoeff());
  BOOST_TEST(b.status == a.status);
}

}  // namespace contactrom::test
