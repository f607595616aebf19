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
    if (!rows) {
      search_pair(pair, u_surface, nullptr, pair.row_end - pair.row_begin, hint, p, memory, pq);
      continue;
    }
    const size_t first = r;
    while (r < rows->size() && (*rows)[r] < pair.row_end) ++r;
    if (r > first)
      search_pair(pair, u_surface, rows->data() + first, static_cast<int>(r - first), hint, p, memory, pq);
  }
}

void NodeToSegmentContact::search_pair(const Pair& pair, const Eigen::VectorXd& u_surface, const int* rows,
                                       int nrows, const Pairing* hint, Pairing& p, SearchMemory* memory,
                                       int pair_index) const {
  const int nm = static_cast<int>(pair.master.size());
  // Per-thread scratch arrays: a search takes a few microseconds inside the online
  // loops, where allocating them on every call would be a visible share.
  thread_local struct {
    Eigen::Matrix2Xd xm, node_normal, seg_t, mid, block_c;
    Eigen::VectorXd inv_len2, half, block_r;
  } scratch;
  // Deformed master nodes and, for the distances, per segment: tangent t, midpoint,
  // 1/|t|² and the radius of a circle about the midpoint holding the segment
  // (½(|t_x|+|t_y|) ≥ ½|t|, no root); `prepare` fills segments j0 … j1−1 (the
  // circles only for a full search).
  const int nseg = std::max(nm - 1, 0);
  Eigen::Matrix2Xd& xm = scratch.xm;
  Eigen::Matrix2Xd& seg_t = scratch.seg_t;
  Eigen::Matrix2Xd& mid = scratch.mid;
  Eigen::VectorXd& inv_len2 = scratch.inv_len2;
  Eigen::VectorXd& half = scratch.half;
  xm.resize(2, nm);
  seg_t.resize(2, nseg);
  mid.resize(2, nseg);
  inv_len2.resize(nseg);
  half.resize(nseg);
  auto prepare = [&](int j0, int j1, bool circles) {
    for (int j = j0; j <= std::min(j1, nm - 1); ++j)
      xm.col(j) = pair.master_x.col(j) + u_surface.segment<2>(2 * pair.master_surface[static_cast<size_t>(j)]);
    for (int j = j0; j < j1; ++j) {
      const Eigen::Vector2d t = xm.col(j + 1) - xm.col(j);
      seg_t.col(j) = t;
      inv_len2(j) = 1.0 / t.squaredNorm();
      if (!circles) continue;  // the settled rows need no pruning
      mid.col(j) = 0.5 * (xm.col(j + 1) + xm.col(j));
      half(j) = 0.5 * (std::abs(t.x()) + std::abs(t.y()));
    }
  };

  // Closest point of slave position (px, py) on segment j, kept when closer than
  // the best so far; ties (a slave node exactly at a master node) go to the lower
  // segment index. The distance itself (a square root on the critical path) is
  // taken only where it is used: by the pruning of a full search after each
  // improvement, by the certificate of a settled row once.
  struct Best {
    double dist2 = std::numeric_limits<double>::max(), root = std::numeric_limits<double>::max();
    int seg = -1;
    double xi = 0.0, raw = 0.0;
  };
  auto try_segment = [&](double px, double py, int j, Best& best) {
    const double dx = px - xm(0, j), dy = py - xm(1, j), tx = seg_t(0, j), ty = seg_t(1, j);
    const double raw = (dx * tx + dy * ty) * inv_len2(j);
    const double xi = raw < 0.0 ? 0.0 : (raw > 1.0 ? 1.0 : raw);
    const double ex = dx - xi * tx, ey = dy - xi * ty;
    const double dist2 = ex * ex + ey * ey;
    if (dist2 < best.dist2 * (1.0 - 1e-14) || (best.seg >= 0 && dist2 <= best.dist2 * (1.0 + 1e-14) && j < best.seg))
      best = {dist2, best.root, j, xi, raw};
    return dist2;
  };
  auto slave_position = [&](int k) {
    return Eigen::Vector2d(m_slave_x(0, k) + u_surface(2 * k), m_slave_x(1, k) + u_surface(2 * k + 1));
  };
  int lowest = nseg, highest = -1;
  // Stores row k's closest segment in the pairing.
  auto pair_row = [&](int k, const Best& best) {
    // A projection beyond either end of the master chain is no contact pair, except
    // within kChainEndExtension of the end segment's length: there the slave node is
    // paired with the chain's end (ξ clamped, the end segment's normal), i.e. with
    // the end segment extended. Flush ends (two blocks of equal width, a corner
    // shared by both surfaces) put slave corner nodes exactly at a master end, where
    // round-off alone would otherwise switch the pair on and off between iterations.
    if (best.seg < 0 || (best.seg == 0 && best.raw < -kChainEndExtension) ||
        (best.seg == nm - 2 && best.raw > 1.0 + kChainEndExtension))
      return;
    p.segment[k] = best.seg;
    p.xi[k] = best.xi;
    lowest = std::min(lowest, best.seg);
    highest = std::max(highest, best.seg);
  };

  // With a record of an earlier search: every row settled among its recorded
  // segment and the neighbours, or the whole pair searched again below.
  bool settled = memory && memory->recorded[static_cast<size_t>(pair_index)] && nseg > 0;
  if (settled) {
    const Eigen::Matrix2Xd& ref = memory->master_reference[static_cast<size_t>(pair_index)];
    double b2 = 0.0;  // largest master-node movement since the record, squared
    for (int j = 0; j < nm; ++j)
      b2 = std::max(b2, (u_surface.segment<2>(2 * pair.master_surface[static_cast<size_t>(j)]) - ref.col(j)).squaredNorm());
    const double b = std::sqrt(b2);
    // Only the segments the recorded ones and their neighbours reach (the normals
    // below use one more on each side).
    int c_min = nseg, c_max = -1;
    for (int r = 0; r < nrows; ++r) {
      const int c = memory->centre[static_cast<size_t>(rows ? rows[r] : pair.row_begin + r)];
      if (c >= 0) c_min = std::min(c_min, c), c_max = std::max(c_max, c);
    }
    if (c_max >= 0) prepare(std::max(c_min - 2, 0), std::min(c_max + 3, nseg), false);
    for (int r = 0; r < nrows && settled; ++r) {
      const int k = rows ? rows[r] : pair.row_begin + r, c = memory->centre[static_cast<size_t>(k)];
      if (c < 0) {
        settled = false;
        break;
      }
      const Eigen::Vector2d x = slave_position(k);
      Best best;
      try_segment(x.x(), x.y(), c, best);
      if (c > 0) try_segment(x.x(), x.y(), c - 1, best);
      if (c + 1 < nseg) try_segment(x.x(), x.y(), c + 1, best);
      best.root = std::sqrt(best.dist2);
      const double a = (u_surface.segment<2>(2 * k) - memory->slave_reference.col(k)).norm();
      settled = memory->clearance[static_cast<size_t>(k)] - a - b > best.root * (1.0 + 1e-12);

      if (settled) pair_row(k, best);
    }
    if (settled) {
      memory->certified += nrows;
    } else {  // start again, in full
      lowest = nseg, highest = -1;
      for (int r = 0; r < nrows; ++r) p.segment[rows ? rows[r] : pair.row_begin + r] = -1;
    }
  }

  if (!settled) {
    prepare(0, nseg, true);
    // Bounding circles of blocks of m_block consecutive segments (centre, radius):
    // a block is skipped when its circle is farther than the best distance found
    // (plus the margin when recording, so that skipped segments are known to be
    // at least that much farther).
    const int nblock = (nseg + m_block - 1) / m_block;
    Eigen::Matrix2Xd& block_c = scratch.block_c;
    Eigen::VectorXd& block_r = scratch.block_r;
    block_c.resize(2, nblock);
    block_r.resize(nblock);
    for (int b = 0; b < nblock; ++b) {
      const int j0 = b * m_block, j1 = std::min(nseg, j0 + m_block);  // vertices j0..j1
      block_c.col(b) = xm.middleCols(j0, j1 - j0 + 1).rowwise().mean();
      double r2 = 0.0;
      for (int j = j0; j <= j1; ++j) r2 = std::max(r2, (xm.col(j) - block_c.col(b)).squaredNorm());
      block_r(b) = std::sqrt(r2);
    }
    const double margin = memory ? pair.margin : 0.0;
    if (memory)  // rows of the pair left out of this search lose their record
      std::fill(memory->centre.begin() + pair.row_begin, memory->centre.begin() + pair.row_end, -1);
    // The four nearest segments tried, by squared distance (for the clearance: at
    // least one of them is not the closest segment or one of its two neighbours).
    constexpr int kept = 4;
    int tried_seg[kept];
    double tried_d2[kept];

    // Exact closest segment per slave node. Squared distances only; the segment of
    // the previous slave node is tried first (neighbouring slave nodes have
    // neighbouring pairs), then every block whose circle may hold a closer point,
    // then within it every segment whose circle (centre mid, radius half) may.
    int guess = 0;
    for (int r = 0; r < nrows; ++r) {
      const int k = rows ? rows[r] : pair.row_begin + r;
      const Eigen::Vector2d x = slave_position(k);
      const double px = x.x(), py = x.y();
      Best best;
      int ntried = 0;
      auto visit = [&](int j) {
        double d2 = try_segment(px, py, j, best);
        if (best.seg == j) best.root = std::sqrt(d2);  // closer than before: the pruning's radius
        if (!memory) return;
        for (int t = 0; t < std::min(ntried, kept); ++t)  // insertion into the sorted four
          if (d2 < tried_d2[t]) std::swap(d2, tried_d2[t]), std::swap(j, tried_seg[t]);
        if (ntried < kept) tried_seg[ntried] = j, tried_d2[ntried] = d2;
        ++ntried;
      };
      if (hint && hint->segment.size() == p.segment.size() && hint->segment[k] >= 0) guess = hint->segment[k];
      if (nseg > 0) {
        // The guess and its neighbours first: a good first distance prunes the rest.
        visit(guess);
        if (guess > 0) visit(guess - 1);
        if (guess + 1 < nseg) visit(guess + 1);
      }
      for (int b = 0; b < nblock; ++b) {
        const double bx = px - block_c(0, b), by = py - block_c(1, b), reach = best.root + margin + block_r(b);
        if (bx * bx + by * by > reach * reach * (1.0 + 1e-12)) continue;
        const int j1 = std::min(nseg, (b + 1) * m_block);
        for (int j = b * m_block; j < j1; ++j) {
          if (j >= guess - 1 && j <= guess + 1) continue;
          const double mx = px - mid(0, j), my = py - mid(1, j), sreach = best.root + margin + half(j);
          if (mx * mx + my * my > sreach * sreach * (1.0 + 1e-12)) continue;
          visit(j);
        }
      }
      if (best.seg >= 0) guess = best.seg;
      pair_row(k, best);
      if (!memory) continue;
      // Clearance: skipped segments are farther than best + margin (the pruning
      // above used a best that was at least the final one); tried ones are known.
      double clearance = best.root + margin;
      for (int t = 0; t < std::min(ntried, kept); ++t)
        if (std::abs(tried_seg[t] - best.seg) > 1) {
          clearance = std::min(clearance, std::sqrt(tried_d2[t]));
          break;
        }
      memory->centre[static_cast<size_t>(k)] = best.seg;
      memory->clearance[static_cast<size_t>(k)] = clearance;
      memory->slave_reference.col(k) = u_surface.segment<2>(2 * k);
    }
    if (memory) {
      Eigen::Matrix2Xd& ref = memory->master_reference[static_cast<size_t>(pair_index)];
      ref.resize(2, nm);
      for (int j = 0; j < nm; ++j) ref.col(j) = u_surface.segment<2>(2 * pair.master_surface[static_cast<size_t>(j)]);
      memory->recorded[static_cast<size_t>(pair_index)] = 1;
      memory->searched += nrows;
    }
  }
  if (highest < 0) return;

  // Nodal normals of the deformed master surface (average of the adjacent
  // segments' outward normals) where rows are paired, nodes lowest … highest+1:
  // interpolating them along a segment gives a normal field that is continuous
  // across master nodes, so the constraint row does not jump when a slave node
  // passes from one segment to the next.
  Eigen::Matrix2Xd& node_normal = scratch.node_normal;
  node_normal.resize(2, nm);
  node_normal.middleCols(lowest, highest + 2 - lowest).setZero();
  for (int j = std::max(lowest - 1, 0); j <= std::min(highest + 1, nseg - 1); ++j) {
    const Eigen::Vector2d t = seg_t.col(j);
    // Chains run with their body on the left: (t_y, −t_x) points out of the master body.
    const Eigen::Vector2d n = (1.0 / t.norm()) * Eigen::Vector2d(t.y(), -t.x());
    if (j >= lowest) node_normal.col(j) += n;
    if (j + 1 <= highest + 1) node_normal.col(j + 1) += n;
  }
  for (int j = lowest; j <= highest + 1; ++j) node_normal.col(j).normalize();
  for (int r = 0; r < nrows; ++r) {
    const int k = rows ? rows[r] : pair.row_begin + r, j = p.segment[k];
    if (j < 0) continue;
    const double xi = p.xi[k];
    p.normal.col(k) = ((1.0 - xi) * node_normal.col(j) + xi * node_normal.col(j + 1)).normalized();
  }
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
  std::vector<Eigen::Triplet<double>> dq, dc;
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
      for (int d = 0; d < 2; ++d) {
        if (dc_xi[e](d) != 0.0) dc.emplace_back(2 * r, dofs[e] + d, dc_xi[e](d));
        dc.emplace_back(2 * r + 1, dofs[e] + d, dc_theta[e](d));
      }
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
    for (int d = 0; d < 2; ++d) {
      for (int e = 0; e < 3; ++e) {
        if (gxi[e](d) == 0.0) continue;
        dq.emplace_back(2 * r, dofs[e] + d, gxi[e](d));
        dq.emplace_back(2 * r + 1, dofs[e] + d, c_xi * gxi[e](d));
      }
      for (int e = 0; e < 4; ++e) {
        const int i = j - 1 + e;
        if (i < 0 || i >= nm || gtheta_master[e](d) == 0.0) continue;
        dq.emplace_back(2 * r + 1, master_dof(i) + d, gtheta_master[e](d));
      }
    }
  }
  out.dq_du.resize(2 * nr, nsd);
  out.dq_du.setFromTriplets(dq.begin(), dq.end());
  out.dc.resize(2 * nr, nsd);
  out.dc.setFromTriplets(dc.begin(), dc.end());
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

}  // namespace contactrom::fom
