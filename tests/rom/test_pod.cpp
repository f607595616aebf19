// POD with the energy criterion (rom/pod.hpp): the kept energy is at least 1 − δ
// and dropping one more mode would violate it; the basis is orthonormal; a planted
// low-rank matrix is reconstructed exactly; edge cases (zero matrix, δ = 0, bad input).
#define BOOST_TEST_MODULE rom_pod
#include <boost/test/unit_test.hpp>

#include <Eigen/Dense>
#include <random>

#include <contactrom/rom/pod.hpp>

using contactrom::Status;
using contactrom::rom::Pod;
using contactrom::rom::PodOptions;
using contactrom::rom::pod_truncation_rank;

namespace {

Eigen::MatrixXd random_matrix(int rows, int cols, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> dist;
  Eigen::MatrixXd a(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) a(i, j) = dist(gen);
  return a;
}

/// Snapshots with prescribed singular values: U diag(sigma) Vᵀ with random orthonormal U, V.
Eigen::MatrixXd with_singular_values(int rows, int cols, const Eigen::VectorXd& sigma, unsigned seed) {
  const Eigen::MatrixXd u = random_matrix(rows, static_cast<int>(sigma.size()), seed).householderQr().householderQ() *
                            Eigen::MatrixXd::Identity(rows, sigma.size());
  const Eigen::MatrixXd v = random_matrix(cols, static_cast<int>(sigma.size()), seed + 1).householderQr().householderQ() *
                            Eigen::MatrixXd::Identity(cols, sigma.size());
  return u * sigma.asDiagonal() * v.transpose();
}

double kept_fraction(const Eigen::VectorXd& sigma, int r) { return sigma.head(r).squaredNorm() / sigma.squaredNorm(); }

}  // namespace

BOOST_AUTO_TEST_CASE(energy_criterion_is_tight) {
  // Geometric decay over 12 orders of magnitude of energy: every δ cuts somewhere.
  Eigen::VectorXd sigma(25);
  for (int i = 0; i < sigma.size(); ++i) sigma(i) = std::pow(10.0, -0.25 * i);
  const Eigen::MatrixXd s = with_singular_values(300, 40, sigma, 7);
  for (double delta : {1e-2, 1e-4, 1e-6, 1e-8, 1e-10}) {
    PodOptions options;
    options.delta = delta;
    Pod pod(options);
    pod.compute(s);
    BOOST_REQUIRE(pod.info() == Status::Success);
    const int r = pod.rank();
    const Eigen::VectorXd& sv = pod.singular_values();
    BOOST_TEST_CONTEXT("delta " << delta << " rank " << r) {
      BOOST_TEST(r >= 1);
      BOOST_TEST(kept_fraction(sv, r) >= 1.0 - delta);
      BOOST_TEST(pod.kept_energy() >= 1.0 - delta);
      // One mode fewer would discard more than δ of the energy.
      BOOST_TEST(1.0 - kept_fraction(sv, r - 1) > delta);
    }
  }
}

BOOST_AUTO_TEST_CASE(truncation_rank_counts_the_discarded_tail) {
  const Eigen::Vector4d sigma(1.0, 1e-1, 1e-3, 1e-6);
  // total = 1 + 1e-2 + 1e-6 + 1e-12
  BOOST_TEST(pod_truncation_rank(sigma, 0.5) == 1);      // discarding 1e-2 of ~1.01 is fine
  BOOST_TEST(pod_truncation_rank(sigma, 1e-3) == 2);     // 1e-6 + 1e-12 ≤ 1e-3·total
  BOOST_TEST(pod_truncation_rank(sigma, 1e-9) == 3);     // 1e-12 ≤ 1e-9·total, 1e-6 is not
  BOOST_TEST(pod_truncation_rank(sigma, 1e-13) == 4);
  BOOST_TEST(pod_truncation_rank(sigma, 0.0) == 4);
  BOOST_TEST(pod_truncation_rank(sigma, 0.0, 1e-4) == 3);  // values below the floor are never kept
  BOOST_TEST(pod_truncation_rank(Eigen::VectorXd::Zero(3), 1e-8) == 0);
}

BOOST_AUTO_TEST_CASE(basis_is_orthonormal) {
  const Eigen::MatrixXd s = random_matrix(500, 60, 11);
  PodOptions options;
  options.delta = 1e-12;
  Pod pod(options);
  pod.compute(s);
  BOOST_REQUIRE(pod.info() == Status::Success);
  BOOST_TEST(pod.rank() == 60);
  const Eigen::MatrixXd gram = pod.basis().transpose() * pod.basis();
  BOOST_TEST((gram - Eigen::MatrixXd::Identity(60, 60)).cwiseAbs().maxCoeff() < 1e-13);
}

BOOST_AUTO_TEST_CASE(planted_low_rank_matrix_is_reconstructed) {
  // Rank 5 matrix of 1000 × 80 plus nothing: δ = 0 must find rank 5 (numerical
  // rank), and the projection must reproduce the matrix to rounding.
  const Eigen::MatrixXd s = random_matrix(1000, 5, 3) * random_matrix(5, 80, 4);
  for (double delta : {0.0, 1e-10}) {
    PodOptions options;
    options.delta = delta;
    Pod pod(options);
    pod.compute(s);
    BOOST_REQUIRE(pod.info() == Status::Success);
    BOOST_TEST(pod.rank() == 5);
    const Eigen::MatrixXd& phi = pod.basis();
    const Eigen::MatrixXd rec = phi * (phi.transpose() * s);
    BOOST_TEST((rec - s).norm() / s.norm() < 1e-13);
  }
}

BOOST_AUTO_TEST_CASE(projection_error_matches_discarded_energy) {
  // ‖S − ΦΦᵀS‖_F² equals the discarded energy Σ_{i>r} σ_i².
  Eigen::VectorXd sigma(10);
  for (int i = 0; i < 10; ++i) sigma(i) = std::pow(0.3, i);
  const Eigen::MatrixXd s = with_singular_values(200, 30, sigma, 21);
  PodOptions options;
  options.delta = 1e-5;
  Pod pod(options);
  pod.compute(s);
  BOOST_REQUIRE(pod.info() == Status::Success);
  const int r = pod.rank();
  const double discarded = sigma.tail(10 - r).squaredNorm();
  const Eigen::MatrixXd err = s - pod.basis() * (pod.basis().transpose() * s);
  BOOST_TEST(err.squaredNorm() == discarded, boost::test_tools::tolerance(1e-8));
  BOOST_TEST(discarded <= 1e-5 * sigma.squaredNorm());
}

BOOST_AUTO_TEST_CASE(edge_cases) {
  Pod pod;
  pod.compute(Eigen::MatrixXd::Zero(20, 4));  // zero snapshots: empty basis
  BOOST_TEST(pod.info() == Status::Success);
  BOOST_TEST(pod.rank() == 0);
  BOOST_TEST(pod.basis().rows() == 20);

  pod.compute(Eigen::MatrixXd(7, 0));  // no snapshots
  BOOST_TEST(pod.info() == Status::Success);
  BOOST_TEST(pod.rank() == 0);

  Eigen::MatrixXd bad = Eigen::MatrixXd::Ones(5, 3);
  bad(2, 1) = std::numeric_limits<double>::quiet_NaN();
  pod.compute(bad);
  BOOST_TEST(pod.info() == Status::InvalidInput);

  PodOptions negative;
  negative.delta = -1.0;
  Pod pod2(negative);
  pod2.compute(Eigen::MatrixXd::Ones(5, 3));
  BOOST_TEST(pod2.info() == Status::InvalidInput);

  // A single snapshot: one mode, equal to the normalised snapshot up to sign.
  const Eigen::VectorXd x = random_matrix(50, 1, 5).col(0);
  Pod pod3;
  pod3.compute(x);
  BOOST_REQUIRE(pod3.rank() == 1);
  BOOST_TEST(std::abs(pod3.basis().col(0).dot(x.normalized())) == 1.0, boost::test_tools::tolerance(1e-14));
}

namespace {

/// Options of the method of snapshots reading `s` in blocks of about `rows` rows.
PodOptions snapshot_options(double delta, const Eigen::MatrixXd& s, int rows, int threads) {
  PodOptions o;
  o.delta = delta;
  o.algorithm = contactrom::rom::PodAlgorithm::Snapshots;
  o.block_bytes = static_cast<std::int64_t>(sizeof(double)) * s.cols() * rows;
  o.threads = threads;
  return o;
}

/// sin of the largest principal angle between the spans of two orthonormal bases.
double subspace_distance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const Eigen::MatrixXd residual = a - b * (b.transpose() * a);
  return Eigen::JacobiSVD<Eigen::MatrixXd>(residual).singularValues()(0);
}

}  // namespace

BOOST_AUTO_TEST_CASE(method_of_snapshots_matches_the_svd) {
  // 400 singular values decaying geometrically over nine decades: δ = 1e-10 keeps
  // modes down to about 1e-5 σ₁, where the Gram matrix alone would give six digits.
  // (No δ falls exactly on a partial sum of the tail.)
  Eigen::VectorXd sigma(400);
  for (int i = 0; i < sigma.size(); ++i) sigma(i) = std::pow(10.0, -9.1 * i / 399.0);
  const Eigen::MatrixXd s = with_singular_values(3000, 400, sigma, 31);
  for (double delta : {1e-4, 1e-6, 1e-8, 1e-10}) {
    PodOptions svd_options;
    svd_options.delta = delta;
    svd_options.algorithm = contactrom::rom::PodAlgorithm::Svd;
    Pod svd(svd_options), snap(snapshot_options(delta, s, 290, 2));
    svd.compute(s);
    snap.compute(s);
    BOOST_REQUIRE(svd.info() == Status::Success);
    BOOST_REQUIRE(snap.info() == Status::Success);
    BOOST_TEST_CONTEXT("delta " << delta << " rank " << svd.rank()) {
      BOOST_TEST(snap.rank() == svd.rank());
      const int r = std::min(snap.rank(), svd.rank());
      const Eigen::ArrayXd relative =
          (snap.singular_values().head(r) - svd.singular_values().head(r)).array().abs() / svd.singular_values().head(r).array();
      BOOST_TEST(relative.maxCoeff() <= 1e-10);
      BOOST_TEST(subspace_distance(snap.basis(), svd.basis()) <= 1e-8);
      const Eigen::MatrixXd gram = snap.basis().transpose() * snap.basis();
      BOOST_TEST((gram - Eigen::MatrixXd::Identity(r, r)).cwiseAbs().maxCoeff() <= 1e-13);
      BOOST_TEST((snap.coordinates() - snap.basis().transpose() * s).cwiseAbs().maxCoeff() <= 1e-13 * sigma(0));
      // The discarded energy of both is the planted tail, to rounding.
      BOOST_TEST(snap.kept_energy() == svd.kept_energy(), boost::test_tools::tolerance(1e-13));
    }
  }
}

BOOST_AUTO_TEST_CASE(method_of_snapshots_does_not_depend_on_the_threads) {
  Eigen::VectorXd sigma(60);
  for (int i = 0; i < sigma.size(); ++i) sigma(i) = std::pow(0.7, i);
  const Eigen::MatrixXd s = with_singular_values(1500, 200, sigma, 41);
  Pod one(snapshot_options(1e-10, s, 100, 1)), three(snapshot_options(1e-10, s, 100, 3));
  one.compute(s);
  three.compute(s);
  BOOST_REQUIRE(one.info() == Status::Success);
  BOOST_TEST(one.rank() == three.rank());
  BOOST_TEST((one.basis() - three.basis()).cwiseAbs().maxCoeff() == 0.0);
  BOOST_TEST((one.singular_values() - three.singular_values()).cwiseAbs().maxCoeff() == 0.0);
}

BOOST_AUTO_TEST_CASE(method_of_snapshots_edge_cases) {
  // Planted rank 5 (δ = 0: the numerical rank) and its exact reconstruction.
  const Eigen::MatrixXd s = random_matrix(1000, 5, 3) * random_matrix(5, 80, 4);
  Pod pod(snapshot_options(0.0, s, 64, 2));
  pod.compute(s);
  BOOST_REQUIRE(pod.info() == Status::Success);
  BOOST_TEST(pod.rank() == 5);
  BOOST_TEST((pod.basis() * (pod.basis().transpose() * s) - s).norm() / s.norm() < 1e-13);

  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(20, 4);
  Pod z(snapshot_options(1e-8, zero, 8, 1));
  z.compute(zero);
  BOOST_TEST(z.info() == Status::Success);
  BOOST_TEST(z.rank() == 0);
  BOOST_TEST(z.basis().rows() == 20);

  Eigen::MatrixXd bad = Eigen::MatrixXd::Ones(50, 3);
  bad(20, 1) = std::numeric_limits<double>::infinity();
  Pod b(snapshot_options(1e-8, bad, 8, 1));
  b.compute(contactrom::rom::MatrixBlocks(bad));  // the block reader sees it, not a pre-check
  BOOST_TEST(b.info() == Status::InvalidInput);

  const Eigen::VectorXd x = random_matrix(50, 1, 5).col(0);
  Pod one(snapshot_options(1e-8, x, 7, 2));
  one.compute(x);
  BOOST_REQUIRE(one.rank() == 1);
  BOOST_TEST(std::abs(one.basis().col(0).dot(x.normalized())) == 1.0, boost::test_tools::tolerance(1e-14));
}

BOOST_AUTO_TEST_CASE(auto_takes_the_svd_up_to_the_size_limit_and_for_wide_sets) {
  PodOptions o;
  o.svd_max_entries = 1000;
  const Pod pod(o);
  BOOST_TEST(pod.uses_svd(100, 10));
  BOOST_TEST(!pod.uses_svd(100, 11));
  // A wide set goes to the SVD at any size (its Gram matrix would outgrow the data).
  BOOST_TEST(pod.uses_svd(100, 100));
  BOOST_TEST(pod.uses_svd(2068, 10000));
  BOOST_TEST(!pod.uses_svd(2068, 2067));
  o.algorithm = contactrom::rom::PodAlgorithm::Snapshots;
  BOOST_TEST(!Pod(o).uses_svd(100, 1000));
  o.algorithm = contactrom::rom::PodAlgorithm::Svd;
  BOOST_TEST(Pod(o).uses_svd(1000, 1000));
}
