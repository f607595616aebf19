#include "fom/contact_model.hpp"

#include <cmath>
#include <limits>
#include <map>

namespace contactrom::fom {

bool Pairing::same_as(const Pairing& other, double tol) const {
  if (segment.size() != other.segment.size()) return false;
  for (size_t s = 0; s < segment.size(); ++s) {
    if ((segment[s] < 0) != (other.segment[s] < 0)) return false;
    if (segment[s] < 0) continue;
    // Position along the master chain, continuous across segment ends: a slave
    // node moving from the end of segment j to the start of j+1 is no change.
    if (std::abs(segment[s] + xi[s] - other.segment[s] - other.xi[s]) > tol) return false;
    if ((normal.col(s) - other.normal.col(s)).cwiseAbs().maxCoeff() > tol) return false;
  }
  return true;
}

Eigen::VectorXd ContactModel::restrict_to_surface(const Eigen::VectorXd& u_full) const {
  Eigen::VectorXd out(m_surface_dofs.size());
  for (size_t i = 0; i < m_surface_dofs.size(); ++i) out(i) = u_full(m_surface_dofs[i]);
  return out;
}

// Surface dof layout: slave node k -> columns 2k, 2k+1; master node j -> 2(n_s+j), 2(n_s+j)+1.
NodeToSegmentContact::NodeToSegmentContact(const Eigen::Matrix2Xd& nodes, const std::vector<int>& slave_chain,
                                           const std::vector<int>& master_chain,
                                           const std::vector<Eigen::Vector2d>& master_inside)
    : m_slave(slave_chain), m_master(master_chain) {
  const int ns = static_cast<int>(m_slave.size()), nm = static_cast<int>(m_master.size());
  m_slave_x.resize(2, ns);
  m_master_x.resize(2, nm);
  for (int k = 0; k < ns; ++k) m_slave_x.col(k) = nodes.col(m_slave[k]);
  for (int j = 0; j < nm; ++j) m_master_x.col(j) = nodes.col(m_master[j]);
  for (int node : m_slave) m_surface_dofs.insert(m_surface_dofs.end(), {2 * node, 2 * node + 1});
  for (int node : m_master) m_surface_dofs.insert(m_surface_dofs.end(), {2 * node, 2 * node + 1});
  m_points = m_slave_x;

  // Tributary lengths: half of each adjacent slave segment.
  m_weights = Eigen::VectorXd::Zero(ns);
  for (int k = 0; k + 1 < ns; ++k) {
    const double len = (m_slave_x.col(k + 1) - m_slave_x.col(k)).norm();
    m_weights(k) += 0.5 * len;
    m_weights(k + 1) += 0.5 * len;
  }

  // Outward orientation of each master segment: the normal must point away from
  // the interior point(s) of the master body nearest to the segment.
  m_orientation.resize(std::max(nm - 1, 0));
  for (int j = 0; j + 1 < nm; ++j) {
    const Eigen::Vector2d a = m_master_x.col(j), b = m_master_x.col(j + 1);
    const Eigen::Vector2d t = b - a, mid = 0.5 * (a + b);
    const Eigen::Vector2d n(t.y(), -t.x());
    double best = std::numeric_limits<double>::max();
    Eigen::Vector2d inside = master_inside.front();
    for (const auto& p : master_inside)
      if ((p - mid).norm() < best) best = (p - mid).norm(), inside = p;
    m_orientation[j] = n.dot(inside - mid) < 0 ? 1.0 : -1.0;
  }
}

Pairing NodeToSegmentContact::search(const Eigen::VectorXd& u_surface) const {
  const int ns = static_cast<int>(m_slave.size()), nm = static_cast<int>(m_master.size());
  Eigen::Matrix2Xd xs = m_slave_x, xm = m_master_x;
  for (int k = 0; k < ns; ++k) xs.col(k) += u_surface.segment<2>(2 * k);
  for (int j = 0; j < nm; ++j) xm.col(j) += u_surface.segment<2>(2 * (ns + j));

  // Nodal normals of the deformed master surface (average of the adjacent
  // segments' outward normals): interpolating them along a segment gives a
  // normal field that is continuous across master nodes, so the constraint row
  // does not jump when a slave node passes from one segment to the next.
  Eigen::Matrix2Xd seg_normal(2, std::max(nm - 1, 0)), node_normal = Eigen::Matrix2Xd::Zero(2, nm);
  for (int j = 0; j + 1 < nm; ++j) {
    const Eigen::Vector2d t = xm.col(j + 1) - xm.col(j);
    seg_normal.col(j) = m_orientation[j] * Eigen::Vector2d(t.y(), -t.x()).normalized();
    node_normal.col(j) += seg_normal.col(j);
    node_normal.col(j + 1) += seg_normal.col(j);
  }
  for (int j = 0; j < nm; ++j) node_normal.col(j).normalize();

  Pairing p;
  p.segment.assign(ns, -1);
  p.xi.assign(ns, 0.0);
  p.normal = Eigen::Matrix2Xd::Zero(2, ns);
  // Segment data once per search; the inner loop uses squared distances only and
  // skips a segment whose bounding circle (centre `mid`, radius `half`) is
  // farther than the best distance found so far. The previous slave node's
  // segment is tried first: neighbouring slave nodes have neighbouring pairs.
  const int nseg = std::max(nm - 1, 0);
  Eigen::Matrix2Xd seg_t(2, nseg), mid(2, nseg);
  Eigen::VectorXd inv_len2(nseg), half(nseg);
  for (int j = 0; j < nseg; ++j) {
    seg_t.col(j) = xm.col(j + 1) - xm.col(j);
    mid.col(j) = 0.5 * (xm.col(j + 1) + xm.col(j));
    inv_len2(j) = 1.0 / seg_t.col(j).squaredNorm();
    half(j) = 0.5 * seg_t.col(j).norm();
  }
  int guess = 0;
  for (int k = 0; k < ns; ++k) {
    const double px = xs(0, k), py = xs(1, k);
    double best = std::numeric_limits<double>::max(), best_root = std::numeric_limits<double>::max();
    int best_seg = -1;
    double best_xi = 0.0, best_raw = 0.0;
    for (int step = -1; step < nseg; ++step) {
      const int j = step < 0 ? guess : step;
      if (step >= 0 && j == guess) continue;
      if (best_seg >= 0) {
        const double mx = px - mid(0, j), my = py - mid(1, j);
        if (mx * mx + my * my > best + half(j) * (2.0 * best_root + half(j))) continue;
      }
      const double dx = px - xm(0, j), dy = py - xm(1, j), tx = seg_t(0, j), ty = seg_t(1, j);
      const double raw = (dx * tx + dy * ty) * inv_len2(j);
      const double xi = raw < 0.0 ? 0.0 : (raw > 1.0 ? 1.0 : raw);
      const double ex = dx - xi * tx, ey = dy - xi * ty;
      const double dist2 = ex * ex + ey * ey;
      // Ties (a slave node exactly at a master node) go to the lower segment index.
      if (dist2 < best * (1.0 - 1e-14) || (best_seg >= 0 && dist2 <= best * (1.0 + 1e-14) && j < best_seg)) {
        best = dist2, best_root = std::sqrt(dist2), best_seg = j, best_xi = xi, best_raw = raw;
      }
    }
    if (best_seg >= 0) guess = best_seg;
    // A projection beyond either end of the master chain is no contact pair.
    if (best_seg < 0 || (best_seg == 0 && best_raw < 0.0) || (best_seg == nm - 2 && best_raw > 1.0)) continue;
    p.segment[k] = best_seg;
    p.xi[k] = best_xi;
    p.normal.col(k) = ((1.0 - best_xi) * node_normal.col(best_seg) + best_xi * node_normal.col(best_seg + 1)).normalized();
  }
  return p;
}

void NodeToSegmentContact::assemble(const Pairing& p, ConstraintMatrix& c, Eigen::VectorXd& g) const {
  const int ns = static_cast<int>(m_slave.size());
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(6 * ns);
  g = Eigen::VectorXd::Zero(ns);
  for (int k = 0; k < ns; ++k) {
    const int j = p.segment[k];
    if (j < 0) continue;
    const double w = m_weights(k), xi = p.xi[k];
    const Eigen::Vector2d n = p.normal.col(k);
    const Eigen::Vector2d xm = (1.0 - xi) * m_master_x.col(j) + xi * m_master_x.col(j + 1);
    g(k) = w * n.dot(m_slave_x.col(k) - xm);
    for (int d = 0; d < 2; ++d) {
      trip.emplace_back(k, 2 * k + d, -w * n(d));
      trip.emplace_back(k, 2 * (ns + j) + d, w * (1.0 - xi) * n(d));
      trip.emplace_back(k, 2 * (ns + j + 1) + d, w * xi * n(d));
    }
  }
  c.resize(ns, static_cast<int>(m_surface_dofs.size()));
  c.setFromTriplets(trip.begin(), trip.end());
}

ObstacleContact::ObstacleContact(const Eigen::VectorXd& x, const Eigen::VectorXd& psi,
                                 const Eigen::VectorXd& weights)
    : m_psi(psi) {
  m_weights = weights;
  m_points = Eigen::Matrix2Xd::Zero(2, x.size());
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
