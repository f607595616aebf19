#include "rom/convex_hull.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>

#include "core/anderson.hpp"
#include "fom/input_values.hpp"
#include "rom/online_methods.hpp"
#include "rom/pod.hpp"

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

double parse_double(const std::string& key, const std::string& text) {
  return parse_option_number("convex-hull", key, text);
}

long long parse_integer(const std::string& key, const std::string& text) {
  return parse_option_integer("convex-hull", key, text);
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

}  // namespace

void check_convex_hull_applicable(const fom::Problem& problem) {
  if (problem.definition().rom.convex_hull) return;
  throw InputError("convex-hull needs a convex, parameter-independent feasible set; problem '" + problem.name() +
                   "' does not declare one (set convex_hull = true in its problem file's [rom] table when the "
                   "pairing changes little over the parameter range)");
}

MonolithicDictionary::MonolithicDictionary(const ReducedModel& model, const ConvexHullOptions& options)
    : m_model(model), m_options(options) {
  const auto t0 = std::chrono::steady_clock::now();
  const fom::Problem& problem = model.problem();
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

  // The monolithic dictionary holds the training solutions as the database stores
  // them, d_p = u_j − u_lift(μ_j) (Dirichlet lifting, so that u = u_lift(μ) + D_p α
  // is a convex combination of the snapshots up to the Dirichlet data): the reduced
  // model measures its snapshots from its own offset u_off, which is undone here.
  MatrixXd dp = model.primal_snapshots();
  const MatrixXd& dd = model.dictionary();
  const Index m = dp.cols();
  const int nt = problem.num_load_terms();
  const std::vector<VectorXd>& offset = model.offset_terms();
  const std::vector<VectorXd>& lifting = problem.lifting_terms();
  std::vector<VectorXd> offset_minus_lift;
  for (int k = 0; k < nt; ++k) offset_minus_lift.push_back(offset[static_cast<std::size_t>(k)] - lifting[static_cast<std::size_t>(k)]);
  for (Index c = 0; c < m; ++c) {
    const VectorXd phi = problem.load_coefficients(model.dictionary_parameters()[static_cast<std::size_t>(c)]);
    for (int k = 0; k < nt; ++k) dp.col(c) += phi(k) * offset_minus_lift[static_cast<std::size_t>(k)];
  }
  m_num_dofs = static_cast<int>(dp.rows());
  m_mono.resize(dp.rows() + dd.rows(), m);
  m_mono << dp, dd;
  m_dd = dd;  // contiguous copy for the online contact block

  // Projection basis B of the residual test space.
  Pod svd(PodOptions{delta, 0});
  svd.compute(dp);
  if (svd.info() != Status::Success)
    throw InputError("SVD of the primal dictionary of '" + problem.name() + "' failed (" + to_string(svd.info()) + ")");
  if (options.basis == ProjectionBasis::Svd) {
    m_b = svd.basis();
  } else {
    const int l = options.rank_l > 0 ? options.rank_l : svd.rank();
    std::mt19937_64 gen(options.seed);
    MatrixXd r(m, l);
    for (Index j = 0; j < r.cols(); ++j)  // column by column: R's columns do not depend on L
      for (Index i = 0; i < r.rows(); ++i) r(i, j) = uniform01(gen);
    // orth(D_p R): left singular vectors above the numerical rank (Pod with δ = 0).
    Pod orth(PodOptions{0.0, 0});
    orth.compute(dp * r);
    if (orth.info() != Status::Success)
      throw InputError("orthogonalisation of the randomised primal dictionary failed (" + std::string(to_string(orth.info())) + ")");
    m_b = orth.basis();
  }
  if (m_b.cols() == 0)
    throw InputError("the primal dictionary of '" + problem.name() + "' is zero: no projection basis");
  const std::vector<char>& dirichlet = problem.is_dirichlet();
  for (Index i = 0; i < m_b.rows(); ++i)
    if (dirichlet[static_cast<std::size_t>(i)]) m_b.row(i).setZero();

  const std::vector<int>& surf = problem.contact().surface_dofs();
  const auto ns = static_cast<Index>(surf.size());
  m_b_s.resize(ns, m_b.cols());
  m_dp_s.resize(ns, m);
  m_lift_s.resize(ns, nt);
  for (Index a = 0; a < ns; ++a) {
    const auto dof = surf[static_cast<std::size_t>(a)];
    m_b_s.row(a) = m_b.row(dof);
    m_dp_s.row(a) = dp.row(dof);
    for (int k = 0; k < nt; ++k) m_lift_s(a, k) = lifting[static_cast<std::size_t>(k)](dof);
  }

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
  // û = Φᵀ(u − u_off(μ)) = Φᵀ D_p α + Σ_k φ_k(μ) Φᵀ(L_k − L̃_k).
  m_phi_dp = model.basis().transpose() * dp;
  m_phi_dl.resize(model.basis().cols(), nt);
  for (int k = 0; k < nt; ++k) m_phi_dl.col(k) = -(model.basis().transpose() * offset_minus_lift[static_cast<std::size_t>(k)]);

  const fom::ContactModel& contact = problem.contact();
  if (!contact.has_pairing()) {  // C and g do not depend on u: the contact block is constant
    fom::ConstraintMatrix c;
    VectorXd g;
    contact.assemble(contact.search(VectorXd::Zero(ns)), c, g);
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

VectorXd MonolithicDictionary::reduced_offset(const fom::Param& mu) const {
  return m_phi_dl * m_model.problem().load_coefficients(mu);
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
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const MonolithicDictionary& dict = m_dictionary;
  const ConvexHullOptions& opt = dict.options();
  const ReducedModel& model = dict.model();
  const fom::ContactModel& contact = model.problem().contact();
  const Index m = dict.size();

  ConvexHullResult res;
  OnlineResult& on = res.online;
  on.mu = mu;

  const MatrixXd bk = dict.projected_stiffness(mu);
  const VectorXd bf = dict.projected_rhs(mu);
  const bool pairing = dict.constant_contact() == nullptr;
  VectorXd lift_s, u_s;
  if (pairing) lift_s = dict.surface_lifting(mu);

  // Pairing fixed point α ↦ g(α): pairing from u_s = u_lift,s + D_p,s α, contact
  // block, projected solve. Two phases. Selection: full solves (nnFOCUSS over all
  // columns) until the support repeats or `selection_iterations` solves are spent.
  // Then the support is frozen and only α iterates (the solve restricted to those
  // columns), a smooth map in which the pairing settles; re-selecting at every step
  // lets near-tied supports alternate forever. The frozen phase converges linearly
  // (rate 0.3–0.6 on hertz) and is accelerated by Anderson mixing, which keeps
  // 1ᵀα = 1 (a combination of iterates with weights summing to one) and is
  // abandoned for a plain step whenever it would make a coefficient negative. Once
  // it settles, one more full solve (budget permitting) checks the selection under
  // the converged pairing.
  const int cap = pairing ? opt.max_pairing_iterations : 1;
  fom::ConstraintMatrix c;
  VectorXd g, x;  // x: the α that defines the pairing (empty: centroid of the hull)
  MatrixXd a;
  Status status = Status::Success;
  bool settled = !pairing, frozen = false;
  std::vector<Index> support_prev;
  AndersonMixer mixer(opt.anderson_depth);  // on α, frozen phase only
  double last_change = std::numeric_limits<double>::infinity();
  int full_solves = 0;
  for (int it = 0; it < cap; ++it) {
    if (pairing) {
      if (x.size() == 0)
        u_s = lift_s + dict.surface_primal() * VectorXd::Constant(m, 1.0 / static_cast<double>(m));
      else
        u_s = lift_s + dict.surface_primal() * x;
      contact.assemble(contact.search(u_s), c, g);
      a = bk + dict.projected_contact(c);
    } else {
      a = bk + *dict.constant_contact();
    }
    auto full_solve = [&] {
      ProjectedSolve step = solve_projected(a, bf, opt);
      res.focuss_iterations += step.focuss_iterations;
      res.nnls_iterations += step.nnls_iterations;
      ++full_solves;
      status = step.status;
      return std::move(step.alpha);
    };
    if (!frozen) {
      res.alpha = full_solve();
    } else {
      ProjectedSolve step = solve_projected(select_columns(a, support_prev), bf, opt);
      res.focuss_iterations += step.focuss_iterations;
      res.nnls_iterations += step.nnls_iterations;
      res.alpha.setZero(m);
      for (std::size_t i = 0; i < support_prev.size(); ++i) res.alpha(support_prev[i]) = step.alpha(static_cast<Index>(i));
      status = step.status;
    }
    res.pairing_iterations = it + 1;
    if (!pairing || status == Status::NumericalIssue) break;
    std::vector<Index> support = nonzeros(res.alpha);
    // Fixed-point residual measured where the pairing reads it: the relative change
    // of the surface displacement (α itself can move along near-dependent columns
    // without any effect on u).
    const VectorXd u_next = lift_s + dict.surface_primal() * res.alpha;
    const double change = (u_next - u_s).norm() / std::max(u_next.norm(), std::numeric_limits<double>::min());
    bool same_support = it > 0 && support == support_prev;
    if (same_support && change <= opt.pairing_tolerance) {
      if (!frozen || full_solves >= opt.selection_iterations) {
        settled = true;
        break;
      }
      // Settled on a frozen support that was selected under an earlier pairing:
      // re-select once under the converged pairing. Same support: done; otherwise
      // continue the fixed point from the new selection.
      VectorXd reselected = full_solve();
      if (status == Status::NumericalIssue) break;
      std::vector<Index> support_new = nonzeros(reselected);
      if (support_new == support) {
        settled = true;
        break;
      }
      res.alpha = std::move(reselected);
      support = std::move(support_new);
      same_support = false;
    }
    if (!frozen && (same_support || full_solves >= opt.selection_iterations)) frozen = true;
    // Anderson safeguard: restart the history when the support changed or the
    // residual grew (the map is only piecewise smooth: pairing segments switch).
    if (!frozen || !same_support || change > last_change) mixer.clear();
    last_change = change;
    support_prev = std::move(support);

    // Next x: Anderson mixing of the last iterates in the frozen phase, else g(x).
    VectorXd next = res.alpha;
    if (frozen && x.size()) {
      const VectorXd mixed = mixer.next(x, res.alpha);
      if (mixed.allFinite() && (mixed.array() >= 0.0).all())
        next = mixed;
      else  // restart the history from the plain step
        mixer.restart();
    }
    x = std::move(next);
  }

  const std::vector<Index> support = nonzeros(res.alpha);
  on.selected.assign(support.begin(), support.end());
  on.coefficients.resize(static_cast<Index>(support.size()));
  on.lambda = VectorXd::Zero(dict.dual().rows());
  on.u_hat = dict.reduced_offset(mu);
  for (std::size_t i = 0; i < support.size(); ++i) {
    const Index j = support[i];
    on.coefficients(static_cast<Index>(i)) = res.alpha(j);
    on.lambda.noalias() += res.alpha(j) * dict.dual().col(j);
    on.u_hat.noalias() += res.alpha(j) * dict.reduced_coordinates().col(j);
  }
  res.sum_violation = std::abs(res.alpha.sum() - 1.0);
  // stableNorm: at a vanishing load (d = 1e-300) the squares of bf underflow, and a
  // zero norm made the residual absolute, i.e. tiny, and the query a success.
  const double bf_norm = bf.stableNorm();
  const double residual = (a * res.alpha - bf).stableNorm();
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
    on.message = "convex-hull pairing fixed point did not settle in " + std::to_string(opt.max_pairing_iterations) +
                 " iterations";
  } else if (status == Status::NoConvergence) {
    on.message = "nnFOCUSS reached its cap of " + std::to_string(opt.focuss.max_iterations) + " iterations";
  } else if (status != Status::Success) {
    on.message = std::string("convex-hull solve failed (") + to_string(status) + ")";
  }
  const auto t1 = clock::now();
  on.time_s = std::chrono::duration<double>(t1 - t0).count();

  // Full field u = u_lift(μ) + D_p α (mesh-size work, for output only).
  on.u = model.problem().lifting(mu);
  for (Index j : support) on.u.noalias() += res.alpha(j) * dict.primal().col(j);
  on.reconstruction_time_s = std::chrono::duration<double>(clock::now() - t1).count();
  return res;
}

ConvexHullOptions convex_hull_options(const OnlineSolverOptions& options) {
  ConvexHullOptions o;
  for (const auto& [key, value] : options.extra) {
    if (key == "basis") {
      if (value == "svd")
        o.basis = ProjectionBasis::Svd;
      else if (value == "random")
        o.basis = ProjectionBasis::Random;
      else
        throw InputError("convex-hull basis '" + value + "' unknown; expected svd or random");
    } else if (key == "basis_delta") {
      o.basis_delta = parse_double(key, value);
    } else if (key == "rank_l") {
      const long long l = parse_integer(key, value);
      if (l < 1 || l > 100000) throw InputError("convex-hull rank_l = " + value + " invalid; expected 1..100000");
      o.rank_l = static_cast<int>(l);
    } else if (key == "seed") {
      const long long s = parse_integer(key, value);
      if (s < 0) throw InputError("convex-hull seed = " + value + " invalid; expected >= 0");
      o.seed = static_cast<std::uint64_t>(s);
    } else if (key == "sum_weight") {
      o.sum_weight = parse_double(key, value);
    } else if (key == "polish") {
      if (value == "1" || value == "true")
        o.polish = true;
      else if (value == "0" || value == "false")
        o.polish = false;
      else
        throw InputError("convex-hull polish = '" + value + "' invalid; expected 0, 1, true or false");
    } else if (key == "max_pairing_iterations") {
      o.max_pairing_iterations = static_cast<int>(std::clamp(parse_integer(key, value), -1LL, 1000000LL));
    } else if (key == "selection_iterations") {
      o.selection_iterations = static_cast<int>(std::clamp(parse_integer(key, value), -1LL, 1000000LL));
    } else if (key == "anderson_depth") {
      o.anderson_depth = static_cast<int>(std::clamp(parse_integer(key, value), 0LL, 100LL));
    } else if (key == "pairing_tolerance") {
      o.pairing_tolerance = parse_double(key, value);
    } else if (key == "focuss_max_iterations") {
      const long long n = parse_integer(key, value);
      if (n < 1 || n > 1000000) throw InputError("convex-hull focuss_max_iterations = " + value + " invalid; expected >= 1");
      o.focuss.max_iterations = static_cast<int>(n);
    } else if (key == "residual_tolerance") {
      o.residual_tolerance = parse_number(value, "convex-hull option residual_tolerance", Interval::at_least(0));
    } else if (key == "focuss_tolerance") {
      o.focuss.tolerance = parse_double(key, value);
    } else if (key == "prune_tolerance") {
      o.focuss.prune_tolerance = parse_double(key, value);
    } else {
      throw InputError("convex-hull option '" + key +
                       "' unknown; expected basis, basis_delta, rank_l, seed, sum_weight, polish, "
                       "max_pairing_iterations, selection_iterations, anderson_depth, pairing_tolerance, residual_tolerance, "
                       "focuss_max_iterations, focuss_tolerance or "
                       "prune_tolerance");
    }
  }
  return o;
}

std::unique_ptr<OnlineSolver> make_convex_hull_solver(const ReducedModel& model, const OnlineSolverOptions& options) {
  return std::make_unique<ConvexHullSolver>(model, convex_hull_options(options));
}

void register_convex_hull_solver() { register_online_solver("convex-hull", make_convex_hull_solver); }

}  // namespace contactrom::rom
