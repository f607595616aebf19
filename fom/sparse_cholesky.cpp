#include <contactrom/fom/sparse_cholesky.hpp>

#include <cholmod.h>

#include <algorithm>
#include <cstddef>

// LAPACK: the inverse of A = L Lᵀ from its Cholesky factor L (uplo = "L"), in place in
// the lower triangle. The trailing argument is the hidden length of `uplo` (gfortran).
extern "C" void dpotri_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t uplo_length);

namespace contactrom::fom {
namespace {

/// A CHOLMOD workspace that prints nothing (CHOLMOD reports warnings such as a
/// matrix that is not positive definite on stdout by default; we return a status).
struct Common {
  cholmod_common c;
  Common() {
    cholmod_start(&c);
    c.print = 0;
  }
  ~Common() { cholmod_finish(&c); }
  Common(const Common&) = delete;
  Common& operator=(const Common&) = delete;
};

/// Read-only CHOLMOD view of a compressed column-major Eigen matrix; CHOLMOD uses
/// its lower triangle only (stype = -1).
cholmod_sparse view_lower(const Eigen::SparseMatrix<double>& a) {
  cholmod_sparse v{};
  v.nrow = static_cast<size_t>(a.rows());
  v.ncol = static_cast<size_t>(a.cols());
  v.nzmax = static_cast<size_t>(a.nonZeros());
  v.p = const_cast<int*>(a.outerIndexPtr());
  v.i = const_cast<int*>(a.innerIndexPtr());
  v.x = const_cast<double*>(a.valuePtr());
  v.stype = -1;
  v.itype = CHOLMOD_INT;
  v.xtype = CHOLMOD_REAL;
  v.dtype = CHOLMOD_DOUBLE;
  v.sorted = 1;
  v.packed = 1;
  return v;
}

/// CHOLMOD view of a dense column-major Eigen matrix (read-only use).
cholmod_dense view_dense(const Eigen::MatrixXd& b) {
  cholmod_dense v{};
  v.nrow = static_cast<size_t>(b.rows());
  v.ncol = static_cast<size_t>(b.cols());
  v.nzmax = v.nrow * v.ncol;
  v.d = v.nrow;
  v.x = const_cast<double*>(b.data());
  v.xtype = CHOLMOD_REAL;
  v.dtype = CHOLMOD_DOUBLE;
  return v;
}

/// The square block of `a` on the unknowns with keep[i] >= 0 (keep[i]: new index).
Eigen::SparseMatrix<double> sub_block(const Eigen::SparseMatrix<double>& a, const std::vector<int>& keep, int size) {
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<size_t>(a.nonZeros()));
  for (int col = 0; col < a.outerSize(); ++col) {
    if (keep[col] < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it)
      if (keep[it.row()] >= 0) trip.emplace_back(keep[it.row()], keep[col], it.value());
  }
  Eigen::SparseMatrix<double> b(size, size);
  b.setFromTriplets(trip.begin(), trip.end());
  return b;
}

/// Whether `set` holds distinct indices in [0, n).
bool valid_set(const std::vector<int>& set, int n) {
  std::vector<char> seen(static_cast<size_t>(n), 0);
  for (int i : set) {
    if (i < 0 || i >= n || seen[i]) return false;
    seen[i] = 1;
  }
  return true;
}

/// Fill-reducing permutation: CHOLMOD's default choice (AMD, or METIS/NESDIS when
/// AMD fills in badly) for the unknowns not in `last`, then `last` in its order.
bool ordering_with_last(const Eigen::SparseMatrix<double>& a, const std::vector<int>& last, std::vector<int>& perm) {
  const int n = static_cast<int>(a.rows());
  std::vector<int> lead_index(n, 0);
  for (int i : last) lead_index[i] = -1;
  std::vector<int> lead;  // leading unknowns, ascending
  for (int i = 0; i < n; ++i)
    if (lead_index[i] >= 0) lead_index[i] = static_cast<int>(lead.size()), lead.push_back(i);
  perm.clear();
  if (!lead.empty()) {
    Eigen::SparseMatrix<double> block = sub_block(a, lead_index, static_cast<int>(lead.size()));
    block.makeCompressed();
    cholmod_sparse view = view_lower(block);
    Common common;
    common.c.supernodal = CHOLMOD_SIMPLICIAL;  // ordering only; no supernodal analysis needed
    // AMD and METIS are both tried and the one with the smaller factor kept (by
    // default CHOLMOD tries METIS only when AMD fills in badly, which misses the 2D
    // meshes here: METIS' factor is about 20% smaller at 100k dofs).
    common.c.nmethods = 2;
    common.c.method[0].ordering = CHOLMOD_AMD;
    common.c.method[1].ordering = CHOLMOD_METIS;
    cholmod_factor* symbolic = cholmod_analyze(&view, &common.c);
    if (!symbolic) return false;
    const int* p = static_cast<const int*>(symbolic->Perm);
    for (size_t k = 0; k < lead.size(); ++k) perm.push_back(lead[p[k]]);
    cholmod_free_factor(&symbolic, &common.c);
  }
  perm.insert(perm.end(), last.begin(), last.end());
  return true;
}

/// Diagonal blocks of the dense lower-triangular `l`: maximal square blocks with
/// no entry below them in their columns (one per body when the bodies' surfaces
/// are listed body by body), as [begin, end) ranges.
std::vector<std::pair<Eigen::Index, Eigen::Index>> diagonal_blocks(const Eigen::MatrixXd& l) {
  std::vector<std::pair<Eigen::Index, Eigen::Index>> blocks;
  const Eigen::Index m = l.rows();
  Eigen::Index begin = 0, reach = -1;  // reach: lowest row with an entry in columns begin..j
  for (Eigen::Index j = 0; j < m; ++j) {
    for (Eigen::Index i = m - 1; i > reach; --i)
      if (l(i, j) != 0.0) {
        reach = i;
        break;
      }
    if (reach > j) continue;
    blocks.emplace_back(begin, j + 1);
    begin = j + 1;
  }
  return blocks;
}

}  // namespace

struct SparseCholesky::Impl {
  Common common;
  cholmod_factor* factor = nullptr;
  int num_last = 0;
  /// Diagonal blocks of L22 (dense lower-triangular), with their first row in L22.
  std::vector<std::pair<Eigen::Index, Eigen::MatrixXd>> l22_blocks;
  void extract_l22(int n);
  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &common.c);
  }
};

SparseCholesky::SparseCholesky() = default;
SparseCholesky::~SparseCholesky() = default;

SparseCholesky& SparseCholesky::compute(const Eigen::SparseMatrix<double>& a, const std::vector<int>& last) {
  std::vector<int> order;
  if (a.rows() != a.cols() || !valid_set(last, static_cast<int>(a.rows())) || !ordering_with_last(a, last, order)) {
    m_impl = std::make_unique<Impl>();
    m_info = Status::InvalidInput;
    return *this;
  }
  return compute(a, last, order);
}

SparseCholesky& SparseCholesky::compute(const Eigen::SparseMatrix<double>& a, const std::vector<int>& last,
                                        const std::vector<int>& order) {
  m_impl = std::make_unique<Impl>();
  m_n = static_cast<int>(a.rows());
  m_trailing = 0;
  m_order.clear();
  m_info = Status::InvalidInput;
  if (a.rows() != a.cols() || order.size() != static_cast<size_t>(m_n) || !valid_set(order, m_n) ||
      last.size() > order.size() || !std::equal(last.begin(), last.end(), order.end() - last.size()))
    return *this;
  std::vector<int> perm = order;

  Eigen::SparseMatrix<double> compressed = a;
  compressed.makeCompressed();
  cholmod_sparse view = view_lower(compressed);
  cholmod_common& c = m_impl->common.c;
  // Exactly the permutation above: no other ordering tried, no postordering (it
  // could interleave the trailing set with the rest), supernodal so that the
  // trailing block is read from dense supernode columns.
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_GIVEN;
  c.postorder = 0;
  c.supernodal = CHOLMOD_SUPERNODAL;
  m_impl->num_last = m_trailing = static_cast<int>(last.size());
  m_impl->factor = cholmod_analyze_p(&view, perm.data(), nullptr, 0, &c);
  if (!m_impl->factor) return *this;
  cholmod_factorize(&view, m_impl->factor, &c);
  if (c.status != CHOLMOD_OK) {
    m_info = Status::NumericalIssue;
    return *this;
  }
  m_impl->extract_l22(m_n);
  m_order = order;
  m_info = Status::Success;
  return *this;
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& b) const {
  if (m_info != Status::Success || b.rows() != m_n) return Eigen::MatrixXd();
  // A workspace per call: CHOLMOD keeps counters and scratch space in its common
  // object, so sharing one between threads would race. The factor is only read.
  Common common;
  cholmod_dense rhs = view_dense(b);
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, m_impl->factor, &rhs, &common.c);
  if (!x) return Eigen::MatrixXd();
  Eigen::MatrixXd result = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), b.rows(), b.cols());
  cholmod_free_dense(&x, &common.c);
  return result;
}

Eigen::MatrixXd SparseCholesky::solve_trailing(const Eigen::MatrixXd& f) const {
  const int m = m_impl ? m_impl->num_last : 0;
  if (m_info != Status::Success || f.rows() != m) return Eigen::MatrixXd();
  // P A⁻¹ Pᵀ = L⁻ᵀ L⁻¹ and Pᵀ [0; f] has zeros outside the trailing set, so the
  // forward solve is y = [0; L22⁻¹ f]: only the backward solve touches all of L.
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(m_n, f.cols());
  for (const auto& [begin, l] : m_impl->l22_blocks) {
    auto part = y.middleRows(m_n - m + begin, l.rows());
    part = f.middleRows(begin, l.rows());
    l.triangularView<Eigen::Lower>().solveInPlace(part);
  }
  Common common;  // per call, see solve()
  cholmod_dense rhs = view_dense(y);
  cholmod_dense* x_perm = cholmod_solve(CHOLMOD_Lt, m_impl->factor, &rhs, &common.c);
  if (!x_perm) return Eigen::MatrixXd();
  cholmod_dense* x = cholmod_solve(CHOLMOD_Pt, m_impl->factor, x_perm, &common.c);
  cholmod_free_dense(&x_perm, &common.c);
  if (!x) return Eigen::MatrixXd();
  Eigen::MatrixXd result = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), m_n, f.cols());
  cholmod_free_dense(&x, &common.c);
  return result;
}

Eigen::MatrixXd SparseCholesky::inverse_block() const {
  const int m = m_impl ? m_impl->num_last : 0;
  if (m_info != Status::Success) return Eigen::MatrixXd();
  // (A⁻¹)_ss = L22⁻ᵀ L22⁻¹ = (L22 L22ᵀ)⁻¹, block by diagonal block of L22: LAPACK's
  // dpotri inverts from the Cholesky factor in 2n³/3 flops of blocked BLAS-3 work (the
  // system BLAS, as CHOLMOD's), a third of a triangular solve against the identity
  // followed by a rank update.
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(m, m);
  for (const auto& [begin, l] : m_impl->l22_blocks) {
    int size = static_cast<int>(l.rows()), info = 0;
    Eigen::MatrixXd block = l;
    dpotri_("L", &size, block.data(), &size, &info, 1);
    if (info != 0) return Eigen::MatrixXd();  // a zero pivot: not after a successful compute()
    result.block(begin, begin, size, size) = block.selfadjointView<Eigen::Lower>();
  }
  return result;
}

void SparseCholesky::Impl::extract_l22(int n) {
  const cholmod_factor& f = *factor;
  const int m = num_last, first = n - m;
  // L22: the trailing m columns of the supernodal factor. Supernode k holds columns
  // [super[k], super[k+1]) as a dense column-major block of its rows s[pi[k]..pi[k+1]).
  Eigen::MatrixXd l22 = Eigen::MatrixXd::Zero(m, m);
  const int* super = static_cast<const int*>(f.super);
  const int* pi = static_cast<const int*>(f.pi);
  const int* px = static_cast<const int*>(f.px);
  const int* rows = static_cast<const int*>(f.s);
  const double* values = static_cast<const double*>(f.x);
  for (size_t k = 0; k < f.nsuper; ++k) {
    const int k1 = super[k], k2 = super[k + 1], nrow = pi[k + 1] - pi[k];
    for (int j = std::max(k1, first); j < k2; ++j)
      for (int r = j - k1; r < nrow; ++r)
        l22(rows[pi[k] + r] - first, j - first) = values[px[k] + r + static_cast<long>(j - k1) * nrow];
  }
  l22_blocks.clear();
  for (const auto& [begin, end] : diagonal_blocks(l22))
    l22_blocks.emplace_back(begin, l22.block(begin, begin, end - begin, end - begin));
}

}  // namespace contactrom::fom
