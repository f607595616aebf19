#include <contactrom/fom/contact_residuals.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include <contactrom/core/format.hpp>
#include <contactrom/fom/contact_model.hpp>
#include <contactrom/fom/kkt.hpp>

namespace contactrom::fom {

bool ContactResiduals::gaps_within(const ContactTolerances& tol) const {
  // Written so that a NaN residual is never within.
  return penetration <= tol.penetration && complementarity <= tol.complementarity;
}

bool ContactResiduals::within(const ContactTolerances& tol) const {
  return gaps_within(tol) && negative_pressure <= tol.negative_pressure;
}

std::string ContactResiduals::describe(const ContactTolerances& tol) const {
  std::ostringstream out;
  const auto item = [&](const char* what, double value, double limit, int row, const char* unit) {
    if (value <= limit) return;
    out << (out.tellp() > 0 ? "; " : "") << what << " " << format_number(value) << unit;
    if (row >= 0) out << " at contact row " << row;
    out << " (tolerance " << format_number(limit) << ")";
  };
  item("penetration", penetration, tol.penetration, penetration_row, " U");
  item("separation under pressure", complementarity, tol.complementarity, complementarity_row, " U");
  item("negative pressure", negative_pressure, tol.negative_pressure, negative_pressure_row, " of the largest");
  return out.str();
}

ScaledContactTolerances tolerances_on_own_scale(const ContactTolerances& tol, const Eigen::VectorXd& u_surface,
                                                double displacement_scale) {
  ScaledContactTolerances out{tol, 1.0};
  const double own = (u_surface.size() ? u_surface.lpNorm<Eigen::Infinity>() : 0.0) / displacement_scale;
  if (!(own < 1.0)) return out;  // NaN: U's tolerances, which a NaN residual fails anyway
  out.scale = std::max(own, kNearZeroReference);
  out.tolerances.penetration *= out.scale;
  out.tolerances.complementarity *= out.scale;
  return out;
}

ContactResiduals contact_residuals(const Problem& problem, const Eigen::VectorXd& u_surface,
                                   const Eigen::VectorXd& lambda) {
  return contact_residuals(problem, problem.contact().search(u_surface), u_surface, lambda);
}

ContactResiduals contact_residuals(const Problem& problem, const Pairing& pairing, const Eigen::VectorXd& u_surface,
                                   const Eigen::VectorXd& lambda) {
  const ContactModel& contact = problem.contact();
  thread_local ConstraintMatrix c;  // storage reused by the thread's next checks
  thread_local Eigen::VectorXd g, gap;
  contact.assemble(pairing, c, g);
  gap.noalias() = c * u_surface;
  gap -= g;  // (Cu − g)_s = w_s d_s
  return contact_residuals_of_gaps(gap, contact.weights(), lambda, problem.displacement_scale());
}

ContactResiduals contact_residuals_of_gaps(const Eigen::VectorXd& gap, const Eigen::VectorXd& w,
                                           const Eigen::VectorXd& lambda, double u_scale) {
  ContactResiduals r;
  const double lambda_max = lambda.size() > 0 ? lambda.cwiseAbs().maxCoeff() : 0.0;
  double force = 0.0, separation = 0.0, worst_separation = 0.0;
  for (Eigen::Index s = 0; s < gap.size(); ++s) {
    const double d = w(s) > 0.0 ? gap(s) / w(s) : 0.0;  // gap of node s in length units
    if (d / u_scale > r.penetration || std::isnan(d)) r.penetration = d / u_scale, r.penetration_row = static_cast<int>(s);
    const double l = lambda(s);
    if (lambda_max > 0.0 && -l / lambda_max > r.negative_pressure)
      r.negative_pressure = -l / lambda_max, r.negative_pressure_row = static_cast<int>(s);
    force += w(s) * std::abs(l);
    const double part = w(s) * std::abs(l) * std::abs(d);
    separation += part;
    if (part > worst_separation) worst_separation = part, r.complementarity_row = static_cast<int>(s);
  }
  r.complementarity = force > 0.0 ? separation / (u_scale * force) : 0.0;
  if (!std::isfinite(r.complementarity)) r.complementarity = std::nan("");
  return r;
}

ContactTolerances default_contact_tolerances(const Problem& problem) {
  ContactTolerances t;
  const RomSettings& rom = problem.definition().rom;
  if (rom.penetration_tolerance > 0) t.penetration = rom.penetration_tolerance;
  if (rom.complementarity_tolerance > 0) t.complementarity = rom.complementarity_tolerance;
  if (rom.negative_pressure_tolerance > 0) t.negative_pressure = rom.negative_pressure_tolerance;
  return t;
}

}  // namespace contactrom::fom
