#pragma once
/// \file problem.hpp
/// \brief The parametrised contact problems of DESIGN §1: `rope`, `hertz`,
/// `ironing`, `ironing2`.
///
/// Discrete problem (paper eq. 1–2), in full dof numbering with Dirichlet dofs
/// kept: \f$ u = u_{lift}(\mu) + u_0 \f$ with \f$ u_0 = 0 \f$ on Dirichlet dofs and
/// \f[ \min_{u_0} \tfrac12 u_0^T K(\mu) u_0 - u_0^T f(\mu) \quad\text{s.t.}\quad
///     C(u)\,u - g(u) \le 0, \f]
/// where \f$ f(\mu) = f_{ext}(\mu) - K(\mu) u_{lift}(\mu) \f$ (zero on Dirichlet rows).
/// Both \f$ K \f$ and \f$ f \f$ are affine in the parameter:
/// \f$ K(\mu) = \sum_q \theta_q(\mu) K_q \f$, \f$ f(\mu) = \sum_k \phi_k(\mu) f_k \f$,
/// \f$ u_{lift}(\mu) = \sum_k \phi_k(\mu) L_k \f$, so for `hertz`/`ironing` K is
/// factorised once and reused for every parameter.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <memory>
#include <string>
#include <vector>

#include "fom/contact_model.hpp"
#include "fom/elasticity.hpp"
#include "fom/mesh.hpp"

namespace contactrom::fom {

using Param = Eigen::VectorXd;

/// \brief Options shared by the problem factories (documented defaults).
struct ProblemOptions {
  std::string mesh_dir;     ///< folder of the .geo files; empty: mesh_directory()
  int rope_elements = 200;  ///< P1 elements of `rope`
  double rope_load = 400.0; ///< uniform load f of `rope` (pulls the rope onto the obstacle)
  double ironing_length = 4.0;  ///< L: d_x ∈ [0, L] for `ironing`/`ironing2`
  double ironing_dy = 0.3;      ///< fixed d_y of `ironing`
};

/// \brief A parametrised linear-elastic contact problem; see the file comment.
class Problem {
 public:
  virtual ~Problem() = default;

  const std::string& name() const { return m_name; }
  int num_params() const { return static_cast<int>(m_lower.size()); }
  const std::vector<std::string>& param_names() const { return m_param_names; }
  const Eigen::VectorXd& param_lower() const { return m_lower; }
  const Eigen::VectorXd& param_upper() const { return m_upper; }
  /// Whether the lower bound is excluded (hertz: d ∈ (0, 0.3]).
  bool lower_open() const { return m_lower_open; }
  /// \throws InputError naming the value and the expected range.
  void check_param(const Param& mu) const;
  /// Human-readable range, e.g. "d in (0, 0.3]".
  std::string range_text() const;

  /// Training set: `hertz` uniform of size n; `ironing`/`ironing2` nested level n;
  /// `rope` ignores n (the 9 values of DESIGN §1). Throws InputError on bad n.
  virtual std::vector<Param> training_set(int n) const = 0;
  /// Validation set associated with training size/level n (see DESIGN §1).
  virtual std::vector<Param> validation_set(int n) const = 0;
  /// Whether training sets are selected by `--level` (true) or `--train` (false).
  virtual bool uses_levels() const { return false; }
  /// Whether the feasible set is convex and parameter-independent (convex-hull ROM).
  virtual bool convex_parameter_independent_feasible_set() const { return false; }

  int num_dofs() const { return static_cast<int>(m_is_dirichlet.size()); }
  /// Spatial dimension of a node's displacement (2, or 1 for rope).
  int dofs_per_node() const { return m_dofs_per_node; }
  const std::vector<char>& is_dirichlet() const { return m_is_dirichlet; }
  /// Indices of the free dofs, ascending.
  const std::vector<int>& free_dofs() const { return m_free_dofs; }

  int num_stiffness_terms() const { return static_cast<int>(m_k_terms.size()); }
  const SparseMatrix& stiffness_term(int q) const { return m_k_terms[q]; }
  virtual Eigen::VectorXd stiffness_coefficients(const Param& mu) const = 0;
  /// K(μ) on all dofs (Dirichlet rows/columns kept).
  SparseMatrix stiffness(const Param& mu) const;
  bool stiffness_is_constant() const { return m_k_terms.size() == 1; }

  int num_load_terms() const { return static_cast<int>(m_lift_terms.size()); }
  /// Coefficients φ_k(μ) of the affine load/lifting.
  virtual Eigen::VectorXd load_coefficients(const Param& mu) const = 0;
  /// Lifting basis vectors L_k (Dirichlet values; zero elsewhere).
  const std::vector<Eigen::VectorXd>& lifting_terms() const { return m_lift_terms; }
  /// External load basis f_ext,k (same coefficients as the lifting).
  const std::vector<Eigen::VectorXd>& external_load_terms() const { return m_fext_terms; }
  Eigen::VectorXd lifting(const Param& mu) const;
  /// f(μ) = f_ext(μ) − K(μ) u_lift(μ), zeroed on Dirichlet rows.
  Eigen::VectorXd rhs(const Param& mu) const;

  const ContactModel& contact() const { return *m_contact; }
  /// Gram matrix of the H¹ norm used for primal errors.
  const SparseMatrix& h1_gram() const { return m_h1; }
  /// The Q1 mesh (nullptr for the 1D rope).
  const Mesh* mesh() const { return m_mesh.get(); }
  const std::vector<Material>& materials() const { return m_materials; }
  /// Node coordinates of the 1D rope (empty otherwise).
  const Eigen::VectorXd& rope_x() const { return m_rope_x; }
  /// Fingerprint of the discretisation (mesh hash + problem options).
  std::string fingerprint() const { return m_fingerprint; }
  /// Scale of the displacement field (max |lifting| over the range, or |f|/|K|),
  /// used to make penetration and complementarity residuals relative.
  double displacement_scale() const { return m_u_scale; }

 protected:
  void finalize_dofs();  // builds m_free_dofs from m_is_dirichlet

  std::string m_name;
  std::vector<std::string> m_param_names;
  Eigen::VectorXd m_lower, m_upper;
  bool m_lower_open = false;
  int m_dofs_per_node = 2;
  std::vector<char> m_is_dirichlet;
  std::vector<int> m_free_dofs;
  std::vector<SparseMatrix> m_k_terms;
  std::vector<Eigen::VectorXd> m_lift_terms, m_fext_terms;
  std::unique_ptr<ContactModel> m_contact;
  SparseMatrix m_h1;
  std::unique_ptr<Mesh> m_mesh;
  std::vector<Material> m_materials;
  Eigen::VectorXd m_rope_x;
  std::string m_fingerprint;
  double m_u_scale = 1.0;
};

/// \brief The free-dof block K_ff of a matrix on all dofs (Dirichlet rows and columns
/// dropped). \param free_index position of each dof among the free dofs (−1: Dirichlet)
/// \param num_free number of free dofs
SparseMatrix free_block(const SparseMatrix& k, const std::vector<int>& free_index, int num_free);

/// Names accepted by make_problem, for help texts and error messages.
const std::vector<std::string>& problem_names();

/// \brief Builds a problem by name (meshes it with gmsh if needed).
/// \throws InputError for an unknown name (listing the known ones) or a bad mesh.
std::unique_ptr<Problem> make_problem(const std::string& name, const ProblemOptions& options = {});

/// \brief Parses "V" or "V1,V2" into a parameter for `problem` and checks its range.
Param parse_param(const Problem& problem, const std::string& text);

}  // namespace contactrom::fom
