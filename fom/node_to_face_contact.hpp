#pragma once
/// \file node_to_face_contact.hpp
/// \brief Node-to-face contact in 3D: each slave node is projected onto the
/// closest facet (linear triangle or bilinear quad) of its pair's master surface in
/// the deformed configuration; its constraint row is the linearised normal approach
/// weighted by the node's tributary area, so the multiplier is a pressure. The
/// theory is in docs/theory.md ("Node-to-face contact").
#include <Eigen/Dense>
#include <array>
#include <vector>

#include <contactrom/fom/contact_model.hpp>

namespace contactrom::fom {

/// \brief Closest point of a point on one facet.
struct FacetProjection {
  /// Local coordinates of the closest point: triangle — barycentric weights of
  /// nodes 1 and 2 (node 0 has 1 − ξ − η); quad — ξ, η ∈ [−1, 1]² of the bilinear map.
  double xi = 0.0, eta = 0.0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< the closest point
  double distance2 = 0.0;                            ///< squared distance to it
  /// Where the closest point lies: inside the facet (both −1), on edge `edge`
  /// (from local node k to k+1) or at local node `vertex`.
  int edge = -1, vertex = -1;
};

/// \brief Options of the facet projections and of NodeToFaceContact (documented defaults).
struct NodeToFaceOptions {
  /// Newton iterations of the projection onto a bilinear quad (default 30).
  int newton_iterations = 30;
  /// Newton stops when the step in (ξ, η) is below this (default 1e-14).
  double newton_tolerance = 1e-14;
  /// A slave node whose closest point is on the boundary of the master surface is
  /// unpaired when it lies beyond that boundary edge (along the facet's plane, away
  /// from the facet) by more than this fraction of the edge's length and by more than
  /// its distance from the facet's plane (the 3D form of a projection beyond the end
  /// of a 2D master chain, whose ends reach as far). Within it the node pairs with
  /// the boundary facet extended: blocks of the same footprint put slave nodes on the
  /// master's boundary edges, which non-matching meshes move out by a little.
  /// The second bound keeps nodes on a symmetry plane through the boundary paired
  /// when the facet tilts. Default 0.1.
  double boundary_tolerance = 0.1;
};

/// \brief Closest point of `p` on the triangle (a, b, c).
FacetProjection project_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c);

/// \brief Closest point of `p` on the bilinear quad x0..x3 (counter-clockwise):
/// Newton's method on the stationarity of \f$ |x(\xi,\eta) - p|^2 \f$ from the
/// centre; if it leaves [−1,1]² the closest point is on an edge (straight for a
/// bilinear quad) and is found there in closed form.
FacetProjection project_on_quad(const Eigen::Vector3d& p, const std::array<Eigen::Vector3d, 4>& x,
                                const NodeToFaceOptions& options = {});

/// \brief The integrals \f$ \int_f N_a \, dA \f$ of the shape functions of facet `f`
/// (triangle: a third of its area each; bilinear quad: 2x2 Gauss points) over its
/// reference configuration: tributary areas, and the consistent nodal forces of a
/// uniform traction. Entry 3 is 0 for a triangle.
std::array<double, 4> facet_node_areas(const Eigen::MatrixXd& nodes, const std::array<int, 4>& f);

/// \brief One contact pair of NodeToFaceContact: the slave and master facets
/// (Mesh::faces: triangles with a last id −1, or quads), counter-clockwise seen from
/// outside their body.
struct ContactPairFacets {
  std::vector<std::array<int, 4>> slave;
  std::vector<std::array<int, 4>> master;
};

/// \brief Node-to-face contact of any number of pairs.
///
/// Rows are the slave nodes of pair 0 (ascending node id), then of pair 1, …; the
/// surface dofs are the slave nodes' (row s ↔ surface node s) followed by the
/// master nodes not already listed, pair after pair, three per node. A slave node
/// is paired with the master surface of its own pair only.
///
/// Row s, with slave node x_s projected onto master facet f at local coordinates
/// (ξ, η), shape functions N_a and unit normal n: entries −w_s n on the slave node
/// and w_s N_a(ξ, η) n on the facet's nodes; g_s = w_s n·(X_s − Σ N_a X_a) with the
/// reference coordinates X, so that C u − g = −w_s n·(x_s − x_m) ≤ 0 keeps the slave
/// node on the outer side of the master. The normal interpolates the master's nodal
/// normals (area-weighted averages of the adjacent facets' outward normals, in the
/// deformed configuration) with N_a and is normalised, so it is continuous across
/// facets. w_s is the node's tributary area on the slave surface, ∫ N_s dA.
///
/// The search uses a uniform bucket grid over the deformed master facets' bounding
/// boxes (about one cell per facet): a slave node visits the cells in rings of
/// growing distance around its own (projecting only onto facets whose bounding box is
/// nearer than the closest facet found) and stops once the grid beyond the rings is
/// farther than that facet, so a search tries a few facets per node, also for nodes
/// far from the master surface.
class NodeToFaceContact final : public ContactModel {
 public:
  /// \param nodes reference coordinates of the mesh (3 x n_nodes)
  /// \param pairs the pairs' facets; slave nodes must be distinct across pairs
  /// \throws InputError if a pair has no facets, a slave node is in two pairs or
  ///   in its own pair's master surface
  NodeToFaceContact(const Eigen::MatrixXd& nodes, const std::vector<ContactPairFacets>& pairs,
                    const NodeToFaceOptions& options = {});

  bool has_pairing() const override { return true; }
  using ContactModel::search_rows;
  void search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows, const Pairing* hint,
                   Pairing& out) const override;
  void assemble(const Pairing& pairing, ConstraintMatrix& c, Eigen::VectorXd& g) const override;
  void assemble_rows(const Pairing& pairing, const std::vector<int>& rows, ConstraintMatrix& c,
                     Eigen::VectorXd& g) const override;

  /// Slave node ids of every row, in row order.
  const std::vector<int>& slave_nodes() const { return m_slave; }
  int num_pairs() const override { return static_cast<int>(m_pairs.size()); }
  /// Pair of a constraint row.
  int pair_of_row(int row) const override { return m_row_pair[static_cast<size_t>(row)]; }
  int slave_node(int row) const override { return m_slave[static_cast<size_t>(row)]; }

 private:
  struct Pair {
    int row_begin = 0, row_end = 0;                 // rows [row_begin, row_end)
    std::vector<std::array<int, 4>> facets;         // master facets, local master node ids (−1: triangle)
    std::vector<int> master_surface;                // surface node index of each local master node
    Eigen::Matrix3Xd master_x;                      // reference coordinates of the local master nodes
    std::vector<std::array<char, 4>> boundary;      // per facet and edge: on the master surface's boundary
    std::vector<int> node_edges_start;              // per local master node: its boundary edges (CSR) …
    std::vector<std::pair<int, int>> node_edges;    // … as (facet, local edge)
  };
  void search_pair(const Pair& pair, const Eigen::VectorXd& u_surface, const int* rows, int nrows,
                   const Pairing* hint, Pairing& p) const;
  /// Whether slave point x, closest to `pr` on facet f, lies beyond the master surface's boundary.
  bool beyond_boundary(const Pair& pair, const Eigen::Matrix3Xd& xm, int f, const FacetProjection& pr,
                       const Eigen::Vector3d& x) const;
  FacetProjection project(const Pair& pair, const Eigen::Matrix3Xd& xm, int f, const Eigen::Vector3d& x) const;

  NodeToFaceOptions m_options;
  std::vector<int> m_slave;
  Eigen::Matrix3Xd m_slave_x;  // reference coordinates
  std::vector<Pair> m_pairs;
  std::vector<int> m_row_pair;
};

}  // namespace contactrom::fom
