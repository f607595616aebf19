#include <contactrom/baselines/kkt_verifier.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace contactrom::baselines {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// NaN (from non-finite input that slipped through) must never hide in a maximum.
double finite_or_inf(double v) { return std::isnan(v) ? kInfinity : v; }

VerificationReport invalid_report(const fom::Param& mu, const std::string& message, bool has_reference) {
  VerificationReport r;
  r.mu = mu;
  r.status = Status::InvalidInput;
  r.message = message;
  r.kkt.stationarity = r.kkt.penetration = r.kkt.negative_pressure = r.kkt.complementarity = kInfinity;
  r.has_reference = has_reference;
  if (has_reference) {
    r.errors.primal_h1 = r.errors.dual_l2 = kInfinity;
    r.errors.active_set_differences = 0;
  }
  return r;
}

/// Empty when the sizes and values fit the problem, else what does not.
std::string check_vectors(const fom::Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& lambda,
                          const char* what) {
  const int n = problem.num_dofs(), nc = problem.contact().num_constraints();
  std::ostringstream msg;
  if (u.size() != n)
    msg << what << " displacement has " << u.size() << " entries, expected " << n;
  else if (lambda.size() != nc)
    msg << what << " pressure has " << lambda.size() << " entries, expected " << nc;
  else if (!u.allFinite() || !lambda.allFinite())
    msg << what << " solution has non-finite entries";
  return msg.str();
}

}  // namespace

VerificationReport verify_solution(const fom::Problem& problem, const fom::Param& mu, const Eigen::VectorXd& u,
                                   const Eigen::VectorXd& lambda, const fom::FomSolution* reference,
                                   double degenerate_tol) {
  const bool has_reference = reference != nullptr;
  if (mu.size() != problem.num_params())
    return invalid_report(mu, "parameter has " + std::to_string(mu.size()) + " entries, expected " +
                                  std::to_string(problem.num_params()),
                          has_reference);
  if (!mu.allFinite()) return invalid_report(mu, "parameter has non-finite entries", has_reference);
  std::string bad = check_vectors(problem, u, lambda, "candidate");
  if (bad.empty() && reference) {
    bad = check_vectors(problem, reference->u, reference->lambda, "reference");
    // An empty reference μ means "not recorded"; otherwise it must be this μ.
    const fom::Param& rmu = reference->mu;
    const double mu_tol = 1e-12 * (1.0 + mu.cwiseAbs().maxCoeff());
    if (bad.empty() && rmu.size() > 0 && (rmu.size() != mu.size() || (rmu - mu).cwiseAbs().maxCoeff() > mu_tol))
      bad = "reference solution belongs to another parameter";
  }
  if (!bad.empty()) return invalid_report(mu, bad, has_reference);

  VerificationReport r;
  r.mu = mu;
  r.kkt = fom::kkt_residuals(problem, mu, u, lambda);
  if (reference) {
    r.has_reference = true;
    r.errors = fom::compare_solutions(problem, u, lambda, reference->u, reference->lambda, degenerate_tol);
  }
  return r;
}

VerificationReport verify_solution(const fom::Problem& problem, const fom::FomSolution& candidate,
                                   const fom::FomSolution* reference, double degenerate_tol) {
  return verify_solution(problem, candidate.mu, candidate.u, candidate.lambda, reference, degenerate_tol);
}

void VerificationSummary::add(const VerificationReport& report) {
  ++count;
  if (report.status != Status::Success) ++invalid;
  max_kkt.stationarity = std::max(max_kkt.stationarity, finite_or_inf(report.kkt.stationarity));
  max_kkt.penetration = std::max(max_kkt.penetration, finite_or_inf(report.kkt.penetration));
  max_kkt.negative_pressure = std::max(max_kkt.negative_pressure, finite_or_inf(report.kkt.negative_pressure));
  max_kkt.complementarity = std::max(max_kkt.complementarity, finite_or_inf(report.kkt.complementarity));
  if (!report.has_reference) return;
  ++with_reference;
  const double h1 = finite_or_inf(report.errors.primal_h1), l2 = finite_or_inf(report.errors.dual_l2);
  max_primal_h1 = std::max(max_primal_h1, h1);
  max_dual_l2 = std::max(max_dual_l2, l2);
  m_sum_primal_h1 += h1;
  m_sum_dual_l2 += l2;
  mean_primal_h1 = m_sum_primal_h1 / with_reference;
  mean_dual_l2 = m_sum_dual_l2 / with_reference;
  max_active_set_differences = std::max(max_active_set_differences, report.errors.active_set_differences);
  total_active_set_differences += report.errors.active_set_differences;
}

std::vector<std::pair<std::string, double>> VerificationSummary::fields() const {
  return {{"count", count},
          {"invalid", invalid},
          {"with_reference", with_reference},
          {"max_stationarity", max_kkt.stationarity},
          {"max_penetration", max_kkt.penetration},
          {"max_negative_pressure", max_kkt.negative_pressure},
          {"max_complementarity", max_kkt.complementarity},
          {"max_kkt", max_kkt.max()},
          {"max_primal_error", max_primal_h1},
          {"mean_primal_error", mean_primal_h1},
          {"max_dual_error", max_dual_l2},
          {"mean_dual_error", mean_dual_l2},
          {"max_active_set_differences", max_active_set_differences},
          {"total_active_set_differences", total_active_set_differences}};
}

VerificationSummary summarize(const std::vector<VerificationReport>& reports) {
  VerificationSummary s;
  for (const VerificationReport& r : reports) s.add(r);
  return s;
}

}  // namespace contactrom::baselines
