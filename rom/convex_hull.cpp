#include <contactrom/rom/convex_hull.hpp>

#include <contactrom/core/format.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include <contactrom/fom/input_values.hpp>
#include <contactrom/fom/pairing_fixed_point.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/pod.hpp>

namespace contactrom::rom {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// Uniform [0, 1) draw with 53 random bits, written out so that the sequence is the
/// same with every standard library (std::uniform_real_distribution is not
/// specified bit for bit; std::mt19937_64 is).
double uniform01(std::mt19937_64& gen) { return static_cast<double>(gen() >> 11) * 0x1.0p-53; }

/// Columns of `m` listed in `columns`.
MatrixXd select_columns(const MatrixXd& m, const std::vector<Index>& columns) {
  MatrixXd out(m.rows(), static_cast<Index>(columns.size()));
  for (std::size_t i = 0; i < columns.size(); ++i) out.col(static_cast<Index>(i)) = m.col(columns[i]);
  return out;
}

std::vector<Index> nonzeros(const VectorXd& v) {
  std::vector<Index> out;
  for (Index i = 0; i < v.size(); ++i)
    if (v(i) != 0.0) out.push_back(i);
  return out;
}

/// One solve of the projected problem for a fixed contact operator.
struct ProjectedSolve {
  VectorXd alpha;
  Status status = Status::Success;
  int focuss_iterations = 0;
  int nnls_iterations = 0;
};

/// nnFOCUSS from NNLS on D = [A; ω1ᵀ], x = [b; ω], then the exact simplex
/// least squares on the selected support (file comment of convex_hull.hpp).
ProjectedSolve solve_projected(const MatrixXd& a, const VectorXd& b, const ConvexHullOptions& options) {
  ProjectedSolve out;
  const Index rb = a.rows(), m = a.cols();
  double scale = a.colwise().norm().maxCoeff();
  if (!(scale > 0.0)) scale = 1.0;
  const double omega = options.sum_weight * scale;
  MatrixXd d(rb + 1, m);
  d.topRows(rb) = a;
  d.row(rb).setConstant(omega);
  VectorXd x(rb + 1);
  x.head(rb) = b;
  x(rb) = omega;

  NnFocuss focuss(options.focuss, options.nnls);
  out.alpha = focuss.compute(d).solve(x);
  out.status = focuss.info();
  out.focuss_iterations = focuss.iterations();
  out.nnls_iterations = focuss.nnls().iterations();
  if (out.status == Status::InvalidInput || !out.alpha.allFinite()) {
    out.status = Status::NumericalIssue;
    out.alpha = VectorXd::Constant(m, 1.0 / static_cast<double>(m));
  }

  if (options.polish) {
    std::vector<Index> support = nonzeros(out.alpha);
    if (support.empty())  // nothing selected (e.g. a failed start): use every column
      for (Index j = 0; j < m; ++j) support.push_back(j);
    SimplexLeastSquares simplex(options.simplex);
    const VectorXd alpha_s = simplex.compute(select_columns(a, support)).solve(b);
    if (simplex.info() == Status::InvalidInput || simplex.info() == Status::NumericalIssue) {
      if (out.status == Status::Success) out.status = Status::NumericalIssue;
    } else {
      out.alpha.setZero();
      for (std::size_t i = 0; i < support.size(); ++i) out.alpha(support[i]) = alpha_s(static_cast<Index>(i));
    }
  }
  return out;
}

/// The shared pairing fixed point's settings from the convex-hull options. The
/// penetration term is left out of its stopping test: a convex combination of
/// snapshots penetrates slightly whatever its pairing (fom/pairing_fixed_point.hpp).
fom::PairingFixedPointOptions pairing_options(const ConvexHullOptions& options) {
  fom::PairingFixedPointOptions o;
  o.max_iterations = options.max_pairing_iterations;
  o.tolerance = options.pairing_tolerance;
  o.anderson_depth = options.anderson_depth;
  o.penetration = false;
  return o;
}

/// The exact solve at one pairing, the `solve_at` of fom::solve_pairing_fixed_point():
/// the projected problem with that pairing's contact block (B_s^T C^T D_d, or the
/// constant block without pairing), returning u_s = u_lift,s + D_p,s α and
/// λ = D_d α. Two phases. Selection: full solves (nnFOCUSS over all columns) until
/// the support repeats or `selection_iterations` full solves are spent. Then the
/// support is frozen and only α is re-solved on it (a column a solve drops stays
/// out), a smooth map in which the pairing settles: re-selecting at every step lets
/// near-tied supports alternate for ever. Every change of the support is reported
/// as PairedSolution::map_changed, so that the Anderson history of the old map is
/// dropped. Anderson mixing acts on u_s only, to choose the pairing; α is always an
/// exact solve, hence on the simplex, and is never extrapolated.
class PairedHullSolve {
 public:
  PairedHullSolve(const MonolithicDictionary& dict, const fom::Param& mu)
      : m_dict(dict), m_bk(dict.projected_stiffness(mu)), m_bf(dict.projected_rhs(mu)),
        m_lift_s(dict.constant_contact() ? VectorXd() : dict.surface_lifting(mu)) {}

  fom::PairedSolution operator()(const fom::Pairing&, const fom::ConstraintMatrix& c, const VectorXd&,
                                 const VectorXd&) {
    const MatrixXd* constant = m_dict.constant_contact();
    m_a = m_bk + (constant ? *constant : m_dict.projected_contact(c));
    m_last_full = !m_frozen;
    if (m_frozen) {
      const ProjectedSolve step = count(solve_projected(select_columns(m_a, m_support), m_bf, m_dict.options()));
      m_alpha.setZero(m_dict.size());
      for (std::size_t i = 0; i < m_support.size(); ++i) m_alpha(m_support[i]) = step.alpha(static_cast<Index>(i));
    } else {
      m_alpha = full_solve();
    }
    std::vector<Index> support = nonzeros(m_alpha);  // frozen: a column dropped stays out
    const bool same_support = support == m_support;
    if (!m_frozen)
      m_frozen = (m_full_solves > 1 && same_support) || m_full_solves >= m_dict.options().selection_iterations;
    m_support = std::move(support);
    fom::PairedSolution out;
    out.map_changed = !same_support;
    // An nnFOCUSS cap still leaves an exact polished α on the simplex: the pairing
    // goes on, and status() reports the cap at the end.
    out.status = m_status == Status::NoConvergence ? Status::Success : m_status;
    if (constant) return out;  // no pairing: the fixed point reads neither
    out.surface_displacement = surface_displacement(m_alpha);
    out.lambda = m_dict.dual() * m_alpha;
    return out;
  }

  /// Whether the last solve was on a frozen support that a full solve may re-select.
  bool may_reselect() const { return !m_last_full && m_full_solves < m_dict.options().selection_iterations; }
  /// One full solve at the last solve's pairing. True when it selects the frozen
  /// support again (α is kept); otherwise α and the frozen support become its.
  bool reselect() {
    VectorXd alpha = full_solve();
    std::vector<Index> support = nonzeros(alpha);
    if (m_status == Status::NumericalIssue || support == m_support) return true;
    m_alpha = std::move(alpha);
    m_support = std::move(support);
    return false;
  }

  VectorXd surface_displacement(const VectorXd& alpha) const { return m_lift_s + m_dict.surface_primal() * alpha; }
  const VectorXd& alpha() const { return m_alpha; }
  Index num_columns() const { return m_dict.size(); }
  const MatrixXd& projected_operator() const { return m_a; }  ///< Bᵀ K_mono of the last solve
  const VectorXd& projected_rhs() const { return m_bf; }
  Status status() const { return m_status; }  ///< of the last solve
  int focuss_iterations() const { return m_focuss_iterations; }
  int nnls_iterations() const { return m_nnls_iterations; }

 private:
  ProjectedSolve count(ProjectedSolve step) {
    m_focuss_iterations += step.focuss_iterations;
    m_nnls_iterations += step.nnls_iterations;
    m_status = step.status;
    return step;
  }
  VectorXd full_solve() {
    ++m_full_solves;
    return count(solve_projected(m_a, m_bf, m_dict.options())).alpha;
  }

  const MonolithicDictionary& m_dict;
  const MatrixXd m_bk;      // Bᵀ K(μ) D_p
  const VectorXd m_bf;      // Bᵀ f(μ)
  const VectorXd m_lift_s;  // u_lift(μ) on the surface (with pairing only)
  MatrixXd m_a;             // Bᵀ K_mono of the last solve
  VectorXd m_alpha;
  std::vector<Index> m_support;  // of the last solve; once m_frozen, the columns solved on
  bool m_frozen = false, m_last_full = true;
  int m_full_solves = 0, m_focuss_iterations = 0, m_nnls_iterations = 0;
  Status m_status = Status::Success;
};

/// Outcome of run_pairing_fixed_point().
struct HullFixedPoint {
  fom::PairingFixedPointResult last;  ///< the last run of the shared fixed point
  int iterations = 0;                 ///< solves in all its runs
  bool settled = false;               ///< converged, and the re-selection kept the support
  std::string message;                ///< why not, when the solves succeeded but it did not settle
};

/// The pairing fixed point shared with the FOM (fom/pairing_fixed_point.hpp) on the
/// surface displacement x = u_s, from the centroid of the hull, each solve the exact
/// projected solve at its pairing (`solve_at`). Once it settles on a frozen
/// support, one full solve at the settled pairing re-selects; a different support
/// continues the fixed point from there, within the same budget.
HullFixedPoint run_pairing_fixed_point(const fom::ContactModel& contact, double u_scale,
                                       const ConvexHullOptions& options, PairedHullSolve& solve_at) {
  HullFixedPoint out;
  if (!contact.has_pairing()) {  // constant contact block: one solve, no operator to build
    const fom::PairedSolution solution = solve_at(fom::Pairing{}, fom::ConstraintMatrix{}, VectorXd{}, VectorXd{});
    out.last.status = solution.status;
    out.last.residual = 0.0;
    out.iterations = 1;
    out.settled = true;
    return out;
  }
  const fom::PairingFixedPointOptions fp_options = pairing_options(options);
  const Index m = solve_at.num_columns();
  VectorXd x = solve_at.surface_displacement(VectorXd::Constant(m, 1.0 / static_cast<double>(m)));
  fom::Pairing pairing = contact.search(x);
  for (;;) {
    fom::PairingFixedPointOptions remaining = fp_options;
    remaining.max_iterations = fp_options.max_iterations - out.iterations;
    out.last = fom::solve_pairing_fixed_point(contact, u_scale, x, pairing, remaining, solve_at);
    out.iterations += out.last.iterations;
    if (out.last.status == Status::NoConvergence) {
      out.message = fom::pairing_no_convergence_message(out.last, fp_options);
      return out;
    }
    if (out.last.status != Status::Success || !solve_at.may_reselect() || solve_at.reselect()) {
      out.settled = out.last.status == Status::Success;
      return out;
    }
    if (out.iterations >= fp_options.max_iterations) {
      out.message = "convex-hull support changed when re-selected at the settled pairing, with none of the " +
                    std::to_string(fp_options.max_iterations) + " pairing iterations left";
      return out;
    }
    x = solve_at.surface_displacement(solve_at.alpha());
    pairing = contact.search_rows(x, nullptr, &out.last.pairing);
  }
}

}  // namespace

void check_convex_hull_applicable(const fom::Problem& problem) {
  if (problem.definition().rom.convex_hull) return;
  throw InputError("convex-hull needs a convex, parameter-independent feasible set; problem '" + problem.name() +
                   "' does not declare one (set convex_hull = true in its problem file's [rom] table when the "
                   "pairing changes little over the parameter range)");
}

namespace {

/// Refuses a reduced model or options the monolithic dictionary cannot be built
/// from; returns the energy tolerance δ of the SVD basis.
double checked_basis_delta(const ReducedModel& model, const ConvexHullOptions& options) {
  // A convex combination of training solutions pairs each primal snapshot with its
  // whole pressure: a dictionary split by contact pair has no such columns.
  for (int p = 0; p < model.dictionary_size(); ++p)
    if (model.sibling_columns(p).size() != 1)
      throw InputError("convex-hull needs one dictionary column per snapshot; the reduced model of '" +
                       model.problem().name() + "' splits its " + std::to_string(model.problem().contact().num_pairs()) +
                       " contact pairs (build it with ReducedModelOptions::split_pairs = false)");
  const double delta = options.basis_delta < 0.0 ? model.delta() : options.basis_delta;
  if (!(delta >= 0.0) || !std::isfinite(delta))
    throw InputError("convex-hull basis tolerance " + std::to_string(delta) + " invalid; expected >= 0");
  if (options.rank_l > 100000)
    throw InputError("convex-hull rank L = " + std::to_string(options.rank_l) + " invalid; expected 1..100000");
  if (!(options.sum_weight > 0.0) || !std::isfinite(options.sum_weight))
    throw InputError("convex-hull sum weight " + std::to_string(options.sum_weight) + " invalid; expected > 0");
  if (options.selection_iterations < 1)
    throw InputError("convex-hull selection iteration cap " + std::to_string(options.selection_iterations) +
                     " invalid; expected >= 1");
  if (options.max_pairing_iterations < 1)
    throw InputError("convex-hull pairing iteration cap " + std::to_string(options.max_pairing_iterations) +
                     " invalid; expected >= 1");
  if (!model.has_primal_snapshots())
    throw InputError("convex-hull combines the primal training snapshots, which this reduced model of '" +
                     model.problem().name() + "' does not keep (build it with keep_primal_snapshots = true)");
  return delta;
}

/// Projection basis B of the residual test space: the SVD basis of D_p at δ, or
/// orth(D_p R) for a random R of L columns; zero on the Dirichlet rows.
MatrixXd make_projection_basis(const MatrixXd& dp, const fom::Problem& problem, const ConvexHullOptions& options,
                               double delta) {
  Pod svd(PodOptions{delta, 0});
  svd.compute(dp);
  if (svd.info() != Status::Success)
    throw InputError("SVD of the primal dictionary of " + quoted(problem.name(), 200) + " failed (" + to_string(svd.info()) + ")");
  MatrixXd b;
  if (options.basis == ProjectionBasis::Svd) {
    b = svd.basis();
  } else {
    const int l = options.rank_l > 0 ? options.rank_l : svd.rank();
    std::mt19937_64 gen(options.seed);
    MatrixXd r(dp.cols(), l);
    for (Index j = 0; j < r.cols(); ++j)  // column by column: R's columns do not depend on L
      for (Index i = 0; i < r.rows(); ++i) r(i, j) = uniform01(gen);
    // orth(D_p R): left singular vectors above the numerical rank (Pod with δ = 0).
    Pod orth(PodOptions{0.0, 0});
    orth.compute(dp * r);
    if (orth.info() != Status::Success)
      throw InputError("orthogonalisation of the randomised primal dictionary failed (" + std::string(to_string(orth.info())) + ")");
    b = orth.basis();
  }
  if (b.cols() == 0)
    throw InputError(dp.norm() > 0.0 && options.basis == ProjectionBasis::Svd
                         ? "the SVD of the primal dictionary of " + quoted(problem.name(), 200) + " keeps no mode at delta " +
                               format_number(delta) + ": no projection basis; expected a delta below 1"
                         : "the primal dictionary of " + quoted(problem.name(), 200) + " is zero: no projection basis");
  const std::vector<char>& dirichlet = problem.is_dirichlet();
  for (Index i = 0; i < b.rows(); ++i)
    if (dirichlet[static_cast<std::size_t>(i)]) b.row(i).setZero();
  return b;
}

/// The rows `rows` of m.
MatrixXd rows_of(const MatrixXd& m, const std::vector<int>& rows) {
  MatrixXd out(static_cast<Index>(rows.size()), m.cols());
  for (std::size_t a = 0; a < rows.size(); ++a) out.row(static_cast<Index>(a)) = m.row(rows[a]);
  return out;
}

/// The columns `columns` as one matrix.
MatrixXd as_matrix(const std::vector<VectorXd>& columns, Index rows) {
  MatrixXd out(rows, static_cast<Index>(columns.size()));
  for (std::size_t k = 0; k < columns.size(); ++k) out.col(static_cast<Index>(k)) = columns[k];
  return out;
}

}  // namespace

MonolithicDictionary::MonolithicDictionary(const ReducedModel& model, const ConvexHullOptions& options)
    : m_model(model), m_options(options) {
  const auto t0 = std::chrono::steady_clock::now();
  const fom::Problem& problem = model.problem();
  const double delta = checked_basis_delta(model, options);
  // The training solutions as the database stores them, d_p = u_j − u_lift(μ_j), so
  // that u = u_lift(μ) + D_p α is a convex combination of the snapshots up to the
  // Dirichlet data (whatever offset the model's POD is measured from).
  const MatrixXd& dp = model.primal_snapshots();
  const MatrixXd& dd = model.dictionary();
  const int nt = problem.num_load_terms();
  m_num_dofs = static_cast<int>(dp.rows());
  m_mono.resize(dp.rows() + dd.rows(), dp.cols());
  m_mono << dp, dd;
  m_dd = dd;  // contiguous copy for the online contact block
  m_b = make_projection_basis(dp, problem, options, delta);

  // Their surface rows, for the contact block.
  const std::vector<int>& surf = problem.contact().surface_dofs();
  m_b_s = rows_of(m_b, surf);
  m_dp_s = rows_of(dp, surf);
  m_lift_s = rows_of(as_matrix(problem.lifting_terms(), dp.rows()), surf);

  // Parameter-independent pieces of Bᵀ r(α) (K_q symmetric, so Bᵀ K_q = (K_q B)ᵀ).
  m_bf.resize(m_b.cols(), nt);
  for (int k = 0; k < nt; ++k) m_bf.col(k) = m_b.transpose() * problem.external_load_terms()[static_cast<std::size_t>(k)];
  for (int q = 0; q < problem.num_stiffness_terms(); ++q) {
    const MatrixXd kb = problem.stiffness_term(q) * m_b;
    m_bkd.push_back(kb.transpose() * dp);
    MatrixXd kl(m_b.cols(), nt);
    for (int k = 0; k < nt; ++k) kl.col(k) = kb.transpose() * problem.lifting_terms()[static_cast<std::size_t>(k)];
    m_bkl.push_back(kl);
  }
  // û = Φᵀ(u − u_off(μ)) = Φᵀ D_p α + Φᵀ(u_lift(μ) − u_off(μ)) (ReducedModel::reduced_lifting).
  m_phi_dp = model.basis().transpose() * dp;

  const fom::ContactModel& contact = problem.contact();
  if (!contact.has_pairing()) {  // C and g do not depend on u: the contact block is constant
    fom::ConstraintMatrix c;
    VectorXd g;
    contact.assemble(contact.search(VectorXd::Zero(static_cast<Index>(surf.size()))), c, g);
    m_bc_const = projected_contact(c);
    m_has_constant_contact = true;
  }
  m_setup_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

MatrixXd MonolithicDictionary::projected_stiffness(const fom::Param& mu) const {
  const VectorXd theta = m_model.problem().stiffness_coefficients(mu);
  MatrixXd k = theta(0) * m_bkd[0];
  for (std::size_t q = 1; q < m_bkd.size(); ++q) k += theta(static_cast<Index>(q)) * m_bkd[q];
  return k;
}

VectorXd MonolithicDictionary::surface_lifting(const fom::Param& mu) const {
  return m_lift_s * m_model.problem().load_coefficients(mu);
}

VectorXd MonolithicDictionary::projected_rhs(const fom::Param& mu) const {
  const VectorXd theta = m_model.problem().stiffness_coefficients(mu);
  const VectorXd phi = m_model.problem().load_coefficients(mu);
  VectorXd f = m_bf * phi;
  for (std::size_t q = 0; q < m_bkl.size(); ++q) f.noalias() -= theta(static_cast<Index>(q)) * (m_bkl[q] * phi);
  return f;
}

MatrixXd MonolithicDictionary::projected_contact(const fom::ConstraintMatrix& c) const {
  const MatrixXd cb = c * m_b_s;  // n_c × r_B
  return cb.transpose() * m_dd;
}

ConvexHullSolver::ConvexHullSolver(const ReducedModel& model, const Options& options)
    : m_dictionary((check_convex_hull_applicable(model.problem()), model), options) {}

ConvexHullResult ConvexHullSolver::solve_detailed(const fom::Param& mu) const {
  ConvexHullResult res;
  res.online = run_query(mu, [&](OnlineResult& on) { solve_hull(mu, res, on); });
  return res;
}

void ConvexHullSolver::solve_reduced(const fom::Param& mu, OnlineResult& res) const {
  ConvexHullResult details;
  solve_hull(mu, details, res);
}

Eigen::VectorXd ConvexHullSolver::reconstruct_primal(const OnlineResult& res) const {
  // u = u_lift(μ) + D_p α over the support (mesh-size work, for output only).
  VectorXd u = model().problem().lifting(res.mu);
  for (std::size_t i = 0; i < res.selected.size(); ++i)
    u.noalias() += res.coefficients(static_cast<Index>(i)) * m_dictionary.primal().col(res.selected[i]);
  return u;
}

void ConvexHullSolver::solve_hull(const fom::Param& mu, ConvexHullResult& res, OnlineResult& on) const {
  const MonolithicDictionary& dict = m_dictionary;
  const ConvexHullOptions& opt = dict.options();
  const ReducedModel& model = dict.model();
  const fom::ContactModel& contact = model.problem().contact();

  // The pairing fixed point around the exact projected solve at each pairing.
  PairedHullSolve solve_at(dict, mu);
  const HullFixedPoint fp = run_pairing_fixed_point(contact, model.problem().displacement_scale(), opt, solve_at);
  res.alpha = solve_at.alpha();
  res.focuss_iterations = solve_at.focuss_iterations();
  res.nnls_iterations = solve_at.nnls_iterations();
  res.pairing_iterations = fp.iterations;
  res.pairing = fp.last.pairing;
  res.pairing_change = fp.last.residual;
  const Status status = solve_at.status();
  const bool settled = fp.settled;

  const std::vector<Index> support = nonzeros(res.alpha);
  on.selected.assign(support.begin(), support.end());
  on.coefficients.resize(static_cast<Index>(support.size()));
  on.lambda = VectorXd::Zero(dict.dual().rows());
  on.u_hat = model.reduced_lifting(mu);
  for (std::size_t i = 0; i < support.size(); ++i) {
    const Index j = support[i];
    on.coefficients(static_cast<Index>(i)) = res.alpha(j);
    on.lambda.noalias() += res.alpha(j) * dict.dual().col(j);
    on.u_hat.noalias() += res.alpha(j) * dict.reduced_coordinates().col(j);
  }
  res.sum_violation = std::abs(res.alpha.sum() - 1.0);
  const VectorXd& bf = solve_at.projected_rhs();
  // stableNorm: at a vanishing load (d = 1e-300) the squares of bf underflow, and a
  // zero norm made the residual absolute, i.e. tiny, and the query a success.
  const double bf_norm = bf.stableNorm();
  const double residual = (solve_at.projected_operator() * res.alpha - bf).stableNorm();
  res.projected_residual = bf_norm > 0.0 ? residual / bf_norm : residual;
  on.iterations = res.focuss_iterations;
  on.converged = status == Status::Success && settled;
  on.status = status;
  // The projected problem may be solved exactly and still leave the load
  // unbalanced: the query lies outside the hull. That is not a success.
  if (on.converged && !(res.projected_residual <= opt.residual_tolerance)) {
    on.converged = false;
    on.status = Status::NoConvergence;
    char text[200];
    std::snprintf(text, sizeof text,
                  "no convex combination of the training snapshots balances this load: projected residual %.3g > %.3g"
                  " (query outside the convex hull, e.g. outside the training range)",
                  res.projected_residual, opt.residual_tolerance);
    on.message = text;
  } else if (status == Status::Success && !settled) {
    on.status = Status::NoConvergence;
    on.message = fp.message;
  } else if (status == Status::NoConvergence) {
    on.message = "nnFOCUSS reached its cap of " + std::to_string(opt.focuss.max_iterations) + " iterations";
  } else if (status != Status::Success) {
    on.message = std::string("convex-hull solve failed (") + to_string(status) + ")";
  }
}

const OptionTable<ConvexHullOptions>& convex_hull_option_table() {
  static const OptionTable<ConvexHullOptions> t = [] {
    using O = ConvexHullOptions;
    OptionTable<O> o;
    o.choice("basis", &O::basis, "projection basis: truncated SVD or random combinations",
             {{"svd", ProjectionBasis::Svd}, {"random", ProjectionBasis::Random}})
        .number("basis_delta", &O::basis_delta, "energy tolerance of the SVD basis; < 0: delta of the model",
                Interval{-std::numeric_limits<double>::infinity(), 1.0})
        .integer("rank_l", &O::rank_l, "random basis: number of combinations (0: rank of the SVD basis)", 0, 100000)
        .integer("seed", &O::seed, "random basis: seed of the generator", 0, 9e15)
        .number("sum_weight", &O::sum_weight, "weight of the convexity row relative to the largest column norm",
                Interval::greater_than(0))
        .flag("polish", &O::polish, "re-solve the simplex-constrained least squares on the support")
        .integer("max_pairing_iterations", &O::max_pairing_iterations, "cap of the pairing fixed point", 1, 1e6)
        .integer("selection_iterations", &O::selection_iterations,
                 "pairing loop: full nnFOCUSS solves before the support is frozen", 1, 1e6)
        .integer("anderson_depth", &O::anderson_depth,
                 "Anderson depth of the pairing fixed point (on the surface displacement)", 0, 100)
        .number("pairing_tolerance", &O::pairing_tolerance,
                "pairing fixed point: largest relative change of contact forces and gaps on re-pairing")
        .number("residual_tolerance", &O::residual_tolerance,
                "largest relative projected residual reported as success", Interval::at_least(0))
        .integer("focuss_max_iterations", [](auto& c) -> auto& { return c.focuss.max_iterations; },
                 "nnFOCUSS iteration cap", 1, 1e6)
        .number("focuss_tolerance", [](auto& c) -> auto& { return c.focuss.tolerance; },
                "nnFOCUSS stopping tolerance")
        .number("prune_tolerance", [](auto& c) -> auto& { return c.focuss.prune_tolerance; },
                "nnFOCUSS pruning threshold");
    return o;
  }();
  return t;
}

ConvexHullOptions convex_hull_options(const OnlineSolverOptions& options) {
  return read_options(convex_hull_option_table(), options, "convex-hull");
}

std::unique_ptr<OnlineSolver> make_convex_hull_solver(const ReducedModel& model, const OnlineSolverOptions& options) {
  return std::make_unique<ConvexHullSolver>(model, convex_hull_options(options));
}

}  // namespace contactrom::rom
