#pragma once
/// \file exact_scaling.hpp
/// \brief Powers of two that bring a dictionary and a signal of extreme magnitude
/// near 1 before a sparse kernel sees them: the kernels form Gram matrices and
/// squared norms, which underflow to zero (entries below about 1e-154) or overflow
/// (above 1e154), and would then answer from zeros or infinities. Scaling by a power
/// of two changes no digit, so data of ordinary magnitude is left exactly as it is
/// and scaled data gives the same answer as unscaled data would in exact range.
#include <Eigen/Dense>
#include <cmath>

namespace contactrom {

/// \brief The factors of exact_scaling(): solve with dictionary·D and signal·x, then
/// multiply the coefficients by coefficients().
struct ExactScaling {
  double dictionary = 1.0, signal = 1.0;
  /// Factor from the coefficients of the scaled problem to those of the given one.
  double coefficients() const { return dictionary / signal; }
};

/// \brief 1 for a dictionary and a signal whose largest entries lie in [2^-200, 2^200]
/// (or are zero); otherwise the power of two that brings the largest entry near 1.
inline ExactScaling exact_scaling(const Eigen::MatrixXd& d, const Eigen::VectorXd& x) {
  const auto factor = [](double largest) {
    if (!(largest > 0.0) || !std::isfinite(largest)) return 1.0;
    int e = 0;
    std::frexp(largest, &e);
    return (e < -200 || e > 200) ? std::ldexp(1.0, -e) : 1.0;
  };
  return {factor(d.size() ? d.cwiseAbs().maxCoeff() : 0.0), factor(x.size() ? x.cwiseAbs().maxCoeff() : 0.0)};
}

/// \brief `solve(D', x')` on D and x scaled by exact_scaling() (D and x themselves,
/// not copied, when they are in range), with the coefficients of its result —
/// `coefficients(result)`, a reference into it — scaled back to those of D and x.
template <class Solve, class Coefficients>
auto solve_exactly_scaled(const Eigen::MatrixXd& d, const Eigen::VectorXd& x, Solve&& solve,
                          Coefficients&& coefficients) {
  const ExactScaling s = exact_scaling(d, x);
  if (s.dictionary == 1.0 && s.signal == 1.0) return solve(d, x);
  auto result = solve(Eigen::MatrixXd(d * s.dictionary), Eigen::VectorXd(x * s.signal));
  coefficients(result) *= s.coefficients();
  return result;
}

/// \brief ||D a − x|| and that relative to ||x|| (the residual itself when x = 0), by
/// norms that neither underflow nor overflow with data of extreme magnitude: how a
/// sparse kernel's answer is reported (`contactrom sparse`, Python's SparseResult).
struct ResidualNorms {
  double residual = 0.0, relative = 0.0;
};
inline ResidualNorms residual_norms(const Eigen::MatrixXd& d, const Eigen::VectorXd& a, const Eigen::VectorXd& x) {
  ResidualNorms r;
  r.residual = (d * a - x).stableNorm();
  const double x_norm = x.stableNorm();
  r.relative = x_norm > 0.0 ? r.residual / x_norm : r.residual;
  return r;
}

}  // namespace contactrom
