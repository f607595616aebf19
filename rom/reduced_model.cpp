#include <contactrom/rom/reduced_model.hpp>

#include <contactrom/rom/error_indicator.hpp>

#include <contactrom/core/format.hpp>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/rom/error_indicator.hpp>
#include <contactrom/rom/pod.hpp>

namespace contactrom::rom {
namespace {

/// Unconstrained FOM responses L̃_k = L_k + K_ff⁻¹ (f_ext,k − K L_k)_f at μ̄: the
/// load responses of the FOM's condensation.
std::vector<Eigen::VectorXd> harmonic_offsets(const fom::Problem& problem) {
  const Eigen::MatrixXd z = fom::unconstrained_load_responses(problem, 0.5 * (problem.param_lower() + problem.param_upper()));
  std::vector<Eigen::VectorXd> out;
  for (Eigen::Index t = 0; t < z.cols(); ++t) out.push_back(z.col(t));
  return out;
}

/// Column k: Φᵀ(L_k − L̃_k), the lifting term's coordinates measured from the offset.
Eigen::MatrixXd lifting_coordinates(const Eigen::MatrixXd& phi, const fom::Problem& problem,
                                    const std::vector<Eigen::VectorXd>& offset_terms) {
  Eigen::MatrixXd out(phi.cols(), static_cast<Eigen::Index>(offset_terms.size()));
  for (size_t k = 0; k < offset_terms.size(); ++k)
    out.col(static_cast<Eigen::Index>(k)) = phi.transpose() * (problem.lifting_terms()[k] - offset_terms[k]);
  return out;
}

/// Refuses a database whose sizes are not the problem's, or a δ outside [0, 1].
void check_model_input(const fom::Problem& problem, const SnapshotDatabase& db, const ReducedModelOptions& options) {
  const int nd = problem.num_dofs(), nc = problem.contact().num_constraints();
  if (db.num_dofs() != nd || db.num_constraints() != nc)
    throw InputError("database of problem " + quoted(db.problem.name, 200) + " has " + std::to_string(db.num_dofs()) + " dofs and " +
                     std::to_string(db.num_constraints()) + " contact rows, but " + problem.name() + " has " +
                     std::to_string(nd) + " and " + std::to_string(nc));
  if (!(options.delta >= 0.0 && options.delta <= 1.0))
    throw InputError("delta = " + format_number(options.delta) +
                     " is outside [0, 1]; expected a POD tolerance such as 1e-8");
}

}  // namespace

std::vector<int> reduced_model_columns(const SnapshotDatabase& db, const ReducedModelOptions& options) {
  std::vector<int> out;
  for (int j = 0; j < db.num_snapshots(); ++j)
    if (options.include_failed_snapshots || db.status[j] == Status::Success) out.push_back(j);
  return out;
}

std::vector<Eigen::VectorXd> reduced_model_offsets(const fom::Problem& problem, OffsetKind kind) {
  return kind == OffsetKind::Harmonic ? harmonic_offsets(problem) : problem.lifting_terms();
}

ReducedSnapshots::ReducedSnapshots(const fom::Problem& problem, const SnapshotDatabase& db, std::vector<int> columns,
                                   const std::vector<Eigen::VectorXd>& offset_terms)
    : m_stored(primal_blocks(db, columns)) {
  // The database stores u − u_lift; the reduced displacement is measured from the
  // offset: u − u_off = (u − u_lift) − Σ_k φ_k (L̃_k − L_k).
  const int nt = problem.num_load_terms();
  for (int k = 0; k < nt; ++k) {
    Eigen::VectorXd d = offset_terms[k] - problem.lifting_terms()[k];
    if (d.cwiseAbs().maxCoeff() > 0.0) m_shift.emplace_back(k, std::move(d));
  }
  m_coefficients.resize(nt, static_cast<Eigen::Index>(columns.size()));
  for (size_t c = 0; c < columns.size(); ++c)
    m_coefficients.col(static_cast<Eigen::Index>(c)) = problem.load_coefficients(db.parameter(columns[c]));
}

void ReducedSnapshots::read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const {
  m_stored->read_rows(first, count, out);
  to_offset(first, out);
}

void ReducedSnapshots::to_offset(Eigen::Index first, Eigen::MatrixXd& block) const {
  for (Eigen::Index c = 0; c < block.cols(); ++c)
    for (const auto& [k, d] : m_shift) block.col(c) -= m_coefficients(k, c) * d.segment(first, block.rows());
}

void share_reduced_model_pod(const fom::Problem& problem, const SnapshotDatabase& db, const ReducedModelOptions& options) {
  const ReducedSnapshots snapshots(problem, db, reduced_model_columns(db, options),
                                   reduced_model_offsets(problem, options.offset));
  PodOptions pod_options = options.pod;
  pod_options.delta = options.delta;
  Pod(pod_options).compute(snapshots);
}

ReducedModel::ReducedModel(const fom::Problem& problem, const SnapshotDatabase& db, const ReducedModelOptions& options)
    : m_problem(problem), m_options(options) {
  const auto t0 = std::chrono::steady_clock::now();
  check_model_input(problem, db, options);
  m_dict_snapshots = reduced_model_columns(db, options);
  if (m_dict_snapshots.empty())
    throw InputError("database of problem " + quoted(db.problem.name, 200) + " holds no successful snapshot");
  m_offset = reduced_model_offsets(problem, options.offset);
  take_dictionary(db);
  compute_basis(ReducedSnapshots(problem, db, m_dict_snapshots, m_offset));
  reduce_operators();
  if (options.split_pairs) split_by_pair();
  derive();
  m_setup_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void ReducedModel::take_dictionary(const SnapshotDatabase& db) {
  m_dict.resize(db.num_constraints(), static_cast<Eigen::Index>(m_dict_snapshots.size()));
  for (size_t c = 0; c < m_dict_snapshots.size(); ++c) {
    const int j = m_dict_snapshots[c];
    m_dict.col(static_cast<Eigen::Index>(c)) = db.dual.col(j);
    m_dict_params.push_back(db.parameter(j));
  }
}

void ReducedModel::compute_basis(const ReducedSnapshots& snapshots) {
  // Primal basis: POD of u − u_off with the energy criterion (rom/pod.hpp); Dirichlet
  // rows of the snapshots are zero, so are those of Φ (set exactly, against rounding).
  // The snapshots are read whole only when kept (as stored, u − u_lift) or small
  // enough for the SVD; otherwise the POD reads them by blocks and gives their coordinates.
  const Eigen::Index nd = snapshots.rows(), m = snapshots.cols();
  PodOptions pod_options = m_options.pod;
  pod_options.delta = m_options.delta;
  Pod pod(pod_options);
  const auto t_pod = std::chrono::steady_clock::now();
  const bool whole = m_options.keep_primal_snapshots || pod.uses_svd(nd, m);
  Eigen::MatrixXd from_offset;  // u − u_off, when read whole
  if (whole) {
    Eigen::MatrixXd stored = snapshots.read_stored();
    from_offset = stored;
    snapshots.to_offset(0, from_offset);
    pod.compute(from_offset);
    m_primal = m_options.keep_primal_snapshots ? std::move(stored) : Eigen::MatrixXd(nd, 0);
  } else {
    pod.compute(snapshots);
    m_primal.resize(nd, 0);
  }
  m_pod_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_pod).count();
  if (pod.info() != Status::Success)
    throw InputError("POD of the primal snapshots of " + quoted(m_problem.name(), 200) + " failed (" + to_string(pod.info()) + ")");
  m_phi = pod.basis();
  m_sigma = pod.singular_values();
  const std::vector<char>& dirichlet = m_problem.is_dirichlet();
  // (A basis of rank 0, δ = 1, has no row to clear: row() of an empty matrix is
  // an offset on a null pointer.)
  for (Eigen::Index i = 0; i < nd && m_phi.cols() > 0; ++i)
    if (dirichlet[static_cast<size_t>(i)]) m_phi.row(i).setZero();
  m_snapshot_coords = whole ? Eigen::MatrixXd(m_phi.transpose() * from_offset) : pod.coordinates();
}

void ReducedModel::reduce_operators() {
  // Affine reduced operators (file comment).
  const int r = primal_rank(), nt = m_problem.num_load_terms();
  m_f_hat.resize(r, nt);
  for (int k = 0; k < nt; ++k) m_f_hat.col(k) = m_phi.transpose() * m_problem.external_load_terms()[k];
  for (int q = 0; q < m_problem.num_stiffness_terms(); ++q) {
    const fom::SparseMatrix& kq = m_problem.stiffness_term(q);
    const Eigen::MatrixXd kphi = kq * m_phi;
    Eigen::MatrixXd khat = m_phi.transpose() * kphi;
    m_k_hat.push_back(0.5 * (khat + khat.transpose()));  // symmetric to rounding
    Eigen::MatrixXd kl(r, nt);
    for (int k = 0; k < nt; ++k) kl.col(k) = kphi.transpose() * m_offset[k];  // Φᵀ K_q L̃_k, K_q symmetric
    m_kl_hat.push_back(kl);
  }
  m_lift_hat = lifting_coordinates(m_phi, m_problem, m_offset);
}

Eigen::MatrixXd ReducedModel::coordinates_of(const Eigen::MatrixXd& stored) const {
  Eigen::MatrixXd coords = m_phi.transpose() * stored;
  for (Eigen::Index c = 0; c < coords.cols(); ++c) coords.col(c) += reduced_lifting(m_dict_params[static_cast<size_t>(c)]);
  return coords;
}

void ReducedModel::split_by_pair() {
  const fom::ContactModel& contact = m_problem.contact();
  const int pairs = contact.num_pairs(), nc = static_cast<int>(m_dict.rows()), m = dictionary_size();
  if (pairs < 2) return;
  const bool primal_kept = m_primal.cols() == m;
  Eigen::MatrixXd dict(nc, 0), primal(m_primal.rows(), 0), coords(m_snapshot_coords.rows(), 0);
  std::vector<int> snapshots;
  std::vector<fom::Param> params;
  std::vector<std::pair<int, int>> parts;  // (column, pair) of the new columns
  for (int p = 0; p < m; ++p) {
    const size_t before = parts.size();
    for (int k = 0; k < pairs; ++k) {
      bool nonzero = false;
      for (int s = 0; s < nc && !nonzero; ++s) nonzero = contact.pair_of_row(s) == k && m_dict(s, p) != 0.0;
      if (nonzero) parts.emplace_back(p, k);
    }
    if (parts.size() == before) parts.emplace_back(p, -1);  // no pressure at all: one (zero) column
  }
  const int n = static_cast<int>(parts.size());
  dict.setZero(nc, n);
  primal.resize(m_primal.rows(), primal_kept ? n : 0);
  coords.resize(m_snapshot_coords.rows(), n);
  for (int c = 0; c < n; ++c) {
    const auto [p, k] = parts[static_cast<size_t>(c)];
    for (int s = 0; s < nc; ++s)
      if (k < 0 || contact.pair_of_row(s) == k) dict(s, c) = m_dict(s, p);
    if (primal_kept) primal.col(c) = m_primal.col(p);
    coords.col(c) = m_snapshot_coords.col(p);
    snapshots.push_back(m_dict_snapshots[static_cast<size_t>(p)]);
    params.push_back(m_dict_params[static_cast<size_t>(p)]);
  }
  m_dict = std::move(dict);
  m_primal = std::move(primal);
  m_snapshot_coords = std::move(coords);
  m_dict_snapshots = std::move(snapshots);
  m_dict_params = std::move(params);
}

ReducedModel::ReducedModel(const fom::Problem& problem, ReducedModelData data)
    : m_problem(problem), m_options(data.options) {
  const auto t0 = std::chrono::steady_clock::now();
  const long n = problem.num_dofs(), nc = problem.contact().num_constraints(), r = data.basis.cols();
  const long m = data.dictionary.cols(), nq = problem.num_stiffness_terms(), nt = problem.num_load_terms();
  const auto require = [&](bool ok, const std::string& what, long got, long expected) {
    if (!ok)
      throw InputError("reduced model of " + quoted(problem.name(), 200) + ": " + what + " has size " + std::to_string(got) +
                       ", expected " + std::to_string(expected));
  };
  require(data.basis.rows() == n, "the basis' row count", data.basis.rows(), n);
  require(r <= n, "the basis' column count", r, n);
  require(data.singular_values.size() >= r, "the singular values", data.singular_values.size(), r);
  require(static_cast<long>(data.offset_terms.size()) == nt, "the offset terms", data.offset_terms.size(), nt);
  for (const auto& l : data.offset_terms) require(l.size() == n, "an offset term", l.size(), n);
  require(static_cast<long>(data.stiffness_terms.size()) == nq, "the reduced stiffness terms",
          data.stiffness_terms.size(), nq);
  require(static_cast<long>(data.stiffness_offset_terms.size()) == nq, "the reduced stiffness-offset terms",
          data.stiffness_offset_terms.size(), nq);
  for (long q = 0; q < nq; ++q) {
    require(data.stiffness_terms[q].rows() == r && data.stiffness_terms[q].cols() == r, "a reduced stiffness term",
            data.stiffness_terms[q].size(), r * r);
    require(data.stiffness_offset_terms[q].rows() == r && data.stiffness_offset_terms[q].cols() == nt,
            "a reduced stiffness-offset term", data.stiffness_offset_terms[q].size(), r * nt);
  }
  require(data.load_terms.rows() == r && data.load_terms.cols() == nt, "the reduced load terms", data.load_terms.size(),
          r * nt);
  require(m > 0 && data.dictionary.rows() == nc, "the dictionary's row count", data.dictionary.rows(), nc);
  require(static_cast<long>(data.dictionary_snapshots.size()) == m, "the dictionary snapshot list",
          data.dictionary_snapshots.size(), m);
  require(static_cast<long>(data.dictionary_parameters.size()) == m, "the dictionary parameter list",
          data.dictionary_parameters.size(), m);
  for (const auto& p : data.dictionary_parameters)
    require(p.size() == problem.num_params(), "a dictionary parameter", p.size(), problem.num_params());
  if (data.primal_snapshots.cols() > 0)
    require(data.primal_snapshots.rows() == n && data.primal_snapshots.cols() == m, "the primal snapshots",
            data.primal_snapshots.size(), n * m);
  m_phi = std::move(data.basis);
  m_sigma = std::move(data.singular_values);
  m_offset = std::move(data.offset_terms);
  m_k_hat = std::move(data.stiffness_terms);
  m_f_hat = std::move(data.load_terms);
  m_kl_hat = std::move(data.stiffness_offset_terms);
  m_dict = std::move(data.dictionary);
  m_dict_snapshots = std::move(data.dictionary_snapshots);
  m_dict_params = std::move(data.dictionary_parameters);
  m_primal = data.primal_snapshots.cols() > 0 ? std::move(data.primal_snapshots) : Eigen::MatrixXd(n, 0);
  m_lift_hat = lifting_coordinates(m_phi, m_problem, m_offset);
  m_snapshot_coords = data.snapshot_coordinates.size() == 0 && m_primal.cols() > 0 ? coordinates_of(m_primal)
                                                                                   : std::move(data.snapshot_coordinates);
  require(m_snapshot_coords.rows() == r && m_snapshot_coords.cols() == m, "the snapshot coordinates",
          m_snapshot_coords.size(), r * m);
  m_options.keep_primal_snapshots = m_primal.cols() > 0;
  derive();
  m_setup_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

ReducedModelData ReducedModel::data() const {
  ReducedModelData d;
  d.options = m_options;
  d.basis = m_phi;
  d.singular_values = m_sigma;
  d.offset_terms = m_offset;
  d.stiffness_terms = m_k_hat;
  d.load_terms = m_f_hat;
  d.stiffness_offset_terms = m_kl_hat;
  d.dictionary = m_dict;
  d.dictionary_snapshots = m_dict_snapshots;
  d.dictionary_parameters = m_dict_params;
  d.primal_snapshots = m_primal;
  d.snapshot_coordinates = m_snapshot_coords;
  return d;
}

std::shared_ptr<const ErrorIndicator> ReducedModel::error_indicator() const {
  std::call_once(m_indicator->once, [this] { m_indicator->indicator = std::make_shared<const ErrorIndicator>(*this); });
  return m_indicator->indicator;
}

void ReducedModel::derive() {
  const std::vector<int>& surf = m_problem.contact().surface_dofs();
  const int ns = static_cast<int>(surf.size()), r = primal_rank(), nt = static_cast<int>(m_offset.size());
  build_parameter_grid();
  int snapshots = 0;
  for (int j : m_dict_snapshots) snapshots = std::max(snapshots, j + 1);
  m_siblings.assign(static_cast<size_t>(snapshots), {});
  for (int c = 0; c < dictionary_size(); ++c) m_siblings[static_cast<size_t>(m_dict_snapshots[static_cast<size_t>(c)])].push_back(c);
  m_phi_s.resize(ns, r);
  for (int a = 0; a < ns && r > 0; ++a) m_phi_s.row(a) = m_phi.row(surf[a]);
  m_phi_s_rows = m_phi_s;
  m_off_s.resize(ns, nt);
  for (int k = 0; k < nt; ++k)
    for (int a = 0; a < ns; ++a) m_off_s(a, k) = m_offset[k](surf[a]);
  // The contact search at every reduced snapshot, over all rows (a query's support
  // rows are a subset): one full search per column, offline.
  m_snapshot_memory.assign(static_cast<size_t>(dictionary_size()), fom::SearchMemory());
  fom::Pairing pairing;
  for (int p = 0; p < dictionary_size(); ++p) {
    const Eigen::VectorXd u_s = m_phi_s * m_snapshot_coords.col(p) + surface_offset(m_dict_params[static_cast<size_t>(p)]);
    m_problem.contact().search_rows(u_s, nullptr, nullptr, m_snapshot_memory[static_cast<size_t>(p)], pairing);
  }
  if (m_k_hat.size() == 1) {
    m_k_llt.compute(m_k_hat[0]);
    m_single_ok = m_k_llt.info() == Eigen::Success;
    if (m_single_ok) {
      m_k_inv = m_k_llt.solve(Eigen::MatrixXd::Identity(r, r));
      m_k_inv = (0.5 * (m_k_inv + m_k_inv.transpose())).eval();
    }
  }
}

void ReducedModel::build_parameter_grid() {
  const int m = dictionary_size(), d = m > 0 ? static_cast<int>(m_dict_params[0].size()) : 0;
  m_grid_values.assign(static_cast<size_t>(d), {});
  for (int k = 0; k < d; ++k) {
    std::vector<double>& v = m_grid_values[static_cast<size_t>(k)];
    for (const fom::Param& p : m_dict_params) v.push_back(p(k));
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }
  // A grid far larger than the dictionary is no tensor grid: interpolation_stencil
  // then falls back to the nearest training parameter.
  double nodes = 1.0;
  for (const auto& v : m_grid_values) nodes *= static_cast<double>(v.size());
  m_grid_columns.clear();
  if (m == 0 || nodes > 64.0 * m) return;
  m_grid_columns.assign(static_cast<size_t>(nodes), -1);
  for (int c = m - 1; c >= 0; --c) {  // the first column wins on duplicates
    size_t index = 0, stride = 1;
    for (int k = 0; k < d; ++k) {
      const auto& v = m_grid_values[static_cast<size_t>(k)];
      index += stride * static_cast<size_t>(std::lower_bound(v.begin(), v.end(), m_dict_params[c](k)) - v.begin());
      stride *= v.size();
    }
    m_grid_columns[index] = c;
  }
}

int ReducedModel::nearest_column(const std::vector<StencilPoint>& stencil) {
  const auto heaviest = std::max_element(stencil.begin(), stencil.end(),
                                         [](const StencilPoint& a, const StencilPoint& b) { return a.weight < b.weight; });
  return heaviest == stencil.end() ? -1 : heaviest->column;
}

std::vector<ReducedModel::StencilPoint> ReducedModel::interpolation_stencil(const fom::Param& mu) const {
  const int m = dictionary_size(), d = static_cast<int>(m_grid_values.size());
  std::vector<StencilPoint> out;
  if (m == 0) return out;
  if (!m_grid_columns.empty() && mu.size() == d) {
    // Per dimension: lower grid index and the weight t of the upper one.
    std::vector<size_t> lower(static_cast<size_t>(d));
    std::vector<double> t(static_cast<size_t>(d));
    for (int k = 0; k < d; ++k) {
      const auto& v = m_grid_values[static_cast<size_t>(k)];
      const double x = std::clamp(mu(k), v.front(), v.back());
      size_t i = static_cast<size_t>(std::upper_bound(v.begin(), v.end(), x) - v.begin());
      i = i == 0 ? 0 : i - 1;
      if (i + 1 >= v.size()) i = v.size() - 1;
      lower[static_cast<size_t>(k)] = i;
      t[static_cast<size_t>(k)] = i + 1 < v.size() ? (x - v[i]) / (v[i + 1] - v[i]) : 0.0;
    }
    bool complete = true;
    for (int corner = 0; corner < (1 << d) && complete; ++corner) {
      double weight = 1.0;
      size_t index = 0, stride = 1;
      for (int k = 0; k < d; ++k) {
        const bool up = (corner >> k) & 1;
        const double tk = t[static_cast<size_t>(k)];
        weight *= up ? tk : 1.0 - tk;
        index += stride * (lower[static_cast<size_t>(k)] + (up ? 1 : 0));
        stride *= m_grid_values[static_cast<size_t>(k)].size();
      }
      if (weight <= 0.0) continue;
      const int c = index < m_grid_columns.size() ? m_grid_columns[index] : -1;
      if (c < 0) complete = false;
      else out.push_back({c, weight});
    }
    if (complete && !out.empty()) return out;
    out.clear();
  }
  // Not a tensor grid around μ: the nearest training parameter, distances scaled by
  // the parameter range.
  const Eigen::VectorXd range = (m_problem.param_upper() - m_problem.param_lower()).cwiseMax(1e-300);
  int best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int c = 0; c < m; ++c) {
    if (m_dict_params[c].size() != mu.size()) continue;
    const double dist = (m_dict_params[c] - mu).cwiseQuotient(range).squaredNorm();
    if (dist < best_distance) best_distance = dist, best = c;
  }
  out.push_back({best, 1.0});
  return out;
}

Eigen::MatrixXd ReducedModel::reduced_stiffness(const fom::Param& mu) const {
  const Eigen::VectorXd theta = m_problem.stiffness_coefficients(mu);
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(primal_rank(), primal_rank());
  for (size_t q = 0; q < m_k_hat.size(); ++q) k += theta(q) * m_k_hat[q];
  return k;
}

Eigen::VectorXd ReducedModel::reduced_rhs(const fom::Param& mu) const {
  const Eigen::VectorXd theta = m_problem.stiffness_coefficients(mu);
  const Eigen::VectorXd phi = m_problem.load_coefficients(mu);
  Eigen::VectorXd f = m_f_hat * phi;
  for (size_t q = 0; q < m_kl_hat.size(); ++q) f.noalias() -= theta(q) * (m_kl_hat[q] * phi);
  return f;
}

ReducedStiffnessInverse::ReducedStiffnessInverse(const ReducedModel& model, const fom::Param& mu)
    : m_factor(model.single_term_factor()) {
  if (m_factor) {
    m_inv_theta = 1.0 / model.problem().stiffness_coefficients(mu)(0);
    m_inverse = model.single_term_inverse();
  } else {
    m_local.compute(model.reduced_stiffness(mu));
    m_factor = &m_local;
  }
  m_ok = m_factor->info() == Eigen::Success && std::isfinite(m_inv_theta);
}

Eigen::VectorXd ReducedModel::surface_offset(const fom::Param& mu) const {
  return m_off_s * m_problem.load_coefficients(mu);
}

Eigen::VectorXd ReducedModel::reduced_lifting(const fom::Param& mu) const {
  return m_lift_hat * m_problem.load_coefficients(mu);
}

Eigen::VectorXd ReducedModel::offset(const fom::Param& mu) const {
  const Eigen::VectorXd phi = m_problem.load_coefficients(mu);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(m_problem.num_dofs());
  for (size_t k = 0; k < m_offset.size(); ++k) u.noalias() += phi(static_cast<Eigen::Index>(k)) * m_offset[k];
  return u;
}

Eigen::VectorXd ReducedModel::reconstruct_primal(const Eigen::VectorXd& u_hat, const fom::Param& mu) const {
  Eigen::VectorXd u = offset(mu);
  u.noalias() += m_phi * u_hat;
  return u;
}

Eigen::VectorXd ReducedModel::reconstruct_dual(const std::vector<int>& columns,
                                               const Eigen::VectorXd& coefficients) const {
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m_dict.rows());
  for (size_t i = 0; i < columns.size(); ++i) lambda.noalias() += coefficients(static_cast<Eigen::Index>(i)) * m_dict.col(columns[i]);
  return lambda;
}

}  // namespace contactrom::rom
