// AndersonMixer: on a linear fixed point x = A x + b, Anderson acceleration with
// depth >= n reaches the solution in about n + 2 steps (GMRES-equivalence, Walker &
// Ni 2011), where the plain iteration needs hundreds; depth 0 is the plain iteration.
#define BOOST_TEST_MODULE core_anderson
#include <Eigen/Dense>
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <vector>

#include <contactrom/core/anderson.hpp>

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

// The ring buffers against the definition: on a linear map with a rotating part and
// depth 3 < n (the window slides many times, and the residual grows at least once,
// so the history restarts), every
// iterate equals x_next = F(x) − ΔF γ with γ the least-squares solution (by QR) over
// the last three differences since the last restart, formed here from lists. The
// in-place call next(x, f, x) gives the same iterates.
BOOST_AUTO_TEST_CASE(ring_buffer_matches_the_least_squares_definition) {
  const Linear p(8);
  Eigen::MatrixXd skew(8, 8);  // a rotating part, so that the residual does not decrease monotonically
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) skew(i, j) = 0.3 * (std::cos(2.0 * i + j) - std::cos(2.0 * j + i));
  const Eigen::MatrixXd a = p.a + skew;
  const int depth = 3;
  AndersonMixer mixer(depth), in_place(depth);
  std::vector<Eigen::VectorXd> df, dr;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(p.b.size()), y = x, x_ref = x, f_prev, r_prev;
  int restarts = 0, steps = 0;
  for (int k = 0; k < 25; ++k, ++steps) {
    const Eigen::VectorXd f = a * x_ref + p.b, r = f - x_ref;
    if (k > 0) {
      if (r.norm() > r_prev.norm()) df.clear(), dr.clear(), ++restarts;
      df.push_back(f - f_prev), dr.push_back(r - r_prev);
      if (static_cast<int>(df.size()) > depth) df.erase(df.begin()), dr.erase(dr.begin());
    }
    f_prev = f, r_prev = r;
    Eigen::VectorXd next = f;
    if (!dr.empty()) {
      Eigen::MatrixXd dr_m(f.size(), static_cast<Eigen::Index>(dr.size())), df_m = dr_m;
      for (size_t j = 0; j < dr.size(); ++j) dr_m.col(static_cast<Eigen::Index>(j)) = dr[j], df_m.col(static_cast<Eigen::Index>(j)) = df[j];
      next -= df_m * dr_m.colPivHouseholderQr().solve(r);
    }
    x = mixer.next(x, a * x + p.b);
    in_place.next(y, a * y + p.b, y);
    BOOST_TEST((x - next).norm() <= 1e-9 * next.norm(), "step " << k);
    BOOST_TEST((y - x).norm() <= 1e-12 * x.norm(), "step " << k);
    x_ref = next;
  }
  BOOST_TEST_MESSAGE("restarts on residual growth: " << restarts << " in " << steps << " steps");
  BOOST_TEST(restarts > 0);  // the restart rule was exercised
}
