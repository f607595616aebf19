#include <contactrom/fom/pairing_fixed_point.hpp>

#include <algorithm>
#include <cmath>

#include <contactrom/core/format.hpp>

namespace contactrom::fom {

double pairing_change(const ConstraintMatrix& c, const Eigen::VectorXd& g, const ConstraintMatrix& c_next,
                      const Eigen::VectorXd& g_next, const Eigen::VectorXd& u_s, const Eigen::VectorXd& lambda,
                      const Eigen::VectorXd& weights, double u_scale, double tolerance, bool penetration) {
  const Eigen::VectorXd force = c.transpose() * lambda;
  const double force_scale = std::max(force.norm(), 1e-300);
  double change = (c_next.transpose() * lambda - force).norm() / force_scale;
  const Eigen::VectorXd v = (c * u_s - g).cwiseQuotient(weights);
  const Eigen::VectorXd v_next = (c_next * u_s - g_next).cwiseQuotient(weights);
  for (Eigen::Index s = 0; s < v.size(); ++s) {
    if (penetration) change = std::max(change, v_next(s) / u_scale);  // penetration under the new pairing
    // A row without a pair (empty row, v = 0) is no contact: only its penetration
    // under the new pairing counts, not the gap at which the new pairing puts it.
    const bool paired = static_cast<bool>(ConstraintMatrix::InnerIterator(c, s));
    if (paired && (lambda(s) > 0.0 || v(s) > -tolerance * u_scale))
      change = std::max(change, std::abs(v_next(s) - v(s)) / u_scale);
  }
  return change;
}

std::string pairing_no_convergence_message(const PairingFixedPointResult& result,
                                           const PairingFixedPointOptions& options) {
  return "contact pairing did not settle in " + std::to_string(options.max_iterations) +
         " fixed-point iterations (last change " + format_number(result.residual) + " > tolerance " +
         format_number(options.tolerance) + ")";
}

}  // namespace contactrom::fom
