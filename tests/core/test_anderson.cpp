// AndersonMixer: on a linear fixed point x = A x + b, Anderson acceleration with
// depth >= n reaches the solution in about n + 2 steps (GMRES-equivalence, Walker &
// Ni 2011), where the plain iteration needs hundreds; depth 0 is the plain iteration.
#define BOOST_TEST_MODULE core_anderson
#include <Eigen/Dense>
#include <boost/test/unit_test.hpp>
#include <cmath>

#include "core/anderson.hpp"

using contactrom::AndersonMixer;

namespace {

struct Linear {
  Eigen::MatrixXd a;
  Eigen::VectorXd b, solution;
  explicit Linear(int n) {
    // Symmetric with eigenvalues in [-0.95, 0.95], not diagonal in the unit basis.
    Eigen::MatrixXd q = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) q(i, j) = std::sin(1.0 + i * 7.0 + j * 3.0);
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(q);
    const Eigen::MatrixXd o = qr.householderQ();
    Eigen::VectorXd eig(n);
    for (int i = 0; i < n; ++i) eig(i) = -0.95 + 1.9 * i / (n - 1);
    a = o * eig.asDiagonal() * o.transpose();
    b = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
    solution = (Eigen::MatrixXd::Identity(n, n) - a).partialPivLu().solve(b);
  }
  /// Steps until |x - solution| <= tol |solution| (cap `max`).
  int steps(int depth, double tol, int max) const {
    AndersonMixer mixer(depth);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    for (int k = 0; k < max; ++k) {
      if ((x - solution).norm() <= tol * solution.norm()) return k;
      x = mixer.next(x, a * x + b);
    }
    return max;
  }
};

}  // namespace

BOOST_AUTO_TEST_CASE(linear_fixed_point_converges_in_about_n_steps) {
  const Linear p(6);
  const int accelerated = p.steps(10, 1e-10, 1000);
  const int plain = p.steps(0, 1e-10, 1000);
  BOOST_TEST_MESSAGE("Anderson " << accelerated << " steps, plain " << plain);
  BOOST_TEST(accelerated <= 6 + 3);
  BOOST_TEST(plain > 300);  // rate 0.95: log(1e-10)/log(0.95) ≈ 450
}

BOOST_AUTO_TEST_CASE(depth_zero_is_the_plain_iteration) {
  AndersonMixer mixer(0);
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(3, 1.0), f = Eigen::VectorXd::Constant(3, 2.0);
  BOOST_TEST((mixer.next(x, f) - f).norm() == 0.0);
  BOOST_TEST((mixer.next(f, 0.5 * f) - 0.5 * f).norm() == 0.0);
}
