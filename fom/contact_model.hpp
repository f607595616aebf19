#pragma once
/// \file contact_model.hpp
/// \brief Linearised non-penetration constraints \f$ \mathbf{C}(u)\,u - \mathbf{g}(u) \le 0 \f$.
///
/// A ContactModel owns the geometry of the potential contact surface. It works on
/// the *surface dofs* only (the displacement dofs that constraint rows may touch),
/// so that a reduced model can rebuild \f$ \mathbf{C} \f$ from the contact-surface
/// rows of its basis at a cost independent of the mesh size.
///
/// Row s is the constraint of slave node (or obstacle node) s, weighted by its
/// tributary length \f$ w_s \f$, so the multiplier \f$ \lambda_s \f$ is a
/// pressure. The number of rows is fixed: an unpaired slave node keeps a zero row
/// and \f$ g_s = 0 \f$ and can never be active.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <string>
#include <vector>

namespace contactrom::fom {

/// Row-major sparse matrix: the constraint operator restricted to surface dofs.
using ConstraintMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// \brief Contact pairing: for every constraint row, the master segment (2D) or
/// facet (3D) it is projected on (closest point, -1: unpaired), the local
/// coordinates there and the master's outward unit normal, all in the deformed
/// configuration. The normal interpolates nodal (averaged) normals so that it
/// is continuous along the master surface.
/// Empty vectors for models without pairing (obstacles).
struct Pairing {
  std::vector<int> segment;  ///< master segment (2D) or facet (3D) index within its pair, −1: unpaired
  /// 2D: ξ ∈ [0,1] along the segment. 3D: first local coordinate on the facet
  /// (triangle: barycentric weight of its node 1; quad: ξ ∈ [−1,1]).
  std::vector<double> xi;
  /// 3D only (empty in 2D): second local coordinate (triangle: weight of node 2; quad: η ∈ [−1,1]).
  std::vector<double> eta;
  Eigen::MatrixXd normal;    ///< outward unit normals of the master, dim x n_c
  /// True when both pairings pair the same rows, their chain positions
  /// (segment + ξ) and normals agree to `tol`.
  bool same_as(const Pairing& other, double tol) const;
};

/// \brief What a search leaves for the next one at a nearby displacement (one per
/// caller, e.g. per online query): per row, the closest segment found and a lower
/// bound of the distance to every segment that is not that one or a neighbour of
/// it, with the displacement they were found at. While the nodes have moved less
/// than that clearance allows, the closest segment is still among the three, and
/// the search tries only those: its result is the full search's (see
/// NodeToSegmentContact::search_rows). Empty: nothing recorded.
struct SearchMemory {
  std::vector<int> centre;           ///< per row: closest segment at the reference (−1: none)
  std::vector<double> clearance;     ///< per row: lower bound of the distance to the other segments
  Eigen::Matrix2Xd slave_reference;  ///< per row: displacement of its node at the reference
  std::vector<Eigen::Matrix2Xd> master_reference;  ///< per pair: displacements of its master nodes
  std::vector<char> recorded;        ///< per pair: whether the above hold for its rows
  int certified = 0, searched = 0;   ///< rows settled by the memory / by a full search, so far
};

/// \brief First-order model of a pairing, for the Newton steps of the contact zone
/// (fom/contact_zone.hpp): k continuous coordinates per listed row (2D node
/// to segment: the position along the master chain, segment + ξ, and the angle of
/// the normal), their derivatives with respect to the surface displacement, and the
/// derivatives of the rows of C and g with respect to them.
struct PairingLinearisation {
  int per_row = 0;        ///< coordinates per row, k
  Eigen::VectorXd q;      ///< the coordinates, row after row (k·|rows|)
  /// ∂q/∂u_s at the pairing of u_s itself (its closest points), k·|rows| x n_s
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> dq_du;
  /// ∂C_r/∂q_j: row j is the derivative of the constraint row r of coordinate j
  /// (at fixed u), k·|rows| x n_s; dg the same for g
  ConstraintMatrix dc;
  Eigen::VectorXd dg;
};

/// \brief Abstract contact model; see the file comment.
class ContactModel {
 public:
  virtual ~ContactModel() = default;

  /// Number of constraint rows n_c (fixed).
  int num_constraints() const { return static_cast<int>(m_weights.size()); }
  /// Global dof indices the constraint rows may touch, in the column order of C.
  const std::vector<int>& surface_dofs() const { return m_surface_dofs; }
  /// Tributary length (2D) or area (3D) \f$ w_s \f$ of each row (reference configuration).
  const Eigen::VectorXd& weights() const { return m_weights; }
  /// Reference coordinates of the constrained nodes (dim x n_c; rope: x and 0).
  const Eigen::MatrixXd& constraint_points() const { return m_points; }
  /// Whether C and g depend on the displacement through a pairing.
  virtual bool has_pairing() const = 0;
  /// Number of contact pairs (slave/master couples); 1 for an obstacle.
  virtual int num_pairs() const { return 1; }
  /// The contact pair a constraint row belongs to (0 … num_pairs() − 1).
  virtual int pair_of_row(int row) const {
    (void)row;
    return 0;
  }
  /// The mesh node of a constraint row's slave side (−1 for models without slave
  /// nodes: the rope, obstacles).
  virtual int slave_node(int row) const {
    (void)row;
    return -1;
  }

  /// \brief Contact search in the deformed configuration, every row.
  /// \param u_surface full displacement restricted to surface_dofs()
  Pairing search(const Eigen::VectorXd& u_surface) const { return search_rows(u_surface, nullptr, nullptr); }
  /// \brief Same, for the listed rows only (ascending; nullptr: every row). The
  /// other rows are left unpaired, i.e. zero rows of C after assemble(). A reduced
  /// model whose dual dictionary vanishes outside a set of rows needs only those.
  /// `hint` (may be nullptr): a nearby pairing (e.g. of the previous iterate) whose
  /// segments are tried first; it speeds the search up and never changes its result.
  Pairing search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows, const Pairing* hint) const {
    Pairing p;
    search_rows(u_surface, rows, hint, p);
    return p;
  }
  /// \brief Same, into `out`, whose storage is reused (repeated online searches do
  /// not allocate). `hint` must not be `&out`.
  virtual void search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows, const Pairing* hint,
                           Pairing& out) const = 0;
  /// \brief Same result, using and updating `memory` of the previous searches by the
  /// same caller with the same `rows`, so that rows whose nodes moved little since
  /// are settled without the search of the whole master chain. The default
  /// ignores the memory.
  virtual void search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows, const Pairing* hint,
                           SearchMemory& memory, Pairing& out) const {
    (void)memory;
    search_rows(u_surface, rows, hint, out);
  }

  /// \brief Constraint operator for a pairing: C (n_c x surface dofs) and g (n_c).
  virtual void assemble(const Pairing& pairing, ConstraintMatrix& c, Eigen::VectorXd& g) const = 0;
  /// \brief The listed rows of C and g only, compact: row i of `c` (|rows| x surface
  /// dofs) and g(i) are row rows[i] of assemble()'s. The storage of `c` and `g` is
  /// reused, so repeated online calls do not allocate.
  virtual void assemble_rows(const Pairing& pairing, const std::vector<int>& rows, ConstraintMatrix& c,
                             Eigen::VectorXd& g) const;

  /// \brief The pairing's coordinates and derivatives at the listed rows (all paired)
  /// for the surface displacement `u_surface` whose pairing (search) is `pairing`;
  /// see PairingLinearisation. Returns false when the model has none (obstacles,
  /// node-to-face contact): the contact zone then takes Anderson steps only.
  virtual bool linearise_pairing(const Eigen::VectorXd& u_surface, const Pairing& pairing,
                                 const std::vector<int>& rows, PairingLinearisation& out) const {
    (void)u_surface, (void)pairing, (void)rows, (void)out;
    return false;
  }
  /// \brief The surface dofs (column indices of C, ascending) that the pairing of the
  /// listed rows reads — their slave nodes', and the master nodes' that the segments
  /// and normals depend on — while each row stays within `reach` segments of its
  /// segment in `pairing` (all listed rows paired). Returns false when the model
  /// cannot say (node-to-face contact, obstacles).
  virtual bool pairing_support(const Pairing& pairing, const std::vector<int>& rows, int reach,
                               std::vector<int>& dofs) const {
    (void)pairing, (void)rows, (void)reach, (void)dofs;
    return false;
  }
  /// \brief Sets the listed rows of `pairing` to the coordinates `q` (as
  /// linearise_pairing() numbers them). Only for models whose linearise_pairing() succeeds.
  virtual void move_pairing(Pairing& pairing, const std::vector<int>& rows, const Eigen::VectorXd& q) const {
    (void)pairing, (void)rows, (void)q;
  }

  /// Gather a full dof vector onto the surface dofs.
  Eigen::VectorXd restrict_to_surface(const Eigen::VectorXd& u_full) const;

 protected:
  std::vector<int> m_surface_dofs;
  Eigen::VectorXd m_weights;
  Eigen::MatrixXd m_points;
};

/// \brief One contact pair of NodeToSegmentContact: node chains of the slave and
/// master curves, each in the mesh's chain order (its body on the left, so that a
/// master segment a→b has the outward normal (t_y, −t_x) of its own body).
struct ContactPairChains {
  std::vector<int> slave;   ///< slave node ids in chain order
  std::vector<int> master;  ///< master node ids in chain order
};

/// \brief Node-to-segment contact of any number of pairs (slave nodes against
/// master segments). Rows are the slave nodes of pair 0, then of pair 1, …; the
/// surface dofs are the slave nodes in row order (row s ↔ surface node s), then the
/// master nodes that are not slave nodes, pair after pair in chain order. A slave
/// node is paired only with the master chain of its own pair.
class NodeToSegmentContact final : public ContactModel {
 public:
  /// \param nodes reference coordinates of the mesh (2 x n_nodes)
  /// \param pairs the pairs' chains; slave nodes must be distinct across pairs
  /// \throws InputError if a slave node appears twice or a chain is too short
  NodeToSegmentContact(const Eigen::Matrix2Xd& nodes, const std::vector<ContactPairChains>& pairs);

  bool has_pairing() const override { return true; }
  using ContactModel::search_rows;
  void search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows, const Pairing* hint,
                   Pairing& out) const override;
  /// With a memory: a full search records, per row, its closest segment j and a
  /// clearance c (a lower bound of the distance to the segments outside j ± 1; the
  /// search prunes with a margin of half the mean master segment length so that c
  /// is useful). The next search first tries j ± 1 only; the slave node has moved
  /// by a and no master node by more than b since, so every other segment is at
  /// least c − a − b away: if that exceeds the distance found, the row is settled.
  /// Otherwise the pair is searched in full (and recorded anew).
  void search_rows(const Eigen::VectorXd& u_surface, const std::vector<int>* rows, const Pairing* hint,
                   SearchMemory& memory, Pairing& out) const override;
  void assemble(const Pairing& pairing, ConstraintMatrix& c, Eigen::VectorXd& g) const override;
  void assemble_rows(const Pairing& pairing, const std::vector<int>& rows, ConstraintMatrix& c,
                     Eigen::VectorXd& g) const override;

  /// Coordinates (position segment + ξ along the master chain, normal angle) of the
  /// rows; dq_du from the closest-point projection and the averaged nodal normals.
  bool linearise_pairing(const Eigen::VectorXd& u_surface, const Pairing& pairing, const std::vector<int>& rows,
                         PairingLinearisation& out) const override;
  void move_pairing(Pairing& pairing, const std::vector<int>& rows, const Eigen::VectorXd& q) const override;
  bool pairing_support(const Pairing& pairing, const std::vector<int>& rows, int reach,
                       std::vector<int>& dofs) const override;

  /// Slave node ids of every row, in row order.
  const std::vector<int>& slave_nodes() const { return m_slave; }
  int num_pairs() const override { return static_cast<int>(m_pairs.size()); }
  /// Pair of a constraint row.
  int pair_of_row(int row) const override;
  int slave_node(int row) const override { return m_slave[static_cast<size_t>(row)]; }

 private:
  struct Pair {
    int row_begin = 0, row_end = 0;     // rows [row_begin, row_end)
    std::vector<int> master;            // master node ids, chain order
    std::vector<int> master_surface;    // surface node index of each master node
    Eigen::Matrix2Xd master_x;          // reference coordinates
    double margin = 0.0;                // pruning margin of a recorded search: half the mean segment length
  };
  /// \brief What one pair's search is asked.
  struct PairRequest {
    int pair_index = 0;
    /// The rows to search: `listed_rows[0 … num_rows)` (ascending, all of this pair),
    /// or, when `listed_rows` is nullptr, every row of the pair.
    const int* listed_rows = nullptr;
    int num_rows = 0;
    const Pairing* hint = nullptr;   ///< pairing whose segments are tried first (none: nullptr)
    SearchMemory* memory = nullptr;  ///< memory to certify from and record into (none: nullptr)
  };
  /// One pair's search (contact_model.cpp): the certificate of the memory, else the
  /// pruned search, then the nodal normals.
  class PairSearch;
  void search_pair(const PairRequest& request, const Eigen::VectorXd& u_surface, Pairing& p) const;
  /// Both search_rows: every pair's run of the listed rows.
  void search_all(const Eigen::VectorXd& u_surface, const std::vector<int>* rows, const Pairing* hint,
                  SearchMemory* memory, Pairing& p) const;

  std::vector<int> m_slave;
  Eigen::Matrix2Xd m_slave_x;  // reference coordinates
  std::vector<Pair> m_pairs;
  std::vector<int> m_row_pair;  // pair of each row
  int m_block = 8;              // segments per bounding circle of the search
};

/// \brief Scalar obstacle constraint \f$ u_i \ge \psi(x_i) \f$ on 1D nodes (rope).
class ObstacleContact final : public ContactModel {
 public:
  /// \param x node coordinates, \param psi obstacle height at the nodes,
  /// \param weights tributary lengths (the dof of node i is i).
  ObstacleContact(const Eigen::VectorXd& x, const Eigen::VectorXd& psi, const Eigen::VectorXd& weights);
  bool has_pairing() const override { return false; }
  using ContactModel::search_rows;
  void search_rows(const Eigen::VectorXd&, const std::vector<int>*, const Pairing*, Pairing& out) const override {
    out = Pairing{};
  }
  void assemble(const Pairing& pairing, ConstraintMatrix& c, Eigen::VectorXd& g) const override;

 private:
  Eigen::VectorXd m_psi;
};

}  // namespace contactrom::fom
