#include <contactrom/fom/kkt.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <contactrom/core/errors.hpp>

namespace contactrom::fom {

double KktResiduals::max() const {
  return std::max({stationarity, penetration, negative_pressure, complementarity});
}

namespace {
/// Throws InputError unless `v` has `expected` entries: Eigen would read past a
/// shorter one.
void check_size(const Eigen::VectorXd& v, Eigen::Index expected, const char* what, const char* per) {
  if (v.size() != expected)
    throw InputError(std::string(what) + " has " + std::to_string(v.size()) + " entries; expected " +
                     std::to_string(expected) + ", one per " + per + " of the problem");
}
/// A displacement: one value per dof.
void check_displacement(const Problem& problem, const Eigen::VectorXd& u, const char* what) {
  check_size(u, problem.num_dofs(), what, "dof");
}
/// A pressure: one value per contact row.
void check_pressure(const Problem& problem, const Eigen::VectorXd& lambda, const char* what) {
  check_size(lambda, problem.contact().num_constraints(), what, "contact row");
}

/// C u - g with the pairing recomputed from u (per row, weighted).
Eigen::VectorXd constraint_values(const Problem& problem, const Eigen::VectorXd& u, ConstraintMatrix& c) {
  const ContactModel& contact = problem.contact();
  const Eigen::VectorXd us = contact.restrict_to_surface(u);
  Eigen::VectorXd g;
  contact.assemble(contact.search(us), c, g);
  return c * us - g;
}
}  // namespace

Eigen::VectorXd normal_gaps(const Problem& problem, const Eigen::VectorXd& u) {
  check_displacement(problem, u, "u");
  const ContactModel& contact = problem.contact();
  const Eigen::VectorXd us = contact.restrict_to_surface(u);
  const Pairing pairing = contact.search(us);
  ConstraintMatrix c;
  Eigen::VectorXd g;
  contact.assemble(pairing, c, g);
  Eigen::VectorXd gap = -(c * us - g).cwiseQuotient(contact.weights());
  if (contact.has_pairing())
    for (int s = 0; s < gap.size(); ++s)
      if (pairing.segment[s] < 0) gap(s) = std::numeric_limits<double>::infinity();
  return gap;
}

KktResiduals kkt_residuals(const Problem& problem, const Param& mu, const Eigen::VectorXd& u,
                           const Eigen::VectorXd& lambda) {
  check_displacement(problem, u, "u");
  check_pressure(problem, lambda, "lambda");
  problem.check_param(mu);
  const ContactModel& contact = problem.contact();
  ConstraintMatrix c;
  const Eigen::VectorXd cv = constraint_values(problem, u, c);
  const Eigen::VectorXd f = problem.rhs(mu);
  // Stationarity on free dofs: K (u - lift) - f + Cᵀλ, relative to the largest of
  // its three terms (a normwise backward error): relative to ‖f‖ alone, a vanishing
  // load (d = 1e-300) would turn the round-off of K u into a residual of 1e278.
  const Eigen::VectorXd ku = problem.apply_stiffness(mu, u - problem.lifting(mu));
  Eigen::VectorXd ct = Eigen::VectorXd::Zero(ku.size());
  const Eigen::VectorXd ctl = c.transpose() * lambda;
  const std::vector<int>& surf = contact.surface_dofs();
  for (size_t j = 0; j < surf.size(); ++j) ct(surf[j]) += ctl(j);
  const std::vector<int>& free = problem.free_dofs();
  const auto n_free = static_cast<Eigen::Index>(free.size());
  Eigen::VectorXd r_free(n_free), f_free(n_free), ku_free(n_free), ct_free(n_free);
  for (Eigen::Index j = 0; j < n_free; ++j) {
    const int i = free[static_cast<size_t>(j)];
    f_free(j) = f(i), ku_free(j) = ku(i), ct_free(j) = ct(i);
    r_free(j) = ku(i) - f(i) + ct(i);
  }

  KktResiduals k;
  const double scale = problem.displacement_scale();
  // stableNorm: squares of entries below 1e-154 would underflow to zero. The
  // denominator has a floor: below DBL_MIN/ε per entry (about 1e-292) the terms
  // are subnormal and carry fewer than 53 bits, so a residual there measures the
  // representation of the numbers, not the solution (a load d = 5e-324 has one bit).
  const double resolvable = std::sqrt(static_cast<double>(n_free)) * std::numeric_limits<double>::min() /
                       std::numeric_limits<double>::epsilon();
  const double terms = std::max({f_free.stableNorm(), ku_free.stableNorm(), ct_free.stableNorm(), resolvable});
  k.stationarity = r_free.stableNorm() / terms;
  k.penetration = std::max(0.0, cv.cwiseQuotient(contact.weights()).maxCoeff()) / scale;
  const double lmax = lambda.size() ? lambda.cwiseAbs().maxCoeff() : 0.0;
  k.negative_pressure = lmax > 0.0 ? std::max(0.0, -lambda.minCoeff()) / lmax : 0.0;
  const double wl = contact.weights().cwiseProduct(lambda.cwiseAbs()).sum();
  k.complementarity = wl > 0.0 ? std::abs(lambda.dot(cv)) / (scale * wl) : 0.0;
  return k;
}

double relative_h1_error(const Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& u_ref) {
  check_displacement(problem, u, "u");
  check_displacement(problem, u_ref, "u_ref");
  const Eigen::VectorXd e = u - u_ref;
  const double num = e.dot(problem.h1_gram() * e), den = u_ref.dot(problem.h1_gram() * u_ref);
  return den > 0.0 ? std::sqrt(std::max(num, 0.0) / den) : std::sqrt(std::max(num, 0.0));
}

double relative_l2_pressure_error(const Problem& problem, const Eigen::VectorXd& lambda,
                                  const Eigen::VectorXd& lambda_ref) {
  check_pressure(problem, lambda, "lambda");
  check_pressure(problem, lambda_ref, "lambda_ref");
  const Eigen::VectorXd& w = problem.contact().weights();
  const double num = w.dot((lambda - lambda_ref).cwiseAbs2()), den = w.dot(lambda_ref.cwiseAbs2());
  return den > 0.0 ? std::sqrt(num / den) : std::sqrt(num);
}

ReferenceErrors reference_errors(const Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& lambda,
                                 const Eigen::VectorXd& u_ref, const Eigen::VectorXd& lambda_ref) {
  check_displacement(problem, u, "u");
  check_pressure(problem, lambda, "lambda");
  check_displacement(problem, u_ref, "u_ref");
  check_pressure(problem, lambda_ref, "lambda_ref");
  const SparseMatrix& gram = problem.h1_gram();
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(u_ref.size());
  const double scale = problem.displacement_scale() * std::sqrt(std::max(ones.dot(gram * ones), 0.0));
  const double ref_norm = std::sqrt(std::max(u_ref.dot(gram * u_ref), 0.0));
  ReferenceErrors e;
  e.absolute = ref_norm < kNearZeroReference * scale;
  if (!e.absolute) {
    e.primal = relative_h1_error(problem, u, u_ref);
    e.dual = relative_l2_pressure_error(problem, lambda, lambda_ref);
    return e;
  }
  const Eigen::VectorXd du = u - u_ref, dl = lambda - lambda_ref;
  e.primal = std::sqrt(std::max(du.dot(gram * du), 0.0));
  e.dual = std::sqrt(problem.contact().weights().dot(dl.cwiseAbs2()));
  return e;
}

SolutionErrors compare_solutions(const Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& lambda,
                                 const Eigen::VectorXd& u_ref, const Eigen::VectorXd& lambda_ref,
                                 double degenerate_tol) {
  SolutionErrors e;
  e.primal_h1 = relative_h1_error(problem, u, u_ref);
  e.dual_l2 = relative_l2_pressure_error(problem, lambda, lambda_ref);
  const Eigen::VectorXd gap = normal_gaps(problem, u), gap_ref = normal_gaps(problem, u_ref);
  const double lscale = std::max(lambda_ref.cwiseAbs().maxCoeff(), 1e-300);
  const double uscale = problem.displacement_scale();
  for (int s = 0; s < lambda.size(); ++s) {
    const bool a = lambda(s) > degenerate_tol * lscale, b = lambda_ref(s) > degenerate_tol * lscale;
    if (a == b) continue;
    // One solution has λ_s below the threshold; excuse the row when that solution
    // also touches with zero gap there (weakly active, degenerate node).
    const bool degenerate = std::abs(gap(s)) <= degenerate_tol * uscale && std::abs(gap_ref(s)) <= degenerate_tol * uscale;
    if (!degenerate) ++e.active_set_differences;
  }
  return e;
}

double contact_force(const Problem& problem, const Eigen::VectorXd& lambda) {
  check_pressure(problem, lambda, "lambda");
  return problem.contact().weights().dot(lambda);
}

}  // namespace contactrom::fom
