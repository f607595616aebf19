#include <contactrom/fom/contact_model.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include <contactrom/core/errors.hpp>

namespace contactrom::fom {
namespace {
/// Extension of a master chain beyond its end nodes, as a fraction of the end
/// segment's length, within which a slave node still pairs with the chain's end
/// (docs/theory.md, "Contact pairing"); as the extension zone of common
/// node-to-surface codes, 10 %.
constexpr double kChainEndExtension = 0.1;
}  // namespace

bool Pairing::same_as(const Pairing& other, double tol) const {
  if (segment.size() != other.segment.size() || eta.size() != other.eta.size()) return false;
  for (size_t s = 0; s < segment.size(); ++s) {
    if ((segment[s] < 0) != (other.segment[s] < 0)) return false;
    if (segment[s] < 0) continue;
    if (!eta.empty()) {  // 3D: the same facet, local coordinates and normal
      if (segment[s] != other.segment[s] || std::abs(xi[s] - other.xi[s]) > tol || std::abs(eta[s] - other.eta[s]) > tol ||
          (normal.col(s) - other.normal.col(s)).cwiseAbs().maxCoeff() > tol)
        return false;
      continue;
    }
    // Position along the master chain, continuous across segment ends: a slave
    // node moving from the end of segment j to the start of j+1 is no change.
    // (integer part first: identical pairings differ by exactly zero)
    if (std::abs(static_cast<double>(segment[s] - other.segment[s]) + (xi[s] - other.xi[s])) > tol) return false;
    if ((normal.col(s) - other.normal.col(s)).cwiseAbs().maxCoeff() > tol) return false;
  }
  return true;
}

Eigen::VectorXd ContactModel::restrict_to_surface(const Eigen::VectorXd& u_full) const {
  Eigen::VectorXd out(m_surface_dofs.size());
  for (size_t i = 0; i < m_surface_dofs.size(); ++i) out(i) = u_full(m_surface_dofs[i]);
  return out;
}

void ContactModel::assemble_rows(const Pairing& pairing, const std::vector<int>& rows, ConstraintMatrix& c,
                                 Eigen::VectorXd& g) const {
  ConstraintMatrix full;
  Eigen::VectorXd g_full;
  assemble(pairing, full, g_full);
  c.resize(static_cast<Eigen::Index>(rows.size()), full.cols());
  g.resize(static_cast<Eigen::Index>(rows.size()));
  for (size_t i = 0; i < rows.size(); ++i) {
    c.startVec(static_cast<Eigen::Index>(i));
    for (ConstraintMatrix::InnerIterator it(full, rows[i]); it; ++it) c.insertBack(static_cast<Eigen::Index>(i), it.col()) = it.value();
    g(static_cast<Eigen::Index>(i)) = g_full(rows[i]);
  }
  c.finalize();
}

NodeToSegmentContact::NodeToSegmentContact(const Eigen::Matrix2Xd& nodes, const std::vector<ContactPairChains>& pairs) {
  // Surface nodes: every slave node (row order), then the master nodes not seen yet.
  std::map<int, int> surface_of;  // mesh node -> surface node index
  for (size_t q = 0; q < pairs.size(); ++q) {
    if (pairs[q].slave.empty() || pairs[q].master.size() < 2)
      throw InputError("contact pair " + std::to_string(q) + " has " + std::to_string(pairs[q].slave.size()) +
                       " slave nodes and " + std::to_string(pairs[q].master.size()) +
                       " master nodes; expected at least one slave node and one master segment");
    for (int node : pairs[q].slave) {
      if (!surface_of.emplace(node, static_cast<int>(m_slave.size())).second)
        throw InputError("contact pairs share the slave node at (" + std::to_string(nodes(0, node)) + ", " +
                         std::to_string(nodes(1, node)) + "); expected each slave node in one pair only");
      m_slave.push_back(node);
      m_row_pair.push_back(static_cast<int>(q));
    }
  }
  const int ns = static_cast<int>(m_slave.size());
  int next = ns;
  std::vector<int> surface_nodes(m_slave);
  int row = 0;
  for (const ContactPairChains& chains : pairs) {
    Pair pair;
    pair.row_begin = row;
    pair.row_end = row += static_cast<int>(chains.slave.size());
    pair.master = chains.master;
    pair.master_x.resize(2, static_cast<Eigen::Index>(chains.master.size()));
    for (size_t j = 0; j < chains.master.size(); ++j) {
      const int node = chains.master[j];
      auto [it, inserted] = surface_of.emplace(node, next);
      if (inserted) {
        surface_nodes.push_back(node);
        ++next;
      }
      if (it->second >= pair.row_begin && it->second < pair.row_end)
        throw InputError("a contact pair's master curve contains its own slave node at (" +
                         std::to_string(nodes(0, node)) + ", " + std::to_string(nodes(1, node)) + ")");
      pair.master_surface.push_back(it->second);
      pair.master_x.col(static_cast<Eigen::Index>(j)) = nodes.col(node);
    }
    double length = 0.0;
    for (Eigen::Index j = 0; j + 1 < pair.master_x.cols(); ++j)
      length += (pair.master_x.col(j + 1) - pair.master_x.col(j)).norm();
    pair.margin = 0.5 * length / static_cast<double>(pair.master_x.cols() - 1);
    m_pairs.push_back(std::move(pair));
  }
  for (int node : surface_nodes) m_surface_dofs.insert(m_surface_dofs.end(), {2 * node, 2 * node + 1});
  m_slave_x.resize(2, ns);
  for (int k = 0; k < ns; ++k) m_slave_x.col(k) = nodes.col(m_slave[k]);
  m_points = m_slave_x;

  // Tributary lengths: half of each adjacent slave segment, within each pair's chain.
  m_weights = Eigen::VectorXd::Zero(ns);
  for (const Pair& pair : m_pairs)
    for (int k = pair.row_begin; k + 1 < pair.row_end; ++k) {
      const double len = (m_slave_x.col(k + 1) - m_slave_x.col(k)).norm();
      m_weights(k) += 0.5 * len;
      m_weights(k + 1) += 0.5 * len;
    }
}

int NodeToSegmentContact::pair_of_row(int row) const { return m_row_pair[static_cast<size_t>(row)]; }

void NodeToSegmentContact::search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows,
                                       const Pairing* hint, Pairing& p) const {
  search_all(u_surface, rows, hint, nullptr, p);
}

void NodeToSegmentContact::search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows,
                                       const Pairing* hint, SearchMemory& memory, Pairing& p) const {
  const int ns = static_cast<int>(m_slave.size());
  if (static_cast<int>(memory.centre.size()) != ns) {
    memory.centre.assign(ns, -1);
    memory.clearance.assign(ns, 0.0);
    memory.slave_reference.resize(2, ns);
    memory.master_reference.assign(m_pairs.size(), Eigen::Matrix2Xd());
    memory.recorded.assign(m_pairs.size(), 0);
  }
  search_all(u_surface, rows, hint, &memory, p);
}

void NodeToSegmentContact::search_all(const Eigen::VectorXd& u_surface, const std::vector<int>* rows,
                                      const Pairing* hint, SearchMemory* memory, Pairing& p) const {
  if (hint == &p) {  // the hint is read while p is written
    const Pairing copy = *hint;
    search_all(u_surface, rows, &copy, memory, p);
    return;
  }
  const int ns = static_cast<int>(m_slave.size());
  p.segment.assign(ns, -1);
  p.xi.assign(ns, 0.0);
  p.eta.clear();
  p.normal.setZero(2, ns);
  // The listed rows are ascending, so each pair's rows are one contiguous run of them.
  size_t r = 0;
  for (size_t q = 0; q < m_pairs.size(); ++q) {
    const Pair& pair = m_pairs[q];
    const int pq = static_cast<int>(q);
    PairRequest request;
    request.pair_index = pq;
    request.hint = hint;
    request.memory = memory;
    if (!rows) {
      request.num_rows = pair.row_end - pair.row_begin;
      search_pair(request, u_surface, p);
      continue;
    }
    const size_t first = r;
    while (r < rows->size() && (*rows)[r] < pair.row_end) ++r;
    request.listed_rows = rows->data() + first;
    request.num_rows = static_cast<int>(r - first);
    if (r > first) search_pair(request, u_surface, p);
  }
}

/// One pair's search: closest master segment and normal of every requested row.
/// The geometry of the deformed master chain lives in per-thread scratch arrays: a
/// search takes a few microseconds inside the online loops, where allocating them
/// on every call would be a visible share.
class NodeToSegmentContact::PairSearch {
 public:
  PairSearch(const NodeToSegmentContact& contact, const PairRequest& request, const Eigen::VectorXd& u_surface, Pairing& p)
      : m_contact(contact),
        m_pair(contact.m_pairs[static_cast<size_t>(request.pair_index)]),
        m_request(request),
        m_memory(request.memory),
        m_u(u_surface),
        m_p(p),
        m_nm(static_cast<int>(m_pair.master.size())),
        m_nseg(std::max(m_nm - 1, 0)),
        m_s(scratch()),
        m_lowest(m_nseg) {
    m_s.xm.resize(2, m_nm);
    m_s.seg_t.resize(2, m_nseg);
    m_s.mid.resize(2, m_nseg);
    m_s.inv_len2.resize(m_nseg);
    m_s.half.resize(m_nseg);
  }

  /// Rows settled from the memory: each among its recorded segment and the
  /// neighbours, certified by the clearance. False (and nothing paired) when the
  /// memory holds no record of the pair or one row fails.
  bool certify_from_memory() {
    if (!m_memory || !m_memory->recorded[static_cast<size_t>(m_request.pair_index)] || m_nseg == 0) return false;
    const double b = largest_master_move();
    // Only the segments the recorded ones and their neighbours reach (the normals
    // use one more on each side).
    int c_min = m_nseg, c_max = -1;
    for (int r = 0; r < m_request.num_rows; ++r) {
      const int c = m_memory->centre[static_cast<size_t>(row(r))];
      if (c >= 0) c_min = std::min(c_min, c), c_max = std::max(c_max, c);
    }
    if (c_max >= 0) prepare(std::max(c_min - 2, 0), std::min(c_max + 3, m_nseg), false);
    bool settled = true;
    for (int r = 0; r < m_request.num_rows && settled; ++r) {
      settled = certify_row(row(r), b);
    }
    if (settled) {
      m_memory->certified += m_request.num_rows;
      return true;
    }
    m_lowest = m_nseg, m_highest = -1;  // start again, in full
    for (int r = 0; r < m_request.num_rows; ++r) m_p.segment[row(r)] = -1;
    return false;
  }

  /// Exact closest segment per row, pruned by bounding circles of blocks of
  /// segments and of each segment; recorded in the memory when there is one.
  void pruned_search() {
    prepare(0, m_nseg, true);
    bound_blocks();
    if (m_memory)  // rows of the pair left out of this search lose their record
      std::fill(m_memory->centre.begin() + m_pair.row_begin, m_memory->centre.begin() + m_pair.row_end, -1);
    // The segment of the previous slave node is tried first (neighbouring slave
    // nodes have neighbouring pairs).
    int guess = 0;
    for (int r = 0; r < m_request.num_rows; ++r) {
      const int k = row(r);
      const Pairing* hint = m_request.hint;
      if (hint && hint->segment.size() == m_p.segment.size() && hint->segment[k] >= 0) guess = hint->segment[k];
      Tried tried;
      const Best best = closest_segment(slave_position(k), guess, tried);
      if (best.seg >= 0) guess = best.seg;
      pair_row(k, best);
      if (m_memory) record_row(k, best, tried);
    }
    if (m_memory) record_pair();
  }

  /// Nodal normals of the deformed master surface (average of the adjacent
  /// segments' outward normals) where rows are paired, nodes lowest … highest+1:
  /// interpolating them along a segment gives a normal field that is continuous
  /// across master nodes, so the constraint row does not jump when a slave node
  /// passes from one segment to the next.
  void nodal_normals() {
    if (m_highest < 0) return;
    Eigen::Matrix2Xd& node_normal = m_s.node_normal;
    node_normal.resize(2, m_nm);
    node_normal.middleCols(m_lowest, m_highest + 2 - m_lowest).setZero();
    for (int j = std::max(m_lowest - 1, 0); j <= std::min(m_highest + 1, m_nseg - 1); ++j) {
      const Eigen::Vector2d t = m_s.seg_t.col(j);
      // Chains run with their body on the left: (t_y, −t_x) points out of the master body.
      const Eigen::Vector2d n = (1.0 / t.norm()) * Eigen::Vector2d(t.y(), -t.x());
      if (j >= m_lowest) node_normal.col(j) += n;
      if (j + 1 <= m_highest + 1) node_normal.col(j + 1) += n;
    }
    for (int j = m_lowest; j <= m_highest + 1; ++j) node_normal.col(j).normalize();
    for (int r = 0; r < m_request.num_rows; ++r) {
      const int k = row(r), j = m_p.segment[k];
      if (j < 0) continue;
      const double xi = m_p.xi[k];
      m_p.normal.col(k) = ((1.0 - xi) * node_normal.col(j) + xi * node_normal.col(j + 1)).normalized();
    }
  }

 private:
  struct Scratch {
    Eigen::Matrix2Xd xm, node_normal, seg_t, mid, block_c;
    Eigen::VectorXd inv_len2, half, block_r;
  };
  static Scratch& scratch() {
    thread_local Scratch s;
    return s;
  }

  /// Closest point found so far. The distance itself (a square root on the
  /// critical path) is taken only where it is used: by the pruning of a full search
  /// after each improvement, by the certificate of a settled row once.
  struct Best {
    double dist2 = std::numeric_limits<double>::max(), root = std::numeric_limits<double>::max();
    int seg = -1;
    double xi = 0.0, raw = 0.0;
  };
  /// The four nearest segments tried, by squared distance (for the clearance: at
  /// least one of them is not the closest segment or one of its two neighbours).
  struct Tried {
    static constexpr int kept = 4;
    int seg[kept];
    double d2[kept];
    int count = 0;
    void insert(int j, double d2_j) {
      for (int t = 0; t < std::min(count, kept); ++t)  // insertion into the sorted four
        if (d2_j < d2[t]) std::swap(d2_j, d2[t]), std::swap(j, seg[t]);
      if (count < kept) seg[count] = j, d2[count] = d2_j;
      ++count;
    }
  };

  int row(int r) const { return m_request.listed_rows ? m_request.listed_rows[r] : m_pair.row_begin + r; }

  Eigen::Vector2d slave_position(int k) const {
    const Eigen::Matrix2Xd& x = m_contact.m_slave_x;
    return Eigen::Vector2d(x(0, k) + m_u(2 * k), x(1, k) + m_u(2 * k + 1));
  }

  /// Deformed master nodes and, per segment j0 … j1−1: tangent t, 1/|t|², and (for
  /// the pruning of a full search) the midpoint and the radius ½(|t_x|+|t_y|) ≥ ½|t|
  /// of a circle about it holding the segment (no root).
  void prepare(int j0, int j1, bool circles) {
    for (int j = j0; j <= std::min(j1, m_nm - 1); ++j)
      m_s.xm.col(j) = m_pair.master_x.col(j) + m_u.segment<2>(2 * m_pair.master_surface[static_cast<size_t>(j)]);
    for (int j = j0; j < j1; ++j) {
      const Eigen::Vector2d t = m_s.xm.col(j + 1) - m_s.xm.col(j);
      m_s.seg_t.col(j) = t;
      m_s.inv_len2(j) = 1.0 / t.squaredNorm();
      if (!circles) continue;  // the settled rows need no pruning
      m_s.mid.col(j) = 0.5 * (m_s.xm.col(j + 1) + m_s.xm.col(j));
      m_s.half(j) = 0.5 * (std::abs(t.x()) + std::abs(t.y()));
    }
  }

  /// Closest point of slave position (px, py) on segment j, kept when closer than
  /// the best so far; ties (a slave node exactly at a master node) go to the lower
  /// segment index. Returns the squared distance.
  double try_segment(double px, double py, int j, Best& best) const {
    const double dx = px - m_s.xm(0, j), dy = py - m_s.xm(1, j), tx = m_s.seg_t(0, j), ty = m_s.seg_t(1, j);
    const double raw = (dx * tx + dy * ty) * m_s.inv_len2(j);
    const double xi = raw < 0.0 ? 0.0 : (raw > 1.0 ? 1.0 : raw);
    const double ex = dx - xi * tx, ey = dy - xi * ty;
    const double dist2 = ex * ex + ey * ey;
    if (dist2 < best.dist2 * (1.0 - 1e-14) || (best.seg >= 0 && dist2 <= best.dist2 * (1.0 + 1e-14) && j < best.seg))
      best = {dist2, best.root, j, xi, raw};
    return dist2;
  }

  /// Stores row k's closest segment in the pairing.
  void pair_row(int k, const Best& best) {
    // A projection beyond either end of the master chain is no contact pair, except
    // within kChainEndExtension of the end segment's length: there the slave node is
    // paired with the chain's end (ξ clamped, the end segment's normal), i.e. with
    // the end segment extended. Flush ends (two blocks of equal width, a corner
    // shared by both surfaces) put slave corner nodes exactly at a master end, where
    // round-off alone would otherwise switch the pair on and off between iterations.
    if (best.seg < 0 || (best.seg == 0 && best.raw < -kChainEndExtension) ||
        (best.seg == m_nm - 2 && best.raw > 1.0 + kChainEndExtension))
      return;
    m_p.segment[k] = best.seg;
    m_p.xi[k] = best.xi;
    m_lowest = std::min(m_lowest, best.seg);
    m_highest = std::max(m_highest, best.seg);
  }

  /// Largest movement of a master node since the record.
  double largest_master_move() const {
    const Eigen::Matrix2Xd& ref = m_memory->master_reference[static_cast<size_t>(m_request.pair_index)];
    double b2 = 0.0;
    for (int j = 0; j < m_nm; ++j)
      b2 = std::max(b2, (m_u.segment<2>(2 * m_pair.master_surface[static_cast<size_t>(j)]) - ref.col(j)).squaredNorm());
    return std::sqrt(b2);
  }

  /// Row k settled among its recorded segment c and the neighbours: the slave node
  /// moved by a and no master node by more than b since the record, so every other
  /// segment is at least clearance − a − b away; paired when that exceeds the
  /// distance found.
  bool certify_row(int k, double b) {
    const int c = m_memory->centre[static_cast<size_t>(k)];
    if (c < 0) return false;
    const Eigen::Vector2d x = slave_position(k);
    Best best;
    try_segment(x.x(), x.y(), c, best);
    if (c > 0) try_segment(x.x(), x.y(), c - 1, best);
    if (c + 1 < m_nseg) try_segment(x.x(), x.y(), c + 1, best);
    best.root = std::sqrt(best.dist2);
    const double a = (m_u.segment<2>(2 * k) - m_memory->slave_reference.col(k)).norm();
    if (!(m_memory->clearance[static_cast<size_t>(k)] - a - b > best.root * (1.0 + 1e-12))) return false;
    pair_row(k, best);
    return true;
  }

  /// Bounding circles (centre, radius) of blocks of m_block consecutive segments.
  void bound_blocks() {
    const int block = m_contact.m_block;
    m_nblock = (m_nseg + block - 1) / block;
    m_s.block_c.resize(2, m_nblock);
    m_s.block_r.resize(m_nblock);
    for (int b = 0; b < m_nblock; ++b) {
      const int j0 = b * block, j1 = std::min(m_nseg, j0 + block);  // vertices j0..j1
      m_s.block_c.col(b) = m_s.xm.middleCols(j0, j1 - j0 + 1).rowwise().mean();
      double r2 = 0.0;
      for (int j = j0; j <= j1; ++j) r2 = std::max(r2, (m_s.xm.col(j) - m_s.block_c.col(b)).squaredNorm());
      m_s.block_r(b) = std::sqrt(r2);
    }
  }

  /// Closest segment to x: the guess and its neighbours first (a good first
  /// distance prunes the rest), then every block whose circle may hold a closer
  /// point (plus the margin when recording, so that skipped segments are known to
  /// be at least that much farther), and within it every segment whose circle may.
  Best closest_segment(const Eigen::Vector2d& x, int guess, Tried& tried) const {
    const double px = x.x(), py = x.y();
    const double margin = m_memory ? m_pair.margin : 0.0;
    const int block = m_contact.m_block;
    Best best;
    const auto visit = [&](int j) {
      const double d2 = try_segment(px, py, j, best);
      if (best.seg == j) best.root = std::sqrt(d2);  // closer than before: the pruning's radius
      if (m_memory) tried.insert(j, d2);
    };
    if (m_nseg > 0) {
      visit(guess);
      if (guess > 0) visit(guess - 1);
      if (guess + 1 < m_nseg) visit(guess + 1);
    }
    for (int b = 0; b < m_nblock; ++b) {
      const double bx = px - m_s.block_c(0, b), by = py - m_s.block_c(1, b), reach = best.root + margin + m_s.block_r(b);
      if (bx * bx + by * by > reach * reach * (1.0 + 1e-12)) continue;
      const int j1 = std::min(m_nseg, (b + 1) * block);
      for (int j = b * block; j < j1; ++j) {
        if (j >= guess - 1 && j <= guess + 1) continue;
        const double mx = px - m_s.mid(0, j), my = py - m_s.mid(1, j), sreach = best.root + margin + m_s.half(j);
        if (mx * mx + my * my > sreach * sreach * (1.0 + 1e-12)) continue;
        visit(j);
      }
    }
    return best;
  }

  /// Records row k: its segment and clearance. Skipped segments are farther than
  /// best + margin (the pruning used a best that was at least the final one);
  /// tried ones are known.
  void record_row(int k, const Best& best, const Tried& tried) {
    double clearance = best.root + m_pair.margin;
    for (int t = 0; t < std::min(tried.count, Tried::kept); ++t)
      if (std::abs(tried.seg[t] - best.seg) > 1) {
        clearance = std::min(clearance, std::sqrt(tried.d2[t]));
        break;
      }
    m_memory->centre[static_cast<size_t>(k)] = best.seg;
    m_memory->clearance[static_cast<size_t>(k)] = clearance;
    m_memory->slave_reference.col(k) = m_u.segment<2>(2 * k);
  }

  /// Records the master nodes' displacements of the pair.
  void record_pair() {
    Eigen::Matrix2Xd& ref = m_memory->master_reference[static_cast<size_t>(m_request.pair_index)];
    ref.resize(2, m_nm);
    for (int j = 0; j < m_nm; ++j) ref.col(j) = m_u.segment<2>(2 * m_pair.master_surface[static_cast<size_t>(j)]);
    m_memory->recorded[static_cast<size_t>(m_request.pair_index)] = 1;
    m_memory->searched += m_request.num_rows;
  }

  const NodeToSegmentContact& m_contact;
  const Pair& m_pair;
  const PairRequest& m_request;
  SearchMemory* m_memory;  // the request's (nullptr: none)
  const Eigen::VectorXd& m_u;
  Pairing& m_p;
  const int m_nm, m_nseg;
  Scratch& m_s;
  int m_nblock = 0;
  int m_lowest, m_highest = -1;  // range of the segments paired
};

void NodeToSegmentContact::search_pair(const PairRequest& request, const Eigen::VectorXd& u_surface, Pairing& p) const {
  PairSearch search(*this, request, u_surface, p);
  if (!search.certify_from_memory()) search.pruned_search();
  search.nodal_normals();
}

void NodeToSegmentContact::assemble(const Pairing& p, ConstraintMatrix& c, Eigen::VectorXd& g) const {
  std::vector<int> all(m_slave.size());
  for (size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  assemble_rows(p, all, c, g);
}

void NodeToSegmentContact::assemble_rows(const Pairing& p, const std::vector<int>& rows, ConstraintMatrix& c,
                                         Eigen::VectorXd& g) const {
  // Written straight into the compressed arrays (reused storage, no allocation).
  // Row k paired with segment j = (a, b) of its pair's master chain: entries −w n on
  // slave node k, w(1−ξ) n on a and w ξ n on b, and g_k = w n·(X_k − X_m(ξ)) with
  // the reference coordinates. The rows run through the pairs in order, so the
  // pair's data is looked up once per run.
  const int nr = static_cast<int>(rows.size());
  g.resize(nr);
  c.resize(nr, static_cast<int>(m_surface_dofs.size()));
  c.resizeNonZeros(6 * nr);
  int* outer = c.outerIndexPtr();
  int* inner = c.innerIndexPtr();
  double* value = c.valuePtr();
  int nnz = 0;
  const Pair* pair = nullptr;
  for (int i = 0; i < nr; ++i) {
    outer[i] = nnz;
    const int k = rows[static_cast<size_t>(i)], j = p.segment[static_cast<size_t>(k)];
    g(i) = 0.0;
    if (j < 0) continue;
    if (!pair || k < pair->row_begin || k >= pair->row_end) pair = &m_pairs[static_cast<size_t>(m_row_pair[static_cast<size_t>(k)])];
    const double w = m_weights(k), xi = p.xi[static_cast<size_t>(k)], nx = p.normal(0, k), ny = p.normal(1, k);
    const double* xa = pair->master_x.data() + 2 * j;  // X_a, then X_b
    const double xm0 = (1.0 - xi) * xa[0] + xi * xa[2], xm1 = (1.0 - xi) * xa[1] + xi * xa[3];
    g(i) = w * (nx * (m_slave_x(0, k) - xm0) + ny * (m_slave_x(1, k) - xm1));
    // The three nodes' entries, sorted by node so that the row's columns ascend.
    struct Entry {
      int node;
      double vx, vy;
    } e[3] = {{k, -w * nx, -w * ny},
              {pair->master_surface[static_cast<size_t>(j)], w * (1.0 - xi) * nx, w * (1.0 - xi) * ny},
              {pair->master_surface[static_cast<size_t>(j + 1)], w * xi * nx, w * xi * ny}};
    if (e[1].node < e[0].node) std::swap(e[0], e[1]);
    if (e[2].node < e[1].node) std::swap(e[1], e[2]);
    if (e[1].node < e[0].node) std::swap(e[0], e[1]);
    for (const Entry& en : e) {
      inner[nnz] = 2 * en.node, value[nnz++] = en.vx;
      inner[nnz] = 2 * en.node + 1, value[nnz++] = en.vy;
    }
  }
  outer[nr] = nnz;
  c.resizeNonZeros(nnz);
}

namespace {

/// Writes a row-major sparse matrix row after row straight into its compressed
/// arrays (reused storage): entries of a row may come in any order and repeat a
/// column (they are summed); each row ends sorted.
class RowWriter {
 public:
  RowWriter(ConstraintMatrix& m, int rows, int cols, int max_nonzeros) : m_m(m) {
    m.resize(rows, cols);
    m.resizeNonZeros(max_nonzeros);
    m.outerIndexPtr()[0] = 0;
  }
  void add(int col, double v) {
    int* inner = m_m.innerIndexPtr();
    double* value = m_m.valuePtr();
    for (int e = m_m.outerIndexPtr()[m_row]; e < m_nnz; ++e)
      if (inner[e] == col) {
        value[e] += v;
        return;
      }
    inner[m_nnz] = col, value[m_nnz++] = v;
  }
  void end_row() {
    int* inner = m_m.innerIndexPtr();
    double* value = m_m.valuePtr();
    for (int e = m_m.outerIndexPtr()[m_row] + 1; e < m_nnz; ++e)  // insertion sort: a dozen entries
      for (int f = e; f > m_m.outerIndexPtr()[m_row] && inner[f - 1] > inner[f]; --f)
        std::swap(inner[f - 1], inner[f]), std::swap(value[f - 1], value[f]);
    m_m.outerIndexPtr()[++m_row] = m_nnz;
  }
  void finish() { m_m.resizeNonZeros(m_nnz); }

 private:
  ConstraintMatrix& m_m;
  int m_row = 0, m_nnz = 0;
};

}  // namespace

bool NodeToSegmentContact::linearise_pairing(const Eigen::VectorXd& u_surface, const Pairing& p,
                                             const std::vector<int>& rows, PairingLinearisation& out) const {
  // Row k on segment j = (a, b) of its chain, deformed positions x = X + u:
  //  position  ξ = (x_k − x_a)·τ / |τ|², τ = x_b − x_a (0 where the search clamped ξ);
  //  normal    n = m/|m|, m = (1−ξ) N_a + ξ N_b, N_i the normalised sum of the unit
  //            outward normals ν_e = R τ_e/|τ_e| (R τ = (τ_y, −τ_x)) of the segments
  //            at node i; its angle θ moves by dθ = t·dm/|m|, t = (−n_y, n_x),
  //            dN_i = (I − N_i N_iᵀ) Σ dν_e / |m_i|, dν_e = (I − ν_e ν_eᵀ) R dτ_e / |τ_e|.
  const int nr = static_cast<int>(rows.size()), nsd = static_cast<int>(m_surface_dofs.size());
  out.per_row = 2;
  out.q.resize(2 * nr);
  out.dg.resize(2 * nr);
  // Rows 2r and 2r+1 of row r: a dozen entries each at most.
  RowWriter dc(out.dc, 2 * nr, nsd, 12 * nr), dq(out.dq_du, 2 * nr, nsd, 28 * nr);
  const auto rot = [](const Eigen::Vector2d& v) { return Eigen::Vector2d(v.y(), -v.x()); };    // R
  const auto rot_t = [](const Eigen::Vector2d& v) { return Eigen::Vector2d(-v.y(), v.x()); };  // Rᵀ
  for (int r = 0; r < nr; ++r) {
    const int k = rows[static_cast<size_t>(r)], j = p.segment[static_cast<size_t>(k)];
    if (j < 0) return false;
    const Pair& pair = m_pairs[static_cast<size_t>(m_row_pair[static_cast<size_t>(k)])];
    const int nm = static_cast<int>(pair.master.size()), nseg = nm - 1;
    const auto master_dof = [&](int i) { return 2 * pair.master_surface[static_cast<size_t>(i)]; };
    const auto deformed = [&](int i) -> Eigen::Vector2d {
      return pair.master_x.col(i) + u_surface.segment<2>(master_dof(i));
    };
    const double xi = p.xi[static_cast<size_t>(k)], w = m_weights(k);
    const Eigen::Vector2d n = p.normal.col(k), t(-n.y(), n.x());
    out.q(2 * r) = j + xi;
    out.q(2 * r + 1) = std::atan2(n.y(), n.x());
    // ∂C/∂ξ and ∂C/∂θ at the pairing (entries of the slave node, a and b).
    const Eigen::Vector2d xs_ref = m_slave_x.col(k), xa_ref = pair.master_x.col(j), xb_ref = pair.master_x.col(j + 1);
    const int dofs[3] = {2 * k, master_dof(j), master_dof(j + 1)};
    const Eigen::Vector2d dc_xi[3] = {Eigen::Vector2d::Zero(), -w * n, w * n};
    const Eigen::Vector2d dc_theta[3] = {-w * t, w * (1.0 - xi) * t, w * xi * t};
    for (int e = 0; e < 3; ++e)
      for (int d = 0; d < 2; ++d)
        if (dc_xi[e](d) != 0.0) dc.add(dofs[e] + d, dc_xi[e](d));
    dc.end_row();
    for (int e = 0; e < 3; ++e)
      for (int d = 0; d < 2; ++d) dc.add(dofs[e] + d, dc_theta[e](d));
    dc.end_row();
    out.dg(2 * r) = w * n.dot(xa_ref - xb_ref);
    out.dg(2 * r + 1) = w * t.dot(xs_ref - ((1.0 - xi) * xa_ref + xi * xb_ref));

    // ∂ξ/∂x of the slave node, a and b (zero where the projection is clamped).
    const Eigen::Vector2d xs = xs_ref + u_surface.segment<2>(2 * k), xa = deformed(j), xb = deformed(j + 1);
    const Eigen::Vector2d tau = xb - xa, dist = xs - xa;
    const double len2 = tau.squaredNorm();
    Eigen::Vector2d gxi[3] = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
    if (xi > 0.0 && xi < 1.0) {
      gxi[0] = tau / len2;
      gxi[2] = (dist - 2.0 * xi * tau) / len2;
      gxi[1] = -gxi[0] - gxi[2];
    }
    // Nodal normals at a and b and the gradient of θ on the chain nodes a−1 … b+1.
    Eigen::Vector2d node_m[2], node_n[2];
    for (int e = 0; e < 2; ++e) {
      const int i = j + e;
      node_m[e].setZero();
      for (int seg = std::max(i - 1, 0); seg <= std::min(i, nseg - 1); ++seg) {
        const Eigen::Vector2d ts = deformed(seg + 1) - deformed(seg);
        node_m[e] += rot(ts) / ts.norm();
      }
      node_n[e] = node_m[e].normalized();
    }
    const Eigen::Vector2d m = (1.0 - xi) * node_n[0] + xi * node_n[1];
    const double mlen = m.norm();
    Eigen::Vector2d gtheta_master[4] = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                        Eigen::Vector2d::Zero()};  // nodes j−1 … j+2
    const double c_xi = t.dot(node_n[1] - node_n[0]) / mlen;
    for (int e = 0; e < 2; ++e) {
      const int i = j + e;
      const double weight = (e == 0 ? 1.0 - xi : xi) / (mlen * node_m[e].norm());
      const Eigen::Vector2d v = weight * (t - node_n[e] * node_n[e].dot(t));  // (I − N Nᵀ) t, scaled
      for (int seg = std::max(i - 1, 0); seg <= std::min(i, nseg - 1); ++seg) {
        const Eigen::Vector2d ts = deformed(seg + 1) - deformed(seg);
        const double len = ts.norm();
        const Eigen::Vector2d nu = rot(ts) / len;
        const Eigen::Vector2d ws = rot_t(v - nu * nu.dot(v)) / len;  // ∂/∂τ_e of vᵀν_e
        gtheta_master[seg + 1 - (j - 1)] += ws;
        gtheta_master[seg - (j - 1)] -= ws;
      }
    }
    for (int e = 0; e < 3; ++e)
      for (int d = 0; d < 2; ++d)
        if (gxi[e](d) != 0.0) dq.add(dofs[e] + d, gxi[e](d));
    dq.end_row();
    for (int e = 0; e < 3; ++e)
      for (int d = 0; d < 2; ++d)
        if (gxi[e](d) != 0.0) dq.add(dofs[e] + d, c_xi * gxi[e](d));
    for (int e = 0; e < 4; ++e) {
      const int i = j - 1 + e;
      if (i < 0 || i >= nm) continue;
      for (int d = 0; d < 2; ++d)
        if (gtheta_master[e](d) != 0.0) dq.add(master_dof(i) + d, gtheta_master[e](d));
    }
    dq.end_row();
  }
  dc.finish();
  dq.finish();
  return true;
}

void NodeToSegmentContact::move_pairing(Pairing& p, const std::vector<int>& rows, const Eigen::VectorXd& q) const {
  for (size_t r = 0; r < rows.size(); ++r) {
    const int k = rows[r];
    const int nseg = static_cast<int>(m_pairs[static_cast<size_t>(m_row_pair[static_cast<size_t>(k)])].master.size()) - 1;
    const double position = std::clamp(q(static_cast<Eigen::Index>(2 * r)), 0.0, static_cast<double>(nseg));
    const int j = std::min(static_cast<int>(std::floor(position)), nseg - 1);
    const double theta = q(static_cast<Eigen::Index>(2 * r + 1));
    p.segment[static_cast<size_t>(k)] = j;
    p.xi[static_cast<size_t>(k)] = position - j;
    p.normal.col(k) = Eigen::Vector2d(std::cos(theta), std::sin(theta));
  }
}

ObstacleContact::ObstacleContact(const Eigen::VectorXd& x, const Eigen::VectorXd& psi,
                                 const Eigen::VectorXd& weights)
    : m_psi(psi) {
  m_weights = weights;
  m_points = Eigen::MatrixXd::Zero(2, x.size());
  m_points.row(0) = x.transpose();
  for (int i = 0; i < x.size(); ++i) m_surface_dofs.push_back(i);
}

void ObstacleContact::assemble(const Pairing&, ConstraintMatrix& c, Eigen::VectorXd& g) const {
  const int n = static_cast<int>(m_psi.size());
  c.resize(n, n);
  std::vector<Eigen::Triplet<double>> trip;
  for (int i = 0; i < n; ++i) trip.emplace_back(i, i, -m_weights(i));
  c.setFromTriplets(trip.begin(), trip.end());
  g = -m_weights.cwiseProduct(m_psi);
}

bool NodeToSegmentContact::pairing_support(const Pairing& p, const std::vector<int>& rows, int reach,
                                           std::vector<int>& dofs) const {
  // Row k on segment j (nodes j, j + 1) reads its slave node and, through the
  // nodal normals of nodes j and j + 1, master nodes j − 1 … j + 2; within `reach`
  // segments of j, nodes j − reach − 1 … j + reach + 2.
  std::vector<char> in(m_surface_dofs.size() / 2, 0);
  for (int k : rows) {
    const int j = p.segment[static_cast<size_t>(k)];
    if (j < 0) return false;
    const Pair& pair = m_pairs[static_cast<size_t>(m_row_pair[static_cast<size_t>(k)])];
    in[static_cast<size_t>(k)] = 1;
    const int last = static_cast<int>(pair.master.size()) - 1;
    for (int i = std::max(j - reach - 1, 0); i <= std::min(j + reach + 2, last); ++i)
      in[static_cast<size_t>(pair.master_surface[static_cast<size_t>(i)])] = 1;
  }
  dofs.clear();
  for (size_t node = 0; node < in.size(); ++node)
    if (in[node]) dofs.push_back(static_cast<int>(2 * node)), dofs.push_back(static_cast<int>(2 * node + 1));
  return true;
}

}  // namespace contactrom::fom
