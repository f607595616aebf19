#include <contactrom/baselines/cpg.hpp>

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace contactrom::baselines {
namespace {

/// Snapshots scaled by √w row-wise, so that the weighted norm is the Euclidean norm
/// of the scaled columns and the cone projection is a plain NNLS.
Eigen::MatrixXd scaled_snapshots(const Eigen::MatrixXd& snapshots, const Eigen::VectorXd& weights) {
  if (weights.size() == 0) return snapshots;
  if (weights.size() != snapshots.rows())
    throw InputError("CPG weights have " + std::to_string(weights.size()) + " entries; expected " +
                     std::to_string(snapshots.rows()) + " (one per snapshot row)");
  if (!weights.allFinite() || (weights.array() <= 0.0).any())
    throw InputError("CPG weights must be finite and positive");
  return weights.cwiseSqrt().asDiagonal() * snapshots;
}

/// Errors of the scaled columns `a` on the cone of a[:, basis]; selected columns get 0.
Eigen::VectorXd projection_errors_scaled(const Eigen::MatrixXd& a, const Eigen::VectorXd& norms,
                                         const std::vector<int>& basis, const NnlsOptions& options,
                                         Status* status) {
  const Eigen::Index m = a.cols();
  Eigen::VectorXd errors = Eigen::VectorXd::Zero(m);
  if (status) *status = Status::Success;
  Eigen::MatrixXd ab(a.rows(), static_cast<Eigen::Index>(basis.size()));
  std::vector<char> selected(m, 0);
  for (size_t i = 0; i < basis.size(); ++i) {
    ab.col(static_cast<Eigen::Index>(i)) = a.col(basis[i]);
    selected[basis[i]] = 1;
  }
  Nnls nnls(options);
  if (!basis.empty()) nnls.compute(ab);
  for (Eigen::Index j = 0; j < m; ++j) {
    if (selected[j] || norms(j) == 0.0) continue;  // exactly representable
    if (basis.empty()) {
      errors(j) = 1.0;  // projection on {0}
      continue;
    }
    const Eigen::VectorXd x = nnls.solve(a.col(j));
    // NoConvergence still returns a feasible iterate, whose (larger) error is an
    // honest upper bound; only a failed solve is reported.
    if (nnls.info() == Status::NumericalIssue || nnls.info() == Status::InvalidInput) {
      if (status) *status = Status::NumericalIssue;
    }
    // The residual is formed explicitly (not from ‖b‖² − 2cᵀx + xᵀGx, which cancels
    // to √ε) so that errors down to round-off are resolved.
    errors(j) = (a.col(j) - ab * x).norm() / norms(j);
  }
  return errors;
}

}  // namespace

double default_cpg_tolerance(const fom::Problem& problem) {
  const double from_file = problem.definition().rom.cpg_tolerance;
  return from_file > 0.0 ? from_file : 1e-2;
}

Eigen::VectorXd cone_projection_errors(const Eigen::MatrixXd& snapshots, const Eigen::VectorXd& weights,
                                       const std::vector<int>& basis, const NnlsOptions& nnls, Status* status) {
  const Eigen::MatrixXd a = scaled_snapshots(snapshots, weights);
  for (int p : basis)
    if (p < 0 || p >= a.cols())
      throw InputError("CPG basis column " + std::to_string(p) + " out of range; there are " +
                       std::to_string(a.cols()) + " snapshots");
  return projection_errors_scaled(a, a.colwise().norm().transpose(), basis, nnls, status);
}

CpgBasis cone_projected_greedy(const Eigen::MatrixXd& snapshots, const Eigen::VectorXd& weights,
                               const CpgOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!snapshots.allFinite()) throw InputError("CPG snapshots contain a non-finite value");
  CpgBasis out;
  out.tolerance = options.tolerance < 0.0 ? 1e-2 : options.tolerance;
  if (!(out.tolerance <= 1.0))
    throw InputError("CPG tolerance " + std::to_string(out.tolerance) + " invalid; expected a value in [0, 1]");
  const Eigen::MatrixXd a = scaled_snapshots(snapshots, weights);
  const Eigen::VectorXd norms = a.colwise().norm().transpose();
  const int m = static_cast<int>(a.cols());
  const int cap = options.max_size > 0 ? options.max_size : m;
  out.errors = Eigen::VectorXd::Zero(m);

  // Step 1: the snapshot of largest norm (every non-zero snapshot has error 1 on the
  // empty cone; the norm breaks the tie).
  Eigen::Index first = -1;
  if (m > 0 && norms.maxCoeff(&first) > 0.0) {
    out.columns.push_back(static_cast<int>(first));
    while (true) {
      Status st = Status::Success;
      out.errors = projection_errors_scaled(a, norms, out.columns, options.nnls, &st);
      Eigen::Index worst = 0;
      const double e = out.errors.maxCoeff(&worst);
      out.history.push_back(e);
      if (st != Status::Success) {
        out.status = st;
        break;
      }
      if (e <= out.tolerance) break;
      if (static_cast<int>(out.columns.size()) >= cap) {
        out.status = Status::NoConvergence;
        break;
      }
      out.columns.push_back(static_cast<int>(worst));  // worst approximated snapshot
    }
  }
  out.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

CpgBasis build_cpg_basis(const rom::ReducedModel& model, const CpgOptions& options) {
  CpgOptions o = options;
  if (o.tolerance < 0.0) o.tolerance = default_cpg_tolerance(model.problem());
  return cone_projected_greedy(model.dictionary(), model.problem().contact().weights(), o);
}

CpgActiveSet::CpgActiveSet(const rom::ReducedModel& model, const CpgOptions& cpg,
                           const ReducedActiveSetOptions& options)
    : CpgActiveSet(build_cpg_basis(model, cpg), model, options) {}

CpgActiveSet::CpgActiveSet(CpgBasis&& basis, const rom::ReducedModel& model, const ReducedActiveSetOptions& options)
    : ReducedActiveSet("cpg", model, basis.columns, options), m_basis(std::move(basis)) {}

const rom::OptionTable<CpgOptions>& cpg_option_table() {
  static const rom::OptionTable<CpgOptions> t = [] {
    rom::OptionTable<CpgOptions> o;
    o.number("cpg_tolerance", &CpgOptions::tolerance,
             "cone-projected greedy: worst relative projection error; < 0: the problem's [rom] cpg_tolerance, else "
             "1e-2",
             Interval{-std::numeric_limits<double>::infinity(), 1.0})
        .integer("cpg_max_size", &CpgOptions::max_size, "cap on the CPG basis size (0: none)", 0, 1e9);
    return o;
  }();
  return t;
}

CpgOptions cpg_options(const rom::OnlineSolverOptions& options) {
  return rom::read_options(cpg_option_table(), options, "cpg", /*strict=*/false);
}

std::unique_ptr<rom::OnlineSolver> make_cpg_solver(const rom::ReducedModel& model,
                                                   const rom::OnlineSolverOptions& options) {
  return std::make_unique<CpgActiveSet>(model, cpg_options(options), reduced_active_set_options(options, "cpg"));
}

}  // namespace contactrom::baselines
