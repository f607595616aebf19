#include <contactrom/fom/node_to_face_contact.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <contactrom/core/errors.hpp>

namespace contactrom::fom {
namespace {

using Eigen::Vector3d;

/// Closest point of p on the segment a-b: the parameter t ∈ [0,1] and the point.
double closest_on_segment(const Vector3d& p, const Vector3d& a, const Vector3d& b, Vector3d& q) {
  const Vector3d t = b - a;
  const double len2 = t.squaredNorm();
  double s = len2 > 0 ? (p - a).dot(t) / len2 : 0.0;
  s = std::clamp(s, 0.0, 1.0);
  q = a + s * t;
  return s;
}

/// Local coordinates of the nodes of the reference quad, counter-clockwise.
const double kQuadXi[4] = {-1, 1, 1, -1}, kQuadEta[4] = {-1, -1, 1, 1};

/// Shape functions of a facet at (ξ, η): triangle (1 − ξ − η, ξ, η), quad bilinear.
std::array<double, 4> facet_shape(bool triangle, double xi, double eta) {
  if (triangle) return {1.0 - xi - eta, xi, eta, 0.0};
  std::array<double, 4> n{};
  for (int a = 0; a < 4; ++a) n[static_cast<size_t>(a)] = 0.25 * (1 + kQuadXi[a] * xi) * (1 + kQuadEta[a] * eta);
  return n;
}

/// The closest point among the edges of a polygon x[0..nv): edge k runs from node
/// k to k+1; the local coordinates are set by `local(k, t)`.
template <class Local>
FacetProjection closest_on_edges(const Vector3d& p, const Vector3d* x, int nv, Local&& local) {
  FacetProjection best;
  best.distance2 = std::numeric_limits<double>::max();
  for (int k = 0; k < nv; ++k) {
    Vector3d q;
    const double t = closest_on_segment(p, x[k], x[(k + 1) % nv], q);
    const double d2 = (p - q).squaredNorm();
    if (d2 < best.distance2) {
      best.distance2 = d2;
      best.point = q;
      best.edge = t > 0.0 && t < 1.0 ? k : -1;
      best.vertex = t <= 0.0 ? k : (t >= 1.0 ? (k + 1) % nv : -1);
      local(k, t, best);
    }
  }
  return best;
}

/// Storage of NodeToFaceContact::search_pair, reused from one search to the next
/// (one per thread): the deformed master nodes, the facets' bounding boxes, the
/// bucket grid's lists, the facets' visit stamps and the nodal normals.
struct FacetSearchScratch {
  Eigen::Matrix3Xd xm, node_normal, lo, hi;
  std::vector<int> cell_start, cell_facets, stamp;
};

/// Bounding boxes (columns of lo, hi) of the facets on the nodes xm; returns their
/// mean size (largest extent).
double facet_boxes(const std::vector<std::array<int, 4>>& facets, const Eigen::Matrix3Xd& xm, Eigen::Matrix3Xd& lo,
                   Eigen::Matrix3Xd& hi) {
  const int nf = static_cast<int>(facets.size());
  lo.resize(3, nf);
  hi.resize(3, nf);
  double mean_size = 0.0;
  for (int f = 0; f < nf; ++f) {
    const auto& facet = facets[static_cast<size_t>(f)];
    lo.col(f) = hi.col(f) = xm.col(facet[0]);
    for (int a = 1; a < 4 && facet[static_cast<size_t>(a)] >= 0; ++a) {
      lo.col(f) = lo.col(f).cwiseMin(xm.col(facet[static_cast<size_t>(a)]));
      hi.col(f) = hi.col(f).cwiseMax(xm.col(facet[static_cast<size_t>(a)]));
    }
    mean_size += (hi.col(f) - lo.col(f)).maxCoeff() / nf;
  }
  return mean_size;
}

/// Bucket grid over the facets' bounding boxes: cells of the mean facet size, grown
/// until there are at most about 8 cells per facet; each cell lists the facets whose
/// box meets it (compressed rows in the caller's storage).
class FacetGrid {
 public:
  FacetGrid(const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi, double mean_size, std::vector<int>& start,
            std::vector<int>& list)
      : m_lo(lo.rowwise().minCoeff()), m_h(std::max(mean_size, 1e-300)), m_start(start), m_list(list) {
    const int nf = static_cast<int>(lo.cols());
    const Vector3d box_hi = hi.rowwise().maxCoeff();
    for (;;) {
      for (int i = 0; i < 3; ++i) m_dims(i) = std::max(1, static_cast<int>(std::ceil((box_hi(i) - m_lo(i)) / m_h)));
      if (static_cast<double>(m_dims.prod()) <= 8.0 * nf + 64) break;
      m_h *= 1.5;
    }
    fill(lo, hi);
  }

  /// The cell holding x (clamped to the grid).
  Eigen::Array3i cell_of(const Vector3d& x) const {
    Eigen::Array3i c;
    for (int i = 0; i < 3; ++i) c(i) = std::clamp(static_cast<int>(std::floor((x(i) - m_lo(i)) / m_h)), 0, m_dims(i) - 1);
    return c;
  }

  /// The largest ring around a cell that the grid can hold.
  int max_ring() const { return m_dims.maxCoeff(); }

  /// Calls visit(f) for every facet listed in the cells at ring distance `ring` of c
  /// (the surface of the cube of cells around it).
  template <class Visit>
  void visit_ring(const Eigen::Array3i& c, int ring, Visit&& visit) const {
    for (int kk = std::max(c(2) - ring, 0); kk <= std::min(c(2) + ring, m_dims(2) - 1); ++kk)
      for (int j = std::max(c(1) - ring, 0); j <= std::min(c(1) + ring, m_dims(1) - 1); ++j)
        for (int i = std::max(c(0) - ring, 0); i <= std::min(c(0) + ring, m_dims(0) - 1); ++i) {
          if (std::max({std::abs(i - c(0)), std::abs(j - c(1)), std::abs(kk - c(2))}) != ring) continue;
          const size_t cell = static_cast<size_t>(flat({i, j, kk}));
          for (int e = m_start[cell]; e < m_start[cell + 1]; ++e) visit(m_list[static_cast<size_t>(e)]);
        }
  }

  /// Squared lower bound of the distance from x to the cells outside the cube of
  /// rings 0..r around cell c: the nearest of the (up to six) slabs of the grid
  /// beyond the cube, each a box (∞: the cube covers the grid).
  double beyond_ring(const Eigen::Array3i& c, int r, const Vector3d& x) const {
    double bound = std::numeric_limits<double>::infinity();
    Vector3d grid_hi;
    for (int i = 0; i < 3; ++i) grid_hi(i) = m_lo(i) + m_dims(i) * m_h;
    for (int i = 0; i < 3; ++i)
      for (int side : {-1, 1}) {
        Vector3d slab_lo = m_lo, slab_hi = grid_hi;
        if (side < 0) {
          if (c(i) - r - 1 < 0) continue;
          slab_hi(i) = m_lo(i) + (c(i) - r) * m_h;
        } else {
          if (c(i) + r + 1 > m_dims(i) - 1) continue;
          slab_lo(i) = m_lo(i) + (c(i) + r + 1) * m_h;
        }
        bound = std::min(bound, (x - x.cwiseMax(slab_lo).cwiseMin(slab_hi)).squaredNorm());
      }
    return bound;
  }

 private:
  int flat(const Eigen::Array3i& c) const { return (c(2) * m_dims(1) + c(1)) * m_dims(0) + c(0); }

  /// Lists every facet in the cells its box meets: count, then fill.
  void fill(const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi) {
    const int nf = static_cast<int>(lo.cols());
    m_start.assign(static_cast<size_t>(m_dims.prod()) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (int f = 0; f < nf; ++f) {
        const Eigen::Array3i a = cell_of(lo.col(f)), b = cell_of(hi.col(f));
        for (int k = a(2); k <= b(2); ++k)
          for (int j = a(1); j <= b(1); ++j)
            for (int i = a(0); i <= b(0); ++i) {
              const size_t c = static_cast<size_t>(flat({i, j, k}));
              if (pass == 0) ++m_start[c + 1];
              else m_list[static_cast<size_t>(m_start[c]++)] = f;
            }
      }
      if (pass == 0) {
        for (size_t c = 1; c < m_start.size(); ++c) m_start[c] += m_start[c - 1];
        m_list.resize(static_cast<size_t>(m_start.back()));
      } else {  // the fill advanced every start by its count: shift back
        for (size_t c = m_start.size() - 1; c > 0; --c) m_start[c] = m_start[c - 1];
        m_start[0] = 0;
      }
    }
  }

  Vector3d m_lo;  // the grid's lowest corner
  double m_h;     // cell size
  Eigen::Array3i m_dims;
  std::vector<int>& m_start;
  std::vector<int>& m_list;
};

/// The closest facet found for a node, with its projection.
struct ClosestFacet {
  double dist2 = std::numeric_limits<double>::max();
  int facet = -1;
  FacetProjection pr;
};

/// The facet closest to x (slave row k): the `guess` first (−1: none), then the rings
/// of cells around x's cell until no cell beyond can hold a closer one. A facet whose
/// bounding box is farther than the best so far is not projected on; `stamp` marks
/// the facets tried for row k. `project(f)` is x's projection onto facet f.
template <class Project>
ClosestFacet closest_facet(const FacetGrid& grid, const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi,
                           std::vector<int>& stamp, int k, const Vector3d& x, int guess, Project&& project) {
  ClosestFacet best;
  auto visit = [&](int f) {
    if (stamp[static_cast<size_t>(f)] == k) return;
    stamp[static_cast<size_t>(f)] = k;
    const double box2 = (x - x.cwiseMax(lo.col(f)).cwiseMin(hi.col(f))).squaredNorm();
    if (best.facet >= 0 && box2 > best.dist2 * (1.0 + 1e-12)) return;
    const FacetProjection pr = project(f);
    // Ties (a node exactly on a shared edge) go to the lower facet index.
    if (pr.distance2 < best.dist2 * (1.0 - 1e-14) ||
        (best.facet >= 0 && pr.distance2 <= best.dist2 * (1.0 + 1e-14) && f < best.facet))
      best = {pr.distance2, f, pr};
  };
  if (guess >= 0) visit(guess);
  const Eigen::Array3i c = grid.cell_of(x);
  for (int ring = 0; ring <= grid.max_ring(); ++ring) {
    grid.visit_ring(c, ring, visit);
    if (best.facet >= 0 && best.dist2 <= grid.beyond_ring(c, ring, x)) break;
  }
  return best;
}

/// Nodal normals of the deformed master surface (columns of `node_normal`, unit):
/// area-weighted facet normals.
void nodal_normals(const std::vector<std::array<int, 4>>& facets, const Eigen::Matrix3Xd& xm,
                   Eigen::Matrix3Xd& node_normal) {
  node_normal.setZero(3, xm.cols());
  for (const auto& facet : facets) {
    const bool tri = facet[3] < 0;
    const Vector3d n = tri ? Vector3d(0.5 * (xm.col(facet[1]) - xm.col(facet[0])).cross(xm.col(facet[2]) - xm.col(facet[0])))
                           : Vector3d(0.5 * (xm.col(facet[2]) - xm.col(facet[0])).cross(xm.col(facet[3]) - xm.col(facet[1])));
    for (int a = 0; a < (tri ? 3 : 4); ++a) node_normal.col(facet[static_cast<size_t>(a)]) += n;
  }
  for (Eigen::Index j = 0; j < xm.cols(); ++j) node_normal.col(j).normalize();
}

}  // namespace

std::array<double, 4> facet_node_areas(const Eigen::MatrixXd& nodes, const std::array<int, 4>& f) {
  auto x = [&](int a) -> Vector3d { return nodes.col(f[static_cast<size_t>(a)]).head<3>(); };
  std::array<double, 4> out{0.0, 0.0, 0.0, 0.0};
  if (f[3] < 0) {
    const double area = 0.5 * (x(1) - x(0)).cross(x(2) - x(0)).norm();
    out[0] = out[1] = out[2] = area / 3.0;
    return out;
  }
  const double g = 1.0 / std::sqrt(3.0);
  for (double xi : {-g, g})
    for (double eta : {-g, g}) {
      Vector3d dxi = Vector3d::Zero(), deta = Vector3d::Zero();
      for (int a = 0; a < 4; ++a) {
        dxi += 0.25 * kQuadXi[a] * (1 + kQuadEta[a] * eta) * x(a);
        deta += 0.25 * kQuadEta[a] * (1 + kQuadXi[a] * xi) * x(a);
      }
      const double da = dxi.cross(deta).norm();
      const auto n = facet_shape(false, xi, eta);
      for (size_t a = 0; a < 4; ++a) out[a] += n[a] * da;
    }
  return out;
}

FacetProjection project_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  // Projection onto the plane: solve the 2x2 normal equations for the weights of b, c.
  const Vector3d e1 = b - a, e2 = c - a, r = p - a;
  const double m11 = e1.dot(e1), m12 = e1.dot(e2), m22 = e2.dot(e2), r1 = r.dot(e1), r2 = r.dot(e2);
  const double det = m11 * m22 - m12 * m12;
  FacetProjection out;
  if (det > 0) {
    out.xi = (m22 * r1 - m12 * r2) / det;
    out.eta = (m11 * r2 - m12 * r1) / det;
    if (out.xi >= 0 && out.eta >= 0 && out.xi + out.eta <= 1) {
      out.point = a + out.xi * e1 + out.eta * e2;
      out.distance2 = (p - out.point).squaredNorm();
      return out;
    }
  }
  const Vector3d x[3] = {a, b, c};
  return closest_on_edges(p, x, 3, [](int k, double t, FacetProjection& f) {
    // Edge 0: a→b (ξ = t), 1: b→c (ξ = 1 − t, η = t), 2: c→a (η = 1 − t).
    f.xi = k == 0 ? t : (k == 1 ? 1.0 - t : 0.0);
    f.eta = k == 0 ? 0.0 : (k == 1 ? t : 1.0 - t);
  });
}

FacetProjection project_on_quad(const Vector3d& p, const std::array<Vector3d, 4>& x, const NodeToFaceOptions& options) {
  // x(ξ,η) = Σ N_a x_a = c0 + ξ c1 + η c2 + ξη c3.
  const Vector3d c0 = 0.25 * (x[0] + x[1] + x[2] + x[3]), c1 = 0.25 * (-x[0] + x[1] + x[2] - x[3]),
                 c2 = 0.25 * (-x[0] - x[1] + x[2] + x[3]), c3 = 0.25 * (x[0] - x[1] + x[2] - x[3]);
  double xi = 0.0, eta = 0.0;
  bool converged = false;
  for (int it = 0; it < options.newton_iterations; ++it) {
    const Vector3d r = c0 + xi * c1 + eta * c2 + xi * eta * c3 - p;
    const Vector3d t1 = c1 + eta * c3, t2 = c2 + xi * c3;
    // Gradient and Hessian of ½|r|² (x_ξξ = x_ηη = 0, x_ξη = c3).
    const double g1 = r.dot(t1), g2 = r.dot(t2);
    const double h11 = t1.dot(t1), h22 = t2.dot(t2), h12 = t1.dot(t2) + r.dot(c3);
    const double det = h11 * h22 - h12 * h12;
    if (!(det > 0)) break;  // not a minimum here: leave it to the edges
    const double d1 = (h22 * g1 - h12 * g2) / det, d2 = (h11 * g2 - h12 * g1) / det;
    xi -= d1, eta -= d2;
    if (std::abs(xi) > 2 || std::abs(eta) > 2) break;  // far outside: the closest point is on an edge
    if (std::max(std::abs(d1), std::abs(d2)) <= options.newton_tolerance) {
      converged = true;
      break;
    }
  }
  FacetProjection out;
  if (converged && std::abs(xi) <= 1 && std::abs(eta) <= 1) {
    out.xi = xi, out.eta = eta;
    out.point = c0 + xi * c1 + eta * c2 + xi * eta * c3;
    out.distance2 = (p - out.point).squaredNorm();
    return out;
  }
  return closest_on_edges(p, x.data(), 4, [](int k, double t, FacetProjection& f) {
    const int a = k, b = (k + 1) % 4;
    f.xi = (1 - t) * kQuadXi[a] + t * kQuadXi[b];
    f.eta = (1 - t) * kQuadEta[a] + t * kQuadEta[b];
  });
}

NodeToFaceContact::NodeToFaceContact(const Eigen::MatrixXd& nodes, const std::vector<ContactPairFacets>& pairs,
                                     const NodeToFaceOptions& options)
    : m_options(options) {
  auto point_text = [&](int node) {
    std::ostringstream s;
    s << "(" << nodes(0, node) << ", " << nodes(1, node) << ", " << nodes(2, node) << ")";
    return s.str();
  };
  // Rows: the slave nodes of each pair, ascending.
  std::map<int, int> surface_of;  // mesh node -> surface node index
  std::vector<std::pair<int, int>> row_span;
  for (size_t q = 0; q < pairs.size(); ++q) {
    if (pairs[q].slave.empty() || pairs[q].master.empty())
      throw InputError("contact pair " + std::to_string(q) + " has " + std::to_string(pairs[q].slave.size()) +
                       " slave facets and " + std::to_string(pairs[q].master.size()) +
                       " master facets; expected at least one of each");
    std::vector<int> slave;
    for (const auto& f : pairs[q].slave)
      for (int v : f)
        if (v >= 0) slave.push_back(v);
    std::sort(slave.begin(), slave.end());
    slave.erase(std::unique(slave.begin(), slave.end()), slave.end());
    const int begin = static_cast<int>(m_slave.size());
    for (int node : slave) {
      if (!surface_of.emplace(node, static_cast<int>(m_slave.size())).second)
        throw InputError("contact pairs share the slave node at " + point_text(node) +
                         "; expected each slave node in one pair only");
      m_slave.push_back(node);
      m_row_pair.push_back(static_cast<int>(q));
    }
    row_span.emplace_back(begin, static_cast<int>(m_slave.size()));
  }
  const int ns = static_cast<int>(m_slave.size());
  std::vector<int> surface_nodes(m_slave);
  for (size_t q = 0; q < pairs.size(); ++q) {
    Pair pair;
    pair.row_begin = row_span[q].first;
    pair.row_end = row_span[q].second;
    std::map<int, int> local_of;  // mesh node -> local master node
    for (const auto& f : pairs[q].master) {
      std::array<int, 4> local{-1, -1, -1, -1};
      for (int a = 0; a < 4; ++a) {
        const int node = f[static_cast<size_t>(a)];
        if (node < 0) continue;
        auto [it, inserted] = local_of.emplace(node, static_cast<int>(pair.master_surface.size()));
        if (inserted) {
          auto [s, new_node] = surface_of.emplace(node, static_cast<int>(surface_nodes.size()));
          if (new_node) surface_nodes.push_back(node);
          if (s->second >= pair.row_begin && s->second < pair.row_end)
            throw InputError("a contact pair's master surface contains its own slave node at " + point_text(node));
          pair.master_surface.push_back(s->second);
        }
        local[static_cast<size_t>(a)] = it->second;
      }
      pair.facets.push_back(local);
    }
    pair.master_x.resize(3, static_cast<Eigen::Index>(pair.master_surface.size()));
    for (const auto& [node, local] : local_of) pair.master_x.col(local) = nodes.col(node).head<3>();
    // Boundary edges of the master surface: edges of one facet only.
    std::map<std::pair<int, int>, int> edge_count;
    for (const auto& f : pair.facets) {
      const int nv = f[3] < 0 ? 3 : 4;
      for (int k = 0; k < nv; ++k) {
        const int a = f[static_cast<size_t>(k)], b = f[static_cast<size_t>((k + 1) % nv)];
        ++edge_count[{std::min(a, b), std::max(a, b)}];
      }
    }
    const int nm = static_cast<int>(pair.master_surface.size());
    std::vector<std::vector<std::pair<int, int>>> node_edges(static_cast<size_t>(nm));
    for (int fi = 0; fi < static_cast<int>(pair.facets.size()); ++fi) {
      const auto& f = pair.facets[static_cast<size_t>(fi)];
      const int nv = f[3] < 0 ? 3 : 4;
      std::array<char, 4> flags{0, 0, 0, 0};
      for (int k = 0; k < nv; ++k) {
        const int a = f[static_cast<size_t>(k)], b = f[static_cast<size_t>((k + 1) % nv)];
        if (edge_count[{std::min(a, b), std::max(a, b)}] != 1) continue;
        flags[static_cast<size_t>(k)] = 1;
        node_edges[static_cast<size_t>(a)].emplace_back(fi, k);
        node_edges[static_cast<size_t>(b)].emplace_back(fi, k);
      }
      pair.boundary.push_back(flags);
    }
    pair.node_edges_start.assign(static_cast<size_t>(nm) + 1, 0);
    for (int j = 0; j < nm; ++j) {
      pair.node_edges_start[static_cast<size_t>(j) + 1] =
          pair.node_edges_start[static_cast<size_t>(j)] + static_cast<int>(node_edges[static_cast<size_t>(j)].size());
      pair.node_edges.insert(pair.node_edges.end(), node_edges[static_cast<size_t>(j)].begin(),
                             node_edges[static_cast<size_t>(j)].end());
    }
    m_pairs.push_back(std::move(pair));
  }
  for (int node : surface_nodes) m_surface_dofs.insert(m_surface_dofs.end(), {3 * node, 3 * node + 1, 3 * node + 2});
  m_slave_x.resize(3, ns);
  for (int k = 0; k < ns; ++k) m_slave_x.col(k) = nodes.col(m_slave[static_cast<size_t>(k)]).head<3>();
  m_points = m_slave_x;

  // Tributary areas ∫ N_s dA over the slave facets.
  m_weights = Eigen::VectorXd::Zero(ns);
  for (const ContactPairFacets& pf : pairs)
    for (const auto& f : pf.slave) {
      const std::array<double, 4> area = facet_node_areas(nodes, f);
      for (int a = 0; a < 4 && f[static_cast<size_t>(a)] >= 0; ++a)
        m_weights(surface_of.at(f[static_cast<size_t>(a)])) += area[static_cast<size_t>(a)];
    }
}

FacetProjection NodeToFaceContact::project(const Pair& pair, const Eigen::Matrix3Xd& xm, int f, const Vector3d& x) const {
  const auto& facet = pair.facets[static_cast<size_t>(f)];
  if (facet[3] < 0) return project_on_triangle(x, xm.col(facet[0]), xm.col(facet[1]), xm.col(facet[2]));
  return project_on_quad(x, {xm.col(facet[0]), xm.col(facet[1]), xm.col(facet[2]), xm.col(facet[3])}, m_options);
}

bool NodeToFaceContact::beyond_boundary(const Pair& pair, const Eigen::Matrix3Xd& xm, int f, const FacetProjection& pr,
                                        const Vector3d& x) const {
  auto beyond_edge = [&](int fi, int k) {
    const auto& facet = pair.facets[static_cast<size_t>(fi)];
    const int nv = facet[3] < 0 ? 3 : 4;
    const Vector3d a = xm.col(facet[static_cast<size_t>(k)]), b = xm.col(facet[static_cast<size_t>((k + 1) % nv)]);
    const Vector3d n = nv == 3 ? Vector3d((xm.col(facet[1]) - xm.col(facet[0])).cross(xm.col(facet[2]) - xm.col(facet[0])))
                               : Vector3d((xm.col(facet[2]) - xm.col(facet[0])).cross(xm.col(facet[3]) - xm.col(facet[1])));
    // The edge's in-plane outward direction: counter-clockwise seen along n, t × n points out.
    // Beyond: farther out than off the facet's plane (and than the tolerance). A node
    // off a tilted facet whose edge lies on a symmetry plane moves out of the plane
    // only by the tilt times its normal distance, and stays paired.
    const Vector3d m = (b - a).cross(n);
    const double mn = m.norm(), nn = n.norm();
    if (!(mn > 0 && nn > 0)) return false;
    const double out = (x - pr.point).dot(m) / mn, off = std::abs((x - pr.point).dot(n)) / nn;
    return out > std::max(m_options.boundary_tolerance * (b - a).norm(), off);
  };
  if (pr.edge >= 0) return pair.boundary[static_cast<size_t>(f)][static_cast<size_t>(pr.edge)] && beyond_edge(f, pr.edge);
  if (pr.vertex < 0) return false;
  const int node = pair.facets[static_cast<size_t>(f)][static_cast<size_t>(pr.vertex)];
  for (int e = pair.node_edges_start[static_cast<size_t>(node)]; e < pair.node_edges_start[static_cast<size_t>(node) + 1]; ++e)
    if (beyond_edge(pair.node_edges[static_cast<size_t>(e)].first, pair.node_edges[static_cast<size_t>(e)].second))
      return true;
  return false;
}

void NodeToFaceContact::search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows, const Pairing* hint,
                                    Pairing& p) const {
  if (hint == &p) {  // the hint is read while p is written
    const Pairing copy = *hint;
    search_rows(u_surface, rows, &copy, p);
    return;
  }
  const int ns = static_cast<int>(m_slave.size());
  p.segment.assign(static_cast<size_t>(ns), -1);
  p.xi.assign(static_cast<size_t>(ns), 0.0);
  p.eta.assign(static_cast<size_t>(ns), 0.0);
  p.normal.setZero(3, ns);
  size_t r = 0;
  for (const Pair& pair : m_pairs) {
    if (!rows) {
      search_pair(pair, u_surface, nullptr, pair.row_end - pair.row_begin, hint, p);
      continue;
    }
    const size_t first = r;
    while (r < rows->size() && (*rows)[r] < pair.row_end) ++r;
    if (r > first) search_pair(pair, u_surface, rows->data() + first, static_cast<int>(r - first), hint, p);
  }
}

void NodeToFaceContact::search_pair(const Pair& pair, const Eigen::VectorXd& u_surface, const int* rows, int nrows,
                                    const Pairing* hint, Pairing& p) const {
  const int nm = static_cast<int>(pair.master_surface.size()), nf = static_cast<int>(pair.facets.size());
  thread_local FacetSearchScratch s;
  s.xm.resize(3, nm);
  for (int j = 0; j < nm; ++j)
    s.xm.col(j) = pair.master_x.col(j) + u_surface.segment<3>(3 * pair.master_surface[static_cast<size_t>(j)]);
  const double mean_size = facet_boxes(pair.facets, s.xm, s.lo, s.hi);
  const FacetGrid grid(s.lo, s.hi, mean_size, s.cell_start, s.cell_facets);
  s.stamp.assign(static_cast<size_t>(nf), -1);

  // Each row: its closest facet, unless the node lies beyond the master's boundary.
  for (int r = 0; r < nrows; ++r) {
    const int k = rows ? rows[r] : pair.row_begin + r;
    const Vector3d x = m_slave_x.col(k) + u_surface.segment<3>(3 * k);
    int guess = -1;
    if (hint && hint->segment.size() == p.segment.size() && hint->segment[static_cast<size_t>(k)] >= 0 &&
        hint->segment[static_cast<size_t>(k)] < nf)
      guess = hint->segment[static_cast<size_t>(k)];
    const ClosestFacet best = closest_facet(grid, s.lo, s.hi, s.stamp, k, x, guess,
                                            [&](int f) { return project(pair, s.xm, f, x); });
    if (best.facet < 0 || beyond_boundary(pair, s.xm, best.facet, best.pr, x)) continue;
    p.segment[static_cast<size_t>(k)] = best.facet;
    p.xi[static_cast<size_t>(k)] = best.pr.xi;
    p.eta[static_cast<size_t>(k)] = best.pr.eta;
  }

  // The normal of each paired row: the nodal normals interpolated at its point.
  nodal_normals(pair.facets, s.xm, s.node_normal);
  for (int r = 0; r < nrows; ++r) {
    const int k = rows ? rows[r] : pair.row_begin + r, f = p.segment[static_cast<size_t>(k)];
    if (f < 0) continue;
    const auto& facet = pair.facets[static_cast<size_t>(f)];
    const auto n = facet_shape(facet[3] < 0, p.xi[static_cast<size_t>(k)], p.eta[static_cast<size_t>(k)]);
    Vector3d normal = Vector3d::Zero();
    for (int a = 0; a < 4 && facet[static_cast<size_t>(a)] >= 0; ++a)
      normal += n[static_cast<size_t>(a)] * s.node_normal.col(facet[static_cast<size_t>(a)]);
    p.normal.col(k) = normal.normalized();
  }
}

void NodeToFaceContact::assemble(const Pairing& p, ConstraintMatrix& c, Eigen::VectorXd& g) const {
  std::vector<int> all(m_slave.size());
  for (size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  assemble_rows(p, all, c, g);
}

void NodeToFaceContact::assemble_rows(const Pairing& p, const std::vector<int>& rows, ConstraintMatrix& c,
                                      Eigen::VectorXd& g) const {
  // Written straight into the compressed arrays (reused storage): per row at most
  // five nodes (the slave node and a quad's four), three entries each.
  const int nr = static_cast<int>(rows.size());
  g.resize(nr);
  c.resize(nr, static_cast<int>(m_surface_dofs.size()));
  c.resizeNonZeros(15 * nr);
  int* outer = c.outerIndexPtr();
  int* inner = c.innerIndexPtr();
  double* value = c.valuePtr();
  int nnz = 0;
  for (int i = 0; i < nr; ++i) {
    outer[i] = nnz;
    const int k = rows[static_cast<size_t>(i)], f = p.segment[static_cast<size_t>(k)];
    g(i) = 0.0;
    if (f < 0) continue;
    const Pair& pair = m_pairs[static_cast<size_t>(m_row_pair[static_cast<size_t>(k)])];
    const auto& facet = pair.facets[static_cast<size_t>(f)];
    const auto n = facet_shape(facet[3] < 0, p.xi[static_cast<size_t>(k)], p.eta[static_cast<size_t>(k)]);
    const double w = m_weights(k);
    const Vector3d normal = p.normal.col(k);
    struct Entry {
      int node;
      double factor;
    } e[5];
    int ne = 0;
    e[ne++] = {k, -w};
    Vector3d xm = Vector3d::Zero();
    for (int a = 0; a < 4 && facet[static_cast<size_t>(a)] >= 0; ++a) {
      const int local = facet[static_cast<size_t>(a)];
      e[ne++] = {pair.master_surface[static_cast<size_t>(local)], w * n[static_cast<size_t>(a)]};
      xm += n[static_cast<size_t>(a)] * pair.master_x.col(local);
    }
    g(i) = w * normal.dot(m_slave_x.col(k) - xm);
    std::sort(e, e + ne, [](const Entry& a, const Entry& b) { return a.node < b.node; });
    for (int j = 0; j < ne; ++j)
      for (int d = 0; d < 3; ++d) inner[nnz] = 3 * e[j].node + d, value[nnz++] = e[j].factor * normal(d);
  }
  outer[nr] = nnz;
  c.resizeNonZeros(nnz);
}

}  // namespace contactrom::fom
